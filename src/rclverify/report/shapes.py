"""The shapes of what report/ writes beside the report itself, as types: one TypedDict per record.

The report's own rows are :mod:`rclverify.records.report_schema`'s and the
stages' sealed records :mod:`rclverify.records.stage_records`'s; this module
holds only what report/ builds on top of them (the SARIF log's objects are
:mod:`rclverify.records.sarif`'s): the views the templates and the terminal
read (report/view.py, report/summary.py), the statistics table
(report/statistics.py).  A key written only in some cases is ``NotRequired``.
A value only passed on to JSON (a result's ``properties``) is ``object``.
"""
# No ``from __future__ import annotations``: Python 3.11 reads ``NotRequired`` only from evaluated
# annotations (with string annotations every key would count as required).
from typing import Any, NamedTuple, NotRequired, TypedDict

from rclverify.records.derived_rows import DerivedPropertyRow
from rclverify.records.evidence_rows import EvidenceRow
from rclverify.records.findings import FindingRow
from rclverify.records.node_rows import NodeRow
from rclverify.records.obligations import ObligationRow
from rclverify.records.problem_rows import DiagnosisRow, ProblemRow
from rclverify.records.requirement_rows import RequirementRow, StrengthKind, SupportRow
from rclverify.records.side_condition_rows import SideConditionRow
from rclverify.records.strength_rows import LimitedBy
from rclverify.records.verdict_rows import PendingRow




class NodeSummaryRow(TypedDict):
    """A node's row of the terminal summary (report/summary.py ``node_rows``): ``obligations`` status ->
    count, side conditions proved of all, health checks by outcome, ``unverified`` the guarantees
    (``g<k>``) no obligation covers; ``order`` its place in the report and ``culprit`` (a problem's
    culprit is in it) only for a node's own row, not for a merged one."""
    node: str
    status: str
    obligations: dict[str, int]
    sc_proved: int
    sc_total: int
    health_problems: int
    health_open: int
    health_total: int
    health_warnings: int
    unverified: list[str]
    order: NotRequired[int]
    culprit: NotRequired[bool]


class SummaryMeta(TypedDict):
    """The report's ``meta`` as the summary keeps it."""
    workspace: str
    strict_ok: bool


class ProblemBrief(TypedDict):
    """A problem group as the terminal shows it: culprits as ``what (file:line:col)``, the finding ids
    behind it, how many repairs Z3 checked."""
    status: str
    sentence: str
    culprits: list[str]
    where: str
    members: list[str]
    repairs: int


class GroundingBrief(TypedDict):
    """The ROS grounding as the terminal shows it: error and warning counts, each error one line."""
    error: int
    warning: int
    errors: list[str]


class SummaryData(TypedDict):
    """``artifacts/report/summary.json`` (report/summary.py ``summary_data``): what ``verify`` prints.
    ``requirements`` rows are ``[id, verdict, status]``, ``deadlines`` rows ``[requirement, verdict,
    total, bound, evidence status]``; ``strict`` the clauses a failed ``--strict`` names."""
    meta: SummaryMeta
    #: the report's summary as its JSON object (:class:`~rclverify.records.summary_rows.Summary`)
    summary: dict[str, Any]
    rows: list[NodeSummaryRow]
    unverified: list[str]
    requirements: list[list[str]]
    deadlines: list[list[str]]
    problems: list[ProblemBrief]
    grounding: GroundingBrief | None
    #: the NoDL check in the grounding's shape (report/nodl.py ``terminal_brief``); absent in an older summary
    nodl: NotRequired[GroundingBrief | None]
    strict: list[str]
    acknowledged: list[str]
    #: the near misses, one line each after a heading (report/near_misses.py ``summary_lines``)
    near_misses: NotRequired[list[str]]


class AttentionItem(TypedDict):
    """An item that needs attention (report/view.py ``_attention``): ``formula`` RCL text shown as code, or ''."""
    status: str
    kind: str
    ref: str
    anchor: str
    where: str
    message: str
    formula: str


class AttentionGroup(TypedDict):
    """Attention items that say the same thing, numbers aside (report/view.py ``group_items``)."""
    status: str
    kind: str
    where: str
    message: str
    items: list[AttentionItem]


class PendingGroup(TypedDict):
    """The pending rows of one backend with one reason, numbers aside."""
    backend: str
    reason: str
    items: list[PendingRow]


class DashboardCell(TypedDict):
    """A node's items of one technique: the worst status, how many have it of ``total``, the
    ``counts`` ``[(status, n)]`` worst first, the fragment id of the first worst item."""
    status: str
    worst: int
    total: int
    counts: list[tuple[str, int]]
    anchor: str


