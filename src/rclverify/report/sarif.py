"""The assurance report as a SARIF 2.1.0 log (``reports/assurance.sarif``).

SARIF (OASIS Static Analysis Results Interchange Format 2.1.0) is what code
scanning views read.  This module only lays out the report of
:func:`rclverify.report.build.build_report`, decoded once into
:class:`~rclverify.records.report_record.AssuranceReport` and read as the
attributes mypy checks; it verifies nothing itself.

One ``result`` per item that needs attention:

* an obligation whose status is ``failed``, ``error``, ``stale``,
  ``inconclusive`` or ``pending`` (a discharged one gives none);
* a side condition of the calculus that is not ``discharged``, and one
  ``discharged in context`` (rule ``RCL-SC-IN-CONTEXT``, level ``note``:
  the premise of R1-R3 as printed fails; the upstream premises the proof
  used are in ``properties.inContext``);
* a guarantee no obligation covers (``unverified``, rule
  ``RCL-GUARANTEE-UNVERIFIED``, at the guarantee);
* a contract health finding whose status is ``problem`` or ``inconclusive``;
* a lint warning;
* an end-to-end deadline that is not proved (``RCL-DEADLINE-REFUTED`` /
  ``RCL-DEADLINE-INCONCLUSIVE`` at the plan's ``deadline:`` entry, the
  chain in the message; :mod:`.deadlines`).

Each result names a stable rule id per kind of finding
(:mod:`.sarif_rules`: :data:`~.sarif_rules.RULES`, :func:`~.sarif_rules.lint_rule_id`), a level (``error``/``warning``/``note``), the RCL
file, line and column of the contract clause it is about (the records'
``source``/``location``, 1-based, columns in Unicode code points), and, when
there is one, the counterexample in the message.  Paths are relative to the
workspace root (``uriBaseId`` ``%SRCROOT%``).  The log is deterministic for
a given report dict: no timestamps, keys sorted, results in report order.
The decisions behind the mapping are in ``docs/ci.md``.
"""
from __future__ import annotations

from typing import Any, Mapping, Sequence

import msgspec

from rclverify.records.store import dumps
from rclverify.report.templating import model_text
from rclverify.records.findings import FindingRow
from rclverify.records.grounding_findings import GroundingFindingRow
from rclverify.records.lint_rows import LintRow
from rclverify.records.report_record import AssuranceReport
from rclverify.records.report_schema import Report
from rclverify.records.requirement_check import RequirementCheckRow
from rclverify.report.severity import of
from rclverify.records.sarif import SRCROOT, sarif_locations, sarif_result
from rclverify.records.sarif import (SarifDescriptor, SarifLocation, SarifLog, SarifResult, SarifRun,
                                     SarifSuppression)
from rclverify.report.sarif_diagnoses import attach_diagnoses
from rclverify.report.sarif_rules import HEALTH_RULE, OBLIGATION_RULE, REQUIREMENT_RULE, RULES, Rule, lint_rule_id

#: The SARIF version written and the schema it validates against.
SARIF_VERSION = "2.1.0"
SARIF_SCHEMA = "https://docs.oasis-open.org/sarif/sarif/v2.1.0/errata01/os/schemas/sarif-schema-2.1.0.json"


def _level(kind: str, status: str) -> str:
    """The SARIF level of an item: its one severity (:mod:`.severity`)."""
    return of(kind, status) or "note"

def _obligation_results(report: AssuranceReport) -> list[SarifResult]:
    """One result per obligation that is not discharged, with its evidence row (records/obligations.py,
    records/evidence_rows.py)."""
    evidence = {ev.obligation: ev for ev in report.evidence}
    reasons: dict[str, str] = {}
    for p in report.pending:
        reasons.setdefault(p.obligation, p.reason)
    out = []
    for o in report.obligations:
        rule = OBLIGATION_RULE.get(o.status)
        if rule is None:
            continue
        ev = evidence.get(o.id)
        words = [f"Obligation {o.id} ({o.backend}, {o.kind}) of {o.node} guarantee {o.guarantee} "
                 f"is {o.status}: {o.statement}."]
        expl = ev.explanation if ev is not None else reasons.get(o.id, "no evidence record yet")
        if expl:
            words.append(expl)
        cex = ev.counterexample if ev is not None else None
        if cex:
            words.append(f"Counterexample: {model_text(cex)}.")
        props: dict[str, object] = {"obligation": o.id, "node": o.node, "guarantee": o.guarantee,
                                    "backend": o.backend, "kind": o.kind, "status": o.status,
                                    "artifact": o.artifact}
        if o.instance:  # the part of the guarantee the obligation covers
            props["instance"] = o.instance
        if cex:
            props["counterexample"] = dict(cex)
        if ev is not None and ev.strength:  # the evidence's kind (docs/confidence.md)
            props["strength"] = ev.strength.to_json()
        res = sarif_result(rule, _level("obligation", o.status), " ".join(words), o.source, f"obligation:{o.id}", props)
        cause = (cex or {}).get("cause")
        if isinstance(cause, str) and sarif_locations(f"{cause}:0"):  # at the implementation's line
            rel = sarif_locations(o.source)
            for loc in rel:
                loc["id"] = 0
                loc["message"] = {"text": "the guarantee the example violates"}
            res["locations"] = sarif_locations(f"{cause}:0")
            res["locations"][0]["message"] = {"text": "the implementation's last line the failing example runs"}
            if rel:
                res["relatedLocations"] = rel
        out.append(res)
    return out


