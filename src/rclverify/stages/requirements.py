"""The ``requirements`` stage: check every requirement, write its record.

Writes ``artifacts/requirements/<ID>.json`` (the record of
:func:`.check.check_requirement` plus its ``fingerprint`` and ``inputs``,
the sha256 of each contract snapshot of its cone and of the system model),
``artifacts/requirements/<ID>.smt2`` (the query), ``<ID>.consistency.smt2``
and ``<ID>.vacuity.smt2`` (a proved requirement's side queries, when Z3
decided them) and
``artifacts/requirements/index.json`` (``{"records": {id: sha256 of the
record}}``, in requirement order: the report tasks depend on it).  Records
and index are sealed (:mod:`rclverify.records.sealed`); a record whose seal
does not hold is checked again, never reused.  A requirement whose
fingerprint (its statements, the contract snapshots of its cone, the system
model) equals the recorded one is not checked again, so editing one
contract re-checks only the requirements whose cone contains that node.
Records of requirements no longer in the plan are removed.
"""
from __future__ import annotations

import hashlib
import json
import re
from typing import TYPE_CHECKING, Any, Literal, Mapping, TypeGuard

from rclverify.records.sealed import read_sealed, write_sealed
from rclverify.records.store import atomic_write_text, dumps
from rclverify.records.ties import tie_query

if TYPE_CHECKING:
    from rclverify.records.stage_records import RequirementCheck, RequirementRecord
    from rclverify.stages.workspace import Workspace

DIR = "artifacts/requirements"
INDEX = f"{DIR}/index.json"
_SAFE = re.compile(r"[^A-Za-z0-9_.-]+")


#: The side queries of a proved requirement whose scripts are kept beside its record
#: (``artifacts/requirements/<ID>.<side>.smt2``, ``<side>_smt2`` in the record).
SIDE_QUERIES = ("consistency", "vacuity")
#: ``(kind, record key, file suffix)`` of each query kept beside a record: the proof's, then :data:`SIDE_QUERIES`.
_QUERIES: tuple[tuple[str, Literal["smt2", "consistency_smt2", "vacuity_smt2"], str], ...] = (
    ("requirement", "smt2", ""), ("consistency", "consistency_smt2", ".consistency"),
    ("vacuity", "vacuity_smt2", ".vacuity"))


def record_path(req_id: str) -> str:
    """Workspace-relative path of a requirement's record."""
    return f"{DIR}/{_SAFE.sub('_', req_id)}.json"


def _is_check(rec: Mapping[str, object]) -> TypeGuard["RequirementCheck"]:
    """Does ``rec`` (a requirement check's record, calculus/requirements/own_nodes.py ``decide``) name
    its requirement and verdict?"""
    return isinstance(rec.get("id"), str) and isinstance(rec.get("verdict"), str)


def _is_record(rec: Mapping[str, object]) -> TypeGuard["RequirementRecord"]:
    """Is ``rec`` a requirement's record as this stage writes it (a check with its ``fingerprint``)?"""
    return _is_check(rec) and isinstance(rec.get("fingerprint"), str)


def _read(path: Any) -> "RequirementRecord | None":
    """The sealed record at ``path``; ``None`` when absent, not intact or not a requirement's record."""
    rec, problem = read_sealed(path)
    return None if problem or rec is None or not _is_record(rec) else rec


