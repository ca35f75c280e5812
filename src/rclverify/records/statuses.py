"""The status vocabulary of the assurance report: one enumerated set per kind of item.

Every status or verdict word the report (``reports/assurance.json``) carries
is one of the sets below, and ``docs/assurance.schema.json`` lists the same
words as its enums (``tests/report/test_report_vocabulary.py`` holds the two equal).
Each set is a :class:`typing.Literal` type for mypy and a tuple of its words
for the code that checks or ranks them.

==============================  =================================================  ===================================
set                             words                                              where in the report
==============================  =================================================  ===================================
:data:`EVIDENCE_STATUSES`       discharged, pending, unverified, inconclusive,     ``status`` of obligations, evidence,
                                stale, error, failed (best first: the roll-up      guarantees, nodes, requirements,
                                order, :data:`SEVERITY`)                           side conditions, derived properties
                                                                                   (their ``status`` and
                                                                                   ``evidence_status``), problem rows,
                                                                                   ``summary.status``
:data:`HEALTH_STATUSES`         ok, warning, problem, inconclusive, stale, error   ``findings[].status``
:data:`SIDE_CONDITION_VERDICTS` discharged, discharged in context, failed,         ``side_conditions[].verdict``
                                inconclusive, stale, error
:data:`DERIVATIONS`             derived, not derived, undecided                    ``derived_properties[].derivation``
:data:`REQUIREMENT_VERDICTS`    met, proved, evidence outstanding, proved from     ``requirements[].verdict``
                                an inconsistency, proved vacuously, refuted,
                                inconclusive, informal, stale, error
:data:`DEADLINE_VERDICTS`       proved, refuted, inconclusive, pending, stale,     ``deadlines[].verdict``
                                error
:data:`ACKNOWLEDGEMENT_STATUSES` ok, stale, error                                  ``acknowledgements[].status``
:data:`SEVERITIES`              error, warning, note                               one severity per finding (SARIF
                                                                                   level, JUnit, ``--strict``)
:data:`LINT_SEVERITIES`         error, warning                                     ``lint[].severity``
:data:`AGREEMENTS`              two solvers, one solver, disagree, inconclusive    ``solvers.agreement``
:data:`EVIDENCE_KINDS`          proof, model checking, testing, experiment,        ``kind`` of obligations and evidence
                                review, monitoring
==============================  =================================================  ===================================

The evidence statuses follow the paper's reading of evidence (a guarantee
is established only when every obligation for it is discharged) with the
states a tool run adds: ``pending`` (exported, the tool or manual step
outstanding), ``stale`` (an input changed since the evidence was made),
``error`` (the tool broke, or a record was altered outside rclverify),
``inconclusive`` (the tool could not decide: unknown, a time limit),
``unverified`` (nothing was planned to establish a guarantee; never a
record's own status).

Verdict and status, one rule.  A ``verdict`` (and a derived property's
``derivation``) is what one check decided, in that check's own words: Z3
on a requirement (calculus/requirements/rollup.py), on a side condition,
on an end-to-end deadline (rule D3).  A ``status`` is always an evidence
status: the roll-up the report shows, ranks by and rolls up further
(:data:`SEVERITY`).  A row that carries both derives its status from its
verdict and from the statuses of what it rests on, never the other way,
as :data:`VERDICT_STATUS` says per kind of row; :func:`contradictions`
finds a row that breaks it:

* requirement (and its ``without_deadline``): ``discharged`` exactly when
  the verdict is ``met``; otherwise no better than the verdict's floor in
  :data:`REQUIREMENT_FLOOR` (refuted, proved from an inconsistency or
  vacuously: ``failed``; ``proved, evidence outstanding``: the evidence's
  own status, never ``discharged``);
* side condition: ``discharged`` for ``discharged`` and ``discharged in
  context``; otherwise the verdict's word itself;
* deadline: for ``proved``, the status of the chain's evidence; otherwise
  :data:`DEADLINE_STATUS` of the verdict;
* derived property: the ``derivation`` says its ``status`` (``derived``
  for ``discharged``, ``not derived`` for ``failed``, else ``undecided``);
  its ``evidence_status`` is the roll-up of the node contracts it rests on.

This module imports nothing of the package: it sits in the evidence
records layer, below every stage that writes a status.
"""
from __future__ import annotations

