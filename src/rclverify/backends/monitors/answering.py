"""How the verdict engine (:mod:`.engine`) judges an output message: the question it answers, held or not.

An output message answers the latest question at its stamp (its header
stamp, else its event time: docs/semantics.md, "Answers"); the guarantees
that read an input are judged on that question's inputs and the outputs
published since it, those over outputs only on the outputs as they stand.
:meth:`Answering._output` judges it at once (the common case of one
guarantee inline) or holds it: false for the question at its stamp, or
published well after its stamp, it may answer a question within the
transport skew (or until it was published) after it that gets no answer
of its own (docs/semantics.md, "Transport skew", "Event time").
:meth:`Answering._release` judges the held outputs once those questions
are settled, and :meth:`Answering._decide` gives one output's verdict from
every reading still possible (:func:`.outcome.combine`).
"""
from __future__ import annotations

from typing import Mapping

from rclverify.traces.events import Event
from rclverify.traces.questions import Question
from rclverify.backends.monitors.closing import Closing
from rclverify.backends.monitors.engine_contract import ContractReading
from rclverify.backends.monitors.judging import Judging
from rclverify.backends.monitors.late import Late
from rclverify.backends.monitors.outcome import Outcome, combine, skew_reason
from rclverify.backends.monitors.verdicts import Verdict, in_all

_NONE = Outcome("none")
_EMPTY: Mapping[str, object] = {}