def _unverified_results(report: AssuranceReport) -> list[SarifResult]:
    """One result per guarantee no obligation covers, at the guarantee (report/unverified.py)."""
    rule = RULES["RCL-GUARANTEE-UNVERIFIED"]
    return [sarif_result(rule.id, _level("guarantee", "unverified"), f"Guarantee {u.guarantee} of {u.node} is unverified: {u.reason}. "
                    f"The guarantee: {u.text}", u.source, f"guarantee:{u.id}",
                    {"guarantee": u.id, "node": u.node, "status": u.status})
            for u in report.unverified]


def _set(value: Any) -> Any:
    """``value``, ``None`` for a field the row leaves unset."""
    return None if value is msgspec.UNSET else value


def _side_condition_results(report: AssuranceReport) -> list[SarifResult]:
    out = []
    for sc in report.side_conditions:
        status, verdict = sc.status, sc.verdict or sc.status
        if status == "discharged" and verdict != "discharged in context":
            continue
        rule = {"failed": "RCL-SC-REFUTED", "stale": "RCL-SC-STALE",
                "discharged": "RCL-SC-IN-CONTEXT"}.get(status, "RCL-SC-INCONCLUSIVE")
        said = verdict if status == "discharged" else status
        words = [f"Side condition {sc.id} ({sc.rule}) of {sc.node} is {said}: {sc.conjunct}."]
        if sc.explanation:
            words.append(sc.explanation)
        if sc.model:
            words.append(f"Counterexample: {model_text(sc.model)}.")
        props: dict[str, object] = {"sideCondition": sc.id, "node": sc.node, "rule": sc.rule, "status": status,
                                    "verdict": verdict}
        if sc.strength:
            props["strength"] = sc.strength.to_json()
        if sc.solvers:
            props["solvers"] = {"agreement": sc.solvers.agreement, "why": sc.solvers.why, "proof": _set(sc.solvers.proof)}
        if sc.context is not None:  # decided in context: the cone and the upstream premises used
            ctx = _InContext.of(sc.context)
            props["inContext"] = {"cone": ctx.cone, "used": ctx.used, "opened": ctx.opened, "violated": ctx.violated}
        # one severity (report/severity.py): a side condition discharged in context holds (a note, not gating)
        out.append(sarif_result(rule, _level("side-condition", status), " ".join(words), sc.source,
                                f"side-condition:{sc.id}", props))
    return out


class _InContext(msgspec.Struct, frozen=True):
    """What SARIF shows of a side condition's in-context check (``context``, calculus/side_condition.py
    :class:`~rclverify.records.composition_records.ContextRecord`): the cone's size, the premises used,
    the links opened (rule R4) and the nodes whose assumption the counterexample violates."""

    cone: int | None = None
    used: list[str] = []
    opened: list[str] = []
    violated: list[str] = []

    @classmethod
    def of(cls, context: Mapping[str, Any]) -> _InContext:
        """``context`` decoded, a key written ``null`` at its default."""
        return msgspec.convert({k: v for k, v in context.items() if v is not None}, cls)


def _requirement_results(report: AssuranceReport) -> list[SarifResult]:
    """One result per requirement that is not met, at its formal statement
    (the plan, or the Doorstop item's file); a refuted one carries the
    counterexample node by node and the guarantees that did not prevent it."""
    out = []
    for r in report.requirements:
        rule = REQUIREMENT_RULE.get(r.verdict)
        if rule is None:
            continue
        c = RequirementCheckRow.of(r.check)  # the requirement check's record (calculus/requirements/check.py)
        words = [f"Requirement {r.id} is {r.verdict}" + (f": {c.formal}." if c.formal else ".")]
        words.append(r.note + ".")
        if c.counterexample:
            words.append("Counterexample: " + "; ".join(
                f"{row.node}: " + ", ".join(f"{k} = {v}" for k, v in row.values.items())
                for row in c.counterexample) + ".")
        if c.temporal:  # a temporal requirement: its method, bound and trace step by step
            from rclverify.report.temporal import temporal_words  # deferred: optional or conditional (inside a block)
            words.append(temporal_words(c.temporal))
        for p in c.failed_to_prevent:
            words.append(f"Not prevented by {p.label} ({p.text}, {p.source}).")
        props = {"requirement": r.id, "verdict": r.verdict, "status": r.status}
        out.append(sarif_result(rule, _level("requirement", r.verdict), " ".join(words),
                                c.source or "", f"requirement:{r.id}", props))
    return out


