"""The check of the one-token repairs :mod:`.code_repair` offers for a failing property test whose
culprit is a line of the implementation (docs/diagnosis.md, "Repairs of the implementation"; steps 2-5
of :mod:`.code_repair`'s docstring).

:func:`checked_repairs` copies the implementation's import closure and the files the mapping reads to a
scratch folder, makes each candidate edit there (the workspace is never touched) and runs every
guarantee of the node again through the property-tests backend's own harness, the failing guarantee
first; a candidate is kept when every run is ``discharged``.  The culprit line's own candidates first,
then the lines around it, then two tokens of the line (:mod:`.pair_edits`).  :func:`repaired_line` names
the line a repair found around the culprit edits.  Nothing here raises for the user's code: a candidate
whose run raises is not kept.
"""
from __future__ import annotations

import shutil
import tempfile
from pathlib import Path
from typing import Any, Iterable, Sequence

from rclverify.diagnosis.code_repair import (MAX_AROUND, MAX_REPAIRS, MAX_TRIED, around_lines, candidate_edits,
                                             contract_kinds)
from rclverify.diagnosis.pair_edits import pair_edits
from rclverify.records.stage_records import Repair


def repaired_line(cause: str, repairs: Sequence[Repair]) -> str:
    """The implementation line (``file:line``) where the first of ``repairs`` (:func:`checked_repairs`,
    of the failure whose culprit is ``cause``) edits, when that is another line than ``cause``'s: the
    repair was found around it (module docstring, step 4), and the line it edits is where the wrong value
    is made; ``""`` otherwise (no repair, or one at ``cause`` itself)."""
    if not repairs:
        return ""
    first = repairs[0]
    edit = first.get("edit") or {}
    at = f"{first.get('file', '')}:{edit.get('line', '')}"
    return at if at != cause and edit.get("line") else ""


def _scratch(root: Path, files: Iterable[str], edited: str, text: str) -> Path:
    """A scratch folder holding ``files`` (workspace-relative) copied from ``root`` and ``edited`` with
    ``text``; the caller removes it."""
    tmp = Path(tempfile.mkdtemp(prefix="rclverify-code-repair-"))
    for f in files:
        src = root / f
        if src.is_file():
            (tmp / f).parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(src, tmp / f)
    (tmp / edited).parent.mkdir(parents=True, exist_ok=True)
    (tmp / edited).write_text(text, encoding="utf-8")
    return tmp


def _statuses(target: Any, cfg: Any, text: str, first: int) -> dict[int, str]:
    """Each guarantee's status (``discharged``, ``failed``, ...) of the node of ``target`` run by the
    harness on a scratch copy whose implementation file holds ``text``, guarantee ``first`` first; it
    stops at the first run that is not ``discharged``.  Only ``discharged`` is told apart: each run asks for
    the verdict only (a violation is ``failed``, unshrunk: :attr:`~rclverify.backends.property_tests.harness.GuaranteeRun.verdict_only`)."""
    from rclverify.backends.property_tests.at_width import mapping_inputs  # deferred: start-up (the backend)
    from rclverify.backends.property_tests.closure import resolve_closure  # deferred: start-up (the backend)
    from rclverify.backends.property_tests.harness import run_guarantee  # deferred: start-up (hypothesis)
    from rclverify.backends.timelimit import TimeLimitExceeded, wall_clock_limit  # deferred: start-up
    root = Path(target.root)
    files = [*resolve_closure(root, cfg.file).files, *mapping_inputs(root, target.mapping)]
    if target.mapping:
        files.append(target.mapping)
    tmp = _scratch(root, files, cfg.file, text)
    n = len(target.node.node.guarantees)
    out: dict[int, str] = {}
    try:
        for k in [first, *(j for j in range(1, n + 1) if j != first)]:
            try:
                with wall_clock_limit(cfg.timeout_s):
                    out[k] = run_guarantee(target.checked, target.node, k, cfg, tmp, target.facts, None,
                                           target.mapping, verdict_only=True).status
            except TimeLimitExceeded:
                out[k] = "inconclusive"
            except Exception:  # noqa: BLE001 - the edited code does not load or run: no repair
                out[k] = "error"
            if out[k] != "discharged":
                break
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return out


