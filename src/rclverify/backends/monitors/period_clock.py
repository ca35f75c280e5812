"""Periods kept in simulated time (docs/semantics.md, "Deadlines in simulated time"; :mod:`.periods`).

A node under ``use_sim_time`` refreshes ``periodic( out.y, P )`` at least once
per ``P`` of its own clock, the value of the last ``/clock`` message it
received.  A message of ``out.y`` published at ``t`` on the run's clock was
published, in the node's clock, at ``/clock``'s value at ``t - delta`` for some
delivery delay ``delta`` of ``/clock`` to the node within the transport skew
(:class:`~rclverify.traces.sim_clock.SimClock`).  So a gap between publications
at ``t1`` and ``t2`` lies, in simulated time, between the least
``clock(t2 - skew) - clock(t1)`` and the most ``clock(t2) - clock(t1 - skew)``
(:func:`sim_gap`), and against the period (:func:`judge_gap`) it is late when
the least is over it, in time when the most is not, else undecided.  A node whose
clock is not said, on a run whose ``/clock`` has been heard, is judged in both
clocks: late only when late in both, in time only when in time in both.  The
run's end after the last message is such a gap too (its tail), and so is the
tail of an output stamped in the simulated clock, from its last stamp.
"""
from __future__ import annotations

from rclverify.traces.sim_clock import SimClock

#: a gap's verdict against its period (:func:`judge_gap`)
LATE, IN_TIME, UNDECIDED = "late", "in time", "undecided"


def read_at(sim: SimClock, t_ns: int, skew_ns: int) -> tuple[int | None, int | None]:
    """``(most, least)``: ``/clock`` at ``t_ns`` (the run's clock) as a node reads it with a delivery delay in
    ``[0, skew_ns]`` (``None``: not known)."""
    return sim.at(t_ns), sim.at(t_ns - skew_ns)


def sim_gap(first: tuple[int | None, int | None], sim: SimClock, t2_ns: int, skew_ns: int) -> \
        tuple[int, int] | None:
    """``(least, most)`` simulated ns from a publication read ``first`` (:func:`read_at`, or its own stamp in
    that clock twice) to one at ``t2_ns`` (integer ns, the run's clock) read from ``/clock`` with a delivery
    delay in ``[0, skew_ns]``; ``None`` when ``/clock`` does not say (no sample before one of them, or
    broken)."""
    hi1, lo1 = first
    hi2, lo2 = read_at(sim, t2_ns, skew_ns)
    if hi2 is None or lo2 is None or hi1 is None or lo1 is None:
        return None
    return lo2 - hi1, hi2 - lo1


def judge_gap(gap: tuple[int, int] | None, wall_ns: int | None, period_ns: int, sim_mode: bool | None) -> str:
    """A gap against its period: :data:`LATE`, :data:`IN_TIME` or :data:`UNDECIDED`.  ``gap`` in simulated
    time (:func:`sim_gap`; ``None``: not known), ``wall_ns`` on the run's clock (``None``: not judged there),
    ``sim_mode`` the node's clock (``True`` simulated time only; ``None`` not said: both)."""
    if gap is None:
        return UNDECIDED
    least, most = gap
    sim = LATE if least > period_ns else IN_TIME if most <= period_ns else UNDECIDED
    if sim_mode is True or wall_ns is None:
        return sim
    wall = LATE if wall_ns > period_ns else IN_TIME
    return sim if sim == wall else UNDECIDED


__all__ = ["IN_TIME", "LATE", "UNDECIDED", "judge_gap", "read_at", "sim_gap"]
