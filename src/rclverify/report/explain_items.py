"""What ``rclverify explain ID`` prints for one item of the report: a
requirement, a contract-health finding, an obligation, a side condition of
the calculus, a problem grouped by root cause (:mod:`.explain` finds the item by its id).

A requirement, a finding, an obligation, a side condition and a problem
arrive decoded into their one definition (records/requirement_rows.py,
records/findings.py, records/obligations.py, records/side_condition_rows.py,
records/problem_rows.py) and are read as attributes mypy checks; for a
requirement, a finding, an obligation and a problem each field is printed
here or named in its record module's ``INTERNAL_TO["explain"]`` with the
reason it is not (tests/records/test_record_shapes.py).  What a record keeps
as JSON is decoded into the reader's Struct: a requirement's check into
:class:`~rclverify.records.requirement_check.RequirementCheckRow`, its temporal
check into :class:`_Temporal`, a monitored run's record into
:class:`~rclverify.records.monitored_run.MonitoredRun`.  Each
function returns the lines to print, two spaces indenting what belongs to
the item's first line.
"""
from __future__ import annotations

from typing import Any, Mapping

import msgspec

from rclverify.diagnosis.table import counterexample_rows
from rclverify.records.evidence_rows import EvidenceRow
from rclverify.records.findings import Acknowledged, FindingRow
from rclverify.records.monitored_run import MonitoredRun
from rclverify.records.obligations import ObligationRow
from rclverify.records.problem_rows import ProblemRow
from rclverify.records.requirement_check import RequirementCheckRow
from rclverify.records.requirement_rows import RequirementRow
from rclverify.records.side_condition_rows import SideConditionRow
from rclverify.report.diagnosis_text import clause_cut, table_lines
from rclverify.report.summary import whole_sentence

#: The statuses of an item that holds: its model is a witness, and without a diagnosis there is no problem.
HOLDS = ("discharged", "ok", "warning")


class _Temporal(msgspec.Struct, frozen=True):
    """What is printed of a temporal check's record (``check.temporal``, calculus/shapes.py
    ``TemporalVerdictJson``): its status, the method that decided it, the detail and a proof's certificate."""

    status: str | None = None
    method: str | None = None
    detail: str | None = None
    certificate: str | None = None


def requirement_lines(row: RequirementRow | Mapping[str, Any]) -> list[str]:
    """One requirement of the report (its row, decoded here when given as
    its JSON object) as text: id, verdict, status, source;
    its statement, formal statement, assumptions, the note; the premises a
    proof used, those traced but not needed, an inconsistent or vacuity
    core; a counterexample node by node and the guarantees that did not
    prevent it (docs/requirements.md).  Raises
    :class:`msgspec.ValidationError` for a row of another shape."""
    r = RequirementRow.of(row)
    c = RequirementCheckRow.of(r.check)  # the requirement check's record (calculus/requirements/check.py)
    out = [f"{r.id}: {r.verdict or 'traced'} [{r.status}]  {c.source or ''}".rstrip(), f"  {r.text}"]
    if c.formal:
        out.append(f"  formal: {c.formal}")
    out += [f"  assuming: {a}" for a in c.assuming]
    if r.note:
        out.append(f"  {r.note}")
    t = msgspec.convert(c.temporal or {}, _Temporal)
    if t.method:  # how a temporal statement was decided; an IC3/PDR proof's certificate
        out.append(f"  temporal check: {t.status} by {t.method}" + (f"; {t.detail}" if t.detail else ""))
        if t.certificate:
            out.append(f"    certificate (inductive invariant, re-checked): {t.certificate}")
    out += [f"    used: {p.label}: {p.text}  ({p.source})" for p in c.used]
    out += [f"    traced, not needed: {p.label}" for p in c.traced_not_needed]
    out += [f"    contradictory: {p.label}: {p.text}  ({p.source})" for p in c.inconsistent_core]
    out += [f"    premise never holds with: {p.label}: {p.text}  ({p.source})" for p in c.vacuity_core]
    for step in c.counterexample:
        out.append(f"    counterexample {step.node}: " + ", ".join(f"{k} = {v}" for k, v in step.values.items()))
    if c.counterexample_note:
        out.append(f"    {c.counterexample_note}")
    out += [f"    did not prevent it: {p.label}: {p.text}  ({p.source})" for p in c.failed_to_prevent]
    return out


def violation_id_lines(key: str, m: MonitoredRun) -> list[str]:
    """The lines naming every violation the monitored run ``m`` of obligation ``key`` kept, each by its id
    ``key#N``, and how many more it counted; ``[]`` without one."""
    out = [f"  violation {key}#{k}: {v.where} (t = {v.time} s), guarantee {v.guarantee}"
           for k, v in enumerate(m.violations, 1)]
    if m.violations_dropped:
        out.append(f"  and {m.violations_dropped} more violation(s), counted, not kept")
    return (["", "violations (each: `rclverify explain ID`):"] + out) if out else []


