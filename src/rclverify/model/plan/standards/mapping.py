"""A report's evidence mapped onto a standard profile's clauses, each within its scope (docs/standards.md).

:data:`SUPPORTS` is the one table from what an evidence row says (its record
``kind``, records/statuses.py ``EvidenceKind``, and its ``strength.kind``,
docs/confidence.md) to the profile evidence kinds it can support.

A clause is about something (its item's ``about``, :data:`~.profiles.ABOUT`):
its *scope* is the items of the report that concern it (:func:`scope_items`):

* ``guarantees``: every guarantee of every node;
* ``interfaces``: every side condition (what a node's inputs receive from
  another node's outputs) and every guarantee of a node on a connection;
* ``requirements``: every requirement and the guarantees that support them;
* ``system``: every guarantee, side condition and requirement, every
  health check that failed or is outstanding, and the workspace itself
  while its status is not ``discharged`` (a gate: it never makes a clause
  partial);
* ``field-data``: every run-set target decided over runs of ``origin:
  operation``;
* ``trials``: every target decided over runs or trials (a run set of
  origin ``operation`` or ``simulation``, an experiment's per-trial data).

The plan may narrow a clause's scope to named nodes (:func:`clause_rows`'s
``notes``; the reason is shown in the clause's ``why``).

A guarantee in scope is covered when its own status is ``discharged``, it
has evidence of a kind the clause accepts, all of that evidence is
discharged, and no health check of it failed or is outstanding; a side
condition when Z3 proved it; a requirement when its verdict is ``met``,
its deadline is not left undecided or refuted, its statistical targets
are met and, unless the clause accepts ``proof`` (which its check is), a
supporting guarantee has discharged evidence of an accepted kind; a target when it
is met; the workspace when its status is ``discharged``.  A run of
``origin: harness`` never counts; a review counts for a clause that asks
independence only when the record names its author and its reviewer, they
differ, and its stated independence is at least the clause's
(:func:`independence_of`).

A clause is ``covered`` when its scope is not empty and every item in it
is covered, ``partial`` when some but not all are, ``not covered`` when
none is and evidence of an accepted kind that counts, or an item with a
check of its own (a side condition, requirement, target, health check, the
workspace), is in scope, ``open`` otherwise (no such evidence, or an empty
scope), and ``not recommended``
when the standard marks it ``NR`` at the level (shown, never read as met).
Each clause row says why.  The mapping is a traceability aid for an
assessor, not a compliance claim.
"""
from __future__ import annotations

from collections import Counter
from typing import Any, Callable, Collection, Iterable, Mapping, Sequence, cast, get_args

import msgspec

from rclverify.model.plan.standards import clause_words
from rclverify.model.plan.standards.clause_words import WORST, adds, checked_by
from rclverify.model.plan.standards.profiles import ASKED, INDEPENDENCE, Item, Profile
from rclverify.model.plan.standards.field_data import target_items
from rclverify.model.plan.standards.identity import Person
from rclverify.model.plan.standards.report_view import (EvidenceView, FindingView, ReportView, RequirementView,
                                                         SideConditionView, report_view)
from rclverify.model.plan.standards.reviews import independence_of, review_as_stated, review_identity
from rclverify.records.standards_rows import (About, ClauseEvidence, ClauseRow as ClauseRecord, ClauseStatus,
                                              Independence, PlanNote as PlanNoteRecord, Recommendation, ScopeItem,
                                              ScopeKind)
from rclverify.records.statuses import EvidenceKind, EvidenceStatus

#: A clause's status (the module docstring).
#: (evidence row field, its value) -> the profile evidence kind it supports.  ``kind`` is the
#: record's kind (each backend's ``kind``: hoare and dafny "proof", ajpf "model checking",
#: property_tests "testing", monitors "monitoring", experiment, review); ``strength`` is the
#: strength the confidence pass gave the row ("statistical": a bound over recorded runs).
SUPPORTS: Mapping[tuple[str, str], str] = {
    ("kind", "proof"): "proof",
    ("kind", "model checking"): "model-checking",
    ("kind", "testing"): "property-tests",
    ("kind", "monitoring"): "runtime-monitoring",
    ("kind", "experiment"): "experiment",
    ("kind", "review"): "review",
    ("strength", "statistical"): "run-statistics",
}

