"""Which ``initially`` declarations a temporal proof needs.

A temporal proof over the composed system uses every premise of its cone
(:mod:`.temporal_check`: an induction has no unsat core), and the roll-up
(:mod:`.rollup`) asks evidence of every declaration a proof uses.  An
``initially( F )`` is a claim about what the node publishes before its first
answer, which a recorded run can show only when the node publishes as it
starts (docs/monitors.md, "Declarations on recorded and live runs"); a node
that publishes nothing until it answers leaves it unshown for ever.

Without its ``initially`` a node is modelled as publishing nothing before its
first answer (docs/semantics.md, "Temporal requirements": its readers have
heard nothing yet).  A real node either does that, or publishes a first
value at start: one satisfying F (the system with the declaration, already
proved) or one violating F (the declaration is false, which the monitors and
the property tests report as a failure of the node whatever the proof uses).
So when the statement is proved both with the declaration and without it,
the requirement does not rest on the declaration: it is "traced, not
needed", like a guarantee outside a formal requirement's unsat core.

The nodes are tried greedily, in the premises' order: first all of them at
once (one more decision in the common case), then one at a time, each kept
out when the proof still holds without it and the ones already out.  The
result is a set the proof does without together, not the largest such set.
"""
from __future__ import annotations

from typing import Any, Callable, Collection, Mapping, Sequence

#: At most this many nodes are tried one at a time (each is one more decision of the statement).
MAX_SINGLE_TRIES = 6


def initially_not_needed(premises: Sequence[Mapping[str, Any]],
                         proved_without: Callable[[Collection[str]], bool]) -> frozenset[str]:
    """The nodes whose ``initially`` declarations the proof does without.

    ``premises``: the proof's premises (``{"kind", "node", ...}``, kind
    ``"initial value"`` for an ``initially`` clause); ``proved_without(nodes)``
    decides the statement again on the system built without the
    ``initially`` of ``nodes`` and says whether it is still proved and
    exercised by some run (an ``inconclusive``, or a proof no run
    exercises, :mod:`.exercised`, is not proved: the declaration then stays
    needed).
    Returns the node names (empty when none can go)."""
    nodes = list(dict.fromkeys(str(p["node"]) for p in premises if p.get("kind") == "initial value"))
    if not nodes:
        return frozenset()
    if proved_without(nodes):
        return frozenset(nodes)
    spare: frozenset[str] = frozenset()
    if len(nodes) == 1:
        return spare
    for n in nodes[:MAX_SINGLE_TRIES]:
        if proved_without(spare | {n}):
            spare = spare | {n}
    return spare
