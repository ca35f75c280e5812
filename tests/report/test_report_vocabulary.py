"""The report's published JSON Schema (docs/assurance.schema.json), the one status vocabulary
(rclverify.records.statuses) and the report's TypedDicts (records/report_schema.py, records/nodl_rows.py)
held in step, and the stages' own status tables held to the vocabulary.  Nothing here runs the pipeline (the inner
tier); tests/report/test_report_schema.py validates the reports of a run.
"""
from __future__ import annotations

import copy
import types
import typing
from typing import Any, Literal, NotRequired, TypedDict

import msgspec
from jsonschema import Draft202012Validator

from _report_schema import SCHEMA
from rclverify.records import records, statuses
from rclverify.records import nodl_rows, report_schema as st
from rclverify.records.report_record import AssuranceReport


def _undescribed(x: Any, where: str = "") -> list[str]:
    """The properties of the schema ``x`` without a description, as paths."""
    out: list[str] = []
    if isinstance(x, dict):
        out += [f"{where}/{k}" for k, v in (x.get("properties") or {}).items() if not v.get("description")]
        for k, v in x.items():
            out += _undescribed(v, f"{where}/{k}")
    elif isinstance(x, list):
        for i, v in enumerate(x):
            out += _undescribed(v, f"{where}/{i}")
    return out