def stage_requirements(ws: "Workspace", *, force: bool = False) -> list[tuple["RequirementRecord", bool]]:
    """Check the requirements of ``ws`` (module docstring).  Returns
    ``(record, checked_now)`` per requirement, in plan order (the plan's,
    then the Doorstop items').  Raises ``RclError`` for contracts or a plan
    that do not check."""
    from rclverify.model.plan.load import all_requirements  # deferred: start-up (loads yaml, rclverify.lang and more only when called)
    import z3  # deferred: start-up (loads z3 only when called)

    from rclverify.semantics.world import fresh  # deferred: start-up (loads rclverify.semantics, rclverify.semantics.world only when called)
    from rclverify.core.cache import code_stamp  # deferred: start-up (loads rclverify.core.cache, fractions and more only when called)
    from rclverify.calculus.requirements.check import cone_of, fingerprint, state_text, statement_formals  # deferred: start-up (loads lark, yaml and more only when called)
    from rclverify.calculus.requirements.own_nodes import decide, fingerprint_inputs  # deferred: start-up (loads z3 and more only when called)
    from rclverify.backends.monitors.temporal_evidence import fingerprint_text, requirement_traces, trace_hashes, trace_rows  # deferred: start-up (loads jinja2, lark and more only when called)
    from rclverify.model.plan.fret.seal import compared, sealed_inputs  # deferred: start-up (only a plan that reads FRET)
    code = f"{code_stamp()} z3 {z3.get_version_string()}"
    checked, model, plan = ws.checked, ws.model, ws.plan
    model_text = (ws.root / ws.MODEL).read_text(encoding="utf-8") if (ws.root / ws.MODEL).is_file() else \
        json.dumps(model.to_json(), sort_keys=True)
    model_hash = hashlib.sha256(dumps(model.to_json()).encode("utf-8")).hexdigest()  # as the report takes it
    snaps: dict[str, str] = {}

    def snap(n: str) -> str:
        if n not in snaps:
            p = ws.root / ws.snapshot(n)
            snaps[n] = p.read_text(encoding="utf-8") if p.is_file() else ""
        return snaps[n]
    out: list[tuple[RequirementRecord, bool]] = []
    index: dict[str, str] = {}
    keep = set()
    for req in all_requirements(plan):
        formals = statement_formals(req, checked, plan)
        formal = formals[0] if formals else None
        cone = cone_of(formals, model) if formal is not None else []
        # a temporal requirement also reads the state declarations of its cone (plan.states)
        traces = requirement_traces(req, checked, plan)  # recorded runs checked against it (docs/plan.md)
        th = trace_hashes(ws.root, traces)
        fret = sealed_inputs(ws.root, plan, req)  # a FRET requirement's entry in the export (model/plan/fret/seal.py)
        fp = fingerprint(req, [snap(n) for n in cone] + [state_text(plan, cone)] + ([fingerprint_text(ws.root, traces)] if traces else []) + compared(fret)
                         + (fingerprint_inputs(req, checked, model, plan) if formal is not None else []),
                         model_text if formal is not None else "", code)
        rel = record_path(req.id)
        keep.add(rel.rsplit("/", 1)[1])
        old = None if force else _read(ws.root / rel)
        rec: RequirementRecord
        if old is not None and old.get("fingerprint") == fp:
            rec, now = old, False
        else:
            fresh()  # each check in the same Z3 state whatever ran before it (semantics/world.py)
            made = decide(req, checked, model, plan)  # its own nodes first (calculus/requirements/own_nodes.py)
            if not _is_check(made):
                raise ValueError(f"the check of requirement {req.id} gave no id and verdict")
            queries: dict[str, tuple[str, str]] = {}  # the script's path -> (kind, text)
            for kind, key, suffix in _QUERIES:
                text = made.pop(key, None)  # the proof's query, then the consistency and vacuity queries
                if text is not None:
                    made[key] = rel[:-5] + f"{suffix}.smt2"
                    queries[made[key]] = (kind, text)
            rec = {**made, "fingerprint": fp,
                   "inputs": input_hashes(ws, cone, snap, model_hash) if formal is not None else {}}
            rec["inputs"].update(fret)
            if traces:
                rec["traces"] = trace_rows(req, checked, plan, ws.root)
                rec["inputs"].update(th)
            for path, (kind, text) in queries.items():  # each ends naming the statement it decides (records/ties.py)
                atomic_write_text(ws.root / path, tie_query(text, kind, req.id, rec))
            write_sealed(ws.root / rel, rec)
            now = True
        for _, key, _ in _QUERIES:
            kept = rec.get(key)
            if kept:
                keep.add(kept.rsplit("/", 1)[1])
        index[req.id] = hashlib.sha256((ws.root / rel).read_bytes()).hexdigest()
        out.append((rec, now))
    write_sealed(ws.root / INDEX, {"records": index})
    keep.add("index.json")
    for old_file in (ws.root / DIR).glob("*"):
        if old_file.is_file() and old_file.name not in keep:
            old_file.unlink()
    return out


