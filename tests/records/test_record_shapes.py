"""Each record defined once (records/findings.py, records/obligations.py, records/evidence_rows.py): the
schema's part generated from it, every field rendered or declared internal, sealed records decoded into it.

The rule, for a contract-health finding: :class:`~rclverify.records.findings.FindingRow` (extending
:class:`~rclverify.records.findings.HealthFinding`) is the only statement of its fields; the
``findings[]`` items of docs/assurance.schema.json are generated from it (records/schema_gen.py); each
field is read by one of the report's finding renderers (report/templates/parts/findings.{html,md}.j2)
or named in :data:`~rclverify.records.findings.INTERNAL`.  The same holds for an obligation's row
(:class:`~rclverify.records.obligations.ObligationRow`, ``obligations[]``, rendered by
report/templates/parts/obligations.{html,md}.j2) an evidence record's row
(:class:`~rclverify.records.evidence_rows.EvidenceRow`, ``evidence[]``, rendered by
report/templates/parts/evidence.{html,md}.j2), a row of the statistics table
(:class:`~rclverify.records.statistics_rows.StatisticsRow`, ``statistics[]``, rendered by
report/templates/parts/statistics.{html,md}.j2), a chosen standard's row
(:class:`~rclverify.records.standards_rows.StandardRow`, ``standards[]``, rendered by
report/templates/parts/standards.{html,md}.j2) and a requirement's row
(:class:`~rclverify.records.requirement_rows.RequirementRow`, ``requirements[]``, rendered by
report/templates/assurance.{html,md}.j2).  Each check is also run on a definition with a field
added, and must then fail.  In-process and cheap: no pipeline runs here.

The renderers written in Python (SARIF: report/sarif.py, JUnit: report/junit.py, ``rclverify explain``:
report/explain.py) are held to the same rule for a finding, an obligation and a problem (:data:`CODE`,
:data:`CODE_RECORDS`): each field is read by each of them off the decoded row or named in the record
module's ``INTERNAL_TO[<renderer>]`` with the reason (``"*"``: the renderer shows no row of that record).
The reads are found in Python's parse tree as the templates' are in jinja2's (:func:`fields_read_code`).
"""
from __future__ import annotations

import ast as pyast
import copy
import inspect
import subprocess
import sys
import typing
from pathlib import Path
from typing import Any, Iterable, Mapping, NamedTuple

import jinja2
import msgspec
import pytest
from jinja2 import nodes

from _report_schema import SCHEMA
from _typed_rows import typed_report
from rclverify.records import report_schema, schema_gen, statuses
from rclverify.records import evidence_rows, obligations, requirement_rows, standards_rows, statistics_rows
from rclverify.records import deadline_rows, lint_rows, margin_rows, node_rows, problem_rows, verdict_rows
from rclverify.records import derived_rows, findings, side_condition_rows
from rclverify.records.evidence_rows import EvidenceRow
from rclverify.records.findings import INTERNAL, FindingRow, HealthFinding
from rclverify.records.obligations import ObligationRow
from rclverify.records.report_record import AssuranceReport
from rclverify.records.requirement_rows import RequirementRow
from rclverify.records.standards_rows import StandardRow
from rclverify.records.statistics_rows import RequirementRuns, StatisticsRow
from rclverify.report.render import part_renderer
from rclverify.report.fragments import FragmentCache

PARTS = Path(__file__).resolve().parents[2] / "src" / "rclverify" / "report" / "templates" / "parts"
#: The renderers written in Python, by the name the records' ``INTERNAL_TO`` tables give them: their modules.
CODE: dict[str, tuple[Path, ...]] = {name: tuple(PARTS.parents[1] / f"{m}.py" for m in modules) for name, modules in (
    ("sarif", ("sarif",)), ("junit", ("junit",)), ("explain", ("explain", "explain_items")))}


def _code(renderer: str) -> list[str]:
    return [p.read_text(encoding="utf-8") for p in CODE[renderer]]
RENDERERS = ("findings.html.j2", "findings.md.j2")


class Record(NamedTuple):
    """A record defined once: its class, its INTERNAL table, the filter its renderers decode it with,
    its renderers (parts), and the schema key generated from it."""
    cls: type[msgspec.Struct]
    internal: Mapping[str, str]
    filter: str
    renderers: tuple[str, ...]


_MAIN = ("../assurance.html.j2", "../assurance.md.j2")

RECORDS: dict[str, Record] = {
    # a requirement's row is rendered by the main templates (the requirements table, the Z3 checks' list)
    "requirements": Record(RequirementRow, requirement_rows.INTERNAL, "requirement_rows",
                           ("../assurance.html.j2", "../assurance.md.j2")),
    "findings": Record(FindingRow, INTERNAL, "findings", RENDERERS),
    "obligations": Record(ObligationRow, obligations.INTERNAL, "obligation_row",
                          ("obligations.html.j2", "obligations.md.j2")),
    "evidence": Record(EvidenceRow, evidence_rows.INTERNAL, "evidence_row", ("evidence.html.j2", "evidence.md.j2")),
    "statistics": Record(StatisticsRow, statistics_rows.INTERNAL, "statistics_rows",
                         ("statistics.html.j2", "statistics.md.j2")),
    "standards": Record(StandardRow, standards_rows.INTERNAL, "standard_rows", ("standards.html.j2", "standards.md.j2")),
    # rendered by the main templates: the pending and unverified tables, the lint table, the near misses
    "problems": Record(problem_rows.ProblemRow, problem_rows.INTERNAL, "problem_rows", _MAIN),
    "pending": Record(verdict_rows.PendingRow, verdict_rows.INTERNAL, "pending_rows", _MAIN),
    "unverified": Record(node_rows.UnverifiedRow, node_rows.UNVERIFIED_INTERNAL, "unverified_rows", _MAIN),
    "lint": Record(lint_rows.LintRow, lint_rows.INTERNAL, "lint_rows", _MAIN),
    "near_misses": Record(margin_rows.NearMissRow, margin_rows.NEAR_MISS_INTERNAL, "near_miss_rows", _MAIN),
    "margins": Record(margin_rows.MarginRow, margin_rows.INTERNAL, "margin_rows", ("margins.html.j2", "margins.md.j2")),
    # a node's section of the calculus (its contract, derived property, side conditions) and its LaTeX
    "nodes": Record(node_rows.NodeRow, node_rows.INTERNAL, "node_rows",
                    ("section.html.j2", "section.md.j2", "latex.html.j2", "latex.md.j2")),
    "derived_properties": Record(derived_rows.DerivedPropertyRow, derived_rows.INTERNAL, "derived_rows",
                                 ("section.html.j2", "section.md.j2")),
    "side_conditions": Record(side_condition_rows.SideConditionRow, side_condition_rows.INTERNAL,
                              "side_condition_rows", ("section.html.j2", "section.md.j2")),
    "deadlines": Record(deadline_rows.DeadlineRow, deadline_rows.INTERNAL, "deadline_rows",
                        ("deadlines.html.j2", "deadlines.md.j2")),
}

