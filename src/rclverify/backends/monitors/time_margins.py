"""Time margins of timed guarantees on runs: how early each trigger was answered
(docs/semantics.md, "Margins").

The deadline monitor (:mod:`.deadlines`) measures each answer's margin, the
deadline less the answer's stamp in integer nanoseconds, and keeps per
guarantee the smallest (:class:`TimeMargin`, filled by :func:`note`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import MutableMapping


@dataclass
class TimeMargin:
    """The smallest time margin of one timed guarantee over a run's answered triggers.

    ``guarantee`` 1-based; ``margin_ns`` the deadline less the answer's stamp
    (integer ns; negative: late); ``trigger_where``/``answer_where``/``answer``
    (s) the trigger and the answer it was measured on; ``answers`` how many
    triggers were answered (in time or late), ``unanswered`` how many had no
    answer when the run ended (their margin is below ``-(end - due)``, not
    a number: not in the minimum)."""

    guarantee: int
    margin_ns: int = 0
    trigger_where: str = ""
    answer_where: str = ""
    answer: float = 0.0
    answers: int = 0
    unanswered: int = 0

    def to_json(self) -> dict[str, object]:
        """A JSON-ready dict: ``margin`` (s) and ``margin_ns``, ``None`` when no trigger was answered."""
        return {"guarantee": self.guarantee, "margin": self.margin_ns / 1e9 if self.answers else None,
                "margin_ns": self.margin_ns if self.answers else None, "trigger_where": self.trigger_where,
                "answer_where": self.answer_where, "answer": self.answer if self.answers else None,
                "answers": self.answers, "unanswered": self.unanswered}


def note(kept: MutableMapping[int, TimeMargin], k: int, margin_ns: int | None, trigger_where: str,
         answer_where: str, answer: float, was_unanswered: bool = False) -> None:
    """Count guarantee ``k``'s time margin ``margin_ns`` (integer ns) on one
    trigger in ``kept`` (guarantee -> :class:`TimeMargin`): ``None`` when it was
    unanswered as its deadline expired or the run ended; the smallest is kept
    (the first of equals) with the trigger's and the answer's places and the
    answer's stamp ``answer`` (s); ``was_unanswered``: the late answer of a
    trigger counted unanswered when it expired."""
    m = kept.setdefault(k, TimeMargin(k))
    if margin_ns is None:
        m.unanswered += 1
        return
    if was_unanswered:
        m.unanswered -= 1
    if not m.answers or margin_ns < m.margin_ns:
        m.margin_ns, m.trigger_where, m.answer_where, m.answer = margin_ns, trigger_where, answer_where, answer
    m.answers += 1


__all__ = ["TimeMargin", "note"]
