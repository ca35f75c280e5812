"""The report's view model: the lookups, lists and tables the templates lay out, a pure function of the
report, read off the decoded :class:`~rclverify.records.report_record.AssuranceReport`.

What needs attention comes first: problems (worse than pending) and
outstanding items (pending), worst first (:func:`_attention`); the
dashboard's matrix of nodes against techniques
(:func:`rclverify.report.dashboard.dashboard`); the
traceability rows requirement -> guarantee -> obligation -> evidence
(the paper's five steps); each node's section.  Nothing here verifies.
"""
from __future__ import annotations

import functools
import re
import typing
from collections import defaultdict
from typing import Any, Callable, Mapping, Sequence, TypeVar

import msgspec

from rclverify.records.derived_rows import DerivedPropertyRow
from rclverify.records.evidence_rows import EvidenceRow
from rclverify.records.findings import FindingRow
from rclverify.records.obligations import ObligationRow
from rclverify.records.problem_rows import EARLIER, ProblemRow
from rclverify.records.report_record import AssuranceReport
from rclverify.records.side_condition_rows import SideConditionRow
from rclverify.report.shapes import (AttentionGroup, AttentionItem, PendingGroup,
                                     EvidenceRun, ReportView, Section, TableRuns, TraceEntry, TraceObligation, TraceSupport)
from rclverify.records.records import SEVERITY
from rclverify.report.dashboard import dashboard
from rclverify.report.problems import group_problems
from rclverify.report.templating import COUNT_ORDER, anchor, rank
from rclverify.report.textfmt import natural_key, natural_sorted, natural_within

_T = TypeVar("_T")
_Row = TypeVar("_Row", DerivedPropertyRow, SideConditionRow, FindingRow)
#: the report as a caller may hand it over: the decoded record, or its JSON object (decoded once on entry)
ReportIn = AssuranceReport | Mapping[str, Any]

#: Top-level keys every report dict carries.
REPORT_KEYS: tuple[str, ...] = (
    "meta", "summary", "system", "requirements", "nodes", "side_conditions",
    "derived_properties", "findings", "obligations", "evidence",
    "environment_assumptions", "pending", "lint",
)


def validate(report: Mapping[str, Any]) -> None:
    """Check the top-level shape of ``report``.

    Raises ``ValueError`` naming every missing top-level key (the templates
    themselves raise ``jinja2.UndefinedError`` for a missing inner key).
    """
    missing = [k for k in REPORT_KEYS if k not in report]
    if missing:
        raise ValueError("report dict lacks key(s): " + ", ".join(missing))


def _by_node(items: Sequence[_Row]) -> dict[str, list[_Row]]:
    out: dict[str, list[_Row]] = defaultdict(list)
    for it in items:
        out[it.node].append(it)
    return out


