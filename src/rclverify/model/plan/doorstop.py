"""Requirements read from a Doorstop tree (``requirements_from: {doorstop: DIR}``).

Doorstop (https://doorstop.readthedocs.io) keeps requirements as one YAML
file per item in version control, grouped in documents (a folder with a
``.doorstop.yml``).  The plan names a folder; every document at or below it
is read with the ``doorstop`` package (``doorstop.core.document.Document``)
and each item becomes a :class:`~.load.Requirement` (docs/plan.md,
"Requirements from Doorstop"):

=================  ==========================================================
item               requirement
=================  ==========================================================
``uid``            ``id`` (``SYS001``)
``text``           ``text`` (first paragraph kept whole)
``rcl``            ``formal``: RCL over ``Node.in.x``/``Node.out.y``; absent
                   or empty: informal
``assuming``       ``assuming``: a formula or a list of formulas
``supported_by``   the traced guarantees, as in the plan:
                   ``[{node: N, guarantees: [1, 2]}]``
``links``          Doorstop's links to parent items: kept as ``links``
                   (shown, not checked)
``active: false``, headings and non-normative items are skipped.
=================  ==========================================================

Locations point at the item's file: the ``rcl`` key's line for the formal
statement, the item's first line otherwise.
"""
from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from rclverify.lang import ast
from rclverify.model.plan.errors import PlanError, plan_error
from rclverify.model.plan.formal import Source
from rclverify.model.plan.paths import escape_reason


def _documents(folder: Path) -> list[Path]:
    """Document folders (those with a ``.doorstop.yml``) at or below ``folder``, sorted."""
    return sorted({p.parent for p in folder.rglob(".doorstop.yml")})


def _key_line(lines: list[str], key: str) -> int | None:
    pat = re.compile(rf"^{re.escape(key)}\s*:")
    for k, line in enumerate(lines):
        if pat.match(line):
            return k
    return None


def _formula_source(rel: str, lines: list[str], key: str, value: str, index: int = 0) -> Source:
    """Where ``value`` (the ``index``-th formula of ``key``) is written in the item file."""
    k = _key_line(lines, key)
    if k is None:
        return Source(value, 1, 1, rel)
    first = value.splitlines()[0] if value.strip() else value
    for j in range(k, len(lines)):
        col = lines[j].find(first)
        if col >= 0 and (j > k or col > len(key)):
            if index == 0:
                return Source(value, j + 1, col + 1, rel)
            index -= 1
    return Source(value, k + 1, 1, rel)


def _item_file(root: Path, path: Path, loc: ast.Loc) -> str:
    """The workspace-relative name of the item file ``path`` (as Doorstop
    found it, under ``root``).  Raises a located :class:`PlanError` (``E-path``,
    at the item file, or at ``loc`` when even its name lies outside) when the
    file resolves outside the workspace, e.g. through a symbolic link: every
    file a requirement rests on must be in the workspace, so that the
    assessor's bundle holds it (:mod:`.paths`)."""
    rel = path
    for a, b in ((path, root), (path.absolute(), root.absolute())):
        try:
            rel = a.relative_to(b)
            break
        except ValueError:
            continue
    why = "lies outside the workspace" if rel.is_absolute() else escape_reason(root, str(rel))
    if why is None:
        return rel.as_posix()
    at = (str(rel), 1, 1) if not rel.is_absolute() else (loc.file, loc.line, loc.col)
    raise plan_error(*at, f"requirements_from: the Doorstop item file {str(rel)!r} {why}; every file the plan "
                          "names must lie inside the workspace (so the assessor's bundle contains it)", "E-path")


