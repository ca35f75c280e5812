"""The assurance report, ``reports/assurance.json``, defined once: :class:`AssuranceReport`.

Its fields are the report's top-level keys, in the order the report writes
them, each typed by the record defined once for it (the modules beside
this one) and described.  docs/assurance.schema.json is generated from it
whole (records/schema_gen.py): the top-level keys, which are required and
which refuse others, each key's part.  The report's passes (report/build.py)
build and return its parts' records and the report is one from the first
pass to the renderers, which read its attributes (docs/records.md); its JSON
object (:meth:`~rclverify.records.row.Row.to_json`) is made when it is
written, and :data:`REPORT_KEYS` is what
:func:`rclverify.records.report_schema.as_report` checks such an object has.
"""
from __future__ import annotations

from typing import Annotated

from rclverify.records.deadline_rows import DeadlineRow
from rclverify.records.design_rows import DesignRow
from rclverify.records.derived_rows import DerivedPropertyRow, EnvironmentAssumptionRow
from rclverify.records.evidence_rows import EvidenceRow
from rclverify.records.findings import FindingRow
from rclverify.records.grounding_rows import GroundingRow
from rclverify.records.instance_rows import InstancesRow
from rclverify.records.lint_rows import AcknowledgementRow, LintRow
from rclverify.records.margin_rows import MarginRow, NearMissRow
from rclverify.records.node_rows import NodeRow, UnverifiedRow
from rclverify.records.nodl_rows import NodlRow
from rclverify.records.obligations import ObligationRow
from rclverify.records.problem_rows import DiagnosisRow, ProblemRow
from rclverify.records.requirement_rows import RequirementRow
from rclverify.records.row import DOC, Row
from rclverify.records.side_condition_rows import SideConditionRow
from rclverify.records.standards_rows import StandardRow
from rclverify.records.statistics_rows import StatisticsRow
from rclverify.records.summary_rows import Meta, Summary, SystemView
from rclverify.records.verdict_rows import ExpectedVerdictRow, PendingRow


class AssuranceReport(Row, frozen=True, forbid_unknown_fields=True):
    """What `doit verify` / `rclverify report` writes to reports/assurance.json (docs/reading-the-report.md)."""

    meta: Annotated[Meta, DOC(description="Where the report comes from.")]
    summary: Annotated[Summary, DOC(description="The one-screen summary.")]
    system: Annotated[SystemView, DOC(description="The system model: nodes, links, loops.")]
    requirements: Annotated[list[RequirementRow], DOC(description="The plan's requirements, in plan order.")]
    nodes: Annotated[list[NodeRow], DOC(description="The nodes, in contract order.")]
    side_conditions: Annotated[list[SideConditionRow], DOC(description="Every side condition of every node.")]
    derived_properties: Annotated[list[DerivedPropertyRow], DOC(description="One per node the calculus ran on.")]
    findings: Annotated[list[FindingRow], DOC(description="Contract health findings (vacuity, consistency, realizability, scale).")]
    obligations: Annotated[list[ObligationRow], DOC(description="Every obligation of the plan's evidence entries.")]
    evidence: Annotated[list[EvidenceRow], DOC(description="One row per obligation with an evidence record.")]
    environment_assumptions: Annotated[list[EnvironmentAssumptionRow], DOC(description="Assumptions the system leaves to its environment.")]
    pending: Annotated[list[PendingRow], DOC(description="Obligations without a decided record.")]
    lint: Annotated[list[LintRow], DOC(description="Diagnostics of the contract and plan texts.")]
    expected_verdicts: Annotated[list[ExpectedVerdictRow], DOC(description="Verdicts the plan expects.")]
    grounding: Annotated[GroundingRow | None, DOC(description="The grounding in the ROS code, null when the plan names none.")]
    nodl: Annotated[NodlRow | None, DOC(description="The NoDL documents checked against the contracts and each other (docs/nodl.md), null when the workspace has no document in nodl/.")]
    instances: Annotated[InstancesRow | None, DOC(description="The plan's instances (a contract run under several namespaces) and the requirements naming them decided per namespace (docs/plan.md, \"Instances in the report\"), null for a plan without instances.")]
    design: Annotated[DesignRow | None, DOC(description="The monitoring fields of the Autoware System Designer design the plan names decided against the contracts (stages/design.py; docs/nodl.md, \"The design stage\"), null when the plan names no design.")]
    unverified: Annotated[list[UnverifiedRow], DOC(description="Guarantees no obligation covers.")]
    deadlines: Annotated[list[DeadlineRow], DOC(description="End-to-end deadlines (rule D3).")]
    acknowledgements: Annotated[list[AcknowledgementRow], DOC(description="The plan's acknowledgements of warnings.")]
    near_misses: Annotated[list[NearMissRow], DOC(description="Guarantees held on every run with a margin below the plan's near-miss threshold (report/near_misses.py).")]
    margins: Annotated[list[MarginRow], DOC(description="Per guarantee judged with margins, its margins over every recorded run (report/margin_rows.py).")]
    statistics: Annotated[list[StatisticsRow], DOC(description="Runs counted by environment, bounds and targets (docs/statistics.md).")]
    standards: Annotated[list[StandardRow], DOC(description="The evidence mapped onto the standards the plan names (docs/standards.md); empty when it names none.")]
    diagnoses: Annotated[list[DiagnosisRow], DOC(description="One diagnosis per problem.")]
    problems: Annotated[list[ProblemRow], DOC(description="The problems grouped by root cause.")]


#: The report's top-level keys, in the order the report writes them.
REPORT_KEYS: tuple[str, ...] = AssuranceReport.__struct_fields__


__all__ = ["AssuranceReport", "REPORT_KEYS"]
