"""One output message's outcome, and how the readings of an ambiguous one combine.

An output message is judged against the question it answers and on its own
(guarantees over outputs only); within the transport skew it may answer
more than one question (docs/semantics.md, "Transport skew").  Each reading
gives an :class:`Outcome`; :func:`combine` gives the message's verdict: a
verdict is given only where every reading agrees, never ``satisfied`` where
one reading finds the output false (no wrong green), never
``violated`` where one reading finds it right (no false alarm).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

from rclverify.traces.events import Event
from rclverify.traces.questions import Question

#: What one reading found: ``violated`` (a guarantee false), ``inconclusive``
#: (undecided), ``satisfied`` (every guarantee it decided true), ``none``
#: (nothing owed was decided), ``unasked`` (no question to answer).
KINDS = ("violated", "inconclusive", "satisfied", "none", "unasked")


@dataclass(frozen=True)
class Outcome:
    """One reading's outcome: ``kind`` one of :data:`KINDS`; ``guarantee``
    the 1-based guarantee that was false or undecided; ``semantics`` the
    arithmetic that decided; ``values`` the values it was judged on (a
    violation's); ``reason`` why it is undecided."""

    kind: str
    guarantee: int = 0
    semantics: str = ""
    values: dict[str, object] = field(default_factory=dict)
    reason: str = ""


def combine(alone: Outcome, readings: Sequence[Outcome]) -> Outcome:
    """The message's outcome from its output-only guarantees (``alone``) and
    the readings of the question(s) it may answer (``readings``, the latest
    question at its stamp first).

    Readings: all ``violated`` -> the first's violation; any ``violated`` or
    ``inconclusive`` otherwise -> ``inconclusive`` (reason ``""`` where the
    readings disagree: the caller names the skew); else ``satisfied`` if one
    is; else ``none``.  Then ``alone`` and that: the worse of the two, in
    the order violated, inconclusive, satisfied, none."""
    kinds = [("none" if r.kind == "unasked" else r.kind) for r in readings]
    if not readings:
        asked = Outcome("none")
    elif len(readings) == 1:
        asked = readings[0] if kinds[0] != "none" else Outcome("none")
    elif all(k == "violated" for k in kinds):
        asked = readings[0]
    elif "violated" in kinds or "inconclusive" in kinds:
        undecided = [r for r in readings if r.kind == "inconclusive"]
        disagree = "violated" in kinds
        asked = Outcome("inconclusive", undecided[0].guarantee if undecided else 0,
                        reason="" if disagree or not undecided else undecided[0].reason)
    elif "satisfied" in kinds:
        asked = next(r for r in readings if r.kind == "satisfied")
    else:
        asked = Outcome("none")
    for kind in ("violated", "inconclusive", "satisfied"):
        if asked.kind == kind:
            return asked
        if alone.kind == kind:
            return alone
    return Outcome("none")


def skew_reason(ev: Event, q: Question | None, others: Sequence[Question], skew: float) -> str:
    """The sentence of an output whose readings disagree: it was stamped within
    the skew before the question(s) ``others`` and may answer them or ``q``."""
    later = others[0]
    gap = max(later.stamp - ev.stamped, 0.0) * 1000
    first = f"the question at {q.event.where}" if q is not None else "no question (none was asked before it)"
    return (f"the output at {ev.where} was stamped {gap:.2f} ms before the question at {later.event.where}, "
            f"within the transport skew of {skew:g} s: it answers either that question or {first}, and the two "
            "readings give different verdicts, which the monitor cannot tell apart (docs/semantics.md, "
            "\"Transport skew\")")


__all__ = ["KINDS", "Outcome", "combine", "skew_reason"]