#: Records within a row of :data:`RECORDS`, each decoded by its renderers with a filter of its own.
NESTED: dict[str, Record] = {
    "nodes.guarantees": Record(node_rows.GuaranteeRow, node_rows.GUARANTEE_INTERNAL, "guarantee_rows",
                               ("section.html.j2", "section.md.j2")),
    "deadlines.chain": Record(deadline_rows.DeadlineHop, deadline_rows.HOP_INTERNAL, "hop_rows",
                              ("deadlines.html.j2", "deadlines.md.j2")),
}


def fields_read(source: str, filter_name: str = "findings") -> set[str]:
    """The attributes a template reads on a name bound to a value of ``...|<filter_name>`` (the filter that
    decodes rows into their class): the loop variable of a ``for`` over it, or a name ``set`` to it inside
    a loop (read within that loop), found in jinja2's parse tree."""
    tree = jinja2.Environment().parse(source)
    out: set[str] = set()

    def decoded(x: nodes.Node) -> bool:
        return isinstance(x, nodes.Filter) and x.name == filter_name

    for loop in tree.find_all(nodes.For):
        names = {loop.target.name} if decoded(loop.iter) and isinstance(loop.target, nodes.Name) else set()
        names |= {a.target.name for a in loop.find_all(nodes.Assign)
                  if decoded(a.node) and isinstance(a.target, nodes.Name)}
        for n in loop.find_all(nodes.Getattr):
            if isinstance(n.node, nodes.Name) and n.node.name in names:
                out.add(n.attr)
        for n in loop.find_all(nodes.Getitem):
            if isinstance(n.node, nodes.Name) and n.node.name in names and isinstance(n.arg, nodes.Const):
                out.add(str(n.arg.value))
    return out


def fields_read_code(source: str, record: type[msgspec.Struct]) -> set[str]:
    """The attributes the Python module ``source`` reads on a name bound to a decoded row of ``record``,
    found in Python's parse tree, function by function: a parameter or a variable annotated with the
    class, the target of a ``for`` (or a comprehension) over the record module's ``rows_of`` (under any
    alias it is imported as) or over the decoded report's part of that record (``report.findings``), a name assigned ``<Class>.of(...)``.  A name is one name per function: a
    function that also binds it to something else reads that too (and a read of no field then shows)."""
    tree = pyast.parse(source)
    name = record.__name__
    # the record module's rows_of, when it decodes this record (a module of several records decodes one)
    decodes = typing.get_type_hints(getattr(sys.modules[record.__module__], "rows_of", lambda: None)).get("return")
    decoders = {a.asname or a.name for n in pyast.walk(tree) if isinstance(n, pyast.ImportFrom)
                and n.module == record.__module__ for a in n.names if a.name == "rows_of"} if decodes == list[record] else set()
    # the decoded report's parts of this record (AssuranceReport.findings: list[FindingRow], ...)
    parts = {k for k, t in typing.get_type_hints(AssuranceReport).items() if t == list[record]}

    def typed(ann: pyast.expr | None) -> bool:
        return ann is not None and any(isinstance(x, pyast.Name) and x.id == name or isinstance(x, pyast.Constant)
                                       and isinstance(x.value, str) and name in x.value for x in pyast.walk(ann))

    def decoded(x: pyast.expr) -> bool:
        if isinstance(x, pyast.Attribute) and x.attr in parts:  # a loop over the decoded report's part
            return True
        f = x.func if isinstance(x, pyast.Call) else None
        return isinstance(f, pyast.Name) and f.id in decoders or (
            isinstance(f, pyast.Attribute) and f.attr == "of" and isinstance(f.value, pyast.Name) and f.value.id == name)

    out: set[str] = set()
    for fn in pyast.walk(tree):
        if not isinstance(fn, (pyast.FunctionDef, pyast.AsyncFunctionDef)):
            continue
        names = {a.arg for a in [*fn.args.args, *fn.args.kwonlyargs] if typed(a.annotation)}
        for n in pyast.walk(fn):
            if isinstance(n, pyast.AnnAssign) and isinstance(n.target, pyast.Name) and typed(n.annotation):
                names.add(n.target.id)
            elif isinstance(n, (pyast.For, pyast.comprehension)) and isinstance(n.target, pyast.Name) \
                    and decoded(n.iter):
                names.add(n.target.id)
            elif isinstance(n, pyast.Assign) and decoded(n.value):
                names |= {t.id for t in n.targets if isinstance(t, pyast.Name)}
        out |= {n.attr for n in pyast.walk(fn) if isinstance(n, pyast.Attribute)
                and isinstance(n.value, pyast.Name) and n.value.id in names}
    return out


def unaccounted(cls: type[msgspec.Struct], sources: Iterable[str], internal: Mapping[str, str],
                filter_name: str = "findings", code: type[msgspec.Struct] | None = None) -> list[str]:
    """What breaks the rule for ``cls``: a field no renderer reads and not internal, an internal name
    that is no field, a field both internal and rendered, a read of a name that is no field.  With
    ``code`` (the record class the renderers decode into), ``sources`` are Python modules read by
    :func:`fields_read_code`, a call of the class's own method (``to_json``) is no read of a field, and
    ``internal`` may be ``{"*": why}``: the renderer shows no row of the record, and must read none."""
    fields = set(cls.__struct_fields__)
    if code is None:
        read = set().union(*(fields_read(s, filter_name) for s in sources))
    else:
        read = {k for s in sources for k in fields_read_code(s, code)
                if k in fields or not callable(getattr(cls, k, None))}
        if "*" in internal:
            return [f"{k}: rendered, but the renderer is declared to show no row" for k in sorted(read)]
    out = [f"{k}: neither rendered nor declared internal" for k in sorted(fields - read - set(internal))]
    out += [f"{k}: declared internal but no field" for k in sorted(set(internal) - fields)]
    out += [f"{k}: declared internal but rendered" for k in sorted(set(internal) & read)]
    out += [f"{k}: rendered but no field" for k in sorted(read - fields)]
    return out


def _sources(renderers: tuple[str, ...] = RENDERERS) -> list[str]:
    return [(PARTS / name).read_text(encoding="utf-8") for name in renderers]


@pytest.mark.parametrize("key", [*RECORDS, *NESTED])
def test_every_field_of_a_record_is_rendered_or_internal(key: str) -> None:
    r = RECORDS[key] if key in RECORDS else NESTED[key]
    assert unaccounted(r.cls, _sources(r.renderers), r.internal, r.filter) == []
    assert all(why for why in r.internal.values())  # each internal field says why it is not shown


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


