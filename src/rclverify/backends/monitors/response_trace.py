"""The bounded response pattern on a recorded run.

``always (P -> eventually[<= N] Q)`` and ``always (P -> next Q)`` read step
by step, with the finite-trace verdicts of :mod:`.temporal_trace`: a
trigger not answered in time is ``false`` at the step where the time ran
out; a trigger still pending when the trace ends is ``currently_false`` (a
longer run may answer it); otherwise ``true`` (evidence, not a proof).  A
response undecided at a step may answer every trigger pending there: none
of them is ever ``false`` (the verdict is undecided at that step).
The rule is the composed system's (:mod:`rclverify.calculus.requirements.response`):
a P at step i needs Q at some step i..i+N (``next``: Q at step i+1).
The unbounded ``always (P -> eventually Q)`` is N = infinity: never
``false`` on a finite run, ``currently_false`` while a P waits.
"""
from __future__ import annotations


class ResponseTracker:
    """The obligations of one run.  ``within``: N (``math.inf``: the
    unbounded form), or ``None`` for the next form."""

    def __init__(self, within: float | None) -> None:
        self.within = within
        self.pending: int | None = None  # the step of the oldest trigger not yet answered
        self.before: bool | None = False  # next form: the trigger's value at the step before
        self.longest: int | None = None  # the longest wait (steps) of a trigger answered in time

    def spare(self) -> int | None:
        """The steps to spare: N less the longest wait of an answered trigger
        (``None`` for the next form, the unbounded one, or no trigger answered)."""
        if self.within is None or self.within == float("inf") or self.longest is None:
            return None
        return int(self.within) - self.longest

    def step(self, i: int, p: bool | None, q: bool | None) -> tuple[str, int] | None:
        """Read step ``i`` with the trigger's and the response's truth
        (``None``: undecided there).  Returns ``("false", k)`` when the
        trigger of step ``k`` is not answered in time, ``("undecided", 0)``
        (the trigger) or ``("undecided", 1)`` (the response) when the
        verdict depends on an undecided operand here, else ``None``."""
        if self.within is None:
            before, self.before = self.before, p
            if before is True and q is False:
                return "false", i - 1
            if before is None:
                return "undecided", 0
            return ("undecided", 1) if before is True and q is None else None
        if q is True:
            wait = i - self.pending if self.pending is not None else 0 if p is True else None
            if wait is not None:
                self.longest = wait if self.longest is None else max(self.longest, wait)
            self.pending = None
            return None
        if q is None:  # the response may hold here: what is pending, and a trigger now, may be answered
            self.pending = None
            return "undecided", 1
        if self.pending is None and p is True:
            self.pending = i
        if self.pending is not None and q is False and i - self.pending >= self.within:
            return "false", self.pending
        return ("undecided", 0) if p is None else None
