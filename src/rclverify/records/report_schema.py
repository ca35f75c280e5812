"""The assurance report as its passes write it: :class:`Report`, the dict-shaped view of
:class:`rclverify.records.report_record.AssuranceReport`, and a JSON alias per part.

Every part of the report is defined once as a msgspec Struct (the modules
beside this one: :mod:`rclverify.records.findings`, ``node_rows``,
``deadline_rows`` and the others), and docs/assurance.schema.json is
generated from them (:mod:`rclverify.records.schema_gen`).  The report is
built as its JSON object, pass by pass (report/build.py), then decoded once
into :class:`~rclverify.records.report_record.AssuranceReport`: here each
part appears as that object (``FindingJson``, ``NodeJson``, ...), an alias
naming the Struct whose ``of`` decodes it to read its fields as attributes.
:class:`Report` lists the top-level keys with those aliases, for mypy; its
keys are held to :class:`~rclverify.records.report_record.AssuranceReport`'s
fields by tests/records/test_record_shapes.py.

:func:`as_report` is the one place a report dict built pass by pass
(report/build.py) becomes a :class:`Report`: it checks the top-level keys
and the summary status, so a reader typed on :class:`Report` never reads
a report that lacks a part.
"""
from typing import Any, Mapping, TypedDict, cast

from rclverify.records import report_record
from rclverify.records.statuses import EVIDENCE_STATUSES


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

#: The one-screen summary (``summary``) as the report's JSON object: the encoding of
#: :class:`rclverify.records.summary_rows.Summary` (its diagnoses in short
#: :class:`~rclverify.records.summary_rows.DiagnosisBrief`); decode it with ``Summary.of``.
SummaryJson = dict[str, Any]

#: The system model as the report draws it (``system``) as its JSON object: the encoding of
#: :class:`rclverify.records.summary_rows.SystemView`.
SystemJson = dict[str, Any]

#: An obligation without a decided record (``pending[]``) as its JSON object: the encoding of
#: :class:`rclverify.records.verdict_rows.PendingRow`.
PendingJson = dict[str, Any]

#: An expectation of the plan against the obligation it names (``expected_verdicts[]``) as its JSON
#: object: the encoding of :class:`rclverify.records.verdict_rows.ExpectedVerdictRow`.
ExpectedVerdictJson = dict[str, Any]

#: A diagnostic of the contract or plan text (``lint[]``) as its JSON object: the encoding of
#: :class:`rclverify.records.lint_rows.LintRow`.
LintJson = dict[str, Any]

#: A plan acknowledgement of a warning (``acknowledgements[]``) as its JSON object: the encoding of
#: :class:`rclverify.records.lint_rows.AcknowledgementRow`.
AcknowledgementJson = dict[str, Any]

#: Problems grouped by one root cause (``problems[]``) as its JSON object: the encoding of
#: :class:`rclverify.records.problem_rows.ProblemRow` (its members
#: :class:`~rclverify.records.problem_rows.ProblemMember`, its repairs
#: :class:`~rclverify.records.problem_rows.RepairRef`); decode it with ``ProblemRow.of``.
ProblemJson = dict[str, Any]

#: The grounding in the robot's software (``grounding``) as its JSON object: the encoding of
#: :class:`rclverify.records.grounding_rows.GroundingRow`.
GroundingJson = dict[str, Any]

#: The NoDL documents' check (``nodl``) as its JSON object: the encoding of
#: :class:`rclverify.records.nodl_rows.NodlRow`.
NodlJson = dict[str, Any]


class Report(TypedDict):
    """``reports/assurance.json`` (docs/assurance.schema.json)."""
    #: the encoding of :class:`rclverify.records.summary_rows.Meta`
    meta: dict[str, Any]
    summary: SummaryJson
    system: SystemJson
    requirements: list[RequirementJson]
    nodes: list[NodeJson]
    side_conditions: list[SideConditionJson]
    derived_properties: list[DerivedPropertyJson]
    findings: list[FindingJson]
    obligations: list[ObligationJson]
    evidence: list[EvidenceJson]
    environment_assumptions: list[EnvironmentAssumptionJson]
    pending: list[PendingJson]
    lint: list[LintJson]
    expected_verdicts: list[ExpectedVerdictJson]
    grounding: GroundingJson | None
    #: the NoDL documents' check (stages/nodl.py, report/nodl.py), ``None`` when the workspace has none
    nodl: NodlJson | None
    #: the plan's instances (stages/instances.py, records/instance_rows.py), ``None`` for a plan without instances
    instances: dict[str, Any] | None
    #: the plan's design's monitoring fields decided (stages/design.py), ``None`` when the plan names no design
    design: dict[str, Any] | None
    unverified: list[UnverifiedJson]
    deadlines: list[DeadlineJson]
    acknowledgements: list[AcknowledgementJson]
    #: guarantees held with a margin below the plan's near-miss threshold (report/near_misses.py)
    near_misses: list[NearMissJson]
    #: per guarantee, its margins over every recorded run (report/margin_rows.py)
    margins: list[MarginJson]
    statistics: list[dict[str, Any]]
    #: the evidence mapped onto the plan's standard profiles (report/standards_rows.py, docs/standards.md)
    standards: list[dict[str, Any]]
    #: each the encoding of :class:`rclverify.records.problem_rows.DiagnosisRow`
    diagnoses: list[dict[str, Any]]
    problems: list[ProblemJson]


#: The report's top-level keys, in the order build_report writes them (the fields of its one definition).
REPORT_KEYS: tuple[str, ...] = report_record.REPORT_KEYS


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