class Answering(ContractReading, Judging, Closing, Late):
    """The output part of :class:`~.engine.NodeMonitor` (module docstring)."""

    # set by :class:`~.engine.NodeMonitor` (``_start_stream``): the latest stamp (s) judged, and each held
    # output's message margin (event index -> margin) with margins
    _hi: float
    _held_margins: dict[int, float | None]

    def _output(self, ev: Event, changed: list[str]) -> None:
        values = self.values
        asked, alone = self._touch[ev.topic]
        if not self.has_inputs:
            self._decide(ev, None, [], self._alone_outcome(ev, alone), {})
            return
        states = self._state_set
        mine = {k: values[k] for k in changed if values[k] is not None and k not in states}
        stamped = ev.time if ev.stamp is None else ev.stamp
        q = self.stream.at(stamped)
        if q is not None:
            if ev.time <= q.due or self._at_due(ev.time, q.due):  # an output after the horizon is judged, but is no part of the question's answer
                if q.reported and not q.answered and self._early_superseded:
                    self._answers_superseded(q, ev)  # given superseded early: withdrawn (late.py)
                q.answered = True
                q.last_out = ev
                answer = q.answer
                answer.update(mine)
                view = q.view
                if view is None:
                    view = q.view = dict(q.inputs)
                view.update(mine)
                if self._trigger:
                    for k in asked:  # the triggers its guarantees answer are answered (carried no further)
                        if k in self._trigger and self._owes(q, k):
                            q.mark("answered_triggers", self._trigger[k])
                outs = answer
            else:
                outs = {**q.answer, **mine}
        else:
            outs = mine
        if stamped > self._hi:
            self._hi = stamped
        reach = self._reach(ev, stamped)
        # remembered: reconsidered if a question within the skew after it gets no answer, or a question stamped
        # before it is heard after it (late.py)
        self._recent.append((ev, stamped, mine, self._state() if self._state_outs else _EMPTY))
        k = self._single.get(ev.topic, 0)
        if k and q is not None and q.owed and q.view is not None and outs is q.answer and not self._state_outs \
                and not self.margins and reach <= self.stream.skew:  # with margins, the general path (judging.py) computes them
            # the common case inline: one guarantee, no trigger, no state, no output-only guarantee
            view = q.view
            judged = self._judges[k].quick(view) or self._judge(k, view)
            if judged.truth is True and judged.semantics == "exact":
                if q.waiting:
                    q.waiting.pop(k, None)
                q.decided.add(k)
                result = self.result
                result.counts["satisfied"] += 1
                result.semantics[q.info] += 1
                self._given.append((ev.index, "satisfied", q.info))
                if self.on_verdict is not None:
                    self.on_verdict(Verdict(self.node.name, "satisfied", ev.index, ev.time, ev.where, ev.topic,
                                            max(self.now, ev.time), 0, {}, "", q.info, q.event.where))
                return
        state = self._state() if self._state_outs else {}
        first = self._question_outcome(q, ev, asked, outs, state)
        alone_now = self._alone_outcome(ev, alone) if alone else _NONE
        if reach and (first.kind == "violated" or reach > self.stream.skew):
            # false for the question at its stamp: it may be the right answer to a question stamped within the
            # skew after it that gets no answer of its own; judged once that is known (docs/semantics.md); one
            # published well after its stamp is held whatever it is for that question (a stale stamp's answer
            # is satisfied only if it satisfies every question it could answer: docs/semantics.md, "Event time")
            self._recent.pop()  # judged with both readings when released, not reconsidered
            self._held.append((ev, stamped, q, dict(outs), state, alone_now, first))
            if self.margins:  # its message's margin so far, given to its verdict when released
                index, least = self._margin_now
                self._held_margins[ev.index] = least if index == ev.index else None
            return
        if alone_now is _NONE and first.kind == "satisfied":  # the common case, without combining
            self._verdict("satisfied", ev, semantics=first.semantics, question=q.event.where if q else "")
            return
        self._decide(ev, q, [], alone_now, outs, first)

    def _release(self, now: float, end: bool = False) -> None:
        """Judge the held outputs whose skew has passed and whose questions within
        the skew are settled (answered by outputs of their own, closed, or past
        their horizon); all of them at the ``end``."""
        held = self._held
        while held and (end or held[0][1] + self._reach_of(held[0][0]) < now):
            ev, stamped, q, outs, state, alone, first = held[0]
            others = [o for o in self.stream.within_skew(stamped, q, self._reach_of(ev)) if not o.answered]
            if not end and any(not o.reported and (now <= o.due or self._at_due(now, o.due)) for o in others):
                return  # a question it may answer has no answer of its own yet: wait
            held.popleft()
            if self.margins:
                self._margin_now = (ev.index, self._held_margins.pop(ev.index, None))
            self._decide(ev, q, others, alone, outs, first, state)
            # judged now: an input heard later but stamped before it may still be its question (late.py)
            self._released.append((ev, stamped, {k: outs[k] for k in self._topic_io[ev.topic][1] if k in outs}, state))

    def _decide(self, ev: Event, q: Question | None, others: list[Question], alone: Outcome,
                outs: Mapping[str, object], first: Outcome | None = None, state: Mapping[str, object] | None = None) -> None:
        """One output message's verdict: its output-only guarantees (``alone``)
        and the question(s) it may answer (``first``: the reading of ``q``,
        the question at its stamp; ``others``: those within the skew after
        it that got no answer of their own), combined (:func:`.outcome.combine`)."""
        ks = self._touch[ev.topic][0]
        readings = ([first] if first is not None else []) + [
            self._question_outcome(x, ev, ks, outs, state or {}, False) for x in others]
        if first is not None and first.kind == "unasked" and not others and ks:
            self.result.unasked += 1
            self._unasked.append(ev.index)  # a question heard late may still be the one it answers (late.py)
        outcome = combine(alone, readings)
        question = q if q is not None else (others[0] if others else None)
        qwhere = question.event.where if question is not None else ""
        if outcome.kind == "violated":
            k = outcome.guarantee
            reason = (f"guarantee {k} is false on the output at {ev.where}" +
                      (f" answering the question at {qwhere}" if qwhere else "") +
                      (f": {outcome.reason}" if outcome.reason else in_all(outcome.semantics)))
            if len(readings) > 1:
                reason += f" (and on every question it may answer {self._within(ev)})"
            self._violation(ev, k, outcome.values, reason, outcome.semantics, question.event if question else None)
        elif outcome.kind == "inconclusive":
            reason = outcome.reason if len(readings) < 2 or outcome.reason else \
                self._stale_reason(ev, q, others) if ev.index in self._wins else \
                skew_reason(ev, q, others, self.stream.skew)
            self._verdict("inconclusive", ev, guarantee=outcome.guarantee, reason=reason, question=qwhere)
        elif outcome.kind == "satisfied":
            self._verdict("satisfied", ev, semantics=outcome.semantics, question=qwhere)


__all__ = ["Answering"]