def input_hashes(ws: "Workspace", cone: list[str], snap: Any, model_hash: str) -> dict[str, str]:
    """``{artifacts/contracts/<Node>.json: sha256, artifacts/system/model.json: sha256}``
    of the snapshots of ``cone`` (``snap(node)`` gives a snapshot's text) and
    the model a record is made from: the hashes the report compares with the
    current ones (:func:`read_records`)."""
    from rclverify.model.plan.state import state_key, state_sha256  # deferred: start-up (loads rclverify.lang, rclverify.lang.ast and more only when called)
    out = {ws.snapshot(n): hashlib.sha256(snap(n).encode("utf-8")).hexdigest() for n in cone}
    out.update({state_key(n): state_sha256(ws.plan.states, n) for n in cone})  # a state: edit is stale too
    out[ws.MODEL] = model_hash
    return out


def read_records(ws: "Workspace", current: dict[str, str] | None = None) -> dict[str, dict[str, Any]]:
    """The records named by ``index.json`` (``{}`` before the stage ran), by
    requirement id, as the report may show them:

    * a record (or the index) whose seal does not hold is replaced by
      ``{"verdict": "error", "reason": why, ...}`` (keeping the statements it
      claims to be about, so that :func:`rclverify.report.build.current_record`
      matches it): never the verdict it claims;
    * with ``current`` (path -> sha256 of the contract snapshots and model
      the current contracts and plan give,
      :func:`rclverify.stages.provenance.current_snapshot_hashes`), a record made
      from other inputs (a hash differs, or it records none) is replaced by
      ``{"verdict": "stale", "recorded_verdict": ..., ...}``.
    """
    index, problem = read_sealed(ws.root / INDEX, "requirement index")
    if index is None:
        return {}
    records = index.get("records")
    ids = records if isinstance(records, dict) else {}
    out: dict[str, dict[str, Any]] = {}
    for rid in ids:
        rec, why = read_sealed(ws.root / record_path(rid), "requirement record")
        if rec is None and not why:
            continue
        keep = {k: rec.get(k) for k in ("id", "formal", "assuming", "ranking", "invariant", "source",
                                           "origin", "text")} if rec else {}
        if why or problem:
            out[rid] = {**keep, "verdict": "error", "reason": f"{record_path(rid)}: {why or problem}"}
            continue
        assert rec is not None
        made = rec.get("inputs")
        if current is not None and isinstance(made, dict):  # a recorded run's sha256 now (trace:<path>)
            from rclverify.backends.monitors.temporal_evidence import trace_hashes  # deferred: optional or conditional (inside a block)
            current = {**current, **trace_hashes(ws.root, [(p[6:], None) for p in made
                                                           if p.startswith("trace:") and p not in current])}
            from rclverify.model.plan.fret.seal import current as fret_now  # deferred: optional or conditional (inside a block)
            current = {**current, **fret_now(ws.root, made)}
        if current is not None and rec.get("verdict") != "informal" and (
                not isinstance(made, dict) or any(current.get(p) != h for p, h in made.items())):
            out[rid] = {**keep, "verdict": "stale", "recorded_verdict": rec.get("verdict"),
                        "reason": f"{record_path(rid)} was made from another text of the contracts or plan"}
            continue
        out[rid] = rec
    return out
