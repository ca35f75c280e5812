"""The check and compose stages' sealed records, as types: one TypedDict per record and its parts.

``check`` (app/pipeline.py ``stage_check``) writes :class:`CheckRecord`, the
contracts' warnings; ``compose`` (calculus/compose.py ``composition_json``
with calculus/side_condition.py) writes one :class:`CompositionRecord` per
node: the calculus's rule instances, its side conditions with their Z3
verdicts (:class:`SideCondition`, decided in context: :class:`ContextRecord`)
and the derived property.  As in :mod:`rclverify.records.stage_records`, the
rest of the stages' records: each is the static reading of its JSON record,
key by key, a key a producer writes only in some cases ``NotRequired``;
tests/records/test_stage_records.py checks the case study's records against
them.
"""
# No ``from __future__ import annotations``: Python 3.11 reads ``NotRequired`` only from evaluated
# annotations (with string annotations every key would count as required).
from typing import NotRequired, TypedDict


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


class LocalVerdict(TypedDict):
    """A side condition's local verdict, kept when it is decided again in context."""
    status: str
    variant: str
    model: dict[str, str] | None


class ContextRecord(TypedDict):
    """How a side condition's in-context check went (calculus/side_condition.py ``in_context``):
    the cone's size, the premises and nodes the proof used, the links opened (rule R4), the nodes
    whose assumption the counterexample violates, the joins read, the local verdict, and the
    producers whose cone summaries the proof read."""
    cone: int
    used: list[str]
    used_nodes: list[str]
    opened: list[str]
    violated: list[str]
    joins: list[str]
    local: LocalVerdict
    summaries: NotRequired[list[str]]


class ScaleMismatch(TypedDict):
    """A probable scale mismatch behind a side condition (calculus/scale.py): both ends and their
    ranges (text, ``-oo``/``+oo`` unbounded), the power of ten (0: a named conversion), the factor
    and the sentence."""
    producer: str
    consumer: str
    producer_range: list[str]
    consumer_range: list[str]
    power: int
    factor: str
    message: str


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
    context: ContextRecord | None
    scale_mismatch: NotRequired[list[ScaleMismatch]]


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


__all__ = ["CheckRecord", "CompositionRecord", "ContextRecord", "EnvironmentAssumption", "LintWarning", "LocalVerdict",
           "RuleInstance", "ScaleMismatch", "SideCondition"]