#: A clause's statuses, in the order the report counts them.
CLAUSE_STATUSES: tuple[ClauseStatus, ...] = get_args(ClauseStatus)

#: A side condition's verdicts that count as proved.
_PROVED = ("discharged", "discharged in context")
#: Health check outcomes that leave a guarantee covered (``warning`` is shown, not a failure).
_HEALTH_OK = ("ok", "warning")


#: The JSON object of a clause row as the report carries it: the encoding of
#: :class:`rclverify.records.standards_rows.ClauseRow` (:func:`clause_records` builds the records).
ClauseRow = dict[str, Any]
#: The records of a clause's evidence, its scope items and the plan's note (records/standards_rows.py).
Support = ClauseEvidence
PlanNote = PlanNoteRecord


def kinds_of(row: EvidenceView | Mapping[str, Any]) -> set[str]:
    """The profile evidence kinds the evidence ``row`` (a report ``evidence[]`` row, or its view) supports,
    by :data:`SUPPORTS`."""
    r = row if isinstance(row, EvidenceView) else report_view([row]).evidence[0]
    values = {"kind": r.kind, "strength": r.strength.kind if r.strength is not None else None}
    return {kind for (field, value), kind in SUPPORTS.items() if values[field] == value}


def _harness(row: EvidenceView) -> bool:
    return row.statistics is not None and row.statistics.origin == "harness"


def _support(row: EvidenceView, asked: str, people: Sequence[Person] = ()) -> ClauseEvidence:
    note = ""
    if _harness(row):
        note = "origin: harness: shown, never counted"
    elif row.kind == "review" and asked != "none":
        level, why = independence_of(row, people)
        if INDEPENDENCE.index(level) < INDEPENDENCE.index(asked):
            note = why or f"independence {level}; the clause asks {asked}"
    return ClauseEvidence(row.obligation, row.backend, cast(EvidenceKind, str(row.kind)),
                          cast(EvidenceStatus, str(row.status)), not note, note)


class _Index:
    """The report read once for every clause: each guarantee's evidence rows and status, its health checks."""

    def __init__(self, report: ReportView, unstated: Collection[tuple[str, str]] = (),
                 people: Sequence[Person] = ()) -> None:
        self.report = report
        self.people = people  # the plan's people: (identity.Person), for a review's independence
        self.unstated = unstated  # (node, environment) of the run sets whose plan entry states no origin
        where = {o.id: (o.node, o.guarantee) for o in report.obligations}
        self.guarantees: list[tuple[str, int, str]] = [
            (n.name, g.index, g.status) for n in report.nodes for g in n.guarantees or ()]
        self.rows: dict[tuple[str, int], list[EvidenceView]] = {}
        for e in report.evidence:
            node, k = where.get(e.obligation, ("", -1))
            if k == 0:  # an obligation of the whole contract is evidence for each of its guarantees
                for n, g, _ in self.guarantees:
                    if n == node:
                        self.rows.setdefault((n, g), []).append(e)
            elif node:
                self.rows.setdefault((node, k), []).append(e)
        self.health: dict[tuple[str, int | None], list[FindingView]] = {}
        for f in report.findings:
            self.health.setdefault((str(f.node), f.guarantee), []).append(f)


def _counted(rows: Iterable[EvidenceView], accepts: set[str], asked: str,
             people: Sequence[Person] = ()) -> list[tuple[EvidenceView, ClauseEvidence]]:
    return [(r, _support(r, asked, people)) for r in rows if kinds_of(r) & accepts]