@pytest.mark.parametrize("key", list(schema_gen.GENERATED))
def test_the_schema_part_is_generated_from_the_definition(key: str) -> None:
    assert set(RECORDS) <= set(schema_gen.GENERATED)  # each record checked here has its part generated
    assert SCHEMA["properties"][key] == schema_gen.generated_part(key, SCHEMA)
    items = schema_gen.object_of(SCHEMA["properties"][key])
    if "$ref" in items:  # a class of schema_gen.SHARED: its $defs entry, generated too (test below)
        items = SCHEMA["$defs"][items["$ref"].rsplit("/", 1)[1]]
    assert list(items["properties"]) == list(schema_gen.record_type(key).__struct_fields__)
    assert items["additionalProperties"] is False


@pytest.mark.parametrize("cls", schema_gen.DEFINED, ids=lambda c: c.__name__)
def test_a_shared_entry_is_generated_from_its_class(cls: type[msgspec.Struct]) -> None:
    name = schema_gen.SHARED[cls.__name__]
    assert SCHEMA["$defs"][name] == schema_gen.generated_def(cls)
    assert list(SCHEMA["$defs"][name]["properties"]) == list(cls.__struct_fields__)


def test_every_shared_entry_is_referred_to() -> None:
    """A ``$defs`` entry of a record class no part of the schema refers to is left over: drop it."""
    text = schema_gen.schema_text(SCHEMA)
    assert [n for n in schema_gen.SHARED.values() if f'"#/$defs/{n}"' not in text] == []


def _refs(x: Any) -> set[str]:
    """The ``$defs`` entries the schema part ``x`` refers to, and those they refer to in turn."""
    out: set[str] = set()
    todo = [x]
    while todo:
        y = todo.pop()
        if isinstance(y, dict):
            name = str(y.get("$ref", "")).rsplit("/", 1)[-1]
            if name and name not in out:
                out.add(name)
                todo.append(SCHEMA["$defs"][name])
            todo += list(y.values())
        elif isinstance(y, list):
            todo += y
    return out


def stated_by_hand(schema: dict[str, Any]) -> list[str]:
    """The parts of the report's ``schema`` no record class generates: a top-level key not in
    schema_gen.GENERATED, a ``$defs`` entry that is neither generated (schema_gen.DEFINED), a status
    vocabulary (records/statuses.py, or a union of them schema_gen.UNIONS names), nor reached only from a
    field schema_gen.KEPT states by hand (a tool's record)."""
    kept = set().union(*(_refs(schema_gen.object_of(schema["properties"][k])["properties"][f])
                         for k, fields in schema_gen.KEPT.items() for f in fields))
    allowed = ({schema_gen.SHARED[c.__name__] for c in schema_gen.DEFINED} | set(statuses.VOCABULARY)
               | set(schema_gen.UNIONS.values()) | kept)
    return ([f"properties/{k}" for k in schema["properties"] if k not in schema_gen.GENERATED]
            + [f"$defs/{k}" for k in schema["$defs"] if k not in allowed])


def test_every_top_level_key_of_the_schema_is_generated(monkeypatch: pytest.MonkeyPatch) -> None:
    """docs/assurance.schema.json states nothing by hand but the status vocabularies and the tools' records
    (schema_gen.KEPT): every top-level key is a record class's part, every other ``$defs`` entry a class's."""
    assert list(SCHEMA["properties"]) == list(report_schema.REPORT_KEYS) == SCHEMA["required"]
    assert stated_by_hand(SCHEMA) == []
    assert schema_gen.with_generated(copy.deepcopy(SCHEMA)) == SCHEMA
    # a key or an entry written by hand again is found
    monkeypatch.delitem(schema_gen.GENERATED, "meta")
    hand = copy.deepcopy(SCHEMA)
    hand["$defs"]["nodl_place"] = {"type": "object", "description": "A place a NoDL finding involves."}
    assert stated_by_hand(hand) == ["properties/meta", "$defs/nodl_place"]


def test_the_report_hop_begins_with_the_deadline_stages_hop() -> None:
    """records/deadline_rows.py: the report's hop is the stage's sealed hop (records/stage_records.py) with
    what the report adds, the same keys first, in order."""
    from rclverify.records.deadline_rows import DeadlineHop
    from rclverify.records.stage_records import DeadlineHop as StageHop
    stage = list(typing.get_type_hints(StageHop))
    assert list(DeadlineHop.__struct_fields__)[:len(stage)] == stage
    assert set(DeadlineHop.__struct_fields__[len(stage):]) == {"status", "timing", "monitors", "time_margin"}


class _ObligationWithMargin(ObligationRow, frozen=True, forbid_unknown_fields=True):
    """The obligation row with one field added, as a change to records/obligations.py would add it."""
    margin_added_here: str = ""


def test_a_field_added_to_an_obligation_row_fails_until_rendered_or_internal() -> None:
    r = RECORDS["obligations"]
    sources = _sources(r.renderers)
    assert unaccounted(_ObligationWithMargin, sources, r.internal, r.filter) == [
        "margin_added_here: neither rendered nor declared internal"]
    assert unaccounted(_ObligationWithMargin, sources, {**r.internal, "margin_added_here": "why"}, r.filter) == []
    html = sources[0].replace("{{ o.backend }}", "{{ o.backend }} {{ o.margin_added_here }}", 1)
    assert html != sources[0]
    assert unaccounted(_ObligationWithMargin, [html, sources[1]], r.internal, r.filter) == []
    # a read of the undecoded row (``row.obligation``) does not count: only the decoded row's reads do
    raw = sources[0].replace("{{ o.backend }}", "{{ o.backend }} {{ row.obligation.margin_added_here }}", 1)
    assert unaccounted(_ObligationWithMargin, [raw, sources[1]], r.internal, r.filter) != []
    # the schema part follows the definition, and then the checked-in file differs
    with pytest.MonkeyPatch.context() as mp:
        mp.setitem(schema_gen.GENERATED, "obligations", (list[_ObligationWithMargin], schema_gen.GENERATED["obligations"][1]))
        part = schema_gen.generated_part("obligations")
    assert part["items"]["properties"]["margin_added_here"]["type"] == "string"
    assert SCHEMA["properties"]["obligations"] != part


_OBLIGATION: dict[str, Any] = {
    "id": "N.g1.hoare.c1", "node": "Nodey", "guarantee": 1, "backend": "backend-text", "kind": "model checking",
    "instance": "instance-text", "statement": "statement_text", "source": "a.rcl:3:4",
    "artifact": "artifact-text", "status": "failed"}


