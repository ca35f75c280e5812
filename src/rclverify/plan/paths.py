"""Refuse plan paths that leave the workspace.

Every file a plan names must lie inside the workspace, so that an assessor's
bundle (``rclverify bundle``), which packs the workspace, contains every file
the evidence rests on.  Checked: the ``contracts`` entries, the file part of
``nodes.<Node>.replacement``, and every string in a ``nodes.<Node>.evidence``
entry that is a path (:func:`looks_like_path`), except the keys in
:data:`TOOL_KEYS`, which name installed tools, not workspace files.

A path leaves the workspace when it is absolute, when it climbs out with
``..``, or when it exists and resolves (through symbolic links) outside the
workspace root.  Each is a :class:`~rclverify.plan.errors.PlanError` located
at the value in the plan (``plan.yaml:line:col``).
"""
from __future__ import annotations

import os
from pathlib import Path, PurePosixPath
from typing import Any, Iterator, Mapping

from ..rcl import ast
from ..rcl.errors import Diagnostic
from .errors import PlanError, plan_error

#: Evidence-entry keys whose values are not workspace files: ``dafny`` (the
#: Dafny executable), ``mcapl_home`` (an MCAPL installation), ``options``
#: (tool command-line options such as Dafny's ``/arith:2``).
TOOL_KEYS = frozenset({"dafny", "mcapl_home", "options"})

Path_ = tuple[Any, ...]


def looks_like_path(root: Path, value: str) -> bool:
    """``value`` is meant as a path: it contains no whitespace and has a
    ``/`` (or is ``..``), or it names something that exists under ``root``."""
    if not value:
        return False
    if not any(c.isspace() for c in value) and ("/" in value or value == ".."):
        return True
    return os.path.lexists(root / value)


def escape_reason(root: Path, value: str) -> str | None:
    """Why the workspace-relative ``value`` leaves ``root`` (``None`` if it does not)."""
    pure = PurePosixPath(value)
    if pure.is_absolute() or Path(value).is_absolute():
        return "is an absolute path"
    if os.path.normpath(value).split("/")[0] == "..":
        return "climbs out of the workspace with '..'"
    base = root.resolve()
    target = root / value
    if os.path.lexists(target):
        real = target.resolve()
        if real != base and base not in real.parents:
            return f"resolves to {real}, outside the workspace (through a symbolic link)"
    return None


def _strings(value: Any, path: Path_) -> Iterator[tuple[Path_, str]]:
    if isinstance(value, str):
        yield path, value
    elif isinstance(value, Mapping):
        for k, v in value.items():
            if k not in TOOL_KEYS:
                yield from _strings(v, path + (k,))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from _strings(v, path + (i,))


def check_plan_paths(root: Path, plan_rel: str, data: Mapping[str, Any], locs: Mapping[Path_, ast.Loc]) -> None:
    """Check every path in the schema-valid plan ``data`` (see the module docstring).

    ``locs`` maps value paths to their locations in ``plan_rel``.  Raises
    :class:`PlanError` listing every path that leaves the workspace.
    """
    candidates: list[tuple[Path_, str]] = [(("contracts", i), c) for i, c in enumerate(data.get("contracts") or [])]
    candidates += [(("requirements_from", k), v) for k, v in (data.get("requirements_from") or {}).items()]
    for node, spec in (data.get("nodes") or {}).items():
        if isinstance(spec.get("replacement"), str):
            candidates.append((("nodes", node, "replacement"), spec["replacement"].rpartition(":")[0]))
        for i, entry in enumerate(spec.get("evidence") or []):
            candidates += [(p, s) for p, s in _strings(entry, ("nodes", node, "evidence", i))
                           if looks_like_path(root, s)]
    diags: list[Diagnostic] = []
    for path, value in candidates:
        why = escape_reason(root, value)
        if why is not None:
            l = locs.get(path, ast.Loc(plan_rel, 1, 1))
            diags.extend(plan_error(l.file, l.line, l.col, f"path {value!r} {why}; every file the plan names must "
                                    "lie inside the workspace (so the assessor's bundle contains it)",
                                    "E-path").diagnostics)
    if diags:
        raise PlanError(diags)
