"""The sealed records the stages write, as types: one TypedDict per stage record.

Each stage of the pipeline (app/pipeline.py and the stages it calls) writes
one JSON record under ``artifacts/`` (records/sealed.py seals it) and
returns it; these TypedDicts are the static reading of those records, key
by key, with each key's JSON type.  A key a producer writes only in some
cases is ``NotRequired``.  The inner shape of a record that belongs to one
tool (an obligation's backend ``data``, a health finding's Z3 ``model``, a
temporal requirement's run, cvc5's answer) stays ``dict[str, Any]``, as in
:mod:`rclverify.records.report_schema`.

Producers: ``check`` app/pipeline.py ``stage_check``; ``compose``
calculus/compose.py ``composition_json`` and calculus/side_condition.py;
``health`` calculus/health/finding.py ``Finding.to_json``; ``export``
records/records.py ``Obligation.to_json``; ``deadlines``
calculus/deadlines.py ``DeadlineResult.to_json`` with stages/deadlines.py;
``requirements`` calculus/requirements/check.py, temporal_check.py and
stages/requirements.py; ``crosscheck`` stages/crosscheck/stage.py;
``ground`` app/ros_stage.py; ``diagnosis`` diagnosis/build.py with
stages/diagnoses.py.  tests/test_stage_records.py checks every
record the case study's stages return against these types.
"""
# No ``from __future__ import annotations``: Python 3.11 reads ``NotRequired`` only from evaluated
# annotations (with string annotations every key would count as required).
from typing import Any, NotRequired, TypedDict


class LintWarning(TypedDict):
    """One diagnostic of the check stage (lint, units across connections, unserved calls)."""
    file: str
    line: int
    col: int
    severity: str
    code: str
    message: str


class CheckRecord(TypedDict):
    """``artifacts/diagnostics.json``: the check stage's warnings."""
    warnings: list[LintWarning]


class EnvironmentAssumption(TypedDict):
    """An assumption of a node that no producer in the system guarantees (rule R2's environment)."""
    node: str
    text: str
    source: str


class RuleInstance(TypedDict):
    """One instance of a calculus rule (R1-R4) applied to the node."""
    rule: str
    shape: str
    premises: list[str]
    conclusion: str


class SideCondition(TypedDict):
    """One side condition and its Z3 verdict (calculus/side_condition.py); ``duration_s`` in seconds."""
    id: str
    node: str
    rule: str
    conjunct: str
    source: str
    hypotheses: list[str]
    status: str
    duration_s: float
    smt2: str
    model: dict[str, str] | None
    explanation: str
    variant: str
    links: list[str]
    verdict: str
    context: dict[str, Any] | None
    scale_mismatch: NotRequired[list[dict[str, Any]]]


class CompositionRecord(TypedDict):
    """``artifacts/calculus/<Node>.json``: the calculus applied to one node."""
    node: str
    rules: list[str]
    producers: list[str]
    side_conditions: list[SideCondition]
    environment_assumptions: list[EnvironmentAssumption]
    instances: list[RuleInstance]
    derived_property: str
    loop_assumption: str | None
    cone_size: int
    cone_environment_assumptions: list[str]
    guarantee: str


class HealthFinding(TypedDict):
    """One contract-health finding (consistency, vacuity, realizability, shape); ``duration_s`` in seconds."""
    id: str
    node: str
    check: str
    guarantee: int | None
    status: str
    message: str
    explanation: str
    model: dict[str, str] | None
    core: list[str] | None
    duration_s: float
    instances: dict[str, str] | None
    witness: NotRequired[dict[str, str]]
    smt2: NotRequired[str]
    witness_smt2: NotRequired[str]


class SourceRef(TypedDict):
    """A place in a file: 1-based line and column."""
    file: str
    line: int
    col: int


class ObligationRecord(TypedDict):
    """One exported obligation (records/records.py ``Obligation``); ``data`` is its backend's."""
    id: str
    node: str
    guarantee: int
    backend: str
    kind: str
    statement: str
    source: SourceRef
    instance: str
    artifact: str
    inputs: list[str]
    data: dict[str, Any]


class DeadlineHop(TypedDict):
    """One timed guarantee on a deadline's path (rule D1); times exact (``within_s``) and as written."""
    node: str
    guarantee: int
    trigger: str
    outputs: list[str]
    within_s: str
    within: str
    loc: str


class DeadlineStamp(TypedDict):
    """One event of the worst path's timeline; ``t_s`` a fraction of seconds as text."""
    event: str
    t_s: str


class DeadlineRecord(TypedDict):
    """One end-to-end deadline decided with Z3 (rule D3; ``artifacts/deadlines/index.json``)."""
    requirement: str
    path: list[str]
    within_s: str
    status: str
    reason: str
    within: str
    chain: list[DeadlineHop]
    total_s: str | None
    total: str | None
    stamps: list[DeadlineStamp]
    worst_path: list[str]
    loc: str
    smt2: str
    inputs: dict[str, str]


