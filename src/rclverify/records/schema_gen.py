"""The parts of docs/assurance.schema.json generated from the record classes.

Each entry of :data:`GENERATED` names a top-level key of the report and the
:mod:`msgspec` class of one of its items; :func:`generated_part` turns
:func:`msgspec.json.schema` of the class into the file's style (JSON Schema
draft 2020-12, https://json-schema.org/draft/2020-12): each class inlined
as an object that rejects unknown keys, every nested object too; no
``title`` or ``default`` (the class's docstring and field descriptions say
what a missing key means); a value's ``description`` after its type; an enumeration equal to one of the status
vocabularies of :mod:`rclverify.records.statuses` written as a ``$ref`` to
that vocabulary's ``$defs`` entry (a union of them :data:`UNIONS` names as a ``$ref`` to
that union's entry), and a class of :data:`DEFS` as a
``$ref`` to its ``$defs`` entry, that entry itself generated from the class.  A field named in :data:`KEPT` holds a
value whose inner shape belongs to a tool: its schema is the file's own,
described by hand, taken as it is.

``python -m rclverify.records.schema_gen [FILE]`` rewrites those parts of
``FILE`` (default ``docs/assurance.schema.json``) and those ``$defs`` entries in place through
core/atomic.py and leaves every other part as it is; it prints what it
rewrote.  tests/records/test_record_shapes.py fails when the file and the classes
differ.
"""
from __future__ import annotations

import json
import sys
import typing
from pathlib import Path
from typing import Any

import msgspec

from rclverify.core.atomic import atomic_write_text
from rclverify.records.deadline_rows import DeadlineHop, DeadlineRow, HopTimeMargin
from rclverify.records.margin_rows import MarginBounds, MarginRow, NearMissRow
from rclverify.records.node_rows import CulpritOf
from rclverify.records.report_record import AssuranceReport
from rclverify.records.solvers_rows import Solvers
from rclverify.records.statuses import VOCABULARY, AnyStatus
from rclverify.records.strength_rows import LimitedBy, Strength

#: Top-level key of the report -> (its type: ``list[Row]`` for an array of a record's items, a record's
#: class, or ``Row | None``; the key's description): the fields of :class:`AssuranceReport`, in its order.
GENERATED: dict[str, tuple[Any, str]] = {
    name: (hints[name].__origin__, hints[name].__metadata__[0].description)
    for hints in [typing.get_type_hints(AssuranceReport, include_extras=True)]
    for name in AssuranceReport.__struct_fields__}

#: A record class the report's schema defines once in ``$defs`` -> that entry's name; every use of the
#: class is a ``$ref`` to it, and the entry is generated from the class.
DEFS: dict[type[msgspec.Struct], str] = {
    Strength: "strength", LimitedBy: "limited_by", CulpritOf: "culprit_of", Solvers: "solvers",
    DeadlineRow: "deadline", DeadlineHop: "deadline_hop", HopTimeMargin: "hop_time_margin",
    NearMissRow: "near_miss", MarginRow: "margins_over_runs", MarginBounds: "margin_bounds"}

#: :data:`DEFS` by class name (how msgspec's schema names the class) -> the entry's name.
SHARED: dict[str, str] = {cls.__name__: name for cls, name in DEFS.items()}

#: The classes whose ``$defs`` entry :func:`with_generated` writes: those of :data:`DEFS`.
DEFINED: tuple[type[msgspec.Struct], ...] = tuple(DEFS)

#: A union of status vocabularies the report's schema names in ``$defs`` (the vocabularies' entry names, in
#: order) -> that entry's name: ``any_status`` (records/statuses.py ``AnyStatus``).
UNIONS: dict[tuple[str, ...], str] = {
    tuple(n for a in typing.get_args(AnyStatus) for n, w in VOCABULARY.items() if w == typing.get_args(a)): "any_status"}

#: Top-level key -> the fields of its items (or of its object) whose schema the file states by hand (a
#: tool's record: the monitors backend's run summary, docs/monitors.md; the requirements stage's check
#: record, calculus/requirements/check.py).
KEPT: dict[str, tuple[str, ...]] = {"evidence": ("monitoring",), "requirements": ("check",)}


def record_type(key: str) -> Any:
    """The class of the record of the report's top-level ``key``."""
    tp = GENERATED[key][0]
    args = [a for a in typing.get_args(tp) if a is not type(None)]
    return args[0] if args else tp


def object_of(part: dict[str, Any]) -> dict[str, Any]:
    """The object schema inside a generated part: an array's items, a nullable record's record."""
    if part.get("type") == "array":
        return object_of(part["items"])
    for branch in part.get("anyOf", ()):
        if branch.get("type") == "object":
            return object_of(branch)
    return part