def _guarantee_item(ix: _Index, node: str, k: int, status: str, accepts: set[str], asked: str) -> ScopeItem:
    supports = [s for _, s in _counted(ix.rows.get((node, k), ()), accepts, asked, ix.people)]
    counting = [s for s in supports if s.counts]
    bad = [s for s in counting if s.status != "discharged"]
    health = [f for f in ix.health.get((node, k), []) + ix.health.get((node, None), [])
              if str(f.status) not in _HEALTH_OK]
    state, detail = "covered", "covered"
    if not counting:
        state = "not counted" if supports else "no evidence"
        detail = (f"no {' or '.join(sorted(accepts))} evidence that counts"
                  + (f" ({len(supports)} shown: {supports[0].note})" if supports else ""))
    elif bad:
        counts = Counter[str](b.status for b in bad)
        state = min(counts, key=lambda x: WORST.index(x) if x in WORST else len(WORST))
        detail = (", ".join(f"{n} {st}" for st, n in sorted(counts.items()))
                  + f" of its {len(counting)} record{'s' if len(counting) != 1 else ''}")
    elif status != "discharged":
        state, detail = status, f"the guarantee is {status} by its other evidence"
    elif health:
        state, detail = "problem", f"health check {health[0].check}: {health[0].status}"
    ok = state == "covered"
    return ScopeItem(f"{node} g{k}", "guarantee", ok, state, detail, [s.obligation for s in counting] if ok else [])


def _item(item: str, kind: ScopeKind, state: str, detail: str, evidence: list[str]) -> ScopeItem:
    ok = state == "covered"
    return ScopeItem(item, kind, ok, state, detail if not ok else "covered", evidence if ok else [])


def _proved(sc: SideConditionView) -> bool:
    return sc.verdict in _PROVED and sc.status == "discharged"


def _side_condition_item(sc: SideConditionView) -> ScopeItem:
    return _item(f"side condition {sc.id}", "side condition", "covered" if _proved(sc) else str(sc.status),
                 f"side condition {sc.verdict}", [str(sc.id)])


def _requirement_item(rq: RequirementView, ix: _Index, accepts: set[str], asked: str) -> ScopeItem:
    state, detail = "covered", ""
    if rq.status != "discharged":
        state, detail = str(rq.status), f"verdict: {rq.verdict}"
    if state == "covered" and rq.deadline is not None and rq.deadline.verdict != "proved":
        state, detail = "pending", f"deadline {rq.deadline.verdict}"
    targets = [t for t in rq.statistics or () if t.target and t.status != "discharged"]
    if state == "covered" and targets:
        state = targets[0].status or "pending"
        detail = f"target {state} ({targets[0].origin} runs)"
    if state == "covered" and "proof" not in accepts:
        support = [(s.node, s.guarantee) for s in rq.support or ()]
        if not any(sp.counts and sp.status == "discharged" for key in support
                   for _, sp in _counted(ix.rows.get(key, ()), accepts, asked, ix.people)):
            state, detail = "no evidence", f"no {' or '.join(sorted(accepts))} evidence of its supporting guarantees"
    return _item(f"requirement {rq.id}", "requirement", state, detail, [f"requirement {rq.id}"])


def scope_items(item: Item, level: str | None, report: ReportView | Mapping[str, Any], ix: _Index | None = None,
                narrowed: Sequence[str] | None = None) -> list[ScopeItem]:
    """The items of ``report`` (a report dict, or the parts of it it has, or its
    :class:`~.report_view.ReportView`) in the scope of the profile ``item`` at ``level``, each a
    :class:`~rclverify.records.standards_rows.ScopeItem` with its state (the module docstring).
    ``narrowed``: the nodes the plan narrows the scope to (their guarantees, their side conditions, the
    requirements they support; a node the workspace does not have is an item never covered), ``None`` for
    every item.  Pure; raises nothing for a well-formed report."""
    ix = ix or _Index(report_view(report))
    rep = ix.report
    accepts, asked = set(item.evidence), item.independence_at(level)
    keep = None if narrowed is None else set(narrowed)

    def guarantees(nodes: set[str] | None = None) -> list[ScopeItem]:
        return [_guarantee_item(ix, n, k, st, accepts, asked) for n, k, st in ix.guarantees
                if (nodes is None or n in nodes) and (keep is None or n in keep)]

    # a side condition's check is a Z3 proof: it covers only a clause that accepts proofs; for another
    # clause a side condition not proved is still in scope, a defect of the interface that keeps it uncovered
    scs = [_side_condition_item(sc) for sc in rep.side_conditions
           if (keep is None or str(sc.node) in keep) and ("proof" in accepts or not _proved(sc))]
    reqs = [_requirement_item(rq, ix, accepts, asked) for rq in rep.requirements
            if keep is None or any(x.node in keep for x in rq.support or ())]
    known = {n for n, _, _ in ix.guarantees}
    unknown = [_item(f"node {n}", "guarantee", "no evidence", "the plan names this node; the workspace has no such "
                     "node", []) for n in sorted(keep or ()) if n not in known]
    return unknown + _scope(item, rep, ix, guarantees, scs, reqs, keep)


