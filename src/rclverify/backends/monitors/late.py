"""An input heard after messages stamped later than it, for the verdict engine (:mod:`.engine`).

docs/semantics.md: an output answers the question in force **at its stamp**
(the latest input stamped at or before it), whatever order the run heard
them in.  A recorded log holds messages in the order its logger got them,
and a live monitor's reorder window (``online.py``) bounds only how late a
message may be to be put in its place; so an input may be heard after an
output stamped after it was judged (issue 63, row 3: a reading stamped 1.2 s
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
  undecided), named as the question heard late;
* a later question whose inputs lacked this message's values (it changes an
  input that question read, before the next message of its topic) takes
  them, and the outputs judged against it are judged again on them (a
  ``violated`` follows where false; ``inconclusive`` where the assumption
  no longer holds of them, or undecided);
* what cannot be placed (the question in force at its stamp forgotten, or
  more outputs after it than the engine remembers) is ``inconclusive`` with
  the reason, never judged against the wrong question.

A verdict already given is not withdrawn: a ``violated`` given against the
question before stays (the revision adds to it); the run is not discharged
on the wrong question.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ...traces.events import Event
from ...traces.questions import Question


class Late:
    """The late-input part of :class:`~.engine.NodeMonitor` (module docstring)."""

    if TYPE_CHECKING:  # the engine's state and helpers the mixin reads, declared for the type checker only
        def __getattr__(self, name: str) -> Any: ...

    def _late_input(self, ev: Event, trig: frozenset[str], stamp: float) -> None:
        """Input ``ev`` (it set the inputs ``trig``), stamped ``stamp`` (s), heard after a
        message of the node stamped later: raised at its stamp (module docstring)."""
        stream, values = self.stream, self.values
        mine = {k: values[k] for k in trig}
        kept = stream._questions
        last = kept[-1] if kept else None
        later = last is not None and last.stamp > stamp
        if last is not None and later:  # an input message stamped after it set the values in force now
            for k in trig:
                values[k] = last.inputs.get(k)
        before = stream.at(stamp)
        if before is None and stream.forgot:
            self._verdict("inconclusive", ev, reason=f"the input at {ev.where}, stamped {stamp:.9g} s, was heard "
                          "after messages stamped later, and the questions before its stamp are no longer kept: "
                          "it cannot be put in its place, and the outputs after it were judged without it")
            return
        inputs = {k: v for k, v in (before.inputs if before is not None else {}).items()}
        inputs.update({k: v for k, v in mine.items() if v is not None})
        tainted = self._tainted(ev, stamp, mine)
        missing = [k for k in self.needed_inputs if k not in inputs]
        if missing:
            self._verdict("incomplete input", ev, reason="no value yet for " + ", ".join(missing) +
                          " at its stamp (heard after messages stamped later)")
            self._revise_tainted(ev, stamp, None, tainted)
            return
        owed, accepted, refusal = self._accept(ev, inputs)
        q = Question(ev, stamp, inputs, owed, accepted)
        if later:
            stream.insert(q)
            if owed and self._triggers:
                for t in trig & self._triggers:
                    q.triggers.setdefault(t, ev)
            if refusal:
                self._verdict("inconclusive", ev, reason=refusal)
            if owed:
                self.result.accepted += 1
        else:
            self._raise(ev, q, trig, refusal)
        self._revise_tainted(ev, stamp, q, tainted)
        if later and owed:
            q.reported = True  # only the latest question is watched for its horizon
            nxt = stream.after(stamp)
            if not q.answered and not q.settled and nxt:
                gap = nxt[0].stamp - stamp
                self._verdict("superseded" if gap <= self.horizon else "inconclusive", ev,
                              reason=f"heard after messages stamped later; the question at {nxt[0].event.where} "
                                     f"came {gap:.9g} s after it, before any output answered it" +
                                     ("" if gap <= self.horizon else f" and after its horizon of {self.horizon} s"))

    def _tainted(self, ev: Event, stamp: float, mine: dict[str, Any]) -> list[Question]:
        """The kept questions stamped after ``stamp`` that read an input ``ev`` changes
        (before the next message of ``ev``'s topic): they were raised without it."""
        out = []
        for q in self.stream.after(stamp):
            if q.event.topic == ev.topic:
                break
            if any(q.inputs.get(k) != v for k, v in mine.items() if v is not None):
                out.append(q)
                q.inputs.update({k: v for k, v in mine.items() if v is not None})  # what later outputs are judged on
                q.view = None if not q.answer else {**q.inputs, **q.answer}
        return out

    def _revise_tainted(self, ev: Event, stamp: float, q: Question | None, tainted: list[Question]) -> None:
        """The outputs already judged stamped after ``stamp``: those whose question at
        their stamp is now ``q`` are judged against it; those of a ``tainted`` question
        are ``inconclusive`` (module docstring)."""
        recent = self._recent
        if len(recent) == recent.maxlen and recent[0][1] > stamp:
            self._verdict("inconclusive", ev, reason=f"the input at {ev.where} was heard after more outputs stamped "
                          f"after it than the monitor keeps ({recent.maxlen}): the oldest of them were judged "
                          "without it, and their verdicts cannot be revised")
        for r in [r for r in recent if r[1] > stamp]:
            out_ev, stamped, outs, state = r
            qa = self.stream.at(stamped)
            if q is not None and qa is q:
                self._answers_late(ev, q, out_ev, outs, state)
            elif qa is not None and qa in tainted:
                self._retold(ev, qa, out_ev, outs, state)
        for j, h in enumerate(self._held):  # outputs held for the skew: judged against the question at their stamp
            qa = self.stream.at(h[1])
            if qa is not h[2] and qa is not None:
                self._held[j] = (h[0], h[1], qa, h[3], h[4], h[5],
                                 self._question_outcome(qa, h[0], self._touch[h[0].topic][0], h[3], h[4], False))

    def _retold(self, ev: Event, qa: Question, out_ev: Event, outs: dict[str, Any], state: Any) -> None:
        """Output ``out_ev`` was judged against ``qa``, whose inputs lacked ``ev``'s
        values (now set): judged again on them where the assumption still holds
        of them, else ``inconclusive`` (the verdict given was on other inputs)."""
        if not qa.owed:
            return
        why = (f"; the input at {ev.where}, heard after it but stamped before the question at {qa.event.where}, "
               "changes an input that question reads: the log's order is not the stamps'")
        for aj, _ in self._assumed:
            judged = self._judge(aj, qa.inputs)
            if judged.truth is not True:
                self._verdict("inconclusive", out_ev, reason=f"the output at {out_ev.where} was judged against the "
                              f"question at {qa.event.where} without the input at {ev.where}; with it the assumption "
                              f"is {'false' if judged.truth is False else 'undecided'}" + why,
                              question=qa.event.where)
                return
        got = self._question_outcome(qa, out_ev, self._touch[out_ev.topic][0], outs, dict(state or {}), False)
        self._late_verdict(out_ev, qa.event, got, why)

    def _answers_late(self, ev: Event, q: Question, out_ev: Event, outs: dict[str, Any], state: Any) -> None:
        """Output ``out_ev`` (judged before ``ev`` was heard) answers ``q``, ``ev``'s question:
        judged again against it; a false or undecided reading is a verdict of its own."""
        if not q.owed:
            return
        q.answered = True
        q.last_out = out_ev
        q.answer.update(outs)
        q.view = {**q.inputs, **q.answer}
        got = self._question_outcome(q, out_ev, self._touch[out_ev.topic][0], q.answer, dict(state or {}))
        why = (f"; the question in force at its stamp is the one at {ev.where}, heard after it but stamped before it "
               f"({q.stamp:.9g} s against {out_ev.stamped:.9g} s): the log's order is not the stamps'")
        self._late_verdict(out_ev, ev, got, why)

    def _late_verdict(self, out_ev: Event, qe: Event, got: Any, why: str) -> None:
        """The verdict that follows the one given to ``out_ev``: judged again against the
        question raised by ``qe``, false (``violated``) or undecided (``inconclusive``)."""
        if got.kind == "violated":
            k = got.guarantee
            self._violation(out_ev, k, got.values, f"guarantee {k} is false on the output at {out_ev.where} answering "
                            f"the question at {qe.where}" + (f": {got.reason}" if got.reason else "") + why,
                            got.semantics, qe)
        elif got.kind == "inconclusive":
            self._verdict("inconclusive", out_ev, guarantee=got.guarantee, reason=got.reason + why,
                          question=qe.where)


__all__ = ["Late"]
