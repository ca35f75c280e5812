"""The assurance report's shape as types: :class:`Report` and a TypedDict per row kind not defined once.

The rows defined once as msgspec Structs (findings, obligations, evidence,
requirements, statistics, standards: :mod:`rclverify.records.findings` and
the modules beside it) appear here as the JSON objects they write
(``FindingJson``, ``ObligationJson``, ...); their schema parts are generated
(:mod:`rclverify.records.schema_gen`).

These are the static reading of ``docs/assurance.schema.json`` (JSON Schema
draft 2020-12), the published shape of ``reports/assurance.json``; the
status words are the Literal types of :mod:`rclverify.records.statuses`.
A key the schema lists as optional is ``NotRequired`` here; the two are held
to one shape key by key, both ways, by ``tests/report/test_report_vocabulary.py``.  Records whose
inner shape belongs to a tool (a requirement's check record, a monitoring
summary, a counterexample, the grounding) are ``dict[str, Any]``, as the
schema leaves them open.

:func:`as_report` is the one place a report dict built pass by pass
(report/build.py) becomes a :class:`Report`: it checks the top-level keys
and the summary status, so a renderer typed on :class:`Report` never reads
a report that lacks a part.
"""
# No ``from __future__ import annotations``: Python 3.11 reads ``NotRequired`` only from evaluated
# annotations (with string annotations every key would count as required).
from typing import Any, Literal, Mapping, NotRequired, TypedDict, cast

from rclverify.records.statuses import (AcknowledgementStatus, AnyStatus, Derivation,
                                        EvidenceKind, EvidenceStatus, HealthStatus, LintSeverity, RequirementVerdict,
                                        EVIDENCE_STATUSES)
from rclverify.records.nodl_rows import NodlRow
from rclverify.records.strength_rows import Strength


class SystemView(TypedDict):
    """The system model as the report draws it (``system``; model/system/model.py ``view``)."""
    nodes: list[dict[str, Any]]
    connections: list[dict[str, Any]]
    environment_inputs: list[dict[str, Any]]
    loops: list[list[str]]
    loop_components: list[list[str]]


class ExpectedVerdictRow(TypedDict):
    """An expectation of the plan against the obligation it names (``expected_verdicts[]``; report/expected.py)."""
    node: str
    backend: str
    source: str
    guarantee: int | None
    instance: str | None
    expected: str | None
    actual: EvidenceStatus | None
    obligation: str | None
    reason: str
    outcome: str


class DiagnosisRow(TypedDict):
    """One problem explained, with its repairs checked by Z3 (``diagnoses[]``; docs/diagnosis.md)."""
    id: str
    kind: str
    status: AnyStatus
    node: str
    guarantee: int | None
    sentence: str
    culprits: list[Any]
    counterexample: list[Any]
    related: list[Any]
    repairs: list[dict[str, Any]]


class Meta(TypedDict):
    """Where the report comes from (``meta``)."""
    tool: str
    version: str
    workspace: str
    plan: str
    contracts: list[str]
    z3_version: str
    strict_ok: bool
    inputs_sha256: str


class DiagnosisBrief(TypedDict):
    """One diagnosis in short (``summary.diagnoses[]``); ``repairs``: how many repairs Z3 checked."""
    id: str
    kind: str
    sentence: str
    repairs: int


class Summary(TypedDict):
    """The one-screen summary (``summary``); ``counts``: obligations per status."""
    status: EvidenceStatus
    counts: dict[str, int]
    headline: str
    problems: list[str]
    solvers: dict[str, int]
    diagnoses: list[DiagnosisBrief]
    confidence: NotRequired[float]


#: A node's row (``nodes[]``) as the report's JSON object: the encoding of
#: :class:`rclverify.records.node_rows.NodeRow` (its guarantees
#: :class:`~rclverify.records.node_rows.GuaranteeRow`), the one definition of its fields (the schema's
#: ``nodes`` items are generated from it, records/schema_gen.py); decode it with ``NodeRow.of`` to read
#: its fields as attributes.
NodeJson = dict[str, Any]