def violation_lines(key: str, n: int, m: MonitoredRun) -> list[str] | None:
    """Violation ``key#n`` (1-based) of the monitored run ``m``: where, when, the guarantee, the question
    it answered, why and the values read; ``None`` when the run kept no such violation."""
    vs = m.violations
    if not 1 <= n <= len(vs):
        return None
    v = vs[n - 1]
    out = [f"violation {key}#{n} of {len(vs)} on {m.trace}: {v.where} (t = {v.time} s)",
           f"  guarantee {v.guarantee}: {v.formula}"]
    if v.trigger_where:
        out.append(f"  answering the question at {v.trigger_where} (t = {v.trigger_time} s)")
    out.append(f"  {v.reason}")
    out += [f"    {name} = {value}" for name, value in sorted((v.values or {}).items())]
    return out


def finding_lines(f: FindingRow, diagnosed: bool) -> list[str]:
    """A health check's finding: every field but those ``INTERNAL_TO["explain"]`` names; ``diagnosed``:
    whether a diagnosis of it follows (else one that holds says there is no problem to diagnose)."""
    whom = f"guarantee {f.guarantee}" if f.guarantee is not None else "the whole contract"
    out = [f"{f.id} [{f.status}] (health check of {f.node})", f"  {f.message}",
           f"  check: {f.check}, of {whom}" + (f", decided in {f.duration_s:.3g} s" if f.duration_s else "")]
    if f.explanation:
        out.append(f"  {f.explanation}")
    if f.solvers is not None:  # the second solver's agreement (docs/second-solver.md)
        out.append(f"  second solver: {f.solvers.agreement}: {f.solvers.why}")
    out += _acknowledgement(f.id, f.acknowledged, f.sha256)
    out += [f"  core: {c}" for c in f.core or []]
    out += [f"  instance {k}: {v}" for k, v in sorted((f.instances or {}).items())]
    out += _model_lines(f.status, f.model, f.node)
    out += [f"  witness: {k} = {v}" for k, v in sorted((f.witness or {}).items())]
    out += [f"  {what}: {path}" for what, path in (("query", f.smt2), ("witness query", f.witness_smt2)) if path]
    return out + _undiagnosed(f.status, diagnosed)


def obligation_lines(o: ObligationRow, evidence: EvidenceRow | None, violations: list[str],
                     diagnosed: bool) -> list[str]:
    """An obligation with its ``evidence`` row's explanation (``None`` when it has none) and ``violations``,
    the lines naming what a monitored run of it kept; ``diagnosed`` as in :func:`finding_lines`."""
    whom = f"guarantee {o.guarantee}" if o.guarantee else "the whole contract"
    out = [f"{o.id} [{o.status}] (obligation of {o.node}" + (f", {o.source}" if o.source else "") + ")",
           f"  {o.statement}",
           f"  backend: {o.backend}" + (f"; {evidence.explanation}" if evidence and evidence.explanation else ""),
           f"  {o.kind} of {whom}" + (f", instance {o.instance}" if o.instance else "")
           + (f"; rendered to {o.artifact}" if o.artifact else "")]
    return out + violations + _undiagnosed(o.status, diagnosed)


def side_condition_lines(key: str, x: SideConditionRow, diagnosed: bool) -> list[str]:
    """Side condition ``key`` (its decoded row ``x``): its conjunct, explanation, the upstream premises
    it assumed and its counterexample; ``diagnosed`` as in :func:`finding_lines`."""
    out = [f"{key} [{x.status}] (side condition of {x.node}" + (f", {x.source}" if x.source else "") + ")",
           f"  {x.conjunct}"]
    if x.explanation:
        out.append(f"  {x.explanation}")
    out += [f"  hypothesis: {h}" for h in x.hypotheses]
    return out + _model_lines(x.status, x.model, x.node) + _undiagnosed(x.status, diagnosed)


def problem_lines(number: str, p: ProblemRow) -> list[str]:
    """Problem ``number`` (1-based, as ``rclverify status`` numbers them): its culprits, its whole first
    sentence, where it is, its members and the repairs checked for it."""
    culprits = "; ".join(str(c.get("what") or c.get("source") or "") for c in p.culprits) or "(no culprit named)"
    out = [f"problem {number} [{p.status}]: {culprits}",
           f"  {clause_cut(whole_sentence(p.sentence, [mem.sentence for mem in p.members]))}"]
    if p.where:
        out.append(f"  at {p.where}")
    out.append("  findings:")
    out += [f"    {mem.id} [{mem.status}] ({mem.kind}): `rclverify explain {mem.id}`" for mem in p.members]
    out += [f"  repair {r.index + 1} of {r.diagnosis}, checked: `rclverify explain {r.diagnosis}`" for r in p.repairs]
    return out


def _acknowledgement(key: str, ack: Acknowledged | None, sha256: str) -> list[str]:
    """A warning answered in the plan (model/plan/acknowledged.py), or the line that would answer it."""
    if ack is not None:
        return [f"  accepted risk, acknowledged in the plan ({ack.at}): {ack.reason}"]
    if sha256:
        return [f"  to accept it, add under acknowledged: in the plan: "
                f"{{warning: {key}, sha256: {sha256[:16]}, reason: ...}}"]
    return []


def _model_lines(status: str, model: Mapping[str, Any] | None, node: str) -> list[str]:
    """A model as a table: a witness when the item holds, otherwise a counterexample."""
    if not model:
        return []
    label = "witness" if status in HOLDS else "counterexample"
    return [f"  {label}:"] + table_lines(counterexample_rows(dict(model), node), "    ")


def _undiagnosed(status: str, diagnosed: bool) -> list[str]:
    return ["  no problem to diagnose"] if status in HOLDS and not diagnosed else []
