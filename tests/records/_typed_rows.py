"""A report a test writes by hand, only the parts and keys it is about, completed into the typed report.

The renderers read the report decoded once into
:class:`~rclverify.records.report_record.AssuranceReport`, which refuses a
missing field.  A test states what it is about (``{"findings": [row]}``);
:func:`typed_report` gives every field it leaves out an empty value of its
declared type (``""``, ``0``, ``False``, ``[]``, ``{}``, ``None`` where the
type allows it, a Literal's first word, a record completed the same way)
and decodes the whole, so that a key the record does not declare still
fails as it does for a built report.
"""
from __future__ import annotations

import types
import typing
from typing import Any, Mapping

import msgspec
import msgspec.structs

from rclverify.records.report_record import AssuranceReport


def _strip(tp: Any) -> Any:
    while typing.get_origin(tp) is typing.Annotated:
        tp = typing.get_args(tp)[0]
    return tp


def empty(tp: Any) -> Any:
    """The empty JSON value of the declared type ``tp``."""
    tp = _strip(tp)
    origin = typing.get_origin(tp)
    if origin in (typing.Union, types.UnionType):
        args = [_strip(a) for a in typing.get_args(tp)]
        if type(None) in args:
            return None
        return empty(next(a for a in args if a is not msgspec.UnsetType))
    if origin is typing.Literal:
        return typing.get_args(tp)[0]
    if origin in (list, tuple) or tp in (list, tuple):
        return []
    if origin is dict or tp is dict:
        return {}
    if isinstance(tp, type) and issubclass(tp, msgspec.Struct):
        return complete(tp, {})
    return {str: "", int: 0, float: 0.0, bool: False}.get(tp, None)


def complete(cls: type[msgspec.Struct], given: Mapping[str, Any]) -> dict[str, Any]:
    """``given`` (part of a JSON object of ``cls``) with each required field it lacks set to
    :func:`empty`, and each record within it (a field typed by a record, or a list of them) completed."""
    hints = typing.get_type_hints(cls)
    out = dict(given)
    for f in msgspec.structs.fields(cls):  # by the key the JSON object has (a field renamed: its encoded name)
        name, tp = f.encode_name, _strip(hints[f.name])
        if name not in out:
            if f.required:
                out[name] = empty(tp)
            continue
        out[name] = _completed(tp, out[name])
    return out


def _completed(tp: Any, value: Any) -> Any:
    tp = _strip(tp)
    origin = typing.get_origin(tp)
    if origin in (typing.Union, types.UnionType):
        structs = [a for a in map(_strip, typing.get_args(tp)) if isinstance(a, type) and issubclass(a, msgspec.Struct)]
        return _completed(structs[0], value) if structs and isinstance(value, Mapping) else value
    if origin is list and isinstance(value, list):
        (item,) = typing.get_args(tp)
        return [_completed(item, v) for v in value]
    if isinstance(tp, type) and issubclass(tp, msgspec.Struct) and isinstance(value, Mapping):
        return complete(tp, value)
    return value


def typed_report(parts: Mapping[str, Any]) -> AssuranceReport:
    """``parts`` (some of the report's top-level keys, their rows given in part) as the typed report.
    Raises :class:`msgspec.ValidationError` for a key no record declares or a value of another type."""
    return AssuranceReport.of(complete(AssuranceReport, parts))


def ungrouped_report(parts: Mapping[str, Any]) -> dict[str, Any]:
    """``parts`` completed into a whole report's JSON object but for ``problems``: a report whose
    problems the renderers group themselves (report/problems.py ``group_problems``)."""
    out = complete(AssuranceReport, parts)
    del out["problems"]
    return out


__all__ = ["complete", "empty", "typed_report", "ungrouped_report"]
