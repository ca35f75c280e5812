"""A checked repair of the last report, found by id and written into the
workspace on request (``rclverify repair ID [--apply]``; docs/diagnosis.md,
"Applying a repair").

* :func:`find_repairs`: the repairs the last report (``reports/assurance.json``,
  decoded: :class:`~rclverify.records.report_record.AssuranceReport`) offers for an id: a diagnosis's id (a problem's finding, side
  condition, obligation, requirement or deadline id, as ``rclverify explain``
  takes it: exact first, then up to case, ``_``, ``-`` and spaces) or a
  problem's number (``3``, ``p3``, ``problem 3``, the numbers ``rclverify
  status`` shows), whose repairs are its diagnoses' by reference.
* :func:`none_offered`: why an id has no repair, from its diagnosis
  (``not_offered``) or its kind.
* :func:`apply_repair`: the repair's edit made to the workspace file it names,
  written atomically (:func:`rclverify.core.atomic.atomic_write_bytes`, the
  file's permission bits kept), and only when the file's text still has the
  sha256 the repair was computed on (:attr:`Repair.sha256`,
  :func:`rclverify.diagnosis.repairs.text_sha256`) and the region still holds
  the text the edit deletes; else :class:`NotApplied`, nothing written.

Nothing here runs a check: the re-check after an edit is the pipeline's own
stage that produced the failing record (``rclverify.cli.repair``).
"""
from __future__ import annotations

import re
import stat
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping, Sequence

from rclverify.core.atomic import atomic_write_bytes
from rclverify.core.within import outside
from rclverify.diagnosis.edits import Edit
from rclverify.diagnosis.repairs import text_sha256
from rclverify.records.problem_rows import DiagnosisRow
from rclverify.records.repair_rows import RepairRow
from rclverify.records.report_record import AssuranceReport

_PROBLEM = re.compile(r"^(?:problem\s*|p)?(?P<k>\d+)\.?$", re.IGNORECASE)


#: The diagnosis kinds whose repairs are searched (docs/diagnosis.md, "Repairs"): a guard, a side
#: condition's, a unit conversion, a requirement's, a deadline's, a Hoare program's, a code line's.
SEARCHED = frozenset({"vacuity", "inconsistency", "side-condition", "unit", "requirement", "deadline", "hoare",
                      "property-test"})


class NotApplied(Exception):
    """A repair that is not written: where (``file`` as the repair names it, 1-based ``line`` and ``col``
    of its edit) and the one-line reason ``message``."""

    def __init__(self, file: str, line: int, col: int, message: str) -> None:
        super().__init__(f"{file}:{line}:{col}: error: {message}")
        self.file, self.line, self.col, self.message = file, line, col, message


@dataclass(frozen=True)
class Offered:
    """One repair offered for an id: the ``diagnosis`` record it belongs to, its 0-based ``index`` among
    that diagnosis's repairs, and the ``repair`` record."""

    diagnosis: DiagnosisRow
    index: int
    repair: RepairRow


@dataclass(frozen=True)
class Found:
    """What an id names in the report: ``subject`` (the diagnosis id, or ``problem N``), the diagnoses it
    covers and the repairs they offer, in the report's order."""

    subject: str
    diagnoses: tuple[DiagnosisRow, ...]
    offered: tuple[Offered, ...]


def _fold(text: str) -> str:
    """An id up to case, ``_``/``-`` and spaces (as ``rclverify explain`` matches)."""
    return re.sub(r"[\s_-]+", "", str(text)).lower()


def find_repairs(report: AssuranceReport, wanted: str) -> Found | None:
    """What ``wanted`` names in ``report`` (module docstring); ``None`` when it is neither a diagnosis's id
    nor a problem's number.  A diagnosis id is matched exactly first, then up to case and separators."""
    by_id = {d.id: d for d in report.diagnoses}
    key = wanted if wanted in by_id else next((k for k in by_id if _fold(k) == _fold(wanted)), None)
    if key is not None:
        d = by_id[key]
        return Found(key, (d,), tuple(Offered(d, k, r) for k, r in enumerate(d.repairs)))
    m = _PROBLEM.match(wanted.strip())
    if not m or not 1 <= int(m["k"]) <= len(report.problems):
        return None
    row = report.problems[int(m["k"]) - 1]
    members = [by_id[x.id] for x in row.members if x.id in by_id]
    offered = []
    for ref in row.repairs:
        owner = by_id.get(ref.diagnosis)
        if owner is not None and 0 <= ref.index < len(owner.repairs):
            offered.append(Offered(owner, ref.index, owner.repairs[ref.index]))
    return Found(f"problem {m['k']}", tuple(members), tuple(offered))


