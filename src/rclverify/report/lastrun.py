"""The last run's JSON files, read with their shape checked.

``rclverify status``, ``rclverify explain`` and the end of ``doit verify``
read ``artifacts/report/summary.json`` (:func:`rclverify.report.summary.summary_data`;
:func:`rclverify.report.summary.read_summary` reads it with these checks)
and ``reports/assurance.json`` (:func:`rclverify.report.build.build_report`).
Both are written by rclverify, but a user can edit, truncate or replace
them; a file of another shape (``[]``, ``null``, a string, a missing key, a
list where an object belongs) is a located ``E-io`` error naming the first
place that differs, never a traceback.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from rclverify.lang.ast import Loc
from rclverify.lang.errors import RclError, error

#: What a consumer of the last run reads.  A spec is a type (or a tuple of
#: types), ``{key: spec}`` for an object whose keys must be there (a key
#: ending in ``?`` may be absent), or ``[spec]`` for a list of such items.
_NUM = (int, float)
_TEXT_OR_NONE = (str, type(None))
SUMMARY_SHAPE: dict[str, Any] = {
    "meta": {"workspace": str, "strict_ok": bool},
    "summary": {"status": str, "headline": str, "problems": [str],
                "diagnoses?": [{"id": str, "sentence": str, "repairs?": _NUM}]},
    "rows": [{"node": str, "status": str, "obligations": dict, "sc_proved": _NUM, "sc_total": _NUM,
              "health_problems": _NUM, "health_open": _NUM, "health_total": _NUM}],
    "requirements?": [list],
    "deadlines?": [list],
    "problems?": [{"status": str, "sentence": str, "culprits": [str], "members": [str], "repairs": _NUM}],
    "grounding?": (dict, type(None)),
    "nodl?": (dict, type(None)),
    "strict?": [str],
    "near_misses?": [str],
}

#: What :func:`rclverify.report.summary.summary_data` reads of a JSON report.
_ROW = {"status": str, "node": str}
SUMMARY_SOURCE_SHAPE: dict[str, Any] = {
    "meta": {"workspace": str, "strict_ok": bool},
    "summary": {"status": str, "headline": str, "problems": [str]},
    "nodes": [{"name": str, "status": str}],
    "obligations": [_ROW], "side_conditions": [_ROW], "findings": [_ROW],
    "requirements?": [{"id": str, "status": str}],
    "problems?": [dict],
    "grounding?": (dict, type(None)),
    "nodl?": (dict, type(None)),
}

_ITEM = {"id": str, "status": str, "node": str}
REPORT_SHAPE: dict[str, Any] = {
    "meta": {"workspace": str, "strict_ok": bool},
    "summary": {"status": str, "headline": str, "problems": [str]},
    "nodes": [{"name": str, "status": str, "guarantees?": [{"index": int, "status": str, "text": str}]}],
    "requirements": [{"id": str, "status": str, "text?": _TEXT_OR_NONE, "check?": (dict, type(None))}],
    "obligations": [_ITEM],
    "side_conditions": [_ITEM],
    "findings": [_ITEM],
    "diagnoses?": [{"id": str, "status": str, "kind": str, "sentence": str}],
    "evidence?": [dict],
    "problems?": [dict],
    "lint?": [dict],
    "grounding?": (dict, type(None)),
}


def _kind(value: Any) -> str:
    if value is None:
        return "null"
    return {bool: "true/false", int: "a number", float: "a number", str: "a string", list: "a list",
            dict: "an object"}.get(type(value), type(value).__name__)


def _wanted(spec: Any) -> str:
    if isinstance(spec, dict):
        return "an object"
    if isinstance(spec, list):
        return "a list"
    types = spec if isinstance(spec, tuple) else (spec,)
    names = {dict: "an object", list: "a list", str: "a string", bool: "true/false", int: "a number",
             float: "a number", type(None): "null"}
    return " or ".join(dict.fromkeys(names.get(t, t.__name__) for t in types))


def shape_problem(value: Any, spec: Any, where: str = "") -> str | None:
    """The first place where ``value`` (parsed JSON) differs from ``spec``
    (see :data:`SUMMARY_SHAPE`), as ``"`rows[2].sc_total` is a string, not a
    number"``; ``None`` when it fits.  ``bool`` is not taken for a number."""
    here = f"`{where}`" if where else "the file"
    if isinstance(spec, dict):
        if not isinstance(value, dict):
            return f"{here} is {_kind(value)}, not an object"
        for key, sub in spec.items():
            optional = key.endswith("?")
            name = key.rstrip("?")
            path = f"{where}.{name}" if where else name
            if name not in value:
                if optional:
                    continue
                return f"{here} has no key `{name}`"
            problem = shape_problem(value[name], sub, path)
            if problem:
                return problem
        return None
    if isinstance(spec, list):
        if not isinstance(value, list):
            return f"{here} is {_kind(value)}, not a list"
        for k, item in enumerate(value):
            problem = shape_problem(item, spec[0], f"{where}[{k}]")
            if problem:
                return problem
        return None
    types = spec if isinstance(spec, tuple) else (spec,)
    if isinstance(value, bool) and bool not in types:
        return f"{here} is true/false, not {_wanted(spec)}"
    if not isinstance(value, types):
        return f"{here} is {_kind(value)}, not {_wanted(spec)}"
    return None


def located(path: Path, message: str) -> RclError:
    """A one-line ``path:1:1: error: message`` (``E-io``) as an :class:`RclError`."""
    return RclError([error(Loc(str(path), 1, 1), message, "E-io")])


def read_checked(path: Path, shape: Any, what: str) -> Any:
    """The JSON file ``path``, checked against ``shape``.

    Raises :class:`RclError` (one located line): no such file (``run
    `rclverify verify` first``), unreadable or not JSON, or of another shape
    than ``what`` (e.g. ``"an rclverify summary"``) has."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise located(path, "no report yet: run `rclverify verify` (or `doit verify`) first") from None
    except (OSError, ValueError) as exc:
        raise located(path, f"cannot read it: {exc}") from None
    problem = shape_problem(data, shape)
    if problem:
        raise located(path, f"not {what}: {problem}; run `rclverify verify` (or `doit verify`) to write it again")
    return data


def read_report(root: Path) -> dict[str, Any]:
    """``reports/assurance.json`` of the workspace ``root``, shape-checked
    (:data:`REPORT_SHAPE`), its ``findings`` decoding into their one
    definition (:class:`rclverify.records.findings.FindingRow`).  Raises
    :class:`RclError` as :func:`read_checked` does, and for a finding that
    does not decode."""
    import msgspec  # deferred: start-up (loads msgspec only when called)
    from rclverify.records.findings import rows_of  # deferred: start-up (loads msgspec only when called)
    path = root / "reports/assurance.json"
    data: dict[str, Any] = read_checked(path, REPORT_SHAPE, "an rclverify report")
    try:
        rows_of(data["findings"])
    except msgspec.ValidationError as exc:
        raise located(path, f"not an rclverify report: findings: {exc}; run `rclverify verify` (or `doit verify`) "
                            "to write it again") from None
    return data