def _finding_location(report: AssuranceReport, f: FindingRow) -> str:
    for n in report.nodes:
        if n.name == f.node:
            for g in n.guarantees:
                if f.guarantee is not None and g.index == f.guarantee:
                    return g.source
            return n.source
    return ""


def _finding_results(report: AssuranceReport) -> list[SarifResult]:
    out = []
    for f in report.findings:
        if f.status == "ok":
            continue
        rule = ("RCL-HEALTH-INCONCLUSIVE" if f.status == "inconclusive"
                else "RCL-HEALTH-STALE" if f.status == "stale"
                else HEALTH_RULE.get(f.check, "RCL-HEALTH-OTHER"))
        words = [f.message]
        if f.explanation:
            words.append(f.explanation)
        if f.core:
            words.append("Unsat core: " + "; ".join(f.core) + ".")
        if f.model:
            words.append(f"Counterexample: {model_text(f.model)}.")
        props: dict[str, object] = {"finding": f.id, "node": f.node, "check": f.check, "status": f.status}
        if f.instances:  # the verdict per instance of a quantified premise
            props["instances"] = dict(f.instances)
        if f.solvers is not None:  # the second solver's agreement (docs/second-solver.md)
            props["solvers"] = {"agreement": f.solvers.agreement, "why": f.solvers.why}
        if f.sha256:  # what a plan acknowledgement of this warning binds (docs/plan.md, ``acknowledged``)
            props["sha256"] = f.sha256
        res = sarif_result(rule, _level("health", f.status), " ".join(words), _finding_location(report, f),
                      f"health:{f.id}", props)
        out.append(_accepted(res, f.acknowledged.reason, f.acknowledged.at) if f.acknowledged else res)
    return out


def _suppressed(res: SarifResult, row: LintRow) -> SarifResult:
    """``res`` with a SARIF ``suppressions`` entry when the plan acknowledges
    the lint warning ``row`` (:func:`_accepted`; model/plan/acknowledged.py)."""
    ack = row.acknowledged
    return _accepted(res, ack.reason, ack.at) if ack else res


def _accepted(res: SarifResult, reason: str, at: str) -> SarifResult:
    """``res`` with a SARIF ``suppressions`` entry (kind ``external``, status
    ``accepted``, ``reason`` as ``justification``, SARIF 2.1.0 section 3.35)
    located at ``at``, the plan entry's ``file:line:col``."""
    sup: SarifSuppression = {"kind": "external", "status": "accepted", "justification": reason}
    where = sarif_locations(at)
    if where:
        sup["location"] = where[0]  # the plan entry (SARIF 2.1.0 section 3.35.6: one location)
    res["suppressions"] = [sup]
    return res


def _acknowledgement_results(report: AssuranceReport) -> list[SarifResult]:
    """Stale or refused plan acknowledgements, at their plan entry."""
    return [sarif_result("RCL-ACK-STALE", _level("acknowledgement", a.status),
                         f"Acknowledgement of {a.warning} is {a.status}: {a.message}", a.at,
                         f"ack:{a.at}:{a.warning}", {"status": a.status})
            for a in report.acknowledgements if a.status != "ok"]


def _lint_results(report: AssuranceReport) -> tuple[list[SarifResult], list[Rule]]:
    out: list[SarifResult] = []
    rules: dict[str, Rule] = {}
    for k, d in enumerate(report.lint):
        rid = lint_rule_id(d.code)
        level = _level("lint", d.severity)
        rules.setdefault(rid, Rule(rid, "Lint" + "".join(w.capitalize() for w in rid.split("-")[2:]), level,
                                   "RCL lint: a contract clause that is legal but probably not what was meant."))
        out.append(_suppressed(sarif_result(rid, level, d.message, d.location,
                                            f"lint:{d.location}:{d.code}:{k}", {"severity": d.severity}), d))
    return out, sorted(rules.values(), key=lambda r: r.id)


