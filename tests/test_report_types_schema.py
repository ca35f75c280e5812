"""The report's TypedDicts (records/report_schema.py) and its published JSON Schema
(docs/assurance.schema.json) state one shape: checked key by key, both ways.

For every TypedDict reachable from :class:`Report`, the schema node at the same place is an object
with exactly its keys, the same required keys, and each value's schema admits exactly the value's
type: ``str``/``int``/``float``/``bool`` as JSON types, ``X | None`` as a union with ``null``, a
``Literal`` of status words as the schema's enumeration of the same words, ``list[X]`` as an array
of ``X``, ``dict[str, X]`` as an object of ``X`` values, a nested TypedDict recursively.  ``Any``
and ``dict[str, Any]`` are the parts the schema leaves open.  A test that the checker itself fails
on a changed type keeps it honest.
"""
# No ``from __future__ import annotations``: the TypedDicts' NotRequired must be evaluated.
import json
import types
import typing
from pathlib import Path
from typing import Any, Literal, NotRequired, TypedDict, Union

from rclverify.records import report_schema as st

SCHEMA = json.loads((Path(__file__).resolve().parents[1] / "docs" / "assurance.schema.json").read_text())
_JSON = {str: "string", int: "integer", float: "number", bool: "boolean"}


def _resolve(node: dict[str, Any]) -> dict[str, Any]:
    while "$ref" in node:
        ref = node["$ref"]
        assert ref.startswith("#/$defs/"), ref
        node = {**SCHEMA["$defs"][ref.split("/")[-1]], **{k: v for k, v in node.items() if k != "$ref"}}
    return node


def _branches(node: dict[str, Any]) -> list[dict[str, Any]]:
    """The alternatives a schema node admits, each with one JSON type where it names one."""
    node = _resolve(node)
    for key in ("anyOf", "oneOf"):
        if key in node:
            rest = {k: v for k, v in node.items() if k != key}
            return [b for alt in node[key] for b in _branches({**rest, **alt})]
    if isinstance(node.get("type"), list):
        return [{**node, "type": t} for t in node["type"]]
    if "enum" in node and "type" not in node:
        kinds = {type(v) for v in node["enum"]}
        return [{**node, "enum": [v for v in node["enum"] if type(v) is k], "type": "null" if k is type(None)
                 else _JSON.get(k, "?")} for k in kinds]
    return [node]


def _is_typeddict(tp: Any) -> bool:
    return isinstance(tp, type) and typing.is_typeddict(tp)


def check(tp: Any, node: dict[str, Any], path: str, errors: list[str]) -> None:
    """Append to ``errors`` each place where ``tp`` and the schema ``node`` disagree."""
    if tp is Any:
        return
    origin, args = typing.get_origin(tp), typing.get_args(tp)
    if origin is NotRequired:
        return check(args[0], node, path, errors)
    branches = _branches(node)
    if origin in (Union, types.UnionType):
        nulls = [b for b in branches if b.get("type") == "null"]
        rest = [b for b in branches if b.get("type") != "null"]
        inner = [a for a in args if a is not type(None)]
        if (type(None) in args) != bool(nulls):
            errors.append(f"{path}: null {'allowed' if nulls else 'refused'} by the schema, "
                          f"{'not ' if type(None) not in args else ''}by the type")
        if len(inner) == 1 and rest:
            check(inner[0], {"anyOf": rest} if len(rest) > 1 else rest[0], path, errors)
        elif inner and all(typing.get_origin(a) is Literal for a in inner):  # a union of word sets
            words = {w for a in inner for w in typing.get_args(a)}
            schema_words = {w for b in rest for w in b.get("enum", [b["const"]] if "const" in b else [])}
            if words != schema_words:
                errors.append(f"{path}: the type's words {sorted(map(str, words - schema_words))} and the "
                              f"schema's {sorted(map(str, schema_words - words))} differ")
        else:
            errors.append(f"{path}: a union the check does not read: {tp}")
        return
    if len(branches) != 1:
        errors.append(f"{path}: the schema admits {len(branches)} alternatives, the type one ({tp})")
        return
    node = branches[0]
    kind = node.get("type")
    if _is_typeddict(tp):
        if kind != "object":
            errors.append(f"{path}: {tp.__name__} is an object, the schema says {kind}")
            return
        props = node.get("properties", {})
        hints = typing.get_type_hints(tp, include_extras=True)
        for k in sorted(set(hints) ^ set(props)):
            errors.append(f"{path}.{k}: only in the {'type' if k in hints else 'schema'} ({tp.__name__})")
        required = set(node.get("required", []))
        for k in sorted(set(tp.__required_keys__) ^ required):
            errors.append(f"{path}.{k}: required in the {'type' if k in required else 'schema'}"
                          if k in hints and k in props else f"{path}.{k}: required, and only in one")
        for k in sorted(set(hints) & set(props)):
            check(hints[k], props[k], f"{path}.{k}", errors)
        return
    if origin is Literal:
        if set(node.get("enum", [node["const"]] if "const" in node else [])) != set(args):
            errors.append(f"{path}: the type's words {sorted(map(str, args))} are not the schema's "
                          f"{sorted(map(str, node.get('enum', [])))}")
        return
    if origin is list:
        if kind != "array":
            errors.append(f"{path}: a list, the schema says {kind}")
        elif "items" in node:
            check(args[0], node["items"], f"{path}[]", errors)
        elif args[0] is not Any:
            errors.append(f"{path}: the schema leaves the items open, the type says {args[0]}")
        return
    if origin is dict:
        if kind != "object":
            errors.append(f"{path}: a mapping, the schema says {kind}")
        elif isinstance(node.get("additionalProperties"), dict):
            check(args[1], node["additionalProperties"], f"{path}{{}}", errors)
        return
    if tp in _JSON:
        if kind != _JSON[tp] and not (tp is float and kind == "integer") and not (tp is int and kind == "number"
                                                                                      and node.get("multipleOf") == 1):
            errors.append(f"{path}: {tp.__name__} is {_JSON[tp]}, the schema says {kind}")
        return
    errors.append(f"{path}: a type the check does not read: {tp}")


def _differences(root: Any = st.Report) -> list[str]:
    errors: list[str] = []
    check(root, SCHEMA, "report", errors)
    return errors


def test_the_report_types_and_the_json_schema_state_one_shape() -> None:
    assert _differences() == []


class _Narrow(TypedDict):
    meta: dict[str, Any]


def test_the_check_fails_where_the_type_and_the_schema_part() -> None:
    errs = _differences(_Narrow)
    assert "report.summary: only in the schema (_Narrow)" in errs
    assert "report.meta: a type the check does not read" not in " ".join(errs)
    wrong = TypedDict("Summary", {"status": Literal["discharged", "nonsense"]})  # type: ignore[misc]
    errors: list[str] = []
    check(wrong, SCHEMA["properties"]["summary"], "summary", errors)
    assert any("are not the schema's" in e for e in errors) and any("only in the schema" in e for e in errors)
