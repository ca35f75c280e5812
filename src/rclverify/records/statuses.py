"""The status vocabulary of the assurance report: one enumerated set per kind of item.

Every status or verdict word the report (``reports/assurance.json``) carries
is one of the sets below, and ``docs/assurance.schema.json`` lists the same
words as its enums (``tests/test_report_vocabulary.py`` holds the two equal).
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
record's own status).  A requirement's ``verdict`` says what the Z3 check of its formal
statement found; its ``status`` is an evidence status (only ``met`` is
``discharged``; calculus/requirements/rollup.py).

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

EvidenceKind = Literal["proof", "model checking", "testing", "experiment", "review", "monitoring"]
#: The kinds of evidence an obligation asks for and a record gives (obligations' and evidence rows' ``kind``).
EVIDENCE_KINDS: tuple[EvidenceKind, ...] = get_args(EvidenceKind)

#: Every set by the name the schema's ``$defs`` give it (docs/assurance.schema.json).
VOCABULARY: Mapping[str, tuple[str, ...]] = MappingProxyType({
    "evidence_status": EVIDENCE_STATUSES, "health_status": HEALTH_STATUSES,
    "side_condition_verdict": SIDE_CONDITION_VERDICTS, "derivation": DERIVATIONS,
    "requirement_verdict": REQUIREMENT_VERDICTS, "deadline_verdict": DEADLINE_VERDICTS,
    "acknowledgement_status": ACKNOWLEDGEMENT_STATUSES, "severity": SEVERITIES,
    "lint_severity": LINT_SEVERITIES, "agreement": AGREEMENTS, "evidence_kind": EVIDENCE_KINDS,
})
