"""The ``deadlines`` stage: rule D3 for every requirement's end-to-end
deadline, written as one sealed record (docs/integrity.md).

Writes ``artifacts/deadlines/index.json``, ``{"results": [...]}``: one entry
per ``deadline:`` of the plan, in plan order, each
:meth:`~.deadlines.DeadlineResult.to_json` plus ``smt2`` (the query, saved
as ``artifacts/deadlines/<ID>.smt2`` for re-checking with any SMT solver)
and ``inputs`` (the sha256 of the contract snapshot of every node of the
path and every node between its ends, :func:`.worst_path.nodes_between`,
and of the system model: what a chain is made from, rules D1 and D2, and
what the slowest other path is; with the named path's nodes only, an edit
of a hop off it left a proof recorded before it unstale).
The record is sealed (:mod:`rclverify.records.sealed`); a reader never
believes one whose seal does not hold (:func:`read_deadlines`: ``error``),
nor one made from other inputs than the current ones (``stale``).  Every
deadline is decided again whenever the stage runs (a Z3 query over a few
reals each): the record is a pure function of its inputs, so an
incremental run writes the same record as a clean one.
"""
from __future__ import annotations

import hashlib
import re
from typing import TYPE_CHECKING, Any, Mapping, TypeGuard

from rclverify.records.sealed import read_sealed, write_sealed
from rclverify.records.store import atomic_write_text, dumps
from rclverify.records.ties import tie_query
from rclverify.calculus.deadlines import DeadlineResult, decide_plan
from rclverify.calculus.worst_path import nodes_between, with_worst_path

if TYPE_CHECKING:
    from rclverify.records.stage_records import DeadlineCheck, DeadlineRecord
    from rclverify.stages.workspace import Workspace

DIR = "artifacts/deadlines"
INDEX = f"{DIR}/index.json"
_SAFE = re.compile(r"[^A-Za-z0-9_.-]+")


def smt2_path(req_id: str) -> str:
    """Workspace-relative path of the query of ``req_id``'s deadline."""
    return f"{DIR}/{_SAFE.sub('_', req_id)}.smt2"


def _is_check(rec: Mapping[str, object]) -> TypeGuard["DeadlineCheck"]:
    """Does ``rec`` (calculus/deadlines.py ``DeadlineResult.to_json``) name its requirement and status?"""
    return isinstance(rec.get("requirement"), str) and isinstance(rec.get("status"), str)


def stage_deadlines(ws: "Workspace") -> tuple[list[DeadlineResult], list["DeadlineRecord"]]:
    """Decide every end-to-end deadline of ``ws``'s plan (rule D3) and write
    the stage's record (module docstring).  Reads the contract snapshots the
    ``check`` stage wrote (their sha256 are the record's ``inputs``).
    Returns ``(results, records)`` in plan order.  Raises ``RclError`` for
    contracts or a plan that do not check, ``OSError`` when a file cannot
    be written."""
    results = [with_worst_path(r, ws.checked, ws.model) for r in decide_plan(ws.plan, ws.checked, ws.model)]
    model_hash = hashlib.sha256(dumps(ws.model.to_json()).encode("utf-8")).hexdigest()  # as the report takes it
    records: list[DeadlineRecord] = []
    keep = {"index.json"}
    for r in results:
        made = r.to_json()
        if not _is_check(made):
            raise ValueError(f"the deadline of {r.requirement} was decided without a requirement or status")
        inputs = {}
        for n in nodes_between(ws.model, r.path):  # every node the worst path may take, as the task's inputs
            p = ws.path(ws.snapshot(n))
            inputs[ws.snapshot(n)] = hashlib.sha256(p.read_bytes()).hexdigest() if p.is_file() else ""
        inputs[ws.MODEL] = model_hash
        rec: DeadlineRecord = {**made, "smt2": smt2_path(r.requirement) if r.smt2 else "", "inputs": inputs}
        if r.smt2:  # it ends naming the statement it decides (records/ties.py)
            atomic_write_text(ws.path(rec["smt2"]), tie_query(r.smt2, "deadline", r.requirement, rec))
            keep.add(rec["smt2"].rsplit("/", 1)[1])
        records.append(rec)
    write_sealed(ws.path(INDEX), {"results": records})
    for old in ws.path(DIR).glob("*"):
        if old.is_file() and old.name not in keep:
            old.unlink()
    return results, records


def read_deadlines(ws: "Workspace", current: Mapping[str, str] | None = None) -> tuple[list[dict[str, Any]] | None, str]:
    """``(records, problem)`` of the stage's record: ``(None, "")`` before
    the stage ran; ``(None, why)`` when its seal does not hold (the caller
    shows every deadline ``error``); else the records, where one made from
    other inputs than ``current`` (path -> sha256 of the contract snapshots
    and model the current contracts and plan give,
    :func:`rclverify.stages.provenance.current_snapshot_hashes`) has ``status``
    ``stale`` and its claim kept as ``recorded_status``."""
    body, why = read_sealed(ws.path(INDEX), "deadline record")
    if why:
        return None, f"{INDEX}: {why}"
    if body is None:
        return None, ""
    rows = body.get("results")
    if not isinstance(rows, list) or not all(isinstance(x, dict) for x in rows):
        return None, f"{INDEX}: deadline record malformed: altered outside rclverify"
    out = []
    for rec in rows:
        made = rec.get("inputs")
        if current is not None and (not isinstance(made, dict) or any(current.get(p) != h for p, h in made.items())):
            rec = {**rec, "status": "stale", "recorded_status": rec.get("status"),
                   "reason": f"{INDEX} was made from another text of the contracts or plan (run `doit verify`)"}
        out.append(rec)
    return out, ""
