"""The sealed stage records the report reads, never believed when altered.

Each node's side conditions (``artifacts/calculus/<Node>.json``) and
contract health findings (``artifacts/health/<Node>.json``), the lint
diagnostics and the grounding are sealed records
(:mod:`rclverify.records.sealed`, docs/integrity.md).  A record whose seal
does not hold is shown as ``error`` ("... altered outside rclverify"),
never with the statuses it claims: its side conditions are each ``error``
(one placeholder when it cannot be read at all; so are they when they are
no side-condition rows), its findings are replaced
by one ``error`` finding, which fails ``--strict`` and is listed among the
problems.
"""
from __future__ import annotations

import hashlib
from typing import Any, Iterable, Mapping

import msgspec

from rclverify.records.findings import HealthFinding
from rclverify.records.records import Obligation, SourceRef
from rclverify.records.sealed import obligation_list, read_sealed
from rclverify.records.side_condition_rows import SideConditionRow
from rclverify.records.composition_records import LintWarning
from rclverify.stages.workspace import Workspace
from rclverify.records.store import dumps
from rclverify.stages.provenance import check_inputs


def _error_side_conditions(node: str, body: dict[str, Any] | None, why: str) -> dict[str, Any]:
    scs = (body or {}).get("side_conditions")
    rows = [sc for sc in scs if isinstance(sc, dict) and "id" in sc] if isinstance(scs, list) else []
    if not rows:  # nothing to name: one placeholder, so the node is never shown with no open side condition
        rows = [{"id": f"{node}.calculus", "node": node, "conjunct": "(the node's side conditions)"}]
    return {**(body or {}), "node": node, "side_conditions": [_error_side_condition(node, sc, why) for sc in rows]}


def _error_side_condition(node: str, sc: Mapping[str, Any], why: str) -> dict[str, Any]:
    """The side condition ``sc`` of ``node``'s record not believed (``why``) as an ``error`` row
    (:class:`~rclverify.records.side_condition_rows.SideConditionRow`'s JSON object): its texts kept where
    they are texts, no model."""
    def text(k: str) -> str:
        v = sc.get(k)
        return v if isinstance(v, str) else ""

    def texts(k: str) -> list[str]:
        v = sc.get(k)
        return [x for x in v if isinstance(x, str)] if isinstance(v, list) else []
    d, ctx = sc.get("duration_s"), sc.get("context")
    return SideConditionRow(
        id=str(sc["id"]), node=text("node") or node, rule=text("rule"), conjunct=text("conjunct"),
        source=text("source"), hypotheses=texts("hypotheses"), status="error", verdict="error",
        duration_s=float(d) if isinstance(d, (int, float)) and not isinstance(d, bool) and d >= 0 else 0.0,
        smt2=text("smt2"), model=None, explanation=f"error: {why}; recorded status not shown",
        variant=text("variant"), links=texts("links"), context=ctx if isinstance(ctx, dict) else None).to_json()


def _malformed_side_conditions(body: Mapping[str, Any] | None) -> str:
    """Why a sealed calculus record's side conditions are not side-condition rows
    (:class:`~rclverify.records.side_condition_rows.SideConditionRow`: a key the class does not declare, a
    value of another type), ``""`` when they are (or the stage has not run)."""
    try:
        msgspec.convert((body or {}).get("side_conditions", []), list[SideConditionRow])
    except msgspec.ValidationError as e:
        return f"side-condition record malformed ({e}): altered outside rclverify"
    return ""


def _error_finding(node: str, why: str) -> HealthFinding:
    return HealthFinding(id=f"{node}.health-record", node=node, check="record", guarantee=None, status="error",
                         message=f"error: contract health of {node}: {why}", explanation="")


def _findings(body: Mapping[str, Any] | None) -> tuple[list[HealthFinding], str]:
    """``(findings, problem)`` of a sealed health record's content, decoded into
    :class:`~rclverify.records.findings.HealthFinding` (``[]`` before the stage
    ran); a key the class does not declare or a value of another type is a
    problem (``([], why)``)."""
    try:
        return msgspec.convert((body or {}).get("findings", []), list[HealthFinding]), ""
    except msgspec.ValidationError as e:
        return [], f"contract health record malformed ({e}): altered outside rclverify"


def node_records(ws: Workspace, nodes: Iterable[str]) -> tuple[dict[str, dict[str, Any]], dict[str, list[HealthFinding]]]:
    """``(compositions, health findings)`` of ``nodes``, by node: ``{}`` /
    ``[]`` before the stage ran, the records' content when their seals hold
    (the findings decoded, :func:`_findings`), and ``error`` rows otherwise
    (module docstring)."""
    comps: dict[str, dict[str, Any]] = {}
    health: dict[str, list[HealthFinding]] = {}
    for n in nodes:
        rel = ws.calculus(n)
        body, why = read_sealed(ws.path(rel), "side-condition record")
        why = why or _malformed_side_conditions(body)
        comps[n] = _error_side_conditions(n, body, f"{rel}: {why}") if why else (body or {})
        rel = ws.health(n)
        body, why = read_sealed(ws.path(rel), "contract health record")
        findings, malformed = _findings(body) if not why else ([], "")
        why = why or malformed
        health[n] = [_error_finding(n, f"{rel}: {why}")] if why else findings
    return comps, health