def _attention(report: AssuranceReport, ev_anchor: Sequence[str]) -> tuple[list[AttentionItem], list[AttentionItem]]:
    """Items needing attention: (problems, outstanding).

    Problems are everything worse than pending (failed, error, stale,
    inconclusive evidence; refuted or undecided side conditions; contract
    health problems; derived properties that do not hold; lint errors);
    outstanding are the pending items with their reason.  Each item is
    ``{"status", "kind", "ref", "anchor", "where", "message", "formula"}``
    (``formula`` is RCL text to show as code, or ''); both lists
    are sorted worst first, then by kind and reference.
    """
    items: list[AttentionItem] = []

    def add(status: str, kind: str, ref: str, anchor_id: str, where: str, message: str,
            formula: str = "") -> None:
        items.append({"status": status, "kind": kind, "ref": ref, "anchor": anchor_id,
                      "where": where, "message": message, "formula": formula})

    reasons: dict[str, list[str]] = defaultdict(list)
    for p in report.pending:
        reasons[p.obligation].append(p.reason)
    evidenced: set[str] = set()
    for ev, aid in zip(report.evidence, ev_anchor):
        ob = ev.obligation
        evidenced.add(ob)
        if rank(ev.status) == 0:
            continue
        msg = ev.explanation
        if ev.status == "pending" and reasons.get(ob):
            msg = " ".join(dict.fromkeys([*reasons[ob], msg] if msg else reasons[ob]))
        add(ev.status, "evidence", ob, aid, f"{ev.backend} ({ev.kind})", msg)
    for p in report.pending:
        ob = p.obligation
        if ob not in evidenced:
            add("pending", "obligation", ob, anchor("ob", ob), p.backend, p.reason)
            evidenced.add(ob)
    for o in report.obligations:
        if o.id not in evidenced and rank(o.status) > 0:
            add(o.status, "obligation", o.id, anchor("ob", o.id), o.backend,
                "No evidence record for this obligation.")
    for u in report.unverified:  # a guarantee no obligation covers (report/unverified.py)
        add(u.status, "guarantee", u.id, anchor("g", u.node, u.guarantee), u.source, f"Unverified: {u.reason}.")
    for sc in report.side_conditions:
        if rank(sc.status) > 0:
            add(sc.status, "side condition", sc.id, anchor("sc", sc.id), f"{sc.node}, {sc.rule}, {sc.source}",
                sc.explanation or "Assumption conjunct not established:", sc.conjunct)
    for f in report.findings:
        if rank(f.status) > 0 and not f.acknowledged:  # an accepted risk is listed with its reason
            where = f.node + (f", guarantee {f.guarantee}" if f.guarantee is not None else "")
            msg = f.message + (f" {f.explanation}" if f.explanation else "")
            add(f.status, f"contract health: {f.check}", f.id, anchor("finding", f.id), where, msg)
    for d in report.derived_properties:
        if rank(d.status) > SEVERITY["pending"]:
            add(d.status, "derived property", d.node, anchor("derived", d.node), ", ".join(d.rules),
                f"Derived property {d.derivation} (a side condition of its cone is not discharged):", d.property)
    for a in report.acknowledgements:  # a stale or refused acknowledgement (model/plan/acknowledged.py)
        if a.status != "ok":
            add(a.status, "acknowledgement", a.warning, "acknowledged", a.at, a.message)
    for k, lint in enumerate(report.lint):
        if lint.severity.lower() == "error":
            add("error", "lint", lint.location, anchor("lint", k + 1), lint.location, lint.message)

    kind_order = {"evidence": 0, "obligation": 1, "guarantee": 1, "side condition": 2, "derived property": 4, "lint": 5}
    items.sort(key=lambda it: (-rank(it["status"]), kind_order.get(it["kind"], 3), it["kind"], natural_key(it["ref"])))
    problems = [it for it in items if rank(it["status"]) > SEVERITY["pending"]]
    outstanding = [it for it in items if rank(it["status"]) <= SEVERITY["pending"]]
    return problems, outstanding


_NUMBERS = re.compile(r"\d+")


def group_items(items: Sequence[AttentionItem]) -> list[AttentionGroup]:
    """Attention items grouped when they say the same thing: equal status,
    kind and backend (``where``), and a message that is equal once its
    numbers are left out (39 AJPF instances pending for one reason are one
    group).  Each group is ``{"status", "kind", "where", "message" (the
    first item's), "items" (in order)}``; groups keep the order of their
    first items."""
    groups: dict[tuple[str, str, str, str], AttentionGroup] = {}
    for it in items:
        key = (it["status"], it["kind"], it["where"], _NUMBERS.sub("#", it["message"]))
        g = groups.get(key)
        if g is None:
            g = groups[key] = {"status": it["status"], "kind": it["kind"], "where": it["where"],
                               "message": it["message"], "items": []}
        g["items"].append(it)
    return list(groups.values())


def evidence_anchors(report: ReportIn) -> list[str]:
    """One fragment id per evidence record of ``report`` (decoded on entry), in order:
    ``ev-<obligation>``, then ``ev-<obligation>-2`` ... for further records
    of the same obligation."""
    seen: dict[str, int] = defaultdict(int)
    out = []
    for ev in decoded_parts(report).evidence:
        ob = ev.obligation
        seen[ob] += 1
        out.append(anchor("ev", ob) if seen[ob] == 1 else anchor("ev", ob, seen[ob]))
    return out


@functools.cache
def _later_parts() -> dict[str, object]:
    """The parts a report written by an earlier version may lack (beyond :data:`REPORT_KEYS`), each with
    the empty value it is read as: ``[]`` for a list, ``None`` for a part that may be null."""
    hints = typing.get_type_hints(AssuranceReport)
    return {k: [] if typing.get_origin(hints[k]) is list else None
            for k in AssuranceReport.__struct_fields__ if k not in REPORT_KEYS}


def _earlier(report: Mapping[str, object]) -> dict[str, object]:
    """``report``, a JSON object, with each part :func:`_later_parts` names that it lacks at its empty
    value and each problem row's keys of :data:`~rclverify.records.problem_rows.EARLIER` that it lacks:
    a stored report of an earlier version still decodes (its rows placed nowhere), and so does the report
    before its diagnoses (report/build.py ``undiagnosed_report``: no ``diagnoses``, in the summary too)."""
    out: dict[str, object] = {**_later_parts(), **report}
    summary = out["summary"]
    if isinstance(summary, Mapping) and "diagnoses" not in summary:
        out["summary"] = {**summary, "diagnoses": []}
    problems = out["problems"]
    if isinstance(problems, list):
        out["problems"] = [{**EARLIER, **p} if isinstance(p, Mapping) else p for p in problems]
    return out