from types import MappingProxyType
from typing import Literal, Mapping, get_args

EvidenceStatus = Literal["discharged", "pending", "unverified", "inconclusive", "stale", "error", "failed"]
#: The evidence statuses, best first: the roll-up order (a parent is the worst of its children).
EVIDENCE_STATUSES: tuple[EvidenceStatus, ...] = get_args(EvidenceStatus)
#: Rank of each evidence status (0: discharged, the best): :func:`rclverify.records.records.worst` maximises it.
SEVERITY: Mapping[str, int] = {s: i for i, s in enumerate(EVIDENCE_STATUSES)}  # a dict: its C-level __getitem__ ranks long cones
#: The statuses an evidence record may carry (``unverified`` belongs to a guarantee without obligations only).
RECORD_STATUSES: tuple[EvidenceStatus, ...] = tuple(s for s in EVIDENCE_STATUSES if s != "unverified")

HealthStatus = Literal["ok", "warning", "problem", "inconclusive", "stale", "error"]
#: A contract health finding's status (health/): ``warning`` is shown but changes no status.
HEALTH_STATUSES: tuple[HealthStatus, ...] = get_args(HealthStatus)

SideConditionVerdict = Literal["discharged", "discharged in context", "failed", "inconclusive", "stale", "error"]
#: A side condition's verdict: its status, or ``discharged in context`` when only the cone's contracts proved it.
SIDE_CONDITION_VERDICTS: tuple[SideConditionVerdict, ...] = get_args(SideConditionVerdict)

Derivation = Literal["derived", "not derived", "undecided"]
#: A derived property's derivation, read from the worst side condition of its cone.
DERIVATIONS: tuple[Derivation, ...] = get_args(Derivation)

RequirementVerdict = Literal["met", "proved, evidence outstanding", "proved from an inconsistency",
                             "proved vacuously", "refuted", "inconclusive", "informal", "stale", "error"]
#: A requirement's verdict (calculus/requirements/rollup.py's table).
REQUIREMENT_VERDICTS: tuple[RequirementVerdict, ...] = get_args(RequirementVerdict)

DeadlineVerdict = Literal["proved", "refuted", "inconclusive", "pending", "stale", "error"]
#: An end-to-end deadline's verdict (rule D3, report/deadlines.py).
DEADLINE_VERDICTS: tuple[DeadlineVerdict, ...] = get_args(DeadlineVerdict)

AcknowledgementStatus = Literal["ok", "stale", "error"]
#: A plan acknowledgement's status (model/plan/acknowledged.py).
ACKNOWLEDGEMENT_STATUSES: tuple[AcknowledgementStatus, ...] = get_args(AcknowledgementStatus)

Severity = Literal["error", "warning", "note"]
#: One severity per finding (report/severity.py), the SARIF levels.
SEVERITIES: tuple[Severity, ...] = get_args(Severity)

LintSeverity = Literal["error", "warning"]
#: A diagnostic's severity (lang/errors.py).
LINT_SEVERITIES: tuple[LintSeverity, ...] = get_args(LintSeverity)

Agreement = Literal["two solvers", "one solver", "disagree", "inconclusive"]
#: Whether a second SMT solver confirmed a verdict (crosscheck/).
AGREEMENTS: tuple[Agreement, ...] = get_args(Agreement)

#: A status of any kind of item (``$defs/any_status``: a problem row's member keeps its item's own word).
AnyStatus = EvidenceStatus | HealthStatus | SideConditionVerdict | Derivation | RequirementVerdict | DeadlineVerdict \
    | AcknowledgementStatus | Severity

EvidenceKind = Literal["proof", "model checking", "testing", "experiment", "review", "monitoring"]
#: The kinds of evidence an obligation asks for and a record gives (obligations' and evidence rows' ``kind``).
EVIDENCE_KINDS: tuple[EvidenceKind, ...] = get_args(EvidenceKind)

