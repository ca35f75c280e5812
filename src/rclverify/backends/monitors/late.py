"""An input heard after messages stamped later than it, for the verdict engine (:mod:`.engine`).

docs/semantics.md: an output answers the question in force **at its stamp**
(the latest input stamped at or before it), whatever order the run heard
them in.  A recorded log holds messages in the order its logger got them,
and a live monitor's reorder window (``online.py``) bounds only how late a
message may be to be put in its place; so an input may be heard after an
output stamped after it was judged (a reading stamped 1.2 s
logged after the status stamped 1.5 s, which was judged against the reading
at 1.0 s: "satisfied", a wrong green).  :meth:`Late._late_input` puts the
input at its stamp:

* its question's inputs are those in force at its stamp (the kept question
  before it, with the message's own values), never the values heard since;
  the values in force now are left as the later-stamped messages set them;
* it supersedes nothing stamped after it and is not the latest question
  when one stamped after it was heard (:meth:`QuestionStream.insert`);
* the outputs already judged (the 64 the engine remembers) stamped after it
  and before the next question are **its answer**: judged again against it,
  a ``violated`` (or ``inconclusive``) verdict follows where it is false (or
  undecided), named as the question heard late; one counted ``unasked`` (no
  question at its stamp when judged: before a late first question) gets its
  verdict then, ``satisfied`` too, and leaves the ``unasked`` count;
* a later question whose inputs lacked this message's values (it changes an
  input that question read, before the next message of its topic) takes
  them, and the outputs judged against it are judged again on them (a
  ``violated`` follows where false; ``inconclusive`` where the assumption
  no longer holds of them, or undecided);
* before the first question (every input not yet given a value), the
  messages counted ``incomplete input`` are kept (:attr:`NodeMonitor._in_force`,
  the last 64 per input): a message heard late finds the values in force at
  its stamp there, and those stamped after it that it completes raise their
  questions, in stamp order (:meth:`Late._completed`), the ``incomplete
  input`` given to each when heard withdrawn (:meth:`Late._incomplete_withdrawn`);
* equal stamps keep the order heard: an output stamped with a question and
  heard before it does not answer it;
* its horizon runs from its stamp (live, a late message's time is the clock);
* what cannot be placed (the question in force at its stamp forgotten, or
  more outputs after it than the engine remembers) is ``inconclusive`` with
  the reason, never judged against the wrong question.

A verdict given against the wrong question is **withdrawn** by its
revision (:meth:`Late._withdrawn`): the revision's verdict replaces it in
the counts, the violation records and the semantics counted, and its reason
says which it replaces; an output right for the question heard late is
``satisfied`` in place of a ``violated`` or ``inconclusive`` given against
the one before.  So the run's verdicts are those of the run judged in stamp
order, whatever order it was heard in (docs/semantics.md, "Event time");
the verdicts published before stay published, each followed by the one that
replaces it (a consumer keeps the latest verdict of each node's message).
A verdict the engine no longer holds (the last 256 given) or never gave
one by one (an answer counted in a batch, :mod:`.batch`) is not withdrawn:
the revision follows it.  Every input message pays one comparison (its
stamp against the latest stamp judged) for this; the rest runs only for a
message heard late.
"""
from __future__ import annotations

import bisect
from typing import Any, Callable

from rclverify.traces.events import Event
from rclverify.traces.questions import Question
from rclverify.backends.monitors.engine_state import EngineState
from rclverify.backends.monitors.verdicts import Verdict