def _scope(item: Item, report: ReportView, ix: _Index, guarantees: Callable[..., list[ScopeItem]],
           scs: list[ScopeItem], reqs: list[ScopeItem], keep: set[str] | None) -> list[ScopeItem]:
    """The scope of ``item`` by its ``about`` (:func:`scope_items`); ``keep`` the nodes it is narrowed to."""
    def kept(node: object) -> bool:
        return keep is None or str(node) in keep

    if item.about == "guarantees":
        return guarantees()
    if item.about == "interfaces":
        linked = {str(node) for c in report.system.connections or () for node in (c.from_node, c.to_node)}
        return scs + guarantees(linked)
    if item.about == "requirements":
        supporting = {s.node for rq in report.requirements for s in rq.support or ()}
        return reqs + guarantees(supporting)
    if item.about in ("field-data", "trials"):
        targets = target_items(report, item.about, item.min_runs, ix.unstated)
        return [t for t in targets if kept(t.item.removeprefix("target ").split(".")[0])
                or t.item.startswith("target of requirement")]
    # system: everything, the health checks and the workspace's own status
    health = [_item(f"health check {f.id}", "health check", str(f.status),
                    f"health check {f.check}: {f.status}", []) for f in report.findings
              if str(f.status) not in _HEALTH_OK and kept(f.node)]
    known = {(n, k) for n, k, _ in ix.guarantees}
    unverified = [_item(f"{u.node} g{u.guarantee}", "guarantee", "unverified",
                        "no obligation covers the guarantee", []) for u in report.unverified
                  if (str(u.node), int(u.guarantee or 0)) not in known and kept(u.node)]
    status = report.summary.status
    whole = [] if status == "discharged" else [_item("workspace", "workspace", status,
                                                     f"the workspace's status is {status}", [])]
    return guarantees() + scs + reqs + health + unverified + whole


def _evidence_in_scope(item: Item, level: str | None, scope: Sequence[ScopeItem], ix: _Index) -> list[ClauseEvidence]:
    """The evidence rows of an accepted kind in the clause's scope (the guarantees', the targets'), once each."""
    accepts, asked = set(item.evidence), item.independence_at(level)
    keys = {tuple(s.item.rsplit(" g", 1)) for s in scope if s.kind == "guarantee"}
    seen: set[str] = set()
    out: list[ClauseEvidence] = []
    rows: list[EvidenceView] = [r for (n, k), rs in ix.rows.items() if (n, f"{k}") in keys for r in rs]
    targets = {s.item[len("target "):] for s in scope if s.kind == "target"}
    rows += [e for e in ix.report.evidence if e.obligation in targets]
    for r in rows:
        if r.obligation in seen or not (kinds_of(r) & accepts or r.obligation in targets):
            continue
        seen.add(r.obligation)
        out.append(_support(r, asked, ix.people))
    return out


