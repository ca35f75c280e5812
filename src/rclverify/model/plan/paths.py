"""Refuse plan paths that leave the workspace.

Every file a plan names must lie inside the workspace, so that an assessor's
bundle (``rclverify bundle``), which packs the workspace, contains every file
the evidence rests on.  Checked when the plan is loaded (``rclverify
check``/``compose``, doit's ``check`` task), before any task runs:

* the ``contracts`` entries, ``design`` and the file part of ``nodes.<Node>.replacement``;
* every value of a key an evidence entry's backend declares as a workspace
  path (:mod:`rclverify.model.plan.entries`: ``program``, ``implementation``
  -- the file part of ``<file>:<callable>`` --, ``record``, ``summary``,
  ``data``, ``traces``, ``mapping``, ...), whatever it looks like;
* every other string of an entry that looks like a path
  (:func:`looks_like_path`), except under the keys that name tools
  (:data:`TOOL_KEYS`: ``dafny``, ``mcapl_home``, ``options``), which may
  name anything installed on the machine.

The rule itself is :func:`rclverify.core.within.escape_reason`, shared with the
assessor's bundle and the one writer.  A path leaves the workspace when it is absolute (``/etc/passwd``, ``C:\\x``),
when it climbs out with ``..``, or when it exists and resolves (through
symbolic links) outside the workspace root.  A backslash counts as a
separator for these checks (``..\\..\\evil.py`` climbs out), and a
declared path with a backslash is refused even inside the workspace: plan
paths are written with ``/`` (docs/plan.md, "Paths").  Each is a
:class:`~rclverify.model.plan.errors.PlanError` located at the value in the plan
(``plan.yaml:line:col``).

What each checked path resolves to is kept with the loaded plan
(:func:`~rclverify.core.cache.keys.resolved_paths`, ``Plan.path_targets``): a run that reuses a loaded
plan (the workspace cache, :mod:`rclverify.core.cache.workspace`) resolves
every one of them again and loads the plan anew, with this check, when one
leads elsewhere (a symbolic link retargeted since), so an incremental run
refuses what a clean run refuses (docs/integrity.md).  The files the plan's files name (review records'
``files:``, a trace mapping's ``msg_dirs``) are checked with
:func:`escape_reason` by their backends' check-time validation, located in
those files.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Iterator, Mapping

from rclverify.core.cache.keys import resolved_paths
from rclverify.core.within import escape_reason
from rclverify.lang import ast
from rclverify.lang.errors import Diagnostic
from rclverify.model.plan.document import PlanDocument
from rclverify.model.plan.entries import TOOL_KEYS, TOOL_PATH_KINDS, declared_paths
from rclverify.model.plan.errors import PlanError, plan_error

__all__ = ["TOOL_KEYS", "check_plan_paths", "config_strings", "escape_reason", "looks_like_path"]

Path_ = tuple[Any, ...]


def looks_like_path(root: Path, value: str) -> bool:
    """``value`` is meant as a path: it contains no whitespace and has a
    ``/`` (or is ``..``), or it names something that exists under ``root``."""
    if not value:
        return False
    if not any(c.isspace() for c in value) and ("/" in value or value == ".."):
        return True
    return os.path.lexists(root / value)


def config_strings(value: Any, path: Path_ = ()) -> Iterator[tuple[Path_, str]]:
    """Every string of a plan value (an entry's settings, a mapping, a list)
    with its value path below ``path``, leaving out the values of
    :data:`TOOL_KEYS` (installed tools, not workspace files)."""
    if isinstance(value, str):
        yield path, value
    elif isinstance(value, Mapping):
        for k, v in value.items():
            if k not in TOOL_KEYS:
                yield from config_strings(v, path + (k,))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from config_strings(v, path + (i,))


def check_plan_paths(root: Path, plan_rel: str, doc: PlanDocument,
                     locs: Mapping[Path_, ast.Loc]) -> dict[str, str]:
    """Check every path in the plan's typed sections ``doc`` (see the module docstring).

    ``locs`` maps value paths to their locations in ``plan_rel``.  Returns
    ``{value: absolute path it leads to}`` of every path checked
    (:func:`~rclverify.core.cache.keys.resolved_paths`).  Raises
    :class:`PlanError` listing every path that leaves the workspace.
    """
    candidates: list[tuple[Path_, str]] = [(("contracts", i), c) for i, c in enumerate(doc.contracts)]
    candidates += [(("requirements_from", k), v) for k, v in doc.requirements_from.items()]
    candidates += [(("design",), doc.design)] if doc.design else []
    nodes = doc.nodes or {}
    for node, spec in nodes.items():
        if spec.replacement is not None:
            candidates.append((("nodes", node, "replacement"), spec.replacement.rpartition(":")[0]))
    backslashed: set[Path_] = {p for p, v in candidates if "\\" in v}
    for node, spec in nodes.items():
        for i, entry in enumerate(spec.evidence):
            base = ("nodes", node, "evidence", i)
            declared = {base + p: v for p, v in declared_paths(entry)} if isinstance(entry, Mapping) else {}
            candidates += list(declared.items())
            candidates += [(p, s) for p, s in config_strings(entry, base)
                           if p not in declared and looks_like_path(root, s)]
            backslashed.update(p for p, v in declared.items() if "\\" in v)
    diags: list[Diagnostic] = []
    for path, value in candidates:
        why = escape_reason(root, value)
        l = locs.get(path, ast.Loc(plan_rel, 1, 1))
        if why is not None:
            diags.extend(plan_error(l.file, l.line, l.col, f"path {value!r} {why}; every file the plan names must "
                                    "lie inside the workspace (so the assessor's bundle contains it)",
                                    "E-path").diagnostics)
        elif path in backslashed:
            diags.extend(plan_error(l.file, l.line, l.col, f"path {value!r} uses '\\' as a separator; write plan "
                                    "paths with '/'", "E-path").diagnostics)
    for node, spec in nodes.items():
        for i, entry in enumerate(spec.evidence):
            if isinstance(entry, Mapping):
                for key, kind in TOOL_PATH_KINDS.items():
                    why = tool_path_problem(root, entry.get(key), kind)
                    if why is not None:
                        l = locs.get(("nodes", node, "evidence", i, key), ast.Loc(plan_rel, 1, 1))
                        diags.extend(plan_error(l.file, l.line, l.col, f"{key}: {why}", "E-tool").diagnostics)
    if diags:
        raise PlanError(diags)
    return resolved_paths(root, [value for _, value in candidates])


def tool_path_problem(root: Path, value: Any, kind: str) -> str | None:
    """Why the tool path ``value`` of a plan entry cannot be used (``None``
    when it can, or when it is not a path: a bare command name is looked up
    on ``PATH`` by the backend).  ``kind`` is ``executable`` or
    ``directory`` (:data:`rclverify.model.plan.entries.TOOL_PATH_KINDS`).  A
    relative path is taken from the workspace root; ``~`` is expanded."""
    if not isinstance(value, str) or "/" not in value:
        return None
    p = Path(value).expanduser()
    if not p.is_absolute():
        p = root / p
    if kind == "directory":
        return None if p.is_dir() else f"{value!r} is not a directory (the tool's installation is named explicitly, " \
                                       "so it must exist; leave the key out to use the environment's)"
    if not p.is_file():
        return f"{value!r} does not exist (the tool is named by its path, so it must exist; give a command " \
               "name to look it up on PATH)"
    if not os.access(p, os.X_OK):
        return f"{value!r} is not executable"
    return None
