"""One contract-health finding: the record both health modules produce.

:mod:`.checks` (consistency and vacuity) and :mod:`.shape` (what a guarantee
constrains) both make :class:`Finding` records; it lives here, below both,
so neither imports the other's module to get it (docs/decisions.md,
"Layers").  The report and the evidence store read it through
:meth:`Finding.to_json`.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from rclverify.records.stage_records import HealthFinding


@dataclass(frozen=True)
class Finding:
    """One health finding of one node.

    ``id`` is stable (``<Node>.g<k>.<check>`` or ``<Node>.<check>``);
    ``check`` names the check (``contract-consistent``, ``non-vacuous``,
    ``tautology``, ...); ``guarantee`` is 1-based or ``None`` for the whole
    contract; ``status`` is ``ok``, ``problem``, ``warning`` or
    ``inconclusive``; ``model`` is a witness or counterexample in RCL terms,
    ``core`` an unsat core (RCL clauses), ``instances`` per-instance verdicts
    of a quantified premise; ``duration_s`` is the solver's wall-clock time
    in seconds; ``smt2`` the query as SMT-LIB2 text (not compared, not in
    :meth:`to_json`); ``witness`` (realizability ``ok`` only) output name ->
    RCL term answering every admissible input, ``witness_smt2`` the query
    showing it (calculus/health/realizer.py; not compared, not in :meth:`to_json`).
    Checks: calculus/health/checks.py (consistency and vacuity, paper lines 740-768),
    calculus/health/shape.py and calculus/health/realizable.py.
    """

    id: str
    node: str
    check: str
    guarantee: int | None
    status: str
    message: str
    explanation: str
    model: dict[str, str] | None = None
    core: list[str] | None = None
    duration_s: float = 0.0
    instances: dict[str, str] | None = None
    smt2: str = field(default="", compare=False)
    witness: dict[str, str] | None = None
    witness_smt2: str = field(default="", compare=False)

    def to_json(self) -> HealthFinding:
        """The finding as a JSON object (every field but the two scripts;
        ``witness`` only when there is one)."""
        out: HealthFinding = {"id": self.id, "node": self.node, "check": self.check, "guarantee": self.guarantee,
               "status": self.status, "message": self.message, "explanation": self.explanation,
               "model": self.model, "core": self.core, "duration_s": self.duration_s,
               "instances": self.instances}
        if self.witness is not None:
            out["witness"] = self.witness
        return out


__all__ = ["Finding"]
