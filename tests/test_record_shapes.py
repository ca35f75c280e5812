"""Each record defined once (records/findings.py): the schema's part generated from it, every field
rendered or declared internal, sealed records decoded into it.

The rule, for a contract-health finding: :class:`~rclverify.records.findings.FindingRow` (extending
:class:`~rclverify.records.findings.HealthFinding`) is the only statement of its fields; the
``findings[]`` items of docs/assurance.schema.json are generated from it (records/schema_gen.py); each
field is read by one of the report's finding renderers (report/templates/parts/findings.{html,md}.j2)
or named in :data:`~rclverify.records.findings.INTERNAL`.  Each check is also run on a definition with a
field added, and must then fail.  In-process and cheap: no pipeline runs here.
"""
from __future__ import annotations

import copy
import typing
from pathlib import Path
from typing import Any, Iterable, Mapping

import jinja2
import msgspec
import pytest
from jinja2 import nodes

from _report_schema import SCHEMA
from rclverify.records import schema_gen
from rclverify.records.findings import INTERNAL, FindingRow, HealthFinding
from rclverify.report.render import part_renderer
from rclverify.report.fragments import FragmentCache

PARTS = Path(__file__).resolve().parents[1] / "src" / "rclverify" / "report" / "templates" / "parts"
RENDERERS = ("findings.html.j2", "findings.md.j2")


def fields_read(source: str) -> set[str]:
    """The attributes a template reads on the loop variable of each ``for`` over ``...|findings``
    (the filter that decodes the rows into :class:`FindingRow`), found in jinja2's parse tree."""
    tree = jinja2.Environment().parse(source)
    out: set[str] = set()
    for loop in tree.find_all(nodes.For):
        if not (isinstance(loop.iter, nodes.Filter) and loop.iter.name == "findings"
                and isinstance(loop.target, nodes.Name)):
            continue
        var = loop.target.name
        for n in loop.find_all(nodes.Getattr):
            if isinstance(n.node, nodes.Name) and n.node.name == var:
                out.add(n.attr)
        for n in loop.find_all(nodes.Getitem):
            if isinstance(n.node, nodes.Name) and n.node.name == var and isinstance(n.arg, nodes.Const):
                out.add(str(n.arg.value))
    return out


def unaccounted(cls: type[msgspec.Struct], sources: Iterable[str], internal: Mapping[str, str]) -> list[str]:
    """What breaks the rule for ``cls``: a field no renderer reads and not internal, an internal name
    that is no field, a field both internal and rendered, a read of a name that is no field."""
    fields = set(cls.__struct_fields__)
    read = set().union(*(fields_read(s) for s in sources))
    out = [f"{k}: neither rendered nor declared internal" for k in sorted(fields - read - set(internal))]
    out += [f"{k}: declared internal but no field" for k in sorted(set(internal) - fields)]
    out += [f"{k}: declared internal but rendered" for k in sorted(set(internal) & read)]
    out += [f"{k}: rendered but no field" for k in sorted(read - fields)]
    return out


def _sources() -> list[str]:
    return [(PARTS / name).read_text(encoding="utf-8") for name in RENDERERS]


def test_every_field_of_a_finding_is_rendered_or_internal() -> None:
    assert unaccounted(FindingRow, _sources(), INTERNAL) == []
    assert all(why for why in INTERNAL.values())  # each internal field says why it is not shown


class _WithMargin(FindingRow, frozen=True, omit_defaults=True, forbid_unknown_fields=True):
    """The definition with one field added, as a change to records/findings.py would add it."""
    margin_added_here: str = ""


def test_a_field_added_and_not_rendered_fails_until_rendered_or_internal() -> None:
    sources = _sources()
    assert unaccounted(_WithMargin, sources, INTERNAL) == ["margin_added_here: neither rendered nor declared internal"]
    # declared internal: accounted for
    assert unaccounted(_WithMargin, sources, {**INTERNAL, "margin_added_here": "why it is not shown"}) == []
    # rendered: the HTML part with one more read of the row
    html = sources[0].replace("{{ f.check }}", "{{ f.check }} {{ f.margin_added_here }}", 1)
    assert html != sources[0]
    assert unaccounted(_WithMargin, [html, sources[1]], INTERNAL) == []
    # a read outside the loop over the decoded rows does not count
    assert unaccounted(_WithMargin, [sources[0] + "{{ f.margin_added_here }}", sources[1]], INTERNAL) != []
    # a field that is rendered may not also be declared internal
    assert unaccounted(FindingRow, sources, {**INTERNAL, "core": "x"}) == ["core: declared internal but rendered"]


