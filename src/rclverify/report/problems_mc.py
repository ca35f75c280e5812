"""Model-checking evidence in the problems by root cause (the rule:
"group only findings that share a culprit proved to cause both").

A property instance that SPIN or AJPF decides (backend ``ajpf``,
docs/model-checking.md) checks the Gwendolen program against one instance
of a guarantee through the mapping of the plan.  Its diagnosis names the
guarantee checked (the *victim*), which is not a culprit proved to cause
the counterexample: a failing instance is as often the program's or the
mapping's timing as the contract's flaw.  So, unlike a property test, such
evidence is never explained by a vacuity or inconsistency of its guarantee
(rule 3 of :mod:`rclverify.report.problems`):

- a failed instance whose diagnosis names a culprit other than its own
  guarantee is grouped under that culprit, as any problem;
- otherwise the failed instances of one guarantee are one row, keyed
  ``model-checking:<Node>:<k>``, whose culprits are the Gwendolen program
  lines the counterexample's trail passes through (the ``lasso`` row of the
  diagnosis' counterexample, :mod:`rclverify.backends.model_checking.trail`);
- an inconclusive instance (partial coverage of the guarantee by the
  mapping, bounds reached) is evidence outstanding, not a failure: the
  inconclusive instances of one guarantee are one row of their own, keyed
  ``outstanding:model-checking:<Node>:<k>``, never members of a failed row.
"""
from __future__ import annotations

import re
from collections.abc import Sequence

from rclverify.records.obligations import ObligationRow
from rclverify.records.problem_rows import DiagnosisRow
from rclverify.records.report_record import AssuranceReport
from rclverify.model.plan.declarations import DECLARATIONS
from rclverify.report.problems_places import Member

#: Backends whose evidence is a model checker's verdict on a property instance.
MC_BACKENDS = tuple(n for n, d in DECLARATIONS.items() if d.evidence_kind == "model checking")
FAILED_PREFIX = "model-checking:"
OUTSTANDING_PREFIX = "outstanding:model-checking:"
_TRAIL = re.compile(r"Gwendolen lines? ([\d, ]+) of (\S+)")


def mc_obligations(report: AssuranceReport) -> dict[str, ObligationRow]:
    """``{obligation id: obligation}`` of the report's model-checking obligations."""
    return {o.id: o for o in report.obligations if o.backend in MC_BACKENDS}


def mc_key(o: ObligationRow, status: str) -> str:
    """The group key of an instance of obligation ``o`` with ``status`` whose
    diagnosis names no culprit but its own guarantee (module docstring)."""
    prefix = OUTSTANDING_PREFIX if status in ("inconclusive", "pending", "stale") else FAILED_PREFIX
    return f"{prefix}{o.node}:{o.guarantee}"


def trail_sources(d: DiagnosisRow | None) -> list[str]:
    """The ``file:line`` of every Gwendolen line the counterexample of
    diagnosis record ``d`` passes through (its ``lasso`` row: "...;
    Gwendolen lines 72, 74 of backends/ajpf/jackal.gwen"), in order; ``[]``
    when it names none."""
    out: list[str] = []
    for row in d.counterexample if d is not None else ():
        if row.variable != "lasso":
            continue
        for m in _TRAIL.finditer(row.value):
            out += [f"{m.group(2)}:{n.strip()}" for n in m.group(1).split(",") if n.strip().isdigit()]
    return list(dict.fromkeys(out))


def checker(sentences: Sequence[str]) -> str:
    """``"SPIN"`` when any of ``sentences`` says SPIN decided it, else ``"AJPF"``."""
    return "SPIN" if any("SPIN" in s for s in sentences) else "AJPF"


def row_sentence(key: str, members: Sequence[Member], first: str, cex: str) -> str:
    """The sentence of a model-checking row ``key`` (module docstring):
    how many instances of which guarantee, the checker, and the first
    member's counterexample ``cex`` (failed) or first sentence ``first``
    (outstanding)."""
    outstanding = key.startswith(OUTSTANDING_PREFIX)
    node, k = key.rsplit(":", 2)[-2:]
    n = len(members)
    what = (f"{n} AJPF/{checker([m.sentence for m in members])} property instance{'s' if n != 1 else ''} "
            f"of guarantee {k} of {node}")
    if outstanding:
        return f"{what} {'are' if n != 1 else 'is'} inconclusive (evidence outstanding): {first}"
    cex = cex.replace("; Gwendolen", " through Gwendolen")  # one sentence (problems.first_sentence)
    return f"{what} fail{'' if n != 1 else 's'}: counterexample {cex or first}"