def node_obligations(ws: Workspace, node: str) -> tuple[list[Obligation], str]:
    """``(obligations, problem)`` of ``node``'s obligation list: ``([], "")``
    before export; when its seal does not hold, one placeholder obligation
    ``<node>.obligations`` bearing on every guarantee (guarantee 0) and the
    problem sentence: the caller shows it ``error`` (a list with a failing
    obligation removed by hand is never believed)."""
    rel = ws.obligations(node)
    records, problem = obligation_list(ws.path(rel))
    try:
        obligations = [Obligation.from_json(d) for d in records or []]
    except msgspec.ValidationError as e:  # sealed, but not an obligation: altered and sealed again by hand
        problem = problem or f"obligation list malformed ({e}): altered outside rclverify"
    if problem:
        return [Obligation(id=f"{node}.obligations", node=node, guarantee=0, backend="record", kind="proof",
                           statement=f"error: {rel}: {problem}", source=SourceRef(rel, 1, 1))], f"{rel}: {problem}"
    return obligations, ""


def diagnostics(ws: Workspace) -> list[LintWarning]:
    """The lint warnings rows of ``artifacts/check/diagnostics.json`` (its
    ``warnings``); when its seal does not hold, one ``error`` row saying so
    in their place."""
    body, why = read_sealed(ws.path(ws.DIAGNOSTICS), "lint record")
    if why:
        return [{"severity": "error", "file": ws.DIAGNOSTICS, "line": 1, "col": 1, "code": "E-altered",
                 "message": f"{why}; the lint warnings it claims are not shown"}]
    return list((body or {}).get("warnings", []))


def grounding(ws: Workspace, rel: str) -> dict[str, Any] | None:
    """The grounding record ``rel`` (``None`` before it was made); when its
    seal does not hold, a record of one error and no findings; when the
    files it was made from (its ``inputs``, path -> sha256) changed since,
    the record with ``stale`` (a sentence) added."""
    body, why = read_sealed(ws.path(rel), "grounding record")
    if why:
        return {"counts": {"error": 1, "warning": 0}, "altered": f"{rel}: {why}",
                "findings": [{"code": "ROS-RECORD", "severity": "error", "message": f"{rel}: {why}", "node": None,
                              "topic": None, "rcl": None, "ros": None}],
                "context": {"packages": [], "files": []}, "drawing": {"dot": "", "svg": None},
                "graph": {"nodes": []}, "matched": {}}
    if body is not None:
        from rclverify.records.records import hash_inputs  # deferred: optional or conditional (inside a block)
        from rclverify.ros.graph.inputs import input_files  # deferred: optional or conditional (inside a block)
        made = body.get("inputs")
        now = input_files(ws)
        if not isinstance(made, dict) or set(made) != set(now) or hash_inputs(ws.root, now) != made:
            body["stale"] = (f"{rel} was made from other files of the plan, contracts or ROS software than the "
                             "current ones (run `doit verify`)")
    return body


def inputs_sha256(ws: Workspace, made_from: Mapping[str, str], evidence_inputs: Mapping[str, object],
                  checks: Mapping[str, Mapping[str, object]], nodl: Mapping[str, object] | None = None) -> str:
    """One sha256 over what a report is built from, recorded in its
    ``meta.inputs_sha256``: the sha256 of the plan, contract and replacement
    files (:func:`rclverify.stages.provenance.check_inputs`), of the contract
    snapshots and system model they give (``made_from``), the
    ``input_hashes`` of each obligation's evidence record
    (``evidence_inputs``: obligation id -> hashes, ``None`` without a
    record), and each requirement record's verdict, fingerprint and inputs
    (``checks``), and for a workspace with NoDL documents the files the NoDL
    record was made from and their sha256 now (``nodl``,
    :func:`rclverify.report.nodl.nodl_inputs`).  Timestamps and durations are left out, so an incremental
    run and a clean one give the same value.  The bundle compares it with
    the value of a report built now (docs/argument.md): a report written
    before the evidence was produced again is not packed."""
    body = {"files": check_inputs(ws), "made_from": dict(made_from), "evidence": dict(evidence_inputs),
            "requirements": {k: [v.get("verdict"), v.get("fingerprint"), v.get("inputs")] for k, v in checks.items()}}
    if nodl is not None:  # only then: a workspace without NoDL documents keeps the value it had
        body["nodl"] = dict(nodl)
    return hashlib.sha256(dumps(body).encode("utf-8")).hexdigest()