def clause_records(profile: Profile, level: str | None,
                   report: ReportView | Mapping[str, Any] | Sequence[Mapping[str, Any]],
                   notes: Mapping[str, Any] | None = None, unstated: Collection[tuple[str, str]] = (),
                   people: Sequence[Person] = ()) -> list[ClauseRecord]:
    """The clause rows of ``profile`` at ``level`` as records
    (:class:`rclverify.records.standards_rows.ClauseRow`), in the profile's order: :func:`clause_rows`
    gives the arguments' meaning.  Pure: reads nothing else, raises nothing for well-formed rows."""
    ix = _Index(report_view(report), unstated, people)
    out: list[ClauseRecord] = []
    for item in profile.items:
        code = item.at(level)
        note = (notes or {}).get(item.id)
        scope = scope_items(item, level, ix.report, ix, None if note is None else note.nodes)
        evidence = _evidence_in_scope(item, level, scope, ix)
        done = sum(1 for s in scope if s.covered)
        status: ClauseStatus
        if code == "NR":
            status = "not recommended"
        elif scope and done == len(scope) and not item.safety_case_adds:
            status = "covered"
        elif done:
            status = "partial"
        elif any(e.counts for e in evidence) or any(s.kind != "guarantee" for s in scope):
            status = "not covered"
        else:
            status = "open"
        why = (clause_words.why(status, scope, evidence, item) + adds(item)
               + ("" if note is None or note.nodes is None else
                  f"; scope narrowed by the plan to {', '.join(note.nodes)} ({note.reason})"))
        out.append(ClauseRecord(
            item.id, item.title, cast(Recommendation, code), list(item.evidence), item.strength,
            cast(About, item.about), cast(Independence, item.independence_at(level)), evidence, scope,
            list(dict.fromkeys(ob for x in scope if x.covered for ob in x.evidence)), checked_by(scope, ix.report.evidence),
            status, why, None if note is None else PlanNoteRecord(
                None if note.nodes is None else list(note.nodes), note.reason, note.justification, note.at)))
    return out


def clause_rows(profile: Profile, level: str | None, report: Mapping[str, Any] | Sequence[Mapping[str, Any]],
                notes: Mapping[str, Any] | None = None,
                unstated: Collection[tuple[str, str]] = (), people: Sequence[Person] = ()) -> list[ClauseRow]:
    """The clause rows of ``profile`` at ``level`` (``None`` for a profile
    without levels) over ``report`` (a report dict: its ``evidence``,
    ``obligations``, ``nodes``, ``side_conditions``, ``requirements``,
    ``findings``, ``unverified``, ``system`` and ``summary`` as far as it
    has them; a bare list of evidence rows reads as a report of those rows
    alone), in the profile's order, each the JSON object of its record
    (:func:`clause_records`).  ``notes``: clause id -> what the plan
    says of it (a :class:`~rclverify.model.plan.standards.choice.ClauseNote`:
    ``nodes``, ``reason``, ``justification``, ``at``): the scope narrowed to
    those nodes, and the note shown.  ``unstated``: the (node, environment)
    of the run sets whose plan entry states no origin (never field data,
    :func:`~.field_data.unstated_origins`).  ``people``: the plan's ``people:``
    entries (:class:`~.identity.Person`), names of one person for a review's
    independence (:func:`~.reviews.independence_of`).  Pure: reads nothing else,
    raises nothing for well-formed rows."""
    rows: list[ClauseRow] = msgspec.to_builtins(clause_records(profile, level, report, notes, unstated, people))
    return rows


def not_covered(rows: Sequence[ClauseRecord | Mapping[str, Any]], codes: Sequence[str] = ASKED) -> list[str]:
    """The ids of the clause rows (records, or their JSON objects) whose recommendation is one of ``codes``
    (default: ``HR`` and ``required``) that are not ``covered`` (the ``--strict`` reading)."""
    records = [r if isinstance(r, ClauseRecord) else msgspec.convert(r, ClauseRecord) for r in rows]
    return [r.id for r in records if r.recommendation in codes and r.status != "covered"]


__all__ = ["About", "CLAUSE_STATUSES", "ClauseRow", "ClauseStatus", "Independence", "Recommendation", "ScopeKind",
           "SUPPORTS", "ScopeItem", "Support", "clause_records", "clause_rows", "independence_of", "kinds_of",
           "not_covered", "PlanNote", "review_as_stated", "review_identity", "scope_items"]
