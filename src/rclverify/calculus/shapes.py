"""The calculus's own JSON records and Python-side rows, as TypedDicts.

What a temporal requirement's record says is missing from the contracts
(:class:`Gaps`: the progress a node should declare, the initial values a
producer should declare; calculus/requirements/progress_gap.py), a node
idle in a lasso's loop (:class:`IdleNode`).  The sealed stage records
themselves are :mod:`rclverify.records.stage_records`.
"""
# No ``from __future__ import annotations``: Python 3.11 reads ``NotRequired`` only from evaluated
# annotations (with string annotations every key would count as required).
from typing import NotRequired, TypedDict

from rclverify.records.stage_records import Premise, Traced
# sealed in the compose stage's record, so defined with it (records/ is below calculus/)
from rclverify.records.composition_records import ContextRecord as ContextRecord, LocalVerdict as LocalVerdict, ScaleMismatch as ScaleMismatch


class IdleNode(TypedDict):
    """A node that accepts its input in a lasso's loop (``accepted_at``: steps) and never answers there."""
    node: str
    accepted_at: list[int]


class MissingProgress(TypedDict):
    """A progress declaration a lasso shows missing: the node, its header (``file:line:col``),
    what it declares (``none``), the steps it accepted at, and the fix."""
    node: str
    source: str
    declared: str
    accepted_at: list[int]
    fix: str


class StuckProducer(TypedDict):
    """A producer that keeps a lasso stuck: its header, the output and the value it keeps (or
    ``none: never published``), and the consumer's input (``Node.in.x``)."""
    node: str
    source: str
    output: str
    value: str
    consumer: str


class Gaps(TypedDict, total=False):
    """What a lasso says is missing (``missing_progress``, ``missing_initially``); filled as found."""
    missing_progress: list[MissingProgress]
    missing_initially: list[StuckProducer]


class Vacuity(TypedDict, total=False):
    """The vacuity fields of a proved temporal statement (calculus/requirements/exercised.py
    ``vacuity``): none for a shape that reaches its goal; ``never_publish`` the silent nodes
    when the connections decided it."""
    vacuity: str
    vacuity_core: list[Premise]
    vacuity_reason: str
    never_publish: list[str]


class TraceNode(TypedDict):
    """One node's values at one step of a temporal trace (RCL text)."""
    node: str
    values: dict[str, str]


class TraceStep(TypedDict):
    """One step of a temporal trace, node by node (the record's ``temporal.trace``)."""
    step: int
    nodes: list[TraceNode]


class DeclarationEvidence(TypedDict):
    """A declaration a requirement's proof used, with its evidence (calculus/requirements/rollup.py)."""
    label: str
    node: str
    kind: str
    index: int
    text: str
    source: str
    status: str
    words: str


class TemporalVerdictJson(TypedDict):
    """A temporal statement's verdict as its record keeps it (calculus/requirements/tsys.py
    ``TemporalVerdict.to_json``): ``trace`` one ``{variable: text}`` per step."""
    status: str
    method: str
    k: int | None
    bound: int | None
    trace: list[dict[str, str]]
    detail: str
    loop: int | None
    deadlock: str
    certificate: str


class RefinementSideJson(TypedDict):
    """One side of a refinement check as ``rclverify refines --json`` writes it (calculus/refinement.py
    ``RefinementResult.to_json``): the implication checked, its status, the counterexample (RCL name ->
    value text, null unless refuted), Z3's reason, the wall time in seconds."""
    statement: str
    status: str
    model: dict[str, str] | None
    reason: str
    duration_s: float


class RefinementJson(TypedDict):
    """The verdict on "B refines A" (calculus/refinement.py ``RefinementResult.to_json``): the two nodes,
    the verdict, the assumption and guarantee sides, the conditions it holds under, and the timing side
    when A has triggered guarantees."""
    a: str
    b: str
    verdict: str
    assumption: RefinementSideJson
    guarantee: RefinementSideJson
    conditions: list[str]
    timing: NotRequired[RefinementSideJson]