def none_offered(found: Found) -> list[str]:
    """Why ``found`` offers no repair, one sentence each: a diagnosis's ``not_offered`` sentences (the
    repairs its checks showed do not work), else what kind of problem it is and that no edit tried passed
    its checks (a kind in :data:`SEARCHED`) or that none is searched for its kind, or that the id has no
    diagnosis at all."""
    if not found.diagnoses:
        return [f"{found.subject} has no diagnosis in the last report: nothing was searched"]
    out: list[str] = []
    for d in found.diagnoses:
        said = [f"{d.id}: {s}" for s in d.not_offered or []]
        if not said and d.kind in SEARCHED:
            said = [f"{d.id} ({d.kind}): no edit the diagnosis tried passed its checks "
                    "(docs/diagnosis.md, \"Repairs\", says which edits are tried for this kind)"]
        elif not said and d.kind == "monitor":
            said = [f"{d.id} ({d.kind}): no repair is searched: a node's code is repaired on a "
                    "recorded run by re-running the node on the run's questions (docs/diagnosis.md, \"Monitor "
                    "violations: a node re-run on its recorded run\"), which needs the function that makes its "
                    "rclpy nodes, and its monitors evidence entry names none (`implementation: FILE.py:FUNCTION`, "
                    f"docs/plan.md); `rclverify explain {d.id}` names its culprit"]
        elif not said:
            said = [f"{d.id} ({d.kind}): no repair is searched for this kind of problem; "
                    f"`rclverify explain {d.id}` names its culprit"]
        out += said
    return out


def _refused(repair: RepairRow, message: str) -> NotApplied:
    return NotApplied(repair.file, repair.edit.line, repair.edit.col, message)


def apply_repair(root: Path, repair: RepairRow) -> Path:
    """Make ``repair``'s edit to its file under the workspace ``root`` and return the file's path.

    The file's line ends are kept (the edit is made on its text as stored; positions are lines and
    columns, the same whatever the line end).  Raises :class:`NotApplied` (nothing written) when the
    file is outside ``root``, cannot be read, no longer has the sha256 the repair was computed on, or
    the edit's region does not hold the text it deletes; ``OSError`` when the write fails."""
    rel, e = repair.file, repair.edit
    path = root / rel
    if not rel or outside(root, path):
        raise _refused(repair, f"the repair edits {rel!r}, which is not a file of the workspace {root}")
    try:
        raw = path.read_bytes().decode("utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise _refused(repair, f"cannot read the file the repair edits: {exc}") from None
    text = raw.replace("\r\n", "\n").replace("\r", "\n")  # as read_text gives it: what the digest is of
    want, have = repair.sha256, text_sha256(text)
    if want != have:
        raise _refused(repair, (f"{rel} changed since the last run checked this repair (sha256 {have[:12]}, "
                                 f"the repair was checked on {want[:12] or 'an unrecorded text'}); nothing "
                                 "written: run `rclverify verify` again, then `rclverify repair` on the new report"))
    edit = Edit(rel, e.line, e.col, e.end_line, e.end_col, e.inserted)
    if edit.deleted(raw) != e.deleted:
        raise _refused(repair, f"the region of the edit holds {edit.deleted(raw)!r}, not {e.deleted!r}; "
                                "nothing written")
    mode = stat.S_IMODE(path.stat().st_mode)
    atomic_write_bytes(path, edit.apply(raw).encode("utf-8"), mode=mode, within=root)
    return path


def obligation_checks(diagnosis: DiagnosisRow, repair: RepairRow) -> list[str]:
    """The obligation ids (``Node.gK.<backend>.eI...``) a code or program repair was checked against, the
    diagnosis's own first: the evidence to produce again after the edit."""
    ids = [diagnosis.id] + [c.check for c in repair.checks]
    return list(dict.fromkeys(i for i in ids if re.match(r"^\w+\.g\d+\.\w+\.e\d+", i)))


def statuses_before(report: AssuranceReport) -> dict[str, str]:
    """Every id's status in ``report``: obligations, evidence, side conditions, health findings,
    requirements (their verdict) and deadlines (``REQ.deadline``, their verdict), for the before -> after of a re-check."""
    out: dict[str, str] = {}
    for f in report.findings:
        out[f.id] = str(f.status)
    for sc in report.side_conditions:
        out[sc.id] = str(sc.status)
    for o in report.obligations:
        out[o.id] = str(o.status)
    for ev in report.evidence:
        out[ev.obligation] = str(ev.status)
    for r in report.requirements:
        out[r.id] = str(r.verdict)
    for dl in report.deadlines:
        out[f"{dl.requirement}.deadline"] = str(dl.verdict)
    return out


def changed_lines(before: Mapping[str, str], after: Sequence[tuple[str, str]]) -> list[str]:
    """``id: before -> after`` for each re-checked id (``absent`` for one the report did not have)."""
    return [f"{i}: {before.get(i, 'absent')} -> {s}" for i, s in after]


__all__ = ["SEARCHED", "Found", "NotApplied", "Offered", "apply_repair", "changed_lines", "find_repairs", "none_offered",
           "obligation_checks", "statuses_before"]
