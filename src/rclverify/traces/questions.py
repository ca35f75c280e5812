"""Which message answers which: the one stream model of every stage that judges messages.

docs/semantics.md states the model; this module is its one implementation
(the offline and live monitors, bags, the enforcement gate and the deadline
checks ask it).  From the paper's stream assumption (lines 1866-1869: a
contract consumes one element of its input stream and produces at most one
element of its output stream) and rule R3's persistence:

* a topic has no value until its first message; after it, its value is its
  latest message (the engines keep the values; this module keeps questions);
* a **question** is a node's inputs as they stand after an input message,
  once every input the node reads has a value (:meth:`QuestionStream.ask`);
* a question followed by another question before any output answered it is
  **superseded**: the node owes an answer to the latest question only.  The
  inputs a ``triggered by`` guarantee answers (``triggers``) are carried to
  the superseding question until an output of that guarantee answers them;
* an output message answers the **latest question at its stamp**
  (:meth:`QuestionStream.at`); a question stamped after the output but
  within the transport skew (:meth:`QuestionStream.within_skew`) may be the
  one it answers too, and the judge must give the same verdict under both
  readings to give one at all (backends/monitors/skew.py);
* the horizon is the time an answer may take, never licence to take a later
  question's answer: a question with no output before it is unanswered.

Everything here is stamps and bookkeeping; nothing evaluates a formula.
Times are seconds on the run's clock (header stamps where the messages have
them).
"""
from __future__ import annotations

import bisect
from typing import Any

from rclverify.traces.events import Event

#: Questions remembered for stamp look-ups (an output stamped before the latest question): at least
#: this many, at most twice as many.
KEPT = 64
#: The empty set a question's rarely used sets start as (never mutated: Question.mark replaces it).
_NO_SET: Any = frozenset()


def kept_after(total: int) -> int:
    """How many questions a stream keeps of ``total``: those it keeps now and those then asked in stamp
    order (:meth:`QuestionStream.ask`: past ``2 * KEPT``, the oldest ``KEPT`` forgotten at a time)."""
    return total if total <= 2 * KEPT else KEPT + 1 + (total - 2 * KEPT - 1) % KEPT


class Question:
    """One question of one node.

    ``event`` the input message that raised it; ``stamp`` its time (s);
    ``inputs`` the inputs as they stood (``in.x`` -> value, every input the
    node reads present); ``triggers`` the inputs whose messages are owed an
    answer by a ``triggered by`` guarantee, each with the first such message
    not answered yet (carried from superseded questions); ``owed`` whether
    the node owes this question an answer at all (its assumption held);
    ``answered`` whether an output message answered it; ``settled`` whether
    it needed no answer (every owed guarantee held on the inputs alone);
    ``reported`` whether its own verdict was given (superseded, or closed
    unanswered: it is then superseded no more);
    ``answer`` the outputs published since it (``out.y`` -> value);
    ``info`` the engine's own data (the arithmetic its assumption held in:
    ``exact``, ``double`` or ``tolerance``).
    """

    __slots__ = ("event", "stamp", "inputs", "triggers", "owed", "answered", "settled", "reported", "answer",
                 "answered_triggers", "passed", "followed", "waiting", "decided", "last_out", "view", "due", "info")

    def __init__(self, event: Event, stamp: float, inputs: dict[str, object], owed: bool = True,
                 info: Any = None) -> None:
        self.event, self.stamp, self.inputs, self.owed, self.info = event, stamp, inputs, owed, info
        #: inputs -> the first message of each not answered yet (``triggered by``), carried when superseded
        self.triggers: dict[str, Event] = {}
        self.answered = self.settled = self.reported = False
        #: another question came within its horizon: what its answer left out is owed to that one now
        self.followed = False
        self.answer: dict[str, object] = {}
        #: triggers an output of their guarantee answered, and those carried on to the next question
        #: (made when first needed: most nodes have no trigger)
        self.answered_triggers: set[str] = _NO_SET
        self.passed: set[str] = _NO_SET
        #: guarantee -> (output event, reason, outputs): a partial answer waiting for another output
        self.waiting: dict[int, tuple[Event, str, dict[str, object]]] = {}
        #: guarantees decided (true or false) on this question so far, and the last output that answered it
        self.decided: set[int] = set()
        self.last_out: Event | None = None
        #: its inputs and answer in one dict, kept up to date as the answer grows (the judge's values)
        self.view: dict[str, object] | None = None
        #: the time (s, the run's clock) its horizon passes
        self.due = float("inf")

    def mark(self, which: str, trigger: str) -> None:
        """Add ``trigger`` to the set ``which`` (``answered_triggers`` or ``passed``)."""
        got = getattr(self, which)
        if got is _NO_SET:
            got = set()
            setattr(self, which, got)
        got.add(trigger)