def test_the_obligation_renderers_show_each_field_and_refuse_an_undeclared_key() -> None:
    part = part_renderer(FragmentCache(), "")
    shown = {**{k: str(v) for k, v in _OBLIGATION.items()}, "guarantee": "Nodey g1", "source": "rcl:3:4"}
    assert list(shown) == list(ObligationRow.__struct_fields__)
    rows = [{"obligation": _OBLIGATION, "evidence": ["ev-x"]}]
    for name in ("obligations.html", "obligations.md"):
        text = str(part(name, rows=rows))
        assert [k for k, t in shown.items() if t not in text] == [], name
    with pytest.raises(msgspec.ValidationError, match="margin_added_here"):
        part("obligations.html", rows=[{"obligation": {**_OBLIGATION, "margin_added_here": "0.5 m"}, "evidence": []}])
    # the JSON object the report writes is every field, in the order declared
    assert ObligationRow.of(_OBLIGATION).to_json() == _OBLIGATION
    assert list(ObligationRow.of(_OBLIGATION).to_json()) == list(ObligationRow.__struct_fields__)


def test_a_field_added_reaches_the_schema_and_the_checked_in_file_then_differs(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(schema_gen.GENERATED, "findings", (list[_WithMargin], schema_gen.GENERATED["findings"][1]))
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


class _EvidenceWithMargin(EvidenceRow, frozen=True, forbid_unknown_fields=True):
    """The evidence row with one field added, as a change to records/evidence_rows.py would add it."""
    margin_added_here: str = ""


def test_a_field_added_to_an_evidence_row_fails_until_rendered_or_internal() -> None:
    r = RECORDS["evidence"]
    sources = _sources(r.renderers)
    assert unaccounted(_EvidenceWithMargin, sources, r.internal, r.filter) == [
        "margin_added_here: neither rendered nor declared internal"]
    assert unaccounted(_EvidenceWithMargin, sources, {**r.internal, "margin_added_here": "why"}, r.filter) == []
    html = sources[0].replace("{{ ev.tool_version }}", "{{ ev.tool_version }} {{ ev.margin_added_here }}", 1)
    assert html != sources[0]
    assert unaccounted(_EvidenceWithMargin, [html, sources[1]], r.internal, r.filter) == []
    raw = sources[0].replace("{{ ev.tool_version }}", "{{ ev.tool_version }} {{ item.record.margin_added_here }}", 1)
    assert unaccounted(_EvidenceWithMargin, [raw, sources[1]], r.internal, r.filter) != []
    with pytest.MonkeyPatch.context() as mp:
        mp.setitem(schema_gen.GENERATED, "evidence", (list[_EvidenceWithMargin], schema_gen.GENERATED["evidence"][1]))
        part = schema_gen.generated_part("evidence", SCHEMA)
        regenerated = schema_gen.with_generated(copy.deepcopy(SCHEMA))
    assert part["items"]["properties"]["margin_added_here"]["type"] == "string"
    assert SCHEMA["properties"]["evidence"] != part == regenerated["properties"]["evidence"]
    # the monitors backend's run summary keeps its hand-written schema in the generated part
    assert part["items"]["properties"]["monitoring"] == SCHEMA["properties"]["evidence"]["items"]["properties"]["monitoring"]
    with pytest.raises(KeyError, match="monitoring"):
        schema_gen.generated_part("evidence")


#: An evidence row with every field set to a value of its own, and the text each shows as.
_EVIDENCE: dict[str, tuple[Any, str]] = {
    "obligation": ("N.g1.property_tests.c1", "N.g1.property_tests.c1"), "backend": ("backend-text", "backend-text"),
    "kind": ("testing", "testing"), "status": ("failed", "failed"), "tool": ("tool-text", "tool-text"),
    "tool_version": ("9.8.7", "9.8.7"), "started": ("2026-01-02T03:04:05Z", "2026-01-02T03:04:05Z"),
    "duration_s": (1.5, "1.5"), "explanation": ("explanation-text", "explanation-text"),
    "counterexample": ({"in.x": "42"}, "42"), "artifacts": (["artifact-text"], "artifact-text"),
    "log_excerpt": ("log-text", "log-text"), "figures": ([["figure-name", "figure-value"]], "figure-value"),
    "plot_svg": ("<svg><title>plot-text</title></svg>", "plot-text"),
    "solvers": ({"agreement": "two solvers", "why": "solvers-text", "cvc5": None}, "solvers-text"),
    "examples": ({"run": 100, "valid": 90, "rejected": 10, "failures": 1, "inconclusive": 0, "seed": 7,
                  "replay": "replay-text", "facts": [], "coverage": {}}, "replay-text"),
    "monitoring": ({"trace": "trace-text", "events_read": 3, "node_events": 2, "horizon_s": 1.0, "sha256": "ab" * 32,
                    "counts": {"ok": 3}, "first_violation": None, "first_assumption_violation": None}, "trace-text"),
    "statistics": ({"sha256": "cd" * 32, "answers": 3, "violations": 0, "inconclusive": 0, "seconds": 2.0,
                    "recorded": "2026-01-02", "environment": "environment-text", "origin": "operation"},
                   "environment-text"),
    "strength": ({"kind": "tested", "doubt": 0.2, "detail": "strength-text"}, "strength-text"),
}


def test_the_evidence_renderers_show_each_field_they_read_and_refuse_an_undeclared_key() -> None:
    part = part_renderer(FragmentCache(), "")
    assert list(_EVIDENCE) == list(EvidenceRow.__struct_fields__)
    row = {k: v for k, (v, _) in _EVIDENCE.items()}
    rows = [{"anchor": "ev-x", "record": row}]
    html, md = str(part("evidence.html", rows=rows)), part("evidence.md", rows=rows)
    for k, (_, text) in _EVIDENCE.items():
        if k in evidence_rows.INTERNAL:
            assert text not in html + md, k
        else:
            assert text in html and (text in md or k == "plot_svg"), k  # the Markdown report draws no plot
    with pytest.raises(msgspec.ValidationError, match="margin_added_here"):
        part("evidence.html", rows=[{"anchor": "ev-y", "record": {**row, "margin_added_here": "0.5 m"}}])
    # the JSON object the report writes is every field, in the order declared, each at its default if unset
    bare = EvidenceRow(*(row[k] for k in list(EvidenceRow.__struct_fields__)[:12])).to_json()
    assert list(bare) == list(EvidenceRow.__struct_fields__)
    assert (bare["figures"], bare["plot_svg"], bare["solvers"], bare["monitoring"], bare["strength"]) == (
        [], "", None, {}, None)
    assert EvidenceRow.of(bare).to_json() == bare


class _RequirementWithMargin(RequirementRow, frozen=True, forbid_unknown_fields=True):
    """The requirement row with one field added, as a change to records/requirement_rows.py would add it."""
    margin_added_here: str = ""


def test_a_field_added_to_a_requirement_row_fails_until_rendered_or_internal() -> None:
    r = RECORDS["requirements"]
    sources = _sources(r.renderers)
    assert unaccounted(_RequirementWithMargin, sources, r.internal, r.filter) == [
        "margin_added_here: neither rendered nor declared internal"]
    assert unaccounted(_RequirementWithMargin, sources, {**r.internal, "margin_added_here": "why"}, r.filter) == []
    html = sources[0].replace("{{ req.note|prose }}", "{{ req.note|prose }} {{ req.margin_added_here }}", 1)
    assert html != sources[0]
    assert unaccounted(_RequirementWithMargin, [html, sources[1]], r.internal, r.filter) == []
    # a read of an undecoded row (the view's ``t.req``) does not count
    raw = sources[0].replace("{% set req = t.req %}", "{% set req = t.req %}{{ req.margin_added_here }}", 1)
    assert raw != sources[0]
    assert unaccounted(_RequirementWithMargin, [raw, sources[1]], r.internal, r.filter) != []
    with pytest.MonkeyPatch.context() as mp:
        mp.setitem(schema_gen.GENERATED, "requirements",
                   (list[_RequirementWithMargin], schema_gen.GENERATED["requirements"][1]))
        part = schema_gen.generated_part("requirements", SCHEMA)
    assert part["items"]["properties"]["margin_added_here"]["type"] == "string"
    assert SCHEMA["properties"]["requirements"] != part
    # the requirements stage's check record keeps its hand-written schema in the generated part
    assert part["items"]["properties"]["check"] == SCHEMA["properties"]["requirements"]["items"]["properties"]["check"]


_REQUIREMENT: dict[str, Any] = {
    "id": "R1", "text": "text-words", "verdict": "met", "status": "discharged", "note": "note-words",
    "support": [{"node": "N", "guarantee": 1, "text": "y > 0", "source": "a.rcl:3:4", "status": "discharged",
                 "obligations": ["N.g1.hoare.c1"]}],
    "check": {"formal": "y > 0", "source": "plan.yaml:4:5", "declarations": []}}


def test_a_requirement_row_is_written_whole_and_refuses_an_undeclared_key() -> None:
    from rclverify.model.plan.declarations import STRENGTHS
    assert typing.get_args(requirement_rows.StrengthKind) == STRENGTHS  # the plan's strength words
    row = RequirementRow.of(_REQUIREMENT).to_json()
    # every field, in the order declared, the later passes' at their defaults (a key never absent in one run)
    assert list(row) == list(RequirementRow.__struct_fields__)
    assert (row["deadline"], row["without_deadline"], row["statistics"], row["confidence"], row["limited_by"],
            row["required_strength"], row["strength_shortfall"]) == (None, None, [], None, None, None, [])
    assert RequirementRow.of(row).to_json() == row
    with pytest.raises(msgspec.ValidationError, match="margin_added_here"):
        RequirementRow.of({**row, "margin_added_here": "0.5 m"})
    with pytest.raises(msgspec.ValidationError, match="verdict"):
        RequirementRow.of({**row, "verdict": "nearly met"})
    env = __import__("rclverify.report.templating", fromlist=["environment"]).environment()
    shown = env.from_string("{% for q in rows|requirement_rows %}{{ q.id }} {{ q|reqbadges }} {{ q.note }}"
                            "{% endfor %}").render(rows=[row])
    assert "R1" in shown and "note-words" in shown
    with pytest.raises(msgspec.ValidationError, match="margin_added_here"):
        env.from_string("{% for q in rows|requirement_rows %}{{ q.id }}{% endfor %}").render(
            rows=[{**row, "margin_added_here": "0.5 m"}])


class _StatisticsWithMargin(StatisticsRow, frozen=True, forbid_unknown_fields=True):
    """The statistics row with one field added, as a change to records/statistics_rows.py would add it."""
    margin_added_here: str = ""


def test_a_field_added_to_a_statistics_row_fails_until_rendered_or_internal() -> None:
    r = RECORDS["statistics"]
    sources = _sources(r.renderers)
    assert unaccounted(_StatisticsWithMargin, sources, r.internal, r.filter) == [
        "margin_added_here: neither rendered nor declared internal"]
    assert unaccounted(_StatisticsWithMargin, sources, {**r.internal, "margin_added_here": "why"}, r.filter) == []
    html = sources[0].replace("{{ s.origin }}", "{{ s.origin }} {{ s.margin_added_here }}", 1)
    assert html != sources[0]
    assert unaccounted(_StatisticsWithMargin, [html, sources[1]], r.internal, r.filter) == []
    with pytest.MonkeyPatch.context() as mp:
        mp.setitem(schema_gen.GENERATED, "statistics", (list[_StatisticsWithMargin], schema_gen.GENERATED["statistics"][1]))
        part = schema_gen.generated_part("statistics")
    assert part["items"]["properties"]["margin_added_here"]["type"] == "string"
    assert SCHEMA["properties"]["statistics"] != part


#: One row of each kind, as report/statistics.py writes them, each field's value its own.
_STATISTICS: list[dict[str, Any]] = [
    StatisticsRow(kind="runs", node="Nodey", environment="env-text", origin="operation",
                  counts={"runs": 17, "violating_runs": 0, "undecided_runs": 0, "answers": 90, "seconds": 1.5},
                  recorded={"live": 17}, level=0.95, bound=0.1625, note="note-text").to_json(),
    StatisticsRow(kind="target", node="Nodey", environment="env-text", origin="trials", counts=None, level=0.9,
                  bound=0.25, obligation="Nodey.g1.experiment.t1", backend="experiment", status="pending",
                  target="target-text", runs_needed=13, sprt="continue").to_json(),
    StatisticsRow(kind="requirement", requirement="R1", environment="env-text", origin="operation",
                  **{k: v for k, v in RequirementRuns(
                      environment="env-text", origin="operation", counts={"runs": 3}, bound=0.6316, level=0.95,
                      target="target-text", status="failed", explanation="explanation-text", runs_needed=None,
                      sprt="reject").to_json().items() if k not in ("environment", "origin")}).to_json(),
]


def test_the_statistics_renderers_show_each_field_they_read_and_refuse_an_undeclared_key() -> None:
    part = part_renderer(FragmentCache(), "")
    html, md = str(part("statistics.html", rows=_STATISTICS)), part("statistics.md", rows=_STATISTICS)
    for text in ("Nodey (every run)", "env-text", "operation", "17", "live 17", "0.163 at 95 %", "note-text",
                 "Nodey.g1.experiment.t1", "target-text", "13", "continue", "R1", "explanation-text", "reject"):
        assert text in html and text in md, text
    assert all(list(r) == list(StatisticsRow.__struct_fields__) for r in _STATISTICS)  # every field, always
    with pytest.raises(msgspec.ValidationError, match="margin_added_here"):
        part("statistics.html", rows=[{**_STATISTICS[0], "margin_added_here": "0.5 m"}])
    with pytest.raises(msgspec.ValidationError, match="kind"):
        StatisticsRow.of({**_STATISTICS[0], "kind": "guess"})


class _StandardWithMargin(StandardRow, frozen=True, forbid_unknown_fields=True):
    """The standard's row with one field added, as a change to records/standards_rows.py would add it."""
    margin_added_here: str = ""


def test_a_field_added_to_a_standard_row_fails_until_rendered_or_internal() -> None:
    r = RECORDS["standards"]
    sources = _sources(r.renderers)
    assert unaccounted(_StandardWithMargin, sources, r.internal, r.filter) == [
        "margin_added_here: neither rendered nor declared internal"]
    assert unaccounted(_StandardWithMargin, sources, {**r.internal, "margin_added_here": "why"}, r.filter) == []
    html = sources[0].replace("{{ s.title }}", "{{ s.title }} {{ s.margin_added_here }}", 1)
    assert html != sources[0]
    assert unaccounted(_StandardWithMargin, [html, sources[1]], r.internal, r.filter) == []
    with pytest.MonkeyPatch.context() as mp:
        mp.setitem(schema_gen.GENERATED, "standards", (list[_StandardWithMargin], schema_gen.GENERATED["standards"][1]))
        part = schema_gen.generated_part("standards")
    assert part["items"]["properties"]["margin_added_here"]["type"] == "string"
    assert SCHEMA["properties"]["standards"] != part


_NODE: dict[str, Any] = {
    "name": "Nodey", "source": "a.rcl:1:1", "status": "failed", "inputs": [], "outputs": [], "assumptions": [],
    "guarantees": [{"index": 1, "text": "out.y > 0", "source": "a.rcl:3:3", "status": "failed", "obligations": []}],
    "latex": "latex-text"}


def test_a_node_section_shows_the_later_passes_fields_only_when_they_are_set() -> None:
    """records/node_rows.py: confidence, limited_by, strength and culprit_of are UNSET until their pass runs
    (or when no problem blames the item); the section shows each when set and nothing of it when not."""
    part = part_renderer(FragmentCache(), "")
    bare = {"name": "Nodey", "node": _NODE, "derived": [], "side": [], "findings": [], "ob_status": {}}
    culprit = [{"status": "failed", "sentence": "culprit-sentence"}]
    full = {**bare, "node": {**_NODE, "confidence": 0.25, "culprit_of": culprit,
                             "limited_by": {"label": "limit-label", "kind": "tested", "doubt": 0.75},
                             "guarantees": [{**_NODE["guarantees"][0], "strength": {"kind": "strength-kind",
                                                                                    "doubt": 0.5},
                                             "culprit_of": culprit}]}}
    for name in ("section.html", "section.md"):
        plain, shown = str(part(name, sec=bare)), str(part(name, sec=full))
        assert "UNSET" not in plain + shown and "out.y" in plain
        for text in ("Confidence 0.25", "limit-label", "strength-kind", "culprit-sentence", "culprit of 1 problem"):
            assert text in shown and text not in plain, (name, text)


#: The LaTeX appendix (the contracts typeset, a piece of the HTML and Markdown reports): its parts.
LATEX = ("latex.html.j2", "latex.md.j2")


class _NodeWithMargin(node_rows.NodeRow, frozen=True, forbid_unknown_fields=True):
    """The node row with one field added, as a change to records/node_rows.py would add it."""
    margin_added_here: str = ""


def test_every_field_of_a_node_is_typeset_by_the_latex_appendix_or_internal_to_it() -> None:
    """The LaTeX appendix shows a subset of a node's row on purpose (its name and its contract typeset); the
    rest is named in node_rows.LATEX_INTERNAL with the reason.  A field added to the row fails until the
    appendix shows it or the table names it; a field shown may not also be named."""
    sources = _sources(LATEX)
    internal = node_rows.LATEX_INTERNAL
    assert unaccounted(node_rows.NodeRow, sources, internal, "node_rows") == []
    assert all(why for why in internal.values())
    assert unaccounted(_NodeWithMargin, sources, internal, "node_rows") == [
        "margin_added_here: neither rendered nor declared internal"]
    assert unaccounted(_NodeWithMargin, sources, {**internal, "margin_added_here": "why"}, "node_rows") == []
    shown = [x.replace("n.latex", "n.latex ~ n.margin_added_here", 1) for x in sources]
    assert shown != sources and unaccounted(_NodeWithMargin, shown, internal, "node_rows") == []
    # a read outside the loop over the decoded rows does not count
    assert unaccounted(_NodeWithMargin, [sources[0] + "{{ n.margin_added_here }}", sources[1]], internal,
                       "node_rows") != []
    assert unaccounted(node_rows.NodeRow, sources, {**internal, "latex": "x"}, "node_rows") == [
        "latex: declared internal but rendered"]


#: The records the Python renderers show: each one's class and its module's per-renderer tables.
CODE_RECORDS: dict[str, tuple[type[msgspec.Struct], Mapping[str, Mapping[str, str]]]] = {
    "findings": (FindingRow, findings.INTERNAL_TO),
    "obligations": (ObligationRow, obligations.INTERNAL_TO),
    "problems": (problem_rows.ProblemRow, problem_rows.INTERNAL_TO),
    "requirements": (RequirementRow, requirement_rows.INTERNAL_TO),
    "nodes": (node_rows.NodeRow, node_rows.INTERNAL_TO),
}


@pytest.mark.parametrize("renderer", list(CODE))
@pytest.mark.parametrize("key", list(CODE_RECORDS))
def test_every_field_is_shown_by_each_code_renderer_or_internal_to_it(key: str, renderer: str) -> None:
    cls, tables = CODE_RECORDS[key]
    assert set(tables) == set(CODE)  # a table for each renderer, none for a renderer that is not there
    assert unaccounted(cls, _code(renderer), tables[renderer], code=cls) == []
    assert all(why for why in tables[renderer].values())  # each says why it is not shown


class _ProblemWithMargin(problem_rows.ProblemRow, frozen=True, forbid_unknown_fields=True):
    """The problem row with one field added, as a change to records/problem_rows.py would add it."""
    margin_added_here: str = ""


#: Per renderer, a read of the finding's row put beside one it makes, as a change to the renderer would.
_FINDING_READ = {"sarif": ('"check": f.check,', '"check": f.check, "m": f.margin_added_here,'),
                 "junit": ('{"check": f.check,', '{"check": f.check, "m": f.margin_added_here,'),
                 "explain": ('f"  {f.message}",', 'f"  {f.message}", f.margin_added_here,')}


@pytest.mark.parametrize("renderer", list(CODE))
def test_a_field_added_fails_until_each_code_renderer_shows_it_or_declares_it_internal(renderer: str) -> None:
    sources = _code(renderer)
    source = "\n".join(sources)
    for added, (cls, tables) in ((_WithMargin, CODE_RECORDS["findings"]),
                                 (_ObligationWithMargin, CODE_RECORDS["obligations"])):
        internal = tables[renderer]
        assert unaccounted(added, [source], internal, code=cls) == [
            "margin_added_here: neither rendered nor declared internal"], (renderer, cls)
        assert unaccounted(added, [source], {**internal, "margin_added_here": "why"}, code=cls) == []
    # shown: one more read of the decoded row
    old, new = _FINDING_READ[renderer]
    shown = source.replace(old, new, 1)
    assert shown != source
    internal = findings.INTERNAL_TO[renderer]
    assert unaccounted(_WithMargin, [shown], internal, code=FindingRow) == []
    # a read of a name not bound to a decoded row does not count
    assert unaccounted(_WithMargin, [source + "\ndef _x(row):\n    return row.margin_added_here\n"], internal,
                       code=FindingRow) != []
    # a renderer that shows no problem row needs nothing; one that shows them needs the new field
    problems = problem_rows.INTERNAL_TO[renderer]
    assert unaccounted(_ProblemWithMargin, [source], problems, code=problem_rows.ProblemRow) == (
        [] if "*" in problems else ["margin_added_here: neither rendered nor declared internal"])
    # and one declared to show none of a record must read none of it
    assert unaccounted(FindingRow, [source], {"*": "why"}, code=FindingRow) != []
    # a field declared internal to a renderer that shows it is refused
    assert unaccounted(FindingRow, [source], {**internal, "check": "x"}, code=FindingRow) == [
        "check: declared internal but rendered"]


#: Per renderer, a read of the requirement's row put beside one it makes, as a change to the renderer would.
_REQUIREMENT_READ = {"sarif": ('props = {"requirement": r.id,', 'props = {"m": r.margin_added_here, "requirement": r.id,'),
                     "junit": ('f"verdict: {r.verdict}", r.note,', 'f"verdict: {r.verdict}", r.note, r.margin_added_here,'),
                     "explain": ('out.append(f"  {r.note}")', 'out.append(f"  {r.note} {r.margin_added_here}")')}


@pytest.mark.parametrize("renderer", list(CODE))
def test_a_field_added_to_a_requirement_fails_until_each_code_renderer_shows_it_or_declares_it_internal(
        renderer: str) -> None:
    source = "\n".join(_code(renderer))
    internal = requirement_rows.INTERNAL_TO[renderer]
    assert unaccounted(_RequirementWithMargin, [source], internal, code=RequirementRow) == [
        "margin_added_here: neither rendered nor declared internal"]
    assert unaccounted(_RequirementWithMargin, [source], {**internal, "margin_added_here": "why"},
                       code=RequirementRow) == []
    old, new = _REQUIREMENT_READ[renderer]
    shown = source.replace(old, new, 1)
    assert shown != source
    assert unaccounted(_RequirementWithMargin, [shown], internal, code=RequirementRow) == []
    # a read of the requirement check's JSON (a key of r.check) is no read of a field of the row
    raw = source + "\ndef _x(r: RequirementRow) -> object:\n    return r.check.get('margin_added_here')\n"
    assert unaccounted(_RequirementWithMargin, [raw], internal, code=RequirementRow) != []
    assert unaccounted(RequirementRow, [source], {**internal, "verdict": "x"}, code=RequirementRow) == [
        "verdict: declared internal but rendered"]


@pytest.mark.parametrize("renderer", list(CODE))
def test_a_field_added_to_a_node_fails_until_each_code_renderer_shows_it_or_declares_it_internal(renderer: str) -> None:
    source = "\n".join(_code(renderer))
    internal = node_rows.INTERNAL_TO[renderer]
    assert unaccounted(_NodeWithMargin, [source], internal, code=node_rows.NodeRow) == [
        "margin_added_here: neither rendered nor declared internal"]
    assert unaccounted(_NodeWithMargin, [source], {**internal, "margin_added_here": "why"},
                       code=node_rows.NodeRow) == []
    shown = source + "\ndef _x(n: NodeRow) -> object:\n    return n.margin_added_here\n"
    assert unaccounted(_NodeWithMargin, [shown], internal, code=node_rows.NodeRow) == []


def _shown_by_code(renderer: str, row: Mapping[str, Any]) -> str:
    """The text ``renderer`` writes for a report holding the one finding ``row`` (of node ``N``)."""
    import xml.etree.ElementTree as ET
    from rclverify.report import explain, junit, sarif
    report: Any = {"nodes": [{"name": "N", "source": "a.rcl:1:1", "status": "failed", "guarantees": []}],
                   "requirements": [], "findings": [row], "side_conditions": [], "obligations": [], "evidence": [],
                   "pending": []}
    if renderer == "sarif":
        return str(sarif._finding_results(typed_report(report)))
    if renderer == "junit":
        node = typed_report(report).nodes[0].to_json()
        suite = junit._suite(node, {"items": {"findings": [row]}, "evidence": {}, "reasons": {}})[0]
        return ET.tostring(suite, encoding="unicode")
    return "\n".join(explain.explain(typed_report(report).to_json(), str(row["id"])) or [])


@pytest.mark.parametrize("renderer", list(CODE))
def test_each_code_renderer_shows_each_field_of_a_finding_it_reads(renderer: str) -> None:
    """A finding with every field set to a value of its own: each field's value is in what the renderer
    writes unless the field is internal to it (then it is not); the same row at status ``ok`` is the control
    for SARIF, which lists no finding that is ok."""
    row, shown = _full_row()
    row = {**row, "status": "problem", "witness": {"out.y": "witness-value"}}
    shown = {**shown, "witness": "witness-value", "model": "model-value"}
    # and the same warning not acknowledged, which offers its sha256 to acknowledge it
    text = _shown_by_code(renderer, row) + _shown_by_code(renderer, {**row, "acknowledged": None})
    internal = findings.INTERNAL_TO[renderer]
    assert [k for k, t in shown.items() if k not in internal and t not in text] == []
    assert [k for k, t in shown.items() if k in internal and len(t) > 4 and t in text] == []
    if renderer == "sarif":
        assert _shown_by_code(renderer, {**row, "status": "ok"}) == "[]"


#: The report's template filters written in Python that read a record's fields, each typed on the decoded
#: record (its module under report/ -> the record class), so that mypy, not a rendered page, finds a read
#: of a field the record no longer declares.
TYPED_FILTERS: dict[str, type[msgspec.Struct]] = {"badges": RequirementRow}


def _without_field(source: str, cls_name: str, field: str) -> str:
    """``source`` (a record module) with ``field`` of class ``cls_name`` removed (its declaration's lines)."""
    cls = next(n for n in pyast.walk(pyast.parse(source)) if isinstance(n, pyast.ClassDef) and n.name == cls_name)
    decl = next(n for n in cls.body if isinstance(n, pyast.AnnAssign) and isinstance(n.target, pyast.Name)
                and n.target.id == field)
    lines = source.splitlines(keepends=True)
    return "".join(lines[:decl.lineno - 1] + lines[decl.end_lineno or decl.lineno:])


def _mypy(args: list[str], cache: Path) -> tuple[int, str]:
    """mypy strict (the project's configuration, pyproject.toml) on ``args``, errors in the modules they
    import left out; ``(exit status, output)``."""
    root = PARTS.parents[3].parent
    done = subprocess.run([sys.executable, "-m", "mypy", "--cache-dir", str(cache), "--follow-imports", "silent",
                           "--no-error-summary", *args], cwd=root, capture_output=True, text=True, timeout=600)
    return done.returncode, done.stdout + done.stderr


@pytest.mark.parametrize("module", sorted(TYPED_FILTERS))
def test_a_typed_filter_reading_a_removed_field_fails_mypy(module: str, mypy_cache: Path, tmp_path: Path) -> None:
    """Each field a typed filter reads off its record, removed from the record's class (mypy's
    ``--shadow-file``, the checked-in file untouched), makes mypy strict fail at the filter's read; the
    control, the record as it is, passes."""
    cls = TYPED_FILTERS[module]
    filt = PARTS.parents[1] / f"{module}.py"
    read = sorted(fields_read_code(filt.read_text(encoding="utf-8"), cls) & set(cls.__struct_fields__))
    assert read, f"{filt.name} reads no field of {cls.__name__}"
    record = Path(inspect.getfile(sys.modules[cls.__module__]))
    rc, out = _mypy([str(filt)], mypy_cache)
    assert rc == 0, out
    for field in read:
        shadow = tmp_path / f"without_{field}.py"
        shadow.write_text(_without_field(record.read_text(encoding="utf-8"), cls.__name__, field), encoding="utf-8")
        rc, out = _mypy(["--shadow-file", str(record), str(shadow), str(filt)], mypy_cache)
        assert rc == 1 and f'{filt.name}:' in out and f'"{cls.__name__}" has no attribute "{field}"' in out, out


#: The renderers written in Python, each with the records it reads off the decoded report (its module under
#: report/ -> the record classes): mypy, not a rendered file, finds a read of a field the record no longer
#: declares.
TYPED_CODE: dict[str, tuple[type[msgspec.Struct], ...]] = {
    "standards_sheets": (StandardRow, standards_rows.ClauseRow),
    "explain": (node_rows.NodeRow, node_rows.GuaranteeRow),
    "sarif": (FindingRow,),
}


@pytest.fixture(scope="module")
def mypy_cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One mypy cache for the module's runs (the record modules are read once, then only the shadow differs)."""
    return tmp_path_factory.mktemp("mypy_cache")


@pytest.mark.parametrize("module", sorted(TYPED_CODE))
def test_a_code_renderer_reading_a_removed_field_fails_mypy(module: str, mypy_cache: Path, tmp_path: Path) -> None:
    """For each record a Python renderer reads, every field it reads removed from the record's class at once
    (mypy's ``--shadow-file``, one run a class) makes mypy strict name each of those reads in the renderer;
    the control, the records as they are, passes."""
    renderer = PARTS.parents[1] / f"{module}.py"
    source = renderer.read_text(encoding="utf-8")
    rc, out = _mypy([str(renderer)], mypy_cache)
    assert rc == 0, out
    for cls in TYPED_CODE[module]:
        read = sorted(fields_read_code(source, cls) & set(cls.__struct_fields__))
        assert read, f"{renderer.name} reads no field of {cls.__name__}"
        record = Path(inspect.getfile(sys.modules[cls.__module__]))
        text = record.read_text(encoding="utf-8")
        for field in read:  # from the class that declares it (a base class's field: the base's declaration)
            owner = next(c for c in cls.__mro__ if field in vars(c).get("__annotations__", {}))
            text = _without_field(text, owner.__name__, field)
        shadow = tmp_path / f"{cls.__name__}_without_{len(read)}_fields.py"
        shadow.write_text(text, encoding="utf-8")
        rc, out = _mypy(["--shadow-file", str(record), str(shadow), str(renderer)], mypy_cache)
        lines = [x for x in out.splitlines() if x.startswith(str(renderer)) or f"{renderer.name}:" in x]
        assert rc == 1 and [f for f in read if not any(f'"{cls.__name__}"' in x and f'attribute "{f}"' in x
                                                         for x in lines)] == [], (cls.__name__, out)


#: The standards exports (the CSV/XLSX compliance matrix and its header, the gaps): their modules.
EXPORTS: tuple[Path, ...] = tuple(PARTS.parents[1] / f"{m}.py" for m in ("standards_sheets", "standards_export"))
#: The records the exports show, each with its table of the fields they do not show.
EXPORT_RECORDS: dict[str, tuple[type[msgspec.Struct], Mapping[str, str]]] = {
    "standards": (StandardRow, standards_rows.EXPORTS_INTERNAL),
    "standards.clauses": (standards_rows.ClauseRow, standards_rows.CLAUSE_EXPORTS_INTERNAL),
}


class _StandardWithMargin(StandardRow, frozen=True, forbid_unknown_fields=True):
    """The standard row with one field added, as a change to records/standards_rows.py would add it."""
    margin_added_here: str = ""


@pytest.mark.parametrize("key", list(EXPORT_RECORDS))
def test_every_field_is_shown_by_the_exports_or_internal_to_them(key: str) -> None:
    cls, internal = EXPORT_RECORDS[key]
    assert unaccounted(cls, [p.read_text(encoding="utf-8") for p in EXPORTS], internal, code=cls) == []
    assert all(why for why in internal.values())


def test_a_field_added_to_a_standard_fails_until_the_exports_show_it_or_declare_it_internal() -> None:
    source = "\n".join(p.read_text(encoding="utf-8") for p in EXPORTS)
    internal = standards_rows.EXPORTS_INTERNAL
    assert unaccounted(_StandardWithMargin, [source], internal, code=StandardRow) == [
        "margin_added_here: neither rendered nor declared internal"]
    assert unaccounted(_StandardWithMargin, [source], {**internal, "margin_added_here": "why"}, code=StandardRow) == []
    old = '[standard.edition, level, standard.profile,'
    shown = source.replace(old, '[standard.edition, standard.margin_added_here, level, standard.profile,', 1)
    assert shown != source
    assert unaccounted(_StandardWithMargin, [shown], internal, code=StandardRow) == []
    # a read of an undecoded row (a JSON object read by key) does not count
    raw = source + "\ndef _x(s):\n    return s.get('margin_added_here')\n"
    assert unaccounted(_StandardWithMargin, [raw], internal, code=StandardRow) != []
    assert unaccounted(StandardRow, [source], {**internal, "edition": "x"}, code=StandardRow) == [
        "edition: declared internal but rendered"]