def checked_repairs(ws: Any, node: str, obligation: str, cause: str,
                    before: dict[str, str] | None = None) -> list[Repair]:
    """The checked repairs (module docstring) of the failing property-test ``obligation``
    (``Node.gK.property_tests.eI``) of ``node`` whose culprit is ``cause`` (``file:line``, the file as
    the plan entry names it).  ``before``: obligation id -> status in the report, for each repair's
    ``cost``.  ``[]`` when ``cause`` is not a line of the entry's implementation file, when no
    candidate passes, or when the entry cannot be read."""
    from rclverify.backends.property_tests.boundary import contract_numbers  # deferred: start-up (the backend)
    from rclverify.backends.property_tests.harness import read_config, versions  # deferred: start-up (hypothesis)
    from rclverify.diagnosis.repairs import _record  # deferred: start-up (z3 and the contract checks)
    file, _, at = cause.rpartition(":")
    parts = obligation.split(".")
    if not at.isdigit() or len(parts) < 4 or not parts[-1][1:].isdigit() or not parts[1][1:].isdigit():
        return []
    index, failing = int(parts[-1][1:]), int(parts[1][1:])
    try:
        target = ws.target(node, index)
        cfg = read_config(target.config, target.node, target.root)
        source = (Path(target.root) / cfg.file).read_text(encoding="utf-8")
    except Exception:  # noqa: BLE001 - an entry that no longer reads: the plan's checks say why
        return []
    if file != cfg.file:
        return []
    out: list[Repair] = []
    ids = {k: f"{node}.g{k}.property_tests.e{index}" for k in range(1, len(target.node.node.guarantees) + 1)}
    numbers, kinds = contract_numbers(target.node), contract_kinds(target.node)
    around = [e for k in around_lines(source, int(at)) for e in candidate_edits(source, file, k, numbers, kinds)]
    singles = candidate_edits(source, file, int(at), numbers, kinds)
    pairs = [(e, None) for e in pair_edits(source, singles)]  # two tokens of the line: last (pair_edits.py)
    for edit, at_line in [*((e, True) for e in singles[:MAX_TRIED]), *((e, False) for e in around[:MAX_AROUND]),
                          *pairs]:
        if not at_line and out:
            break  # the culprit line's own repairs first; the lines around, then two tokens, only without one
        got = _statuses(target, cfg, edit.apply(source), failing)
        if len(got) != len(ids) or any(s != "discharged" for s in got.values()):
            continue
        old = source.splitlines()[edit.line - 1].strip()
        new = edit.apply(source).splitlines()[edit.line - 1].strip()
        checks = [{"check": ids[k], "status": got[k]} for k in sorted(got)]
        cost = [{"check": ids[k], "before": (before or {}).get(ids[k], "absent"), "after": got[k]}
                for k in sorted(got) if (before or {}).get(ids[k], "absent") != got[k]]
        where = "the line where the failing example goes wrong" if at_line is not False else \
            f"a statement of the same function as {file}:{at}, where the failing example goes wrong"
        said = f"change `{old}` to `{new}`: a {'two' if at_line is None else 'one'}-token correction of {where}"
        if not edit.deleted(source) and "\n" in edit.text:  # a guard inserted (:func:`_guards`)
            said = f"insert `{' '.join(x.strip() for x in edit.text.splitlines())}` before it: a guard of {where}"
        rec = _record("code", f"At {file}:{edit.line}, {said}.", edit, source, checks, cost,
                      proves=f"every guarantee of {node} ({len(ids)}) held again on every example the property "
                      f"tests drew from a scratch copy with the edit (seed {cfg.seed})",
                      not_shown="that the edit is right for the robot: the tests draw examples, they prove nothing")
        rec["checked_by"] = versions()
        out.append(rec)
        if len(out) >= MAX_REPAIRS:
            break
    return out


__all__ = ["checked_repairs", "repaired_line"]