#: A guarantee of a node's row (``nodes[].guarantees[]``) as its JSON object: the encoding of
#: :class:`rclverify.records.node_rows.GuaranteeRow`.
GuaranteeJson = dict[str, Any]

#: A derived property's row (``derived_properties[]``) as the report's JSON object: the encoding of
#: :class:`rclverify.records.derived_rows.DerivedPropertyRow`, the one definition of its fields (the
#: schema's ``derived_properties`` items are generated from it, records/schema_gen.py).
DerivedPropertyJson = dict[str, Any]

#: An environment assumption's row (``environment_assumptions[]``) as the report's JSON object: the
#: encoding of :class:`rclverify.records.derived_rows.EnvironmentAssumptionRow` (its schema generated
#: from it, records/schema_gen.py).
EnvironmentAssumptionJson = dict[str, Any]

#: A guarantee no obligation covers (``unverified[]``) as the report's JSON object: the encoding of
#: :class:`rclverify.records.node_rows.UnverifiedRow` (its schema generated from it, records/schema_gen.py).
UnverifiedJson = dict[str, Any]

#: The weakest premise behind a confidence (``$defs/limited_by``) as its JSON object: the encoding of
#: :class:`rclverify.records.strength_rows.LimitedBy`.
LimitedByJson = dict[str, Any]


#: A side condition's row (``side_conditions[]``) as the report's JSON object: the encoding of
#: :class:`rclverify.records.side_condition_rows.SideConditionRow`, the one definition of its fields (the
#: schema's ``side_conditions`` items are generated from it, records/schema_gen.py).
SideConditionJson = dict[str, Any]

#: An end-to-end deadline's row (``deadlines[]``, ``$defs/deadline``) as the report's JSON object: the
#: encoding of :class:`rclverify.records.deadline_rows.DeadlineRow` (its hops
#: :class:`~rclverify.records.deadline_rows.DeadlineHop`), the one definition of its fields (the schema's
#: ``$defs`` entry is generated from it, records/schema_gen.py).
DeadlineJson = dict[str, Any]

#: A near miss (``near_misses[]``, ``$defs/near_miss``) as the report's JSON object: the encoding of
#: :class:`rclverify.records.margin_rows.NearMissRow` (its schema generated from it, records/schema_gen.py).
NearMissJson = dict[str, Any]

#: A guarantee's margins over every recorded run (``margins[]``, ``$defs/margins_over_runs``) as the
#: report's JSON object: the encoding of :class:`rclverify.records.margin_rows.MarginRow` (its schema
#: generated from it, records/schema_gen.py).
MarginJson = dict[str, Any]


#: A contract health finding (``findings[]``) as the report's JSON object: the encoding of
#: :class:`rclverify.records.findings.FindingRow`, the one definition of its fields (the schema's
#: ``findings`` items are generated from it, records/schema_gen.py); decode it with
#: ``FindingRow.of`` to read its fields as attributes.
FindingJson = dict[str, Any]


#: An obligation's row (``obligations[]``) as the report's JSON object: the encoding of
#: :class:`rclverify.records.obligations.ObligationRow`, the one definition of its fields (the schema's
#: ``obligations`` items are generated from it, records/schema_gen.py); decode it with
#: ``ObligationRow.of`` to read its fields as attributes.
ObligationJson = dict[str, Any]


#: An evidence record's row (``evidence[]``) as the report's JSON object: the encoding of
#: :class:`rclverify.records.evidence_rows.EvidenceRow`, the one definition of its fields (the schema's
#: ``evidence`` items are generated from it, records/schema_gen.py); decode it with ``EvidenceRow.of``
#: to read its fields as attributes.
EvidenceJson = dict[str, Any]


#: A requirement's row (``requirements[]``) as the report's JSON object: the encoding of
#: :class:`rclverify.records.requirement_rows.RequirementRow`, the one definition of its fields (the
#: schema's ``requirements`` items are generated from it, records/schema_gen.py); decode it with
#: ``RequirementRow.of`` to read its fields as attributes.
RequirementJson = dict[str, Any]