def test_the_schema_findings_part_is_generated_from_the_definition() -> None:
    assert SCHEMA["properties"]["findings"] == schema_gen.generated_part("findings")
    items = SCHEMA["properties"]["findings"]["items"]
    assert list(items["properties"]) == list(FindingRow.__struct_fields__)
    assert items["additionalProperties"] is False


def test_a_field_added_reaches_the_schema_and_the_checked_in_file_then_differs(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(schema_gen.GENERATED, "findings", (_WithMargin, schema_gen.GENERATED["findings"][1]))
    part = schema_gen.generated_part("findings")
    assert part["items"]["properties"]["margin_added_here"]["type"] == "string"
    assert SCHEMA["properties"]["findings"] != part
    regenerated = schema_gen.with_generated(copy.deepcopy(SCHEMA))
    assert regenerated["properties"]["findings"] == part
    assert [k for k in regenerated["properties"] if regenerated["properties"][k] != SCHEMA["properties"][k]] == [
        "findings"]  # only the generated part changes


#: Values of the fields whose type a generic value does not fit, and the text each shows as.
_SET: dict[str, tuple[Any, str]] = {
    "id": ("N.g1.c2.redundant", "N.g1.c2.redundant"), "node": ("N", "N"), "check": ("redundant", "redundant"),
    "guarantee": (1, ""), "status": ("warning", ""), "core": (["x > 0"], "x"), "duration_s": (1.5, "1.5"),
    "solvers": ({"agreement": "two solvers", "why": "both unsat", "cvc5": None, "proof": "", "smt2": ""},
                "two solvers"),
    "acknowledged": ({"reason": "ack-reason", "at": "plan.yaml:3:5"}, "ack-reason"),
    "sha256": ("ab" * 32, "abab"),
}


def _value(name: str, ann: Any) -> tuple[Any, str]:
    """A value of field ``name`` (annotation ``ann``) and the text a renderer that shows it writes."""
    if name in _SET:
        return _SET[name]
    args = [a for a in (typing.get_args(ann) or (ann,)) if a is not type(None)]
    if args == [str]:
        return f"{name}-text", f"{name}-text"
    if typing.get_origin(args[0]) is dict:
        return {f"{name}-key": f"{name}-value"}, f"{name}-value"
    if typing.get_origin(args[0]) is list:
        return [f"{name}-item"], f"{name}-item"
    raise AssertionError(f"{name}: give the field a value in _SET (its type {ann} has no generic one)")


def _full_row(cls: type[msgspec.Struct] = FindingRow) -> tuple[dict[str, Any], dict[str, str]]:
    """A warning row of ``cls`` with every field set to a value of its own, and each field's shown text."""
    hints = typing.get_type_hints(cls)
    made = {k: _value(k, hints[k]) for k in cls.__struct_fields__}
    return {k: v for k, (v, _) in made.items()}, {k: t for k, (_, t) in made.items()}


def test_the_renderers_show_each_field_they_read() -> None:
    """Both parts render a row with every field set (and the same row not acknowledged, whose warning
    offers its sha256 to acknowledge it); each field's value but the internal ones is in one of them."""
    part = part_renderer(FragmentCache(), "")
    row, shown = _full_row()
    rows = [row, {k: v for k, v in row.items() if k != "acknowledged"} | {"id": "N.g1.c3.redundant"}]
    text = str(part("findings.html", rows=rows)) + part("findings.md", rows=rows)
    assert [k for k, t in shown.items() if k not in INTERNAL and t not in text] == []
    assert all(shown[k] not in text for k in INTERNAL)


def test_an_undeclared_key_never_reaches_a_renderer_or_the_report() -> None:
    part = part_renderer(FragmentCache(), "")
    with pytest.raises(msgspec.ValidationError, match="margin_added_here"):
        part("findings.html", rows=[{**_full_row()[0], "margin_added_here": "0.5 m"}])
    with pytest.raises(msgspec.ValidationError, match="margin_added_here"):
        FindingRow.of({**_full_row()[0], "margin_added_here": "0.5 m"})


def test_a_sealed_health_record_decodes_into_the_definition() -> None:
    f = HealthFinding("N.realizable", "N", "realizable", None, "ok", "m", "e", witness={"out.y": "1"},
                      smt2="artifacts/health/N.realizable.smt2")
    j = f.to_json()
    # every field in the JSON, none at its default left out (a key's presence never differs run to run)
    assert list(j) == list(HealthFinding.__struct_fields__) and j["model"] is None and j["duration_s"] == 0.0
    assert msgspec.convert(j, HealthFinding) == f
    with pytest.raises(msgspec.ValidationError):
        msgspec.convert({**j, "guarantee": "one"}, HealthFinding)
    # the two queries are not compared: the same finding with a re-numbered query text is equal
    assert msgspec.structs.replace(f, smt2="(check-sat)") == f and hash(msgspec.structs.replace(f, smt2="")) == hash(f)