def decoded_parts(report: ReportIn) -> AssuranceReport:
    """``report`` decoded for a reader of its rows, which reads no ``problems`` and no diagnoses (a JSON
    object may lack them: :func:`_earlier`).  Raises :class:`msgspec.ValidationError` for a report of
    another shape."""
    return report if isinstance(report, AssuranceReport) else AssuranceReport.of(_earlier(report))


def decoded_report(report: ReportIn) -> AssuranceReport:
    """``report`` decoded once into :class:`~rclverify.records.report_record.AssuranceReport`
    (returned unchanged when it is one); a JSON object without ``problems``
    gets them grouped by root cause here
    (:func:`rclverify.report.problems.group_problems`); one written by an
    earlier version is read with the parts it lacks empty (:func:`_earlier`).  Raises
    :class:`msgspec.ValidationError` (a ``ValueError``) for a report of
    another shape."""
    if isinstance(report, AssuranceReport):
        return report
    if "problems" in report:
        return AssuranceReport.of(_earlier(report))
    draft = AssuranceReport.of(_earlier(report))
    groups = group_problems(draft, _attention(draft, evidence_anchors(draft))[0], anchor)
    return msgspec.structs.replace(draft, problems=groups)


def problem_items(report: ReportIn) -> list[AttentionItem]:
    """The attention items of ``report`` (decoded on entry) that are problems (worse than
    pending), worst first (see :func:`_attention`)."""
    decoded = decoded_parts(report)
    return _attention(decoded, evidence_anchors(decoded))[0]


def problem_groups(report: ReportIn) -> list[ProblemRow]:
    """The report's problems grouped by root cause
    (:func:`rclverify.report.problems.group_problems`): the report's
    ``problems`` (decoded on entry)."""
    return list(decoded_report(report).problems)


def _trace(report: AssuranceReport, obligation: Mapping[str, ObligationRow],
           evidence_of: Mapping[str, list[tuple[str, EvidenceRow]]]) -> list[TraceEntry]:
    """The traceability rows: per requirement, its supporting guarantees with
    each obligation's status and evidence (``rowspan``: rows it spans)."""
    trace: list[TraceEntry] = []
    for req in report.requirements:
        rows: list[TraceSupport] = []
        for sup in req.support:
            obs: list[TraceObligation] = []
            for oid in sup.obligations:
                o = obligation.get(oid)
                obs.append({
                    "id": oid,
                    "known": o is not None,
                    "status": o.status if o is not None else "pending",
                    "backend": o.backend if o is not None else "",
                    "evidence": evidence_of.get(oid, []),
                })
            rows.append({"support": sup, "obligations": obs})
        trace.append({"req": req, "rows": rows, "rowspan": max(1, len(rows))})
    return trace


def _sections(report: AssuranceReport, obligation: Mapping[str, ObligationRow]) -> list[Section]:
    """Per node (then per name only the calculus knows): the node, its derived
    property, side conditions, findings and ``ob_status`` (the status of each
    obligation its guarantees list)."""
    derived = _by_node(report.derived_properties)
    sides = _by_node(natural_sorted(report.side_conditions, key=lambda sc: sc.id))
    findings = _by_node(natural_sorted(report.findings, key=lambda f: f.id))
    sections: list[Section] = []
    named = [n.name for n in report.nodes]
    for n in report.nodes:
        name = n.name
        sections.append({"name": name, "node": n, "derived": derived.get(name, []),
                         "side": sides.get(name, []), "findings": findings.get(name, [])})
    for name in sorted((set(derived) | set(sides)) - set(named)):
        sections.append({"name": name, "node": None, "derived": derived.get(name, []),
                         "side": sides.get(name, []), "findings": findings.get(name, [])})
    for sec in sections:
        node = sec["node"]
        ids = [oid for g in (node.guarantees if node else []) for oid in g.obligations]
        sec["ob_status"] = {oid: obligation[oid].status for oid in ids if oid in obligation}
    return sections


def _pending_groups(report: AssuranceReport) -> list[PendingGroup]:
    """The pending rows grouped by backend and reason (the same reason, numbers aside: one row)."""
    groups: dict[tuple[str, str], PendingGroup] = {}
    for p in natural_sorted(report.pending, key=lambda p: p.obligation):
        key = (p.backend, _NUMBERS.sub("#", p.reason))
        groups.setdefault(key, {"backend": p.backend, "reason": p.reason, "items": []})["items"].append(p)
    return list(groups.values())