def _grounding_results(report: AssuranceReport) -> tuple[list[SarifResult], list[Rule]]:
    """Grounding findings (docs/ros.md): located at the RCL line, with the
    software line it contradicts as a related location."""
    g = report.grounding
    if not g:
        return [], []
    from rclverify.ros.ground.ground import RULES as ROS_RULES  # deferred: start-up (loads rclverify.core.cache, rclverify.ros and more only when called)
    rules = [Rule(code, "Ros" + "".join(w.capitalize() for w in code.split("-")[1:]),
                  "error" if sev == "error" else "warning", text) for code, (sev, text) in ROS_RULES.items()]
    out = []
    for k, f in enumerate(map(GroundingFindingRow.of, g.findings)):  # as ros/ground/ground.py wrote it
        rcl, ros = f.rcl, f.ros
        main = rcl or ros
        where = main.text() if main else ""
        res = sarif_result(f.code, "error" if f.severity == "error" else "warning", str(f.message), where,
                           f"grounding:{f.code}:{f.node}:{f.topic}:{k}", {"node": f.node, "topic": f.topic})
        if rcl and ros:
            rel = sarif_locations(ros.text())
            for i, loc in enumerate(rel):
                loc["id"] = i
                loc["message"] = {"text": "the software this contradicts"}
            res["relatedLocations"] = rel
        out.append(res)
    return out, rules


def _descriptor(r: Rule) -> SarifDescriptor:
    return {"id": r.id, "name": r.name, "shortDescription": {"text": r.text},
            "defaultConfiguration": {"level": r.level}}


def sarif_log(report: Report | AssuranceReport) -> SarifLog:
    """The SARIF 2.1.0 log (a JSON-serialisable dict) of ``report``.

    ``report`` is the :class:`~rclverify.records.report_schema.Report` of
    :func:`~rclverify.report.build.build_report` or the report decoded,
    :class:`~rclverify.records.report_record.AssuranceReport`; a dict is
    decoded once, and every part is read off the decoded report (the
    deadlines', NoDL and near-miss results too).  Every rule of :data:`RULES` is listed in the driver (so ids
    stay stable whether or not they fire), results refer to their rule by
    ``ruleIndex`` too.  Raises :class:`msgspec.ValidationError` for a report
    dict that is not of that shape.
    """
    typed = AssuranceReport.of(report)
    lint, lint_rules = _lint_results(typed)
    ground, ground_rules = _grounding_results(typed)
    from rclverify.report.deadlines import SARIF_RULES, sarif_results  # deferred: start-up (loads rclverify.lang.errors, rclverify.report.deadlines and more only when called)
    from rclverify.report import near_misses  # deferred: start-up (loads rclverify.report.near_misses only when called)
    from rclverify.report import nodl  # deferred: start-up (loads rclverify.report.nodl only when called)
    from rclverify.report import design  # deferred: start-up (loads rclverify.report.design only when called)
    results = (_obligation_results(typed) + _unverified_results(typed) + _side_condition_results(typed)
               + _finding_results(typed) + lint + ground + nodl.sarif_results(typed, sarif_result, sarif_locations)
               + design.sarif_results(typed, sarif_result, sarif_locations)
               + _requirement_results(typed) + sarif_results(typed, sarif_result) + _acknowledgement_results(typed)
               + near_misses.sarif_results(typed, sarif_result))
    attach_diagnoses(typed, results)
    rules: Sequence[Rule] = (list(RULES.values()) + [Rule(*r) for r in SARIF_RULES] + [Rule(*r) for r in nodl.SARIF_RULES]
                             + [Rule(*r) for r in design.SARIF_RULES]
                             + [Rule(*r) for r in near_misses.SARIF_RULES] + lint_rules + ground_rules)
    index = {r.id: i for i, r in enumerate(rules)}
    for res in results:
        res["ruleIndex"] = index[res["ruleId"]]
    meta = typed.meta
    run: SarifRun = {
        "tool": {"driver": {"name": "rclverify", "version": meta.version,
                            "rules": [_descriptor(r) for r in rules]}},
        "originalUriBaseIds": {SRCROOT: {"description": {"text": "the root of the rclverify workspace"}}},
        "columnKind": "unicodeCodePoints",
        "results": results,
        "properties": {"workspace": meta.workspace, "plan": meta.plan, "status": typed.summary.status,
                       "strictOk": meta.strict_ok},
    }
    return {"$schema": SARIF_SCHEMA, "version": SARIF_VERSION, "runs": [run]}


def render_sarif(report: Report | AssuranceReport) -> str:
    """:func:`sarif_log` as deterministic JSON text (sorted keys, final newline)."""
    return dumps(sarif_log(report))
