"""The monitors' JSON records as types: one TypedDict per record a monitor writes.

These are the static reading of what the monitors put in their evidence
``details`` and their logs: a node's verdicts on a run (:class:`NodeResultJson`
and the first violation, inconclusive, inexact verdicts it keeps), the live
verdict message (:class:`VerdictJson`), deadlines (:class:`DeadlineVerdictJson`,
:class:`DeadlineResultJson`), periods (:class:`PeriodResultJson`), a temporal
statement's verdict on a trace (:class:`TraceVerdictJson`), and the run's
origin lines (:mod:`.run_origin`).  Values shown to a reader are rendered
text (``dict[str, str]``).
"""
# No ``from __future__ import annotations``: Python 3.11 reads ``NotRequired`` only from evaluated
# annotations (with string annotations every key would count as required).
from typing import NotRequired, TypedDict

from rclverify.backends.shapes import DeclarationRow as DeclarationRow  # re-exported: a declaration row is the monitors' too
# sealed in a requirement's record (its traces), so defined with it (records/ is below backends/)
from rclverify.records.stage_records import TraceVerdictJson as TraceVerdictJson, Witness as Witness


class OriginLine(TypedDict):
    """A live log's first line: which source and middleware heard the run (:mod:`.run_origin`)."""
    topic: str
    time: float
    kind: str
    source: str
    rmw: str
    middleware: str


class UnseenLine(TypedDict):
    """A live log's line of what its source could not hear, one sentence per link."""
    topic: str
    time: float
    kind: str
    unseen: list[str]


class RunSource(TypedDict):
    """The origin of a run as the evidence shows it (``details["monitoring"]["source"]``)."""
    source: str
    rmw: str
    middleware: str
    unseen: list[str]


class Violation(TypedDict):
    """One ``violated`` verdict: the message, the guarantee (1-based), its
    formula, the rendered values, why, the arithmetic that decided, and the
    question it answered (``trigger*``) when there was one."""
    event: int
    time: float
    where: str
    guarantee: int
    formula: str
    values: dict[str, str]
    reason: str
    semantics: str
    trigger: NotRequired[int]
    trigger_time: NotRequired[float]
    trigger_where: NotRequired[str]


class AssumptionViolation(TypedDict):
    """The first question that violated the assumption, and who is blamed."""
    event: int
    time: float
    where: str
    assumption: str
    values: dict[str, str]
    blame: str
    semantics: str


class Inconclusive(TypedDict):
    """The first event that could not be decided, and why."""
    event: int
    time: float
    where: str
    reason: str


class Inexact(TypedDict):
    """The first formula that held only in double arithmetic or within the tolerance."""
    event: int
    time: float
    where: str
    semantics: str
    formula: str
    values: dict[str, str]
    reason: str


class AssumptionVerdict(TypedDict):
    """The assumption monitor's verdict on a run (``held``, ``violated``, ``not evaluated``)."""
    verdict: str
    violations: int
    accepted: int
    first: AssumptionViolation | None


class VerdictJson(TypedDict):
    """One verdict as the live monitor publishes it (:class:`.verdicts.Verdict`)."""
    node: str
    verdict: str
    event: int
    time: float
    where: str
    topic: str
    decided_at: float
    guarantee: int
    values: dict[str, str]
    reason: str
    semantics: str
    question: NotRequired[str]
    margin: NotRequired[float | None]
    provisional: NotRequired[bool]


class NodeResultJson(TypedDict):
    """One node's verdicts on one run (:class:`.verdicts.NodeResult`)."""
    node: str
    counts: dict[str, int]
    events: int
    first_violation: Violation | None
    first_assumption_violation: AssumptionViolation | None
    first_inconclusive: Inconclusive | None
    accepted: int
    semantics: dict[str, int]
    first_inexact: Inexact | None
    unowed: int
    unasked: int
    violations: list[Violation]
    violations_dropped: int


class DeadlineVerdictJson(TypedDict):
    """One trigger's deadline verdict (:class:`.deadline_records.DeadlineVerdict`)."""
    node: str
    guarantee: int
    verdict: str
    trigger_where: str
    trigger_stamp: float
    due: float
    answer: float | None
    answer_where: str
    reason: str
    update: bool
    semantics: str
    time_margin: NotRequired[float]


class Unaccepted(TypedDict):
    """The first (trigger, guarantee) pair given no deadline verdict, and why."""
    guarantee: int
    where: str
    stamp: float
    why: str
    reason: str


class DeadlineResultJson(TypedDict):
    """One node's deadline verdicts on one run (:class:`.deadline_records.DeadlineResult`)."""
    node: str
    counts: dict[str, int]
    first_false: DeadlineVerdictJson | None
    unaccepted: dict[str, int]
    first_unaccepted: Unaccepted | None
    time_margins: list[dict[str, object]]


#: The first gap longer than an output's period: stamps ``from`` and ``to``
#: (``None``: the run's end), the gap and the period in s, the later message's
#: place (the functional form: ``from`` is a keyword).
PeriodGapJson = TypedDict("PeriodGapJson", {"from": float, "to": float | None, "gap": float, "period": float,
                                            "where": str})


class PeriodResultJson(TypedDict):
    """One node's periodic outputs on one run (:class:`.periods.PeriodResult`)."""
    node: str
    periods: dict[str, float]
    messages: dict[str, int]
    late: dict[str, PeriodGapJson]
    end: float | None
    #: per output whose stamps ran in another clock: its rate against the run's clock (node s per run s)
    clocks: NotRequired[dict[str, float]]
    #: such outputs with a single message: the run's end not carried into their clock, their tail not judged
    unrated: NotRequired[list[str]]
    #: outputs judged in simulated time whose gap or tail was not decided: output -> why
    undecided: NotRequired[dict[str, str]]


class PeriodsPart(TypedDict):
    """The part of an evidence's ``details`` the periods add (:func:`.periods.with_periods`)."""
    periods: PeriodResultJson


class DeadlinesPart(TypedDict):
    """The part of an evidence's ``details`` the deadlines add (:func:`.backend.with_deadlines`)."""
    deadlines: DeadlineResultJson


class DeclarationsPart(TypedDict):
    """The part of an evidence's ``details`` the declarations add (:func:`.declarations.with_declarations`)."""
    declarations: list[DeclarationRow]


class RunCounts(TypedDict):
    """What one run's evidence saw (``details["statistics"]``, :func:`.runset.run_counts`)."""
    trace: str
    sha256: str
    files_sha256: str
    recorded: str
    environment: str
    origin: str
    status: str
    answers: int
    violations: int
    inconclusive: int
    seconds: float
    violations_per_guarantee: dict[str, int]
    per_guarantee_complete: bool


class StepPlace(TypedDict):
    """Where a trace's check stood: the step (0-based; ``None`` before any), its time and place."""
    step: int | None
    time: float | None
    where: str