class Late(EngineState):
    """The late-input part of :class:`~.engine.NodeMonitor` (module docstring)."""

    #: live (set by :mod:`.online`): whether every writer of the node's outputs has been heard past a time
    #: (s, the run's clock); a ``superseded`` given before is provisional, and an output heard later whose
    #: stamp pairs it with that question withdraws it (docs/semantics.md, "Provisional verdicts").
    #: ``None`` offline: the run is read whole, every writer heard.
    answers_heard_past: Callable[[float], bool] | None = None

    def _superseded_early(self, qe: Event, at: float) -> bool:
        """Whether the ``superseded`` about to be given to the question raised by ``qe``, placed at
        ``at`` (s, the run's clock), is given early: a writer of the node's outputs not yet heard past
        ``at`` (:attr:`answers_heard_past`), so an answer stamped at it may still come.  Such a
        question is kept (its event index, the last 1024) for :meth:`_answers_superseded` to withdraw
        the verdict; the verdict goes out ``provisional``."""
        if self.answers_heard_past is None or self.answers_heard_past(at):
            return False
        kept = self._early_superseded
        if len(kept) >= 1024:
            del kept[next(iter(kept))]  # the oldest: long superseded, its question forgotten
        kept[qe.index] = None
        return True

    def _late_input(self, ev: Event, trig: frozenset[str], stamp: float) -> None:
        """Input ``ev`` (it set the inputs ``trig``), stamped ``stamp`` (s), heard after a
        message of the node stamped later: raised at its stamp (module docstring)."""
        stream, values = self.stream, self.values
        mine = {k: values[k] for k in trig}
        if ev.late:  # later than the bound: its own question, and those it is retold to, decide no violation
            self._late_asked(ev, ev)
        # an unreadable message stamped after it is still the one in force: what reads it after is undecided
        unread = {k: u[1] for k in trig for u in (self._unread.get(k),) if u is not None and u[0] > stamp}
        kept = stream._questions
        last = kept[-1] if kept else None
        first = stream._stamps[0] if kept else float("inf")
        hist = self._in_force
        if stamp < first:  # before the first question: kept with the messages counted incomplete
            for k in trig:
                hist.setdefault(k, []).append((stamp, mine[k], ev))
        tainted, reset = self._tainted(ev, stamp, mine)
        if ev.late:  # the questions asked before it was heard read it: they decide no violation
            for qa in tainted:
                if qa.stamp < stamp + ev.late:
                    self._late_asked(qa.event, ev)
        for k in trig:  # the values in force now: a message stamped after it may have set them
            if last is not None and reset:
                values[k] = last.inputs.get(k)
            elif last is None:
                values[k] = value_at(hist.get(k, ()), float("inf"))
        before = stream.at(stamp)
        if before is None and stream.forgot:
            self._verdict("inconclusive", ev, reason=f"the input at {ev.where}, stamped {stamp:.9g} s, was heard "
                          "after messages stamped later, and the questions before its stamp are no longer kept: "
                          "it cannot be put in its place, and the outputs after it were judged without it")
            self.invalid.update(unread)
            return
        inputs = dict(before.inputs) if before is not None else self._inputs_at(stamp)
        inputs.update({k: v for k, v in mine.items() if v is not None})
        missing = [k for k in self.needed_inputs if k not in inputs]
        completed = self._completed(stamp, first) if stamp < first else []
        upto = completed[0][:2] if completed else None
        if missing:
            self._verdict("incomplete input", ev, reason="no value yet for " + ", ".join(missing) +
                          " at its stamp (heard after messages stamped later)")
            self._revise_tainted(ev, stamp, None, tainted, upto)
        else:
            self._place(ev, stamp, inputs, trig, tainted, upto)
        for j, (t, e, got, kinds) in enumerate(completed):  # each before the next is put (what it answers)
            self._incomplete_withdrawn(e, ev)
            self._place(e, t, got, kinds, [], completed[j + 1][:2] if j + 1 < len(completed) else None)
        self.invalid.update(unread)

    def _incomplete_withdrawn(self, e: Event, by: Event) -> None:
        """Message ``e``, counted ``incomplete input`` when heard, has every input at its stamp now that
        ``by``, stamped before it, was heard late: that verdict is withdrawn (out of the counts, a
        :data:`WITHDRAWN` verdict on ``e`` follows it), so ``e`` keeps only what its question gives, as
        in the run read in stamp order, where it was never incomplete (docs/semantics.md, "Event time")."""
        given = self._given
        i = self._last_given(e.index)
        if i is None or given[i][1] != "incomplete input":
            return
        del given[i]
        self.result.counts["incomplete input"] -= 1
        if self.on_verdict is not None:
            self.on_verdict(Verdict(
                self.node.name, WITHDRAWN, e.index, e.time, e.where, e.topic, max(self.now, by.time),
                reason=f"the input at {by.where}, heard after it but stamped before it, gives every input a value "
                       "at its stamp: the incomplete input verdict given when it was heard is withdrawn"))

    def _inputs_at(self, stamp: float) -> dict[str, object]:
        """Before the first question: the inputs as the messages stamped at or before ``stamp`` set them."""
        got = {k: value_at(h, stamp) for k, h in self._in_force.items()}
        return {k: v for k, v in got.items() if v is not None}

    def _place(self, ev: Event, stamp: float, inputs: dict[str, object], trig: frozenset[str],
               tainted: list[Question], upto: tuple[float, Event] | None = None) -> None:
        """The question ``ev`` raises at ``stamp`` with ``inputs`` (those in force at its
        stamp): the latest when none is stamped after it, else kept at its place; the
        outputs judged since that it is the question of are judged again against it
        (those before ``upto``, the next question yet to be put, when given)."""
        stream = self.stream
        owed, accepted, refusal = self._accept(ev, inputs)
        q = Question(ev, stamp, inputs, owed, accepted)
        prev, nxt = stream.at(stamp), stream.after(stamp)
        if not nxt:
            self._raise(ev, q, trig, refusal)
            if self._open is q:  # its horizon runs from its stamp, however late it was heard (live: the clock)
                q.due = self._due = stamp + self.horizon
            self._revise_tainted(ev, stamp, q, tainted, upto)
            return
        stream.insert(q)
        if owed and self._triggers:
            for t in trig & self._triggers:
                q.triggers.setdefault(t, ev)
        if refusal:
            self._verdict("inconclusive", ev, reason=refusal)
        self._revise_tainted(ev, stamp, q, tainted, upto)  # an unowed q is no output's answer: only the tainted
        if not owed:
            return
        self.result.accepted += 1
        # in stamp order it would carry what the question before it left unanswered: owed then, else maybe nothing
        if not (prev is not None and any(t not in prev.answered_triggers for t in prev.triggers)) and self._unowed(q):
            return
        q.reported = True  # only the latest question is watched for its horizon
        if not q.answered and not q.settled:
            gap = nxt[0].stamp - stamp
            if gap > self.horizon:
                self._verdict("inconclusive", ev, reason=f"heard after messages stamped later; the question at "
                              f"{nxt[0].event.where} came {gap:.9g} s after it, before any output answered it and "
                              f"after its horizon of {self.horizon} s")
                return
            self._verdict("superseded", ev, reason=f"heard after messages stamped later; the question at "
                          f"{nxt[0].event.where} came {gap:.9g} s after it, before any output answered it",
                          provisional=self._superseded_early(ev, stamp))

    def _completed(self, stamp: float, first: float) -> list[tuple[float, Event, dict[str, object], frozenset[str]]]:
        """A message stamped ``stamp``, before the first question (stamped ``first``),
        was heard late.  The messages stamped after it and before that question,
        counted ``incomplete input`` when heard, may have every input at their
        stamps now: each raises the question it would have raised in stamp order.
        Returns them in stamp order: (stamp, event, inputs, the inputs it set); the
        outputs judged since stamped after each are judged against it (they were
        ``unasked``) when it is put (:meth:`_place`)."""
        later: dict[int, tuple[float, Event]] = {}
        for h in self._in_force.values():
            for t, _, e in h:
                if stamp < t < first:
                    later[id(e)] = (t, e)
        out: list[tuple[float, Event, dict[str, object], frozenset[str]]] = []
        for t, e in sorted(later.values(), key=lambda x: (x[0], x[1].index)):
            inputs = self._inputs_at(t)
            if all(k in inputs for k in self.needed_inputs):
                out.append((t, e, inputs, frozenset(k for k, h in self._in_force.items() if any(x[2] is e for x in h))))
        return out

    def _tainted(self, ev: Event, stamp: float, mine: dict[str, object]) -> tuple[list[Question], bool]:
        """The kept questions stamped after ``stamp`` that read an input ``ev`` changes
        (before the next message of ``ev``'s topic): they were raised without it (their
        inputs now take its values); and whether a question of ``ev``'s topic stamped
        after it was heard (its values are then not in force now)."""
        out: list[Question] = []
        self._lost: set[int] = set()  # the questions owed an answer on the inputs they had, and no more
        hist = self._in_force  # a message of it counted incomplete, stamped after it, set it again
        again = min((e[0] for k in mine for e in hist.get(k, ()) if e[0] > stamp), default=float("inf"))
        for q in self.stream.after(stamp):
            if q.event.topic == ev.topic or q.stamp >= again:
                return out, True
            if any(q.inputs.get(k) != v for k, v in mine.items() if v is not None):
                out.append(q)
                q.inputs.update({k: v for k, v in mine.items() if v is not None})  # what later outputs are judged on
                q.view = None if not q.answer else {**q.inputs, **q.answer}
                owed = all(self._judge(aj, q.inputs).truth is True for aj, _ in self._assumed)
                if q.owed and not owed:
                    self._lost.add(id(q))
                q.owed = owed  # owed or not on the inputs in force at its stamp (its verdict given stays)
        return out, again < float("inf")

    def _revise_tainted(self, ev: Event, stamp: float, q: Question | None, tainted: list[Question],
                        upto: tuple[float, Event] | None = None) -> None:
        """The outputs already judged stamped after ``stamp`` (and before ``upto``, the
        next question yet to be put: its stamp and event): those whose question at their
        stamp is now ``q`` are judged against it, those of a ``tainted`` question on the
        inputs it has now (:meth:`_retold`); outputs held for the skew take the question
        at their stamp."""
        recent = self._recent
        if len(recent) == recent.maxlen and recent[0][1] > stamp:
            self._verdict("inconclusive", ev, reason=f"the input at {ev.where} was heard after more outputs stamped "
                          f"after it than the monitor keeps ({recent.maxlen}): the oldest of them were judged "
                          "without it, and their verdicts cannot be revised")
        judged = [r for r in recent if r[1] >= stamp] + [r for r in self._released if r[1] >= stamp]
        judged.sort(key=lambda r: r[0].index)  # in the order heard
        for r in judged:
            out_ev, stamped, outs, state = r
            if stamped == stamp and out_ev.index < ev.index:
                continue  # stamped with it but heard before it: no answer to it (equal stamps in the run's order)
            if upto is not None and (stamped > upto[0] or (stamped == upto[0] and out_ev.index > upto[1].index)):
                continue
            qa = self._in_force_at(stamped, out_ev)
            if q is not None and qa is q:
                self._answers_late(ev, q, out_ev, outs, state)
            elif qa is not None and qa in tainted:
                self._retold(ev, qa, out_ev, outs, state)
        for j, h in enumerate(self._held):  # outputs held for the skew: judged against the question at their stamp
            qa, outs = self._in_force_at(h[1], h[0]), h[3]
            if qa is None or (qa is h[2] and qa not in tainted):
                continue
            if qa is q and qa is not h[2]:  # its answer now: the output's own values, not the old question's answer
                own = {k: outs[k] for k in self._topic_io[h[0].topic][1] if k in outs}
                q.answered, q.last_out = True, h[0]
                q.answer.update(own)
                q.view = {**q.inputs, **q.answer}
                outs = dict(q.answer)
            self._held[j] = (h[0], h[1], qa, outs, h[4], h[5],
                             self._question_outcome(qa, h[0], self._touch[h[0].topic][0], outs, h[4], False))

    def _in_force_at(self, stamp: float, out_ev: Event) -> Question | None:
        """The question output ``out_ev``, stamped ``stamp``, answers: the latest stamped at
        or before it, but not one stamped at the same time and heard after it (equal
        stamps are ordered by the run: docs/semantics.md)."""
        stamps, qs = self.stream._stamps, self.stream._questions
        i = bisect.bisect_right(stamps, stamp)
        while i and stamps[i - 1] == stamp and qs[i - 1] is not None and qs[i - 1].event.index > out_ev.index:
            i -= 1
        return qs[i - 1] if i else None

    def _retold(self, ev: Event, qa: Question, out_ev: Event, outs: dict[str, object], state: Any) -> None:
        """Output ``out_ev`` was judged against ``qa``, whose inputs lacked ``ev``'s
        values (now set): judged again on them where the assumption still holds
        of them, else ``inconclusive`` (the verdict given was on other inputs)."""
        why = (f"; the input at {ev.where}, heard after it but stamped before the question at {qa.event.where}, "
               "changes an input that question reads: the log's order is not the stamps'")
        if not qa.owed:
            if id(qa) in self._lost:  # owed when it was judged; with the input heard late the assumption fails
                self._verdict("inconclusive", out_ev, reason=f"the output at {out_ev.where} was judged against the "
                              f"question at {qa.event.where} without the input at {ev.where}; with it the assumption "
                              "does not hold (false or undecided)" + why + self._withdrawn(out_ev),
                              question=qa.event.where)
            return
        got = self._question_outcome(qa, out_ev, self._touch[out_ev.topic][0], outs, dict(state or {}), False)
        self._late_verdict(out_ev, qa.event, got, why)

    def _answers_late(self, ev: Event, q: Question, out_ev: Event, outs: dict[str, object], state: Any) -> None:
        """Output ``out_ev`` (judged before ``ev`` was heard) answers ``q``, ``ev``'s question:
        judged again against it; a false or undecided reading is a verdict of its own."""
        if not q.owed:
            return
        unasked = out_ev.index in self._unasked  # no question when it was judged: this is its first verdict
        if unasked:
            self._unasked.remove(out_ev.index)
            self.result.unasked -= 1
        q.answered = True
        q.last_out = out_ev
        q.answer.update(outs)
        q.view = {**q.inputs, **q.answer}
        got = self._question_outcome(q, out_ev, self._touch[out_ev.topic][0], q.answer, dict(state or {}))
        why = (f"; the question in force at its stamp is the one at {ev.where}, heard after it but stamped before it "
               f"({q.stamp:.9g} s against {out_ev.stamped:.9g} s): the log's order is not the stamps'")
        self._late_verdict(out_ev, ev, got, why, unasked)

    def _late_verdict(self, out_ev: Event, qe: Event, got: Any, why: str, unasked: bool = False) -> None:
        """The verdict that replaces the one given to ``out_ev`` (:meth:`_withdrawn`): judged
        again against the question raised by ``qe``, false (``violated``), undecided
        (``inconclusive``) or true (``satisfied``, where the one given was not, or where none was:
        ``unasked``, no question at its stamp when it was judged, as before a late first trigger)."""
        if got.kind == "violated":
            k = got.guarantee
            self._violation(out_ev, k, got.values, f"guarantee {k} is false on the output at {out_ev.where} answering "
                            f"the question at {qe.where}" + (f": {got.reason}" if got.reason else "") + why
                            + self._withdrawn(out_ev), got.semantics, qe)
        elif got.kind == "inconclusive":
            self._verdict("inconclusive", out_ev, guarantee=got.guarantee,
                          reason=got.reason + why + self._withdrawn(out_ev), question=qe.where)
        elif got.kind == "satisfied" and (unasked or (
                (given := self._given_to(out_ev)) is not None and given[1] != "satisfied")):
            self._verdict("satisfied", out_ev, semantics=got.semantics, question=qe.where,
                          reason=f"the output at {out_ev.where} answers the question at {qe.where}" + why
                          + self._withdrawn(out_ev))

    def _given_to(self, out_ev: Event) -> tuple[int, str, str] | None:
        """Where in ``_given`` the verdict last given to ``out_ev`` is, its kind and semantics, when a
        revision may withdraw it (``None``: none held)."""
        given = self._given
        i = self._last_given(out_ev.index)
        return None if i is None or given[i][1] not in _REVISABLE else (i, given[i][1], given[i][2])

    def _last_given(self, index: int) -> int | None:
        """Where in ``_given`` the verdict last given to event ``index`` is (``None``: none held)."""
        given = self._given
        return next((i for i in range(len(given) - 1, -1, -1) if given[i][0] == index), None)

    def _withdrawn(self, out_ev: Event) -> str:
        """Withdraw the verdict last given to ``out_ev`` (module docstring), just
        before its replacement is given: its count, its semantics' count and its
        violation record go.  Returns the words the replacement's reason ends with
        (``""`` when no verdict is held to withdraw)."""
        got = self._given_to(out_ev)
        if got is None:
            return ""
        i, kind, sem = got
        del self._given[i]
        res = self.result
        res.counts[kind] -= 1
        if kind == "satisfied" and sem in res.semantics:
            res.semantics[sem] -= 1
        elif kind == "violated":
            res.withdraw_violation(out_ev.index)
        elif kind == "inconclusive" and not res.counts[kind]:
            res.first_inconclusive = None
        return f"; this verdict replaces the {kind} one given before (withdrawn)"

    def _answers_superseded(self, q: Question, out_ev: Event) -> None:
        """Output ``out_ev`` answers ``q`` by its stamp, heard after the question that
        superseded ``q``; when ``q``'s ``superseded`` was given early (before every
        writer of the node's outputs had been heard past it: :attr:`~.engine.NodeMonitor.answers_heard_past`),
        it is withdrawn: out of the counts, and a :data:`WITHDRAWN` verdict on ``q``'s
        message follows it, leaving ``q`` no verdict of its own, as the run read in
        stamp order gives an answered question none (docs/semantics.md,
        "Provisional verdicts").  A ``superseded`` given once every writer was heard
        past ``q`` stands."""
        qe = q.event
        if qe.index not in self._early_superseded:
            return
        del self._early_superseded[qe.index]
        self.result.counts["superseded"] -= 1
        self.stream.superseded -= 1
        if self.on_verdict is not None:
            self.on_verdict(Verdict(
                self.node.name, WITHDRAWN, qe.index, qe.time, qe.where, qe.topic, max(self.now, out_ev.time),
                reason=f"the output at {out_ev.where}, heard after the question that superseded the one raised at "
                       f"{qe.where}, answers that one by its header stamp: the superseded verdict given before the "
                       "output's writer was heard past the question is withdrawn (an answered question has no "
                       "verdict of its own)"))


#: the verdicts of an output a revision replaces
_REVISABLE = frozenset({"satisfied", "violated", "inconclusive"})
#: the verdict of a revision that withdraws the one given before and leaves the message without one (a
#: ``superseded`` given early whose question an answer heard late pairs with: :meth:`Late._answers_superseded`)
WITHDRAWN = "withdrawn"


def value_at(entries: Any, stamp: float) -> Any:
    """The value of the entry ``(stamp, value, ...)`` stamped latest at or before ``stamp`` (``None``: none):
    the value an input had at ``stamp`` (its messages' stamps and values, in any order), for the verdict
    engine and the deadline monitor alike."""
    best = None
    for e in entries:
        if e[0] <= stamp and (best is None or e[0] >= best[0]):
            best = e
    return None if best is None else best[1]


__all__ = ["WITHDRAWN", "Late", "value_at"]