class Premise(TypedDict):
    """A premise a requirement's check used (a guarantee, an assumption, a fact, an initial value)."""
    label: str
    kind: str
    node: str
    index: int
    text: str
    source: str


class Traced(TypedDict):
    """A guarantee the plan traces a requirement to."""
    node: str
    guarantee: int


class RequirementRecord(TypedDict):
    """One requirement decided from the composed contracts (``artifacts/requirements/``)."""
    id: str
    text: str
    origin: str
    source: str
    formal: str | None
    assuming: list[str]
    ranking: str | None
    invariant: str | None
    traced: list[Traced]
    verdict: str
    cone: list[str]
    used: list[Premise]
    traced_not_needed: list[Premise]
    fingerprint: str
    inputs: dict[str, str]
    explanation: NotRequired[str]
    reason: NotRequired[str]
    premises: NotRequired[int]
    premises_of: NotRequired[list[str]]
    smt2: NotRequired[str]
    duration_s: NotRequired[float]
    counterexample: NotRequired[list[dict[str, Any]]]
    failed_to_prevent: NotRequired[list[dict[str, Any]]]
    temporal: NotRequired[dict[str, Any]]
    traces: NotRequired[list[dict[str, Any]]]
    consistency: NotRequired[str]
    consistency_reason: NotRequired[str]
    consistency_duration_s: NotRequired[float]
    consistency_smt2: NotRequired[str]
    inconsistent_core: NotRequired[list[Premise]]
    vacuity: NotRequired[str]
    vacuity_core: NotRequired[list[Premise]]
    vacuity_reason: NotRequired[str]
    vacuity_duration_s: NotRequired[float]
    vacuity_smt2: NotRequired[str]


class SecondSolver(TypedDict):
    """The second solver that decided the scripts again (cvc5; docs/second-solver.md)."""
    name: str
    version: str
    rlimit: int


class CrosscheckRow(TypedDict):
    """One discharging item decided again: Z3's verdict, cvc5's answer (``cvc5``) and their agreement."""
    kind: str
    id: str
    smt2: str
    verdict: str
    z3: str
    sha256: str
    key: str
    cvc5: dict[str, Any] | None
    agreement: str
    why: str
    via: NotRequired[str]


class CrosscheckRecord(TypedDict):
    """``artifacts/crosscheck/index.json``; ``solver`` is None when cvc5 is not installed."""
    solver: SecondSolver | None
    counts: dict[str, int]
    items: list[CrosscheckRow]


class DiagnosisEntry(TypedDict):
    """One problem of the report explained (diagnosis/build.py ``diagnose``; docs/diagnosis.md): the
    culprits by source location, the counterexample as a table, the repairs Z3 checked; ``not_offered``
    the repairs Z3 showed do not work (side conditions), ``joins`` and ``lint`` the findings a unit
    mismatch explains, ``passes_through`` and ``consequence_of`` the side conditions and problems a
    refuted requirement rests on, ``requirement`` the requirement of a deadline's record."""
    id: str
    kind: str
    node: str
    status: str
    sentence: str
    culprits: list[dict[str, Any]]
    counterexample: list[dict[str, Any]]
    repairs: list[dict[str, Any]]
    guarantee: int | None
    related: list[str]
    not_offered: NotRequired[list[str]]
    joins: NotRequired[list[str]]
    lint: NotRequired[str]
    passes_through: NotRequired[list[str]]
    consequence_of: NotRequired[list[str]]
    requirement: NotRequired[str]


class DiagnosisRecord(TypedDict):
    """``artifacts/diagnosis/index.json``: the diagnoses of the report dict whose digest is ``report_sha256``
    (stages/diagnoses.py)."""
    report_sha256: str
    diagnoses: list[DiagnosisEntry]


class GroundingFinding(TypedDict):
    """One finding of grounding the contracts in the ROS graph (ros/ground/ground.py ``Finding``)."""
    code: str
    severity: str
    message: str
    node: str | None
    topic: str | None
    rcl: SourceRef | None
    ros: SourceRef | None


class GroundingRecord(TypedDict):
    """``artifacts/ros/grounding.json``: the contracts grounded in the computation graph."""
    findings: list[GroundingFinding]
    counts: dict[str, int]
    graph: dict[str, list[dict[str, Any]]]
    context: dict[str, list[Any]]
    drawing: dict[str, str | None]
    matched: dict[str, str]
    inputs: dict[str, str]


__all__ = ["CheckRecord", "CompositionRecord", "CrosscheckRecord", "DeadlineRecord", "DiagnosisRecord", "GroundingRecord",
           "HealthFinding", "ObligationRecord", "RequirementRecord"]
