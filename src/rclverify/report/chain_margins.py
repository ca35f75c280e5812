"""Time margins of an end-to-end deadline's chain, hop by hop, on the recorded
runs (docs/semantics.md, "Margins", "Time margin of a chain").

Each hop of a chain (:mod:`rclverify.calculus.deadlines`, rule D3) is a timed
guarantee ``triggered by in.x within d`` of one node.  The deadline monitor
(:mod:`rclverify.backends.monitors.deadlines`) measured, on every run of that
node's monitors evidence, the guarantee's smallest time margin: its deadline
less its answer's stamp, in integer nanoseconds
(:class:`rclverify.backends.monitors.time_margins.TimeMargin`).  Here:

* :func:`hop_margin`: a hop's smallest time margin over its node's runs (the
  run, the trigger and the answer it was measured on, how many triggers were
  answered and how many never were);
* :func:`chain_margin`: the chain's measured margin, ``within`` less the sum
  of each hop's worst measured latency ``d_i - m_i``: how much later the
  slowest answer of every hop could have come, all at once, and the chain
  still met its bound.  It is ``None`` unless every hop has a margin (a hop
  no run timed, or one with triggers never answered, has no latency bound).

The latencies are summed as rule D3 sums the deadlines: each hop's worst
case, whether or not they fell on one event's way through the chain, so the
measured margin is never larger than the margin of any one event's
end-to-end latency.
"""
from __future__ import annotations

import math
from fractions import Fraction
from typing import Iterable, Sequence

from rclverify.backends.monitors.payload import TimeMarginItem
from rclverify.records.deadline_rows import DeadlineHop, HopTimeMargin


def hop_margin(guarantee: int, runs: Iterable[tuple[str, Sequence[TimeMarginItem]]]) -> HopTimeMargin | None:
    """The smallest time margin of guarantee ``guarantee`` (1-based) of a
    hop's node over its monitors evidence's runs ``runs`` (each its
    obligation and the time margins of its deadline record, the monitors'
    payload ``deadlines.time_margins``): ``answers`` and ``unanswered``
    summed over the runs, ``margin_s``/``margin_ns`` ``None`` when no
    trigger was answered.  ``None`` when no run measured the guarantee."""
    best: tuple[int | None, str, str, str] | None = None  # margin_ns, obligation, trigger_where, answer_where
    answers = unanswered = 0
    for obligation, margins in runs:
        for t in margins:
            if t.guarantee != guarantee:
                continue
            answers += t.answers
            unanswered += t.unanswered
            ns = t.margin_ns
            if ns is not None and (best is None or best[0] is None or ns < best[0]):
                best = (ns, obligation, t.trigger_where, t.answer_where)
            elif best is None:
                best = (None, obligation, "", "")
    if best is None:
        return None
    ns, obligation, trigger_where, answer_where = best
    return HopTimeMargin(margin_s=None if ns is None else ns / 1e9, margin_ns=ns, obligation=obligation,
                         trigger_where=trigger_where, answer_where=answer_where, answers=answers,
                         unanswered=unanswered)


def chain_margin(within_s: Fraction, chain: Sequence[DeadlineHop]) -> int | None:
    """The chain's measured margin in integer nanoseconds (module
    docstring): ``within_s`` (the requirement's bound, s) less the sum over
    the hops of ``within_s - margin`` (each hop's ``within_s``, an exact
    fraction text, and its ``time_margin``, :func:`hop_margin`); ``None``
    when the chain is empty or a hop has no margin or had a trigger never
    answered."""
    if not chain:
        return None
    spent = Fraction(0)
    for h in chain:
        m = h.time_margin
        if not isinstance(m, HopTimeMargin) or m.margin_ns is None or m.unanswered:
            return None
        spent += Fraction(h.within_s) * 10**9 - m.margin_ns
    return math.floor(within_s * 10**9 - spent)  # rounded down: never more slack than measured


__all__ = ["chain_margin", "hop_margin"]