class DashboardRow(TypedDict):
    """A node's row of the dashboard: one cell per technique (``None``: no item of it)."""
    node: str
    status: str
    cells: list[DashboardCell | None]
    culprit: bool


class Dashboard(TypedDict):
    """The dashboard's matrix (report/view.py ``dashboard``): techniques against nodes."""
    columns: list[str]
    rows: list[DashboardRow]


class TraceObligation(TypedDict):
    """An obligation a supporting guarantee lists, with its status and evidence ``[(anchor, record)]``."""
    id: str
    known: bool
    status: str
    backend: str
    evidence: list[tuple[str, EvidenceRow]]


class TraceSupport(TypedDict):
    """A guarantee that supports a requirement, with its obligations."""
    support: SupportRow
    obligations: list[TraceObligation]


class TraceEntry(TypedDict):
    """A requirement's traceability rows; ``rowspan`` the rows it spans."""
    req: RequirementRow
    rows: list[TraceSupport]
    rowspan: int


class Section(TypedDict):
    """A node's section (``node`` ``None`` for a name only the calculus knows); ``ob_status`` the status of
    each obligation its guarantees list."""
    name: str
    node: NodeRow | None
    derived: list[DerivedPropertyRow]
    side: list[SideConditionRow]
    findings: list[FindingRow]
    ob_status: NotRequired[dict[str, str]]


class ObligationRun(TypedDict):
    """An obligation's row of the obligations table: the fragment ids of its evidence records."""
    obligation: ObligationRow
    evidence: list[str]


class EvidenceRun(TypedDict):
    """An evidence record with its fragment id."""
    anchor: str
    record: EvidenceRow


class TableRuns(TypedDict):
    """The health, obligations and evidence tables' rows cut into runs of one node each."""
    finding_runs: list[list[FindingRow]]
    obligation_runs: list[list[ObligationRun]]
    evidence_runs: list[list[EvidenceRun]]


class ReportView(TableRuns):
    """What the templates read beside the report (report/view.py ``view``); ``problem_groups`` the problems
    by root cause (the report's rows, or grouped now), ``diagnosis`` id -> record, ``counts``
    ``[(status, n)]`` worst first, ``evidence_of`` obligation id -> ``[(anchor, record)]``."""
    dashboard: Dashboard
    problem_groups: list[ProblemRow]
    diagnosis: dict[str, DiagnosisRow]
    counts: list[tuple[str, int]]
    problems: list[AttentionItem]
    outstanding: list[AttentionItem]
    outstanding_groups: list[AttentionGroup]
    pending_groups: list[PendingGroup]
    unmet_requirements: list[RequirementRow]
    ev_anchor: list[str]
    evidence_of: dict[str, list[tuple[str, EvidenceRow]]]
    obligation: dict[str, ObligationRow]
    trace: list[TraceEntry]
    sections: list[Section]
    lint_errors: int


class RunGroupBound(TypedDict):
    """A per-run evidence row's ``statistics.group``: its group's runs and bound at ``level``."""
    runs: int
    bound: float | None
    level: float


class Confidence(NamedTuple):
    """A claim's confidence (docs/confidence.md) as the row fields it sets: ``limited_by`` ``None`` without
    premises."""
    confidence: float
    limited_by: LimitedBy | None


class RequirementConfidence(NamedTuple):
    """What the confidence pass sets on a formal requirement's row: :class:`Confidence`'s fields and, when
    the plan asks a least strength of its proof's guarantees, that strength and the guarantees short of it
    (``None`` and ``[]`` otherwise: the row's defaults)."""
    confidence: float
    limited_by: LimitedBy | None
    required_strength: StrengthKind | None
    strength_shortfall: list[str]


class ElementJson(TypedDict):
    """A GSN element as ``reports/argument.json`` holds it (report/argument/model.py ``Element.to_json``):
    ``challenges`` and ``defeated`` only for counter-evidence, ``acp`` name -> references only with claim points."""
    id: str
    type: str
    text: str
    status: str | None
    supported_by: list[str]
    in_context_of: list[str]
    undeveloped: bool
    ref: str
    url: str
    challenges: NotRequired[list[str]]
    defeated: NotRequired[bool]
    acp: NotRequired[dict[str, list[str]]]


class ArgumentJson(TypedDict):
    """``reports/argument.json``: the top goal's id and every element in order."""
    top: str
    elements: list[ElementJson]