#: The least bad status a requirement of each verdict may show (module docstring, "Verdict and status").
REQUIREMENT_FLOOR: Mapping[str, EvidenceStatus] = MappingProxyType({
    "met": "discharged", "proved, evidence outstanding": "pending", "proved from an inconsistency": "failed",
    "proved vacuously": "failed", "refuted": "failed", "inconclusive": "pending", "informal": "pending",
    "stale": "stale", "error": "error"})
#: A deadline verdict other than ``proved`` as the status its row shows (report/deadlines.py).
DEADLINE_STATUS: Mapping[str, EvidenceStatus] = MappingProxyType({
    "refuted": "failed", "inconclusive": "inconclusive", "pending": "pending", "stale": "stale", "error": "error"})
#: A derived property's derivation status (the worst side condition of its cone) as its ``derivation``
#: (any other status: ``undecided``).
DERIVATION_OF: Mapping[str, Derivation] = MappingProxyType({"discharged": "derived", "failed": "not derived"})
#: Which rows carry both a verdict and a status, and the rule that ties them (module docstring).
VERDICT_STATUS: Mapping[str, str] = MappingProxyType({
    "requirements": "discharged exactly when met; otherwise no better than REQUIREMENT_FLOOR[verdict]",
    "side_conditions": "discharged for discharged and discharged in context; otherwise the verdict",
    "deadlines": "proved: the chain's evidence status; otherwise DEADLINE_STATUS[verdict]",
    "derived_properties": "derivation: derived for discharged, not derived for failed, else undecided"})


def _requirement_breaks(row: Mapping[str, object]) -> bool:
    verdict, status = str(row.get("verdict")), str(row.get("status"))
    if (status == "discharged") != (verdict == "met"):
        return True
    floor = REQUIREMENT_FLOOR.get(verdict)
    return floor is None or SEVERITY.get(status, len(SEVERITY)) < SEVERITY[floor]


def _breaks(kind: str, row: Mapping[str, object]) -> bool:
    """Does ``row`` (a row of the report's list ``kind``) break the rule of :data:`VERDICT_STATUS`?"""
    verdict, status = row.get("verdict"), row.get("status")
    if kind == "requirements":
        without = row.get("without_deadline")
        return _requirement_breaks(row) or (isinstance(without, Mapping) and _requirement_breaks(without))
    if kind == "side_conditions":
        proved = verdict in ("discharged", "discharged in context")
        return status != ("discharged" if proved else verdict)
    if kind == "deadlines":
        return status != (row.get("evidence_status") if verdict == "proved" else DEADLINE_STATUS.get(str(verdict)))
    derivation = DERIVATION_OF.get(str(status), "undecided")
    return row.get("derivation") != derivation


def contradictions(report: Mapping[str, object]) -> list[str]:
    """``kind[i] (id): verdict ... status ...`` for every row of ``report``
    (a report dict, docs/assurance.schema.json) whose status does not follow
    from its verdict by the rule of :data:`VERDICT_STATUS`; empty when every
    row follows it.  Reads the report only."""
    out = []
    for kind in VERDICT_STATUS:
        rows = report.get(kind)
        for i, row in enumerate(rows if isinstance(rows, list) else ()):
            if isinstance(row, Mapping) and _breaks(kind, row):
                name = row.get("id", row.get("requirement", row.get("node")))
                out.append(f"{kind}[{i}] ({name}): verdict {row.get('verdict', row.get('derivation'))!r}, "
                           f"status {row.get('status')!r}")
    return out


#: Every set by the name the schema's ``$defs`` give it (docs/assurance.schema.json).
VOCABULARY: Mapping[str, tuple[str, ...]] = MappingProxyType({
    "evidence_status": EVIDENCE_STATUSES, "health_status": HEALTH_STATUSES,
    "side_condition_verdict": SIDE_CONDITION_VERDICTS, "derivation": DERIVATIONS,
    "requirement_verdict": REQUIREMENT_VERDICTS, "deadline_verdict": DEADLINE_VERDICTS,
    "acknowledgement_status": ACKNOWLEDGEMENT_STATUSES, "severity": SEVERITIES,
    "lint_severity": LINT_SEVERITIES, "agreement": AGREEMENTS, "evidence_kind": EVIDENCE_KINDS,
})