class QuestionStream:
    """The questions of one node, in stamp order, and which one a message answers.

    ``skew`` (s, >= 0) is the transport skew: how far apart two messages
    may be stamped in the other order than they were published; ``horizon``
    (s) the time an answer may take: a question asked after it passed does
    not supersede the one before (that one is unanswered)."""

    __slots__ = ("skew", "horizon", "latest", "_stamps", "_questions", "superseded", "forgot")

    def __init__(self, skew: float = 0.0, horizon: float = float("inf")) -> None:
        self.skew = skew
        self.horizon = horizon
        self.latest: Question | None = None
        self._stamps: list[float] = []
        self._questions: list[Question] = []
        #: how many questions were superseded (no answer before the next question)
        self.superseded = 0
        #: whether older questions were forgotten (a look-up before the oldest kept cannot be answered)
        self.forgot = False

    def ask(self, q: Question, triggers: frozenset[str] = frozenset()) -> Question | None:
        """Raise question ``q`` (its message set the inputs ``triggers``).

        Returns the question it supersedes (the previous one, owed, not
        answered, and ``q`` asked within its horizon), else ``None``.  Triggers the previous question's outputs
        have not answered are carried to ``q`` (the earliest message of each
        kept), then ``q``'s own are added; a question the node is not owed
        (``q.owed`` false) carries none."""
        prev = self.latest
        superseded = None
        if prev is not None:
            if q.event.time <= prev.event.time + self.horizon:
                prev.followed = True
                if prev.owed and not prev.answered and not prev.settled and not prev.reported:
                    superseded = prev
                    self.superseded += 1
            if q.owed and prev.triggers:
                for t, ev in prev.triggers.items():
                    if t not in prev.answered_triggers:
                        q.triggers.setdefault(t, ev)
                        prev.mark("passed", t)
        if q.owed and triggers:
            for t in triggers:
                q.triggers.setdefault(t, q.event)
        self.latest = q
        stamps, qs = self._stamps, self._questions
        if not stamps or q.stamp >= stamps[-1]:
            stamps.append(q.stamp)
            qs.append(q)
        else:  # stamped before an earlier question: keep the stamp order
            i = bisect.bisect_right(stamps, q.stamp)
            stamps.insert(i, q.stamp)
            qs.insert(i, q)
        if len(stamps) > 2 * KEPT:  # forget the oldest, a batch at a time (amortised O(1))
            del stamps[:KEPT]
            del qs[:KEPT]
            self.forgot = True
        return superseded

    def insert(self, q: Question) -> None:
        """Keep question ``q``, heard after a question stamped later than it, at
        its place in stamp order (after those stamped at or before it): it
        supersedes nothing and is not the latest (an output stamped after the
        later question answers that one); its own triggers are owed to it."""
        i = bisect.bisect_right(self._stamps, q.stamp)
        self._stamps.insert(i, q.stamp)
        self._questions.insert(i, q)

    def after(self, stamp: float) -> list[Question]:
        """The questions kept stamped after ``stamp`` (s), in stamp order."""
        return self._questions[bisect.bisect_right(self._stamps, stamp):]

    def at(self, stamp: float) -> Question | None:
        """The latest question stamped at or before ``stamp`` (s), ``None`` when none is."""
        stamps = self._stamps
        if stamps and stamp >= stamps[-1]:
            return self._questions[-1]
        i = bisect.bisect_right(stamps, stamp)
        return self._questions[i - 1] if i else None

    def within_skew(self, stamp: float, answered: Question | None, reach: float | None = None) -> list[Question]:
        """The questions an output stamped ``stamp`` may answer besides
        ``answered`` (the latest question at its stamp when it came): those
        stamped within the skew after it (within ``reach`` s when given: an
        output published that long after its stamp), or at its stamp but
        asked after it."""
        reach = self.skew if reach is None else reach
        if not reach:
            return []
        qs = self._questions
        i = qs.index(answered) + 1 if answered is not None and answered in qs else \
            bisect.bisect_left(self._stamps, stamp)
        j = bisect.bisect_right(self._stamps, stamp + reach)
        return [q for q in qs[i:j] if q.stamp >= stamp]


__all__ = ["KEPT", "Question", "QuestionStream", "kept_after"]
