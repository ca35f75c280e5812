"""The outcome of one guarantee's Hypothesis run (:func:`.harness.run_guarantee`):
its status and message, the example counts, the counterexample, the
coverage of the inputs and the imports left unhashed (docs/property-tests.md).
"""
from __future__ import annotations

from dataclasses import dataclass, field

from rclverify.backends.shapes import InputCoverage


@dataclass
class Counts:
    """Example counts of one run (shrinking steps included in ``valid``)."""

    drawn: int = 0
    valid: int = 0
    rejected: int = 0
    rejected_by_facts: int = 0
    assumption_unknown: int = 0
    failures: int = 0
    inconclusive: int = 0
    steps: int = 0
    #: conjunct checks that held only in the implementation's double arithmetic (false as exact rationals)
    double: int = 0

    def as_dict(self) -> dict[str, int]:
        out = {"run": self.drawn, "valid": self.valid, "rejected": self.rejected,
               "rejected_by_facts": self.rejected_by_facts,
               "assumption_unknown": self.assumption_unknown, "failures": self.failures,
               "inconclusive": self.inconclusive, "steps_checked": self.steps}
        if self.double:
            out["double"] = self.double
        return out


@dataclass
class Outcome:
    """Result of :func:`run_guarantee`.

    ``status``: ``discharged`` (every valid example passed, none
    inconclusive), ``failed`` (a counterexample, shrunk unless the run asked for the verdict only:
    :attr:`.harness.GuaranteeRun.verdict_only`), ``inconclusive``
    (no failure, but Z3 answered unknown on some example), ``error``
    (health check or configuration).  ``counterexample`` maps ``in.x`` /
    ``out.y`` / ``guarantee`` / ``source`` / ``reason`` to RCL text.
    """

    status: str
    message: str
    counts: Counts
    counterexample: dict[str, str] | None = None
    unknown_reasons: list[str] = field(default_factory=list)
    health: str = ""
    #: per input, how much of the assumption's range the valid examples covered (:mod:`.coverage`)
    coverage: dict[str, InputCoverage] = field(default_factory=dict)
    #: ``file:line: why`` of each import whose code is not hashed (:class:`.closure.Closure`); then no run
    unhashed: list[str] = field(default_factory=list)