def test_the_schema_is_a_draft_2020_12_schema_with_each_key_described() -> None:
    Draft202012Validator.check_schema(SCHEMA)
    assert SCHEMA["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    assert _undescribed(SCHEMA) == []


def test_the_schema_enums_are_the_vocabulary() -> None:
    for name, words in statuses.VOCABULARY.items():
        assert SCHEMA["$defs"][name]["enum"] == list(words), name
    assert list(statuses.SEVERITY) == list(statuses.EVIDENCE_STATUSES)
    assert records.SEVERITY is statuses.SEVERITY  # the roll-up ranks the vocabulary's order
    assert records.worst(["discharged", "unverified", "pending"]) == "unverified"


def test_the_stages_use_the_vocabulary() -> None:
    from rclverify.stages.crosscheck.stage import DOWNGRADES
    from rclverify.model.plan.expected import VERDICTS as EXPECTED
    from rclverify.lang.errors import Severity as LintSeverity
    from rclverify.report import severity
    from rclverify.report.cones import DERIVATION as _DERIVATION
    from rclverify.report.contract_rows import FINDING_AS as _FINDING_AS
    from rclverify.report.deadlines import STATUS_OF
    from rclverify.calculus.requirements import rollup
    assert rollup.VERDICTS == statuses.REQUIREMENT_VERDICTS
    assert {rollup.MET, rollup.OUTSTANDING, rollup.INCONSISTENT, rollup.VACUOUS} <= set(statuses.REQUIREMENT_VERDICTS)
    assert set(_FINDING_AS) == set(statuses.HEALTH_STATUSES)
    assert set(_FINDING_AS.values()) <= set(statuses.EVIDENCE_STATUSES)
    assert set(_DERIVATION.values()) | {"undecided"} == set(statuses.DERIVATIONS)
    assert set(STATUS_OF) == set(statuses.DEADLINE_VERDICTS)
    assert set(STATUS_OF.values()) <= set(statuses.EVIDENCE_STATUSES)
    assert (severity.ERROR, severity.WARNING, severity.NOTE) == statuses.SEVERITIES
    assert typing.get_args(LintSeverity) == statuses.LINT_SEVERITIES
    assert DOWNGRADES <= set(statuses.AGREEMENTS)
    assert set(EXPECTED) <= set(statuses.RECORD_STATUSES)


def _resolve(sub: Any) -> Any:
    """``sub`` with a ``$ref`` to ``$defs`` followed."""
    while isinstance(sub, dict) and "$ref" in sub:
        sub = SCHEMA["$defs"][sub["$ref"].rsplit("/", 1)[1]]
    return sub


def _json_types(sub: Any) -> set[str] | None:
    """The JSON types the schema ``sub`` allows (``None``: any)."""
    sub = _resolve(sub)
    if not isinstance(sub, dict) or sub == {}:
        return None
    if "anyOf" in sub:
        parts = [_json_types(x) for x in sub["anyOf"]]
        return None if any(p is None for p in parts) else set().union(*parts)  # type: ignore[arg-type]
    if "enum" in sub:
        return {"null" if w is None else "string" for w in sub["enum"]}
    t = sub.get("type")
    return None if t is None else {t} if isinstance(t, str) else set(t)


def _py_types(ann: Any) -> set[str] | None:
    """The JSON types a value of the annotation ``ann`` is written as (``None``: any)."""
    origin = typing.get_origin(ann)
    if ann is Any:
        return None
    if ann is msgspec.UnsetType:  # a field left out of the JSON: no type of its own
        return set()
    if isinstance(ann, type) and issubclass(ann, msgspec.Struct):  # a record defined once, its schema generated
        return {"object"}
    if origin in (typing.Union, types.UnionType):
        parts = [_py_types(a) for a in typing.get_args(ann)]
        return None if any(p is None for p in parts) else set().union(*parts)  # type: ignore[arg-type]
    if origin is typing.Literal:
        return {"string"}
    if origin is list or origin is tuple:
        return {"array"}
    if origin is dict or typing.is_typeddict(ann):
        return {"object"}
    return {str: {"string"}, int: {"integer"}, float: {"number"}, bool: {"boolean"}, type(None): {"null"}}[ann]


def _words(ann: Any) -> set[str] | None:
    """The status words a ``Literal`` annotation (or a union of them, ``None`` aside) allows; ``None``
    for any other annotation."""
    parts = [a for a in (typing.get_args(ann) if typing.get_origin(ann) in (typing.Union, types.UnionType)
                         else (ann,)) if a is not type(None)]
    if not parts or any(typing.get_origin(a) is not typing.Literal for a in parts):
        return None
    return {w for a in parts for w in typing.get_args(a)}


def _schema_words(sub: Any) -> set[str] | None:
    """The words the schema ``sub`` enumerates (``enum``, ``const``, or a union of them; ``null`` aside)."""
    sub = _resolve(sub)
    if not isinstance(sub, dict):
        return None
    if "const" in sub:
        return {sub["const"]}
    if "enum" in sub:
        return {w for w in sub["enum"] if w is not None}
    if "anyOf" in sub:
        parts = [_schema_words(x) for x in sub["anyOf"] if _resolve(x).get("type") != "null"]
        return None if not parts or any(p is None for p in parts) else set().union(*parts)  # type: ignore[arg-type]
    return None


def _typeddicts_in(ann: Any) -> list[Any]:
    """The TypedDicts ``ann`` holds directly, as itself, a list's item or a member of a union."""
    if typing.is_typeddict(ann):
        return [ann]
    return [t for a in typing.get_args(ann) for t in _typeddicts_in(a)]


def _object_of(sub: Any, array: bool) -> Any:
    """The object schema of a key's value (its items' for a list; the object branch of a union)."""
    sub = _resolve(sub)
    if array:
        sub = _resolve(sub["items"])
    for x in sub.get("anyOf", ()):
        if _resolve(x).get("type") == "object":
            return _resolve(x)
    return sub


def _disagreements(td: Any, sub: Any, where: str) -> list[str]:
    """Where the TypedDict ``td`` and the object schema ``sub`` say different things: a key one has and the
    other lacks, a key required in one and optional in the other, a value of another JSON type; then the
    same for every TypedDict inside, so a key added to either at any depth is found."""
    hints = typing.get_type_hints(td)
    props = sub.get("properties", {})
    out = [f"{where}.{k}: only in the TypedDict" for k in hints if k not in props]
    out += [f"{where}.{k}: only in the schema" for k in props if k not in hints]
    required = set(sub.get("required", ()))
    out += [f"{where}.{k}: required in one only" for k in hints if k in props and (k in required) != (k in td.__required_keys__)]
    for k, ann in hints.items():
        if k not in props:
            continue
        have, want = _py_types(ann), _json_types(props[k])
        if have is not None and want is not None and not have <= want | ({"number"} if "integer" in have else set()):
            out.append(f"{where}.{k}: {sorted(have)} in the TypedDict, {sorted(want)} in the schema")
        elif have is not None and want is not None and "null" in want and "null" not in have:
            out.append(f"{where}.{k}: null allowed by the schema only")
        # status words: a Literal's words are the schema's; a vocabulary of the schema ($defs) is a Literal
        words, schema_words = _words(ann), _schema_words(props[k])
        vocabulary = "$ref" in props[k] or any("$ref" in x for x in props[k].get("anyOf", ()))
        if (words is not None or (vocabulary and schema_words is not None)) and words != schema_words:
            out.append(f"{where}.{k}: words {sorted(words or ())} in the TypedDict, "
                       f"{sorted(schema_words or ())} in the schema")
        array = typing.get_origin(ann) is list or any(typing.get_origin(a) is list for a in typing.get_args(ann))
        for inner in _typeddicts_in(ann):
            out += _disagreements(inner, _object_of(props[k], array), f"{where}.{k}")
    return out


def test_the_typeddicts_are_the_schema() -> None:
    assert list(st.REPORT_KEYS) == list(SCHEMA["properties"]) == SCHEMA["required"]
    # the renderers' dict-shaped view names the keys of the report's one definition, in its order
    assert list(st.Report.__annotations__) == list(st.REPORT_KEYS) == list(AssuranceReport.__struct_fields__)
    assert _disagreements(st.Report, SCHEMA, "report") == []
    # every row type is reached from Report (none is left out of the walk)
    reached = {t for k, ann in typing.get_type_hints(st.Report).items() for t in _reached(ann)}
    assert {getattr(m, n) for m in (st, nodl_rows) for n in dir(m)
            if typing.is_typeddict(getattr(m, n))} == reached | {st.Report}


def _reached(ann: Any) -> set[Any]:
    out = set()
    for t in _typeddicts_in(ann):
        out |= {t} | {x for a in typing.get_type_hints(t).values() for x in _reached(a)}
    return out


#: A TypedDict with a TypedDict inside and its object schema, held in step (functional syntax: the
#: module's string annotations would make every ``NotRequired`` key count as required).
_Inner = TypedDict("_Inner", {"kind": str, "doubt": float})
_Probe = TypedDict("_Probe", {"guarantee": int, "status": Literal["unverified"], "note": str, "latex": str,
                              "inner": NotRequired[_Inner]})
_D = "described"
_PROBE: dict[str, Any] = {
    "type": "object", "required": ["guarantee", "status", "note", "latex"], "additionalProperties": False,
    "properties": {
        "guarantee": {"type": "integer", "description": _D}, "status": {"const": "unverified", "description": _D},
        "note": {"type": "string", "description": _D}, "latex": {"type": "string", "description": _D},
        "inner": {"type": "object", "required": ["kind", "doubt"], "description": _D, "properties": {
            "kind": {"type": "string", "description": _D}, "doubt": {"type": "number", "description": _D}}}}}


def test_a_key_in_one_and_not_the_other_is_found() -> None:
    """The check above fails for a key added to the schema only, to the TypedDict only, made optional
    in one only, given another type, other status words or a null only one side allows, at any depth."""
    assert _disagreements(_Probe, _PROBE, "probe") == []
    for change, want in (
            (lambda s: s["properties"]["inner"]["properties"].update(colour={"type": "string", "description": "x"}),
             "probe.inner.colour: only in the schema"),
            (lambda s: s["required"].remove("latex"), "probe.latex: required in one only"),
            (lambda s: s["properties"]["guarantee"].update(type="string"),
             "probe.guarantee: ['integer'] in the TypedDict, ['string'] in the schema"),
            (lambda s: s["properties"].pop("note"), "probe.note: only in the TypedDict"),
            (lambda s: s["properties"]["status"].update(const="pending"),
             "probe.status: words ['unverified'] in the TypedDict, ['pending'] in the schema"),
            (lambda s: s["properties"]["guarantee"].update(type=["integer", "null"]),
             "probe.guarantee: null allowed by the schema only")):
        schema = copy.deepcopy(_PROBE)
        change(schema)
        assert want in _disagreements(_Probe, schema, "probe"), want


def test_a_status_that_does_not_follow_from_its_verdict_is_found() -> None:
    """records/statuses.py, "Verdict and status": each kind of row that carries both, right and wrong."""
    good = {
        "requirements": [{"id": "R1", "verdict": "met", "status": "discharged"},
                         {"id": "R2", "verdict": "proved, evidence outstanding", "status": "pending"},
                         {"id": "R3", "verdict": "refuted", "status": "failed",
                          "without_deadline": {"verdict": "met", "status": "discharged"}},
                         {"id": "R4", "verdict": "inconclusive", "status": "stale"}],
        "side_conditions": [{"id": "s1", "verdict": "discharged in context", "status": "discharged"},
                            {"id": "s2", "verdict": "stale", "status": "stale"}],
        "deadlines": [{"requirement": "R1", "verdict": "proved", "status": "pending", "evidence_status": "pending"},
                      {"requirement": "R3", "verdict": "refuted", "status": "failed"}],
        "derived_properties": [{"node": "A", "status": "discharged", "derivation": "derived"},
                               {"node": "B", "status": "stale", "derivation": "undecided"}],
    }
    assert statuses.contradictions(good) == []
    bad = {
        "requirements": [{"id": "R1", "verdict": "proved, evidence outstanding", "status": "discharged"},
                         {"id": "R2", "verdict": "met", "status": "pending"},
                         {"id": "R3", "verdict": "refuted", "status": "inconclusive"},
                         {"id": "R4", "verdict": "refuted", "status": "failed",
                          "without_deadline": {"verdict": "proved vacuously", "status": "pending"}}],
        "side_conditions": [{"id": "s1", "verdict": "discharged", "status": "stale"},
                            {"id": "s2", "verdict": "failed", "status": "discharged"}],
        "deadlines": [{"requirement": "R1", "verdict": "proved", "status": "discharged", "evidence_status": "pending"},
                      {"requirement": "R3", "verdict": "inconclusive", "status": "pending"}],
        "derived_properties": [{"node": "A", "status": "failed", "derivation": "derived"}],
    }
    found = statuses.contradictions(bad)
    assert [f.split(" ", 1)[0] for f in found] == [
        "requirements[0]", "requirements[1]", "requirements[2]", "requirements[3]", "side_conditions[0]",
        "side_conditions[1]", "deadlines[0]", "deadlines[1]", "derived_properties[0]"], found
    assert found[0] == "requirements[0] (R1): verdict 'proved, evidence outstanding', status 'discharged'"
    assert set(statuses.REQUIREMENT_FLOOR) == set(statuses.REQUIREMENT_VERDICTS)
    assert set(statuses.DEADLINE_STATUS) | {"proved"} == set(statuses.DEADLINE_VERDICTS)