def read_requirements(root: Path, folder: str, loc: ast.Loc) -> tuple[Any, ...]:
    """The requirements of the Doorstop documents under ``root/folder``.

    Returns :class:`~.load.Requirement` values in document then item order.
    Raises :class:`PlanError` located at ``loc`` (the plan entry) when the
    folder holds no document or Doorstop cannot read it, and located in an
    item's file when an attribute has the wrong shape.
    """
    from rclverify.model.plan.model import Requirement, Support  # deferred: start-up (loads rclverify.model.plan, hashlib and more only when called)
    base = root / folder
    if not base.is_dir():
        raise plan_error(loc.file, loc.line, loc.col, f"requirements_from: {folder!r} is not a folder", "E-io")
    docs = _documents(base)
    if not docs:
        raise plan_error(loc.file, loc.line, loc.col, f"requirements_from: no Doorstop document (a folder with a "
                                                      f".doorstop.yml) under {folder!r}", "E-io")
    try:
        from doorstop.core.document import Document  # deferred: optional or conditional (inside a block)
    except ImportError:  # the doorstop extra (core/extras.py)
        from rclverify.core.extras import missing_message  # deferred: optional or conditional (inside a block)
        raise plan_error(loc.file, loc.line, loc.col,
                         "requirements_from: " + missing_message("doorstop", "reading a Doorstop tree"), "E-io") from None
    out = []
    for d in docs:
        try:
            items = list(Document(str(d), root=str(root)).items)
        except Exception as exc:  # doorstop raises its own DoorstopError and YAML errors
            raise plan_error(loc.file, loc.line, loc.col, f"requirements_from: Doorstop cannot read "
                                                          f"{d.relative_to(root)}: {exc}", "E-io") from None
        for it in items:
            if not it.active or it.heading or not it.normative:
                continue
            rel = _item_file(root, Path(str(it.path)), loc)
            lines = Path(str(it.path)).read_text(encoding="utf-8").splitlines()
            first = ast.Loc(rel, 1, 1)

            def bad(key: str, msg: str) -> PlanError:
                k = _key_line(lines, key)
                return plan_error(rel, (k or 0) + 1, 1, f"{it.uid}: {msg}", "E-plan")
            rcl = it.get("rcl")
            if rcl is not None and not isinstance(rcl, str):
                raise bad("rcl", "the 'rcl' attribute must be an RCL formula (a string)")
            formal = _formula_source(rel, lines, "rcl", rcl.strip()) if rcl and rcl.strip() else None
            assuming = it.get("assuming") or []
            assuming = [assuming] if isinstance(assuming, str) else assuming
            if not isinstance(assuming, list) or not all(isinstance(a, str) for a in assuming):
                raise bad("assuming", "the 'assuming' attribute must be a formula or a list of formulas")
            sup = it.get("supported_by") or []
            support = []
            if not isinstance(sup, list):
                raise bad("supported_by", "'supported_by' must be a list of {node: N, guarantees: [k, ...]}")
            for s in sup:
                if not (isinstance(s, dict) and isinstance(s.get("node"), str) and isinstance(s.get("guarantees"), list)
                        and all(isinstance(g, int) and g >= 1 for g in s["guarantees"])):
                    raise bad("supported_by", "'supported_by' must be a list of {node: N, guarantees: [k, ...]} "
                                              "with guarantee numbers from 1")
                k = _key_line(lines, "supported_by")
                support.append(Support(s["node"], tuple(s["guarantees"]), ast.Loc(rel, (k or 0) + 1, 1)))
            text = " ".join(str(it.text).split())
            out.append(Requirement(str(it.uid), text, tuple(support), first, formal,
                                   tuple(_formula_source(rel, lines, "assuming", a, j) for j, a in enumerate(assuming)),
                                   rel))
    return tuple(out)


def doorstop_files(root: Path, folder: str) -> list[str]:
    """The workspace-relative files of the Doorstop documents under ``folder``
    (a change to any of them re-checks the requirements); a file (a FRET
    export, ``requirements_from: {fret: ...}``) is itself."""
    base = root / folder
    if base.is_file():
        return [folder]
    if not base.is_dir():
        return []
    return sorted(str(p.relative_to(root)) for d in _documents(base) for p in d.iterdir() if p.is_file())
