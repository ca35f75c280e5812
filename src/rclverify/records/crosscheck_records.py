"""The second solver's sealed record, as types: ``artifacts/crosscheck/index.json``.

stages/crosscheck/stage.py writes :class:`CrosscheckRecord`: the second
solver (:class:`SecondSolver`, cvc5; docs/second-solver.md), and for each
discharging item Z3's verdict, cvc5's answer (:class:`Cvc5Answer`) and their
agreement (:class:`CrosscheckRow`).  As in
:mod:`rclverify.records.stage_records`: the static reading of the JSON
record, key by key, a key written only in some cases ``NotRequired``;
tests/records/test_stage_records.py checks the case study's record against it.
"""
# No ``from __future__ import annotations``: Python 3.11 reads ``NotRequired`` only from evaluated
# annotations (with string annotations every key would count as required).
from typing import NotRequired, TypedDict


class SecondSolver(TypedDict):
    """The second solver that decided the scripts again (cvc5; docs/second-solver.md)."""
    name: str
    version: str
    rlimit: int


class Cvc5Answer(TypedDict):
    """cvc5's answer to one script (stages/crosscheck/cvc5_decide.py ``Decision.row``): ``sat``/``unsat``/
    ``unknown``/``error``, the reason, whether its proof checked, its version, the time in seconds, and the
    proof's path (``""`` without one)."""
    answer: str
    reason: str
    proof_checked: bool
    version: str
    duration_s: float
    proof: str


class CrosscheckRow(TypedDict):
    """One discharging item decided again: Z3's verdict, cvc5's answer (``cvc5``) and their agreement."""
    kind: str
    id: str
    smt2: str
    verdict: str
    z3: str
    sha256: str
    key: str
    cvc5: Cvc5Answer | None
    agreement: str
    why: str
    via: NotRequired[str]


class CrosscheckRecord(TypedDict):
    """``artifacts/crosscheck/index.json``; ``solver`` is None when cvc5 is not installed."""
    solver: SecondSolver | None
    counts: dict[str, int]
    items: list[CrosscheckRow]


__all__ = ["CrosscheckRecord", "CrosscheckRow", "Cvc5Answer", "SecondSolver"]