def _table_runs(report: AssuranceReport, ev_anchor: Sequence[str], obligation: Mapping[str, ObligationRow],
                evidence_of: Mapping[str, list[tuple[str, EvidenceRow]]]) -> TableRuns:
    """``finding_runs``, ``obligation_runs`` and ``evidence_runs`` of :func:`view`."""
    def node_of_evidence(item: EvidenceRun) -> str:
        o = obligation.get(item["record"].obligation)
        return o.node if o is not None else ""

    return {
        "finding_runs": runs(natural_within(report.findings, lambda f: f.node, lambda f: f.id), lambda f: f.node),
        "obligation_runs": runs([{"obligation": o, "evidence": [aid for aid, _ in evidence_of.get(o.id, [])]}
                                 for o in natural_within(report.obligations, lambda o: o.node, lambda o: o.id)],
                                lambda row: row["obligation"].node),
        "evidence_runs": runs(natural_within([{"anchor": aid, "record": ev} for aid, ev in zip(ev_anchor, report.evidence)],
                                             node_of_evidence, lambda it: it["record"].obligation), node_of_evidence),
    }


def view(report: ReportIn) -> ReportView:
    """Derived lookups the templates need (pure function of ``report``, decoded on entry:
    :func:`decoded_report`; every row in it is its decoded record).

    Keys: ``dashboard`` (:func:`dashboard`), ``problem_groups`` (the
    problems grouped by root cause, :func:`problem_groups`), ``diagnosis``
    (diagnosis id -> record), ``counts`` (``[(status, n)]`` worst first), ``problems`` and
    ``outstanding`` (see :func:`_attention`), ``unmet_requirements``,
    ``ev_anchor`` (one fragment id per evidence record, in order),
    ``evidence_of`` (obligation id -> ``[(anchor, record)]``), ``obligation``
    (id -> obligation), ``trace`` (requirement rows with ``rowspan`` and the
    evidence of each supporting obligation), ``sections`` (per node: the node,
    its rule instances/derived property, side conditions, findings and
    ``ob_status``, the status of each obligation its guarantees list),
    ``finding_runs``, ``obligation_runs`` (rows ``{"obligation", "evidence":
    [anchor]}``) and ``evidence_runs`` (``{"anchor", "record"}``): the rows of
    the health table, the obligations table and the evidence records, in
    report order, cut into runs of one node each (:func:`runs`).
    """
    if not isinstance(report, AssuranceReport):
        validate(report)
    typed = decoded_report(report)
    ev_anchor = evidence_anchors(typed)
    evidence_of: dict[str, list[tuple[str, EvidenceRow]]] = defaultdict(list)
    for aid, ev in zip(ev_anchor, typed.evidence):
        evidence_of[ev.obligation].append((aid, ev))
    obligation = {o.id: o for o in typed.obligations}
    counts_in: dict[str, int] = {str(k): n for k, n in typed.summary.counts.items()}
    counts = [(s, counts_in[s]) for s in COUNT_ORDER if s in counts_in]
    counts += [(s, counts_in[s]) for s in sorted(counts_in) if s not in SEVERITY]
    problems, outstanding = _attention(typed, ev_anchor)
    return {
        "dashboard": dashboard(typed, evidence_of), "problem_groups": list(typed.problems),
        "diagnosis": {d.id: d for d in typed.diagnoses},
        "counts": counts, "problems": problems, "outstanding": outstanding,
        "outstanding_groups": group_items(outstanding), "pending_groups": _pending_groups(typed),
        "unmet_requirements": [q for q in typed.requirements if rank(q.status) > 0],
        "ev_anchor": ev_anchor, "evidence_of": evidence_of, "obligation": obligation,
        "trace": _trace(typed, obligation, evidence_of), "sections": _sections(typed, obligation),
        "lint_errors": sum(1 for x in typed.lint if x.severity.lower() == "error"),
        **_table_runs(typed, ev_anchor, obligation, evidence_of),
    }


def runs(items: Sequence[_T], key: Callable[[_T], str]) -> list[list[_T]]:
    """``items`` cut into runs of consecutive items with equal ``key``, in
    order (the report lists rows node by node, so a run is usually one
    node's rows: the unit a report piece is rendered and kept by)."""
    out: list[list[_T]] = []
    last: object = object()
    for it in items:
        k = key(it)
        if not out or k != last:
            out.append([])
            last = k
        out[-1].append(it)
    return out