#: A guarantee a requirement is traced to (``requirements[].support[]``) as its JSON object: the encoding
#: of :class:`rclverify.records.requirement_rows.SupportRow`.
SupportJson = dict[str, Any]


class PendingRow(TypedDict):
    """An obligation without a decided record (``pending[]``)."""
    obligation: str
    backend: str
    reason: str


class LintRow(TypedDict):
    """A diagnostic of the contract or plan text (``lint[]``); ``location`` is file:line:col."""
    severity: LintSeverity
    location: str
    message: str
    code: str
    flagged: NotRequired[str]
    sha256: NotRequired[str]
    acknowledged: NotRequired[dict[str, str]]


class AcknowledgementRow(TypedDict):
    """A plan acknowledgement of a warning (``acknowledgements[]``); ``at`` is file:line:col."""
    warning: str
    reason: str
    at: str
    status: AcknowledgementStatus
    message: str
    matched: list[str]


class ProblemMember(TypedDict):
    """An item of a problem row (``problems[].members[]``); ``consequence_of`` the ids of the items whose
    failure it follows from."""
    id: str
    kind: str
    status: AnyStatus
    sentence: str
    anchor: str
    diagnosis: bool
    consequence_of: NotRequired[list[str]]


class RepairRef(TypedDict):
    """A repair by reference (``problems[].repairs[]``): the diagnosis's id and the 0-based index of its repair."""
    diagnosis: str
    index: int


class ProblemRow(TypedDict):
    """Problems grouped by one root cause (``problems[]``)."""
    key: list[str]
    sentence: str
    status: EvidenceStatus
    where: str
    culprits: list[dict[str, Any]]
    members: list[ProblemMember]
    repairs: list[RepairRef]


class Report(TypedDict):
    """``reports/assurance.json`` (docs/assurance.schema.json)."""
    meta: Meta
    summary: Summary
    system: SystemView
    requirements: list[RequirementJson]
    nodes: list[NodeJson]
    side_conditions: list[SideConditionJson]
    derived_properties: list[DerivedPropertyJson]
    findings: list[FindingJson]
    obligations: list[ObligationJson]
    evidence: list[EvidenceJson]
    environment_assumptions: list[EnvironmentAssumptionJson]
    pending: list[PendingRow]
    lint: list[LintRow]
    expected_verdicts: list[ExpectedVerdictRow]
    grounding: dict[str, Any] | None
    #: the NoDL documents' check (stages/nodl.py, report/nodl.py), ``None`` when the workspace has none
    nodl: NodlRow | None
    unverified: list[UnverifiedJson]
    deadlines: list[DeadlineJson]
    acknowledgements: list[AcknowledgementRow]
    #: guarantees held with a margin below the plan's near-miss threshold (report/near_misses.py)
    near_misses: list[NearMissJson]
    #: per guarantee, its margins over every recorded run (report/margin_rows.py)
    margins: list[MarginJson]
    statistics: list[dict[str, Any]]
    #: the evidence mapped onto the plan's standard profiles (report/standards_rows.py, docs/standards.md)
    standards: list[dict[str, Any]]
    diagnoses: list[DiagnosisRow]
    problems: list[ProblemRow]


#: The report's top-level keys, in the order build_report writes them.
REPORT_KEYS: tuple[str, ...] = tuple(Report.__annotations__)


def as_report(report: Mapping[str, Any]) -> Report:
    """``report`` (a report dict, e.g. what the passes of report/build.py
    grew) as a :class:`Report`.  Raises ``ValueError`` naming the missing
    top-level keys, or a ``summary.status`` outside the evidence statuses:
    a report without a part is a bug of the build, never shown."""
    missing = [k for k in REPORT_KEYS if k not in report]
    if missing:
        raise ValueError(f"report lacks {', '.join(missing)}")
    status = report["summary"].get("status")
    if status not in EVIDENCE_STATUSES:
        raise ValueError(f"report summary status {status!r} is not an evidence status")
    return cast(Report, report)