def _styled(x: Any, defs: dict[str, Any]) -> Any:
    """``x`` (a part of msgspec's schema whose ``$defs`` are ``defs``) in the file's style (module docstring)."""
    if isinstance(x, list):
        return [_styled(v, defs) for v in x]
    if not isinstance(x, dict):
        return x
    if "$ref" in x:
        name = x["$ref"].rsplit("/", 1)[1]
        if name in SHARED:
            return {"$ref": f"#/$defs/{SHARED[name]}", **{k: v for k, v in x.items() if k != "$ref"}}
        return _styled({**defs[name], **{k: v for k, v in x.items() if k != "$ref"}}, defs)
    if "enum" in x:
        for name, words in VOCABULARY.items():
            if set(x["enum"]) == set(words):
                return {"$ref": f"#/$defs/{name}", **{k: v for k, v in x.items() if k != "enum"}}
    out = {k: {name: _styled(sub, defs) for name, sub in v.items()} if k == "properties" else _styled(v, defs)
           for k, v in x.items() if k not in ("title", "default")}  # a field may be called title
    refs = tuple(b["$ref"].rsplit("/", 1)[1] for b in out.get("anyOf", ()) if list(b) == ["$ref"])
    if refs and len(refs) == len(out["anyOf"]) and refs in UNIONS:  # a union the file names in $defs
        out = {"$ref": f"#/$defs/{UNIONS[refs]}", **{k: v for k, v in out.items() if k != "anyOf"}}
    if out.get("type") == "object" and "properties" in out:
        head = {k: out.pop(k) for k in ("type", "description", "required", "properties") if k in out}
        out = {**head, **out}
    elif "description" in out:  # a value's schema: what it is, then what it means
        out = {**{k: v for k, v in out.items() if k != "description"}, "description": out["description"]}
    return out


def generated_part(key: str, schema: dict[str, Any] | None = None) -> dict[str, Any]:
    """The schema of the report's top-level ``key`` (:data:`GENERATED`: an array of a record's items, a
    record, or a record or null), in the file's style; each field of :data:`KEPT` as ``schema`` (the
    report's whole schema, as the file holds it) states it.  Raises ``KeyError`` when ``key`` has such
    fields and ``schema`` does not state them."""
    tp, description = GENERATED[key]
    raw = msgspec.json.schema(tp)
    part = _styled({k: v for k, v in raw.items() if k != "$defs"}, raw.get("$defs", {}))
    for name in KEPT.get(key, ()):
        if schema is None:
            raise KeyError(f"{key}.{name}: stated by hand in the schema file, which was not given")
        object_of(part)["properties"][name] = object_of(schema["properties"][key])["properties"][name]
    return {**part, "description": description}


def generated_def(cls: type[msgspec.Struct]) -> dict[str, Any]:
    """The ``$defs`` entry of ``cls`` (one of :data:`DEFINED`), in the file's style: its object, the class's
    docstring its description."""
    raw = msgspec.json.schema(cls)
    defs: dict[str, Any] = raw["$defs"]
    out: dict[str, Any] = _styled(defs[cls.__name__], defs)
    return out


def with_generated(schema: dict[str, Any]) -> dict[str, Any]:
    """``schema`` (the report's whole schema) with its top level generated from :class:`AssuranceReport`
    (every field a required key, in the class's order, no other key) and every generated part and
    ``$defs`` entry put in its place (an entry of :data:`DEFINED` the file lacks is added at the end of
    ``$defs``; the vocabularies' entries and the file's title, ``$id`` and description are kept)."""
    props = {**{k: generated_part(k, schema) for k in GENERATED},
             **{k: v for k, v in schema["properties"].items() if k not in GENERATED}}
    made = {SHARED[c.__name__]: generated_def(c) for c in DEFINED}
    defs = {**{k: made.get(k, v) for k, v in schema.get("$defs", {}).items()}, **made}
    return {**schema, "$defs": defs, "properties": props, "additionalProperties": False, "required": list(GENERATED)}


def schema_text(schema: dict[str, Any]) -> str:
    """The schema file's text: JSON, one-space indent, final newline."""
    return json.dumps(schema, indent=1, ensure_ascii=False) + "\n"


def main(argv: list[str] | None = None) -> int:
    """Rewrite the generated parts of the schema file (module docstring); 0, or 2 when it cannot be read."""
    path = Path((argv if argv is not None else sys.argv[1:] or ["docs/assurance.schema.json"])[0])
    try:
        schema = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as e:
        print(f"error: {path}:1:1: {e}", file=sys.stderr)
        return 2
    changed = atomic_write_text(path, schema_text(with_generated(schema)))
    print(f"{path}: {', '.join(GENERATED)}, $defs {', '.join(SHARED[c.__name__] for c in DEFINED)} "
          f"{'rewritten' if changed else 'unchanged'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
