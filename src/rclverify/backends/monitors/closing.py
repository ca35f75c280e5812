"""How a question ends, for the verdict engine (:mod:`.engine`): the parts that run once per question
or less, kept apart from the per-message hot path.

* :meth:`Closing._accept`: whether the node owes a question an answer (an unreadable input: undecided);
* :meth:`Closing._violation`: a violation recorded and reported; :meth:`Closing._at_due`: a time at a
  question's horizon in integer nanoseconds;
* :meth:`Closing._assumption_violated`: a question the assumption refuses, blamed on the producer;
* :meth:`Closing._at_question`: the owed guarantees its inputs alone decide;
* :meth:`Closing._close`: its horizon passed (or the run ended): partial answers judged, an unanswered
  question ``inconclusive`` (``open`` at the end);
* :meth:`Closing._wrong_whatever`: a newer question followed it with guarantees still waiting: an
  answer false whatever its missing outputs is ``violated``;
* :meth:`Closing._early_answer`: it got no answer of its own: outputs judged at once within the
  transport skew before it are reconsidered.

The rules are docs/semantics.md's; the mixin reads the engine's state and calls its judge (the
methods it expects are declared for the type checker only).
"""
from __future__ import annotations

import math
from collections import deque
from typing import TYPE_CHECKING, Any, Mapping

from rclverify.semantics.floatsem import Judgement
from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.traces.events import Event, to_ns
from rclverify.traces.questions import Question
from rclverify.backends.monitors.verdicts import KEPT_VIOLATIONS, WEAK as _WEAK, in_all, link_of, names, producers
from rclverify.backends.monitors.skew import within_before
from rclverify.backends.monitors.engine_state import EngineState

if TYPE_CHECKING:
    from rclverify.backends.monitors.shapes import Violation


class Closing(EngineState):
    """The once-per-question parts of :class:`~.engine.NodeMonitor` (module docstring)."""

    def _assumption_violated(self, ev: Event, formula: ast.Expr, inputs: Mapping[str, object], judged: Judgement) -> None:
        mentioned: set[str] = set()
        names(formula, mentioned)
        read = [k for k in inputs if k in mentioned or k[3:] in mentioned]
        blamed = sorted({p for k in read for p in producers(self.checked, self.node, k[3:])})
        links = sorted({link_of(self.node, k[3:]) for k in read} - {""})
        blame = ("upstream node(s) " + ", ".join(blamed)) if blamed else "environment"
        if blamed and links:
            blame += f" (through {', '.join(links)})"
        if self.result.first_assumption_violation is None:
            self.result.first_assumption_violation = {
                "event": ev.index, "time": ev.time, "where": ev.where, "assumption": expr_to_rcl(formula),
                "values": self._rendered(inputs), "blame": blame, "semantics": judged.semantics}
        self._verdict("assumption violated", ev, values=self._rendered(inputs),
                      reason=f"assumption {expr_to_rcl(formula)} is false; blamed on the {blame}",
                      semantics=judged.semantics)

    def _accept(self, ev: Event, inputs: dict[str, object]) -> tuple[bool, str, str]:
        """Whether the node owes question ``inputs`` (raised by ``ev``) an answer:
        (owed, the arithmetic its assumption held in, why it is undecided or ``""``);
        a false assumption is reported ``assumption violated`` here."""
        accepted, owed, refusal = "exact", True, ""
        judges = self._judges
        if self.invalid and any(k in self.invalid for k in inputs):
            # an input whose latest message did not map (a NaN): the value before it never stands in, so the
            # question is undecided until that input maps again (docs/semantics.md, "Values")
            unread = next(f"{k}: {why}" for k, why in self.invalid.items() if k in inputs)
            owed, refusal = False, f"undecided: {unread}"
        for aj, formula in (self._assumed if owed else ()):
            judged = judges[aj].quick(inputs) or self._judge(aj, inputs)  # the compiled code first, inline
            if judged.truth is False:
                owed = False
                self._assumption_violated(ev, formula, inputs, judged)
                break
            if judged.truth is None:
                owed, refusal = False, f"assumption undecided: {judged.reason}"
                break
            if judged.semantics != "exact" and _WEAK.get(judged.semantics, 0) > _WEAK[accepted]:
                accepted = judged.semantics
                self._note_inexact(ev, judged, f"assumption {expr_to_rcl(formula)}", inputs)
        return owed, accepted, refusal

    def _violation(self, ev: Event, k: int, values: Mapping[str, object], reason: str, semantics: str,
                   trigger: Event | None) -> None:
        """Guarantee ``k`` false on ``values`` for output ``ev`` (or the question's own message)
        answering the question raised by ``trigger``: ``violated``, or ``inconclusive`` where that
        question reads an input heard later than the lateness bound (docs/semantics.md, "Event time")."""
        cause = self._late_q.get(trigger.index) if trigger is not None and self._late_q else None
        if cause is not None and trigger is not None:
            self._verdict("inconclusive", ev, guarantee=k, values=self._rendered(values),
                          reason=f"{reason}; but the question at {trigger.where} reads the input at {cause.where}, "
                                 f"heard {cause.late * 1e3:.1f} ms after its time, later than the lateness bound, and "
                                 "asked before then: the node may not have had it when it answered, and a "
                                 "message later than the bound makes no violation; a header stamp copied from the "
                                 "question onto the answer, service introspection or a trace of the node's "
                                 "receipts would decide it (docs/semantics.md, \"Event time\")",
                          semantics=semantics, question=trigger.where)
            return
        result = self.result
        if self.on_verdict is None and result.first_violation is not None and \
                len(result.violations) >= KEPT_VIOLATIONS:  # a record nobody keeps or receives: counted, not rendered
            result.violations_dropped += 1
            result.counts["violated"] += 1
            self._given.append((ev.index, "violated", semantics))  # a revision withdraws it as any other (late.py)
            return
        record: Violation = {"event": ev.index, "time": ev.time, "where": ev.where, "guarantee": k,
                                  "formula": self._texts.get(k, ""), "values": self._rendered(values),
                                  "reason": reason, "semantics": semantics}
        if trigger is not None:
            record.update({"trigger": trigger.index, "trigger_time": trigger.time, "trigger_where": trigger.where})
        self.result.add_violation(record)
        self._verdict("violated", ev, guarantee=k, values=record["values"], reason=reason, semantics=semantics,
                      question=trigger.where if trigger is not None and trigger is not ev else "")

    def _unbound_note(self, reason: str) -> str:
        found = [v for v in self.unbound if f"no value for {v}" in reason]
        if not found:
            return ""
        return (f" ({', '.join(found)} of {self.node.name} is carried by no topic or link part: its topics(...) "
                "and services(...)/actions(...) name none, so no run gives it a value)")

    def _at_due(self, t: float, due: float) -> bool:
        """Whether time ``t`` (s), after ``due`` in doubles, is at it in integer nanoseconds
        (``due`` is a question's time plus the horizon: 0.7 + 0.2 is 0.8999999999999999 in
        doubles, and an answer at 0.9 s is within a horizon of 0.2 s).  Called only when the
        double comparison says late, so the common path pays nothing."""
        h = self.horizon
        if not (t - due < 1e-6 and math.isfinite(due) and math.isfinite(h)):
            return False
        return to_ns(t) <= to_ns(due - h) + to_ns(h)

    def _at_question(self, q: Question) -> None:
        """The owed guarantees on the question's inputs and the state outputs:
        one that reads no output false -> ``violated``; all true ->
        ``satisfied`` at once (no answer needed); anything else waits for an
        answer."""
        values = {**q.inputs, **self._state()}
        weakest = q.info
        waits = False
        for k in self._asked:
            if not self._owes(q, k):
                continue
            judged = self._judge(k, values)
            if judged.truth is True:
                q.decided.add(k)
                if _WEAK.get(judged.semantics, 0) > _WEAK[weakest]:
                    weakest = judged.semantics
                continue
            if judged.truth is False and not self._reads_out[k]:
                q.settled = True
                self._violation(q.event, k, values, f"guarantee {k} is false on the inputs of the question at "
                                f"{q.event.where}{in_all(judged.semantics)}", judged.semantics, q.event)
                return
            waits = True
        if not waits:
            q.settled = True
            self._verdict("satisfied", q.event, semantics=weakest)

    def _early_answer(self, qb: Question) -> None:
        """Question ``qb`` got no answer of its own: the outputs judged at once
        that were stamped within the skew before it may have been its answer
        (docs/semantics.md, "Transport skew").  Where they are false for it, the
        two readings disagree: an ``inconclusive`` verdict follows the one given
        at once (never a ``satisfied`` left standing for a wrong answer)."""
        if not qb.owed:
            return
        cands = self._early(qb)
        if not cands:
            return
        outs: dict[str, object] = {}
        ks: list[int] = []
        for ev, _, mine, _ in cands:
            outs.update(mine)
            ks += [k for k in self._touch[ev.topic][0] if k not in ks]
        ev, stamped, _, state = cands[-1]
        reading = self._question_outcome(qb, ev, sorted(ks), outs, state, False)
        if reading.kind != "violated":
            return
        self._forget(cands)
        gap = max(qb.stamp - stamped, 0.0) * 1000
        self._verdict("inconclusive", ev, guarantee=reading.guarantee, values=self._rendered(reading.values),
                      reason=f"the output at {ev.where} met the question at its stamp, but it was stamped {gap:.2f} ms "
                             f"before the question at {qb.event.where}, {self._within(ev)}, "
                             f"and that question got no answer of its own: as its answer, "
                             f"guarantee {reading.guarantee} is false; the two readings disagree (docs/semantics.md, "
                             f"\"Transport skew\")", question=qb.event.where)

    def _early(self, q: Question) -> list[Any]:
        """The outputs judged at once (``_recent``) that were received before
        question ``q`` and stamped within the transport skew before it (the one
        window, :func:`.skew.within_before`, as wide as the output reaches: the
        skew, or how long after its stamp it was published)."""
        return [r for r in self._recent if within_before(r[1], q.stamp, self._reach_of(r[0]))
                and r[0].index < q.event.index]

    def _forget(self, used: list[Any]) -> None:
        """Drop the outputs ``used`` from ``_recent``: their reconsideration is given (an input
        heard late may still be their question: kept with ``_released`` for late.py)."""
        self._released.extend(used)
        self._recent = deque((r for r in self._recent if r not in used), maxlen=self._recent.maxlen)

    def _close(self, q: Question, end: bool = False) -> None:
        """Question ``q``'s horizon passed (``end``: the run ended first):
        its partial answers are judged (an owed guarantee no output decided
        waits for the outputs it reads), and an unanswered one is inconclusive
        (``open`` at the end)."""
        if q.answered and not q.waiting and (q.followed or q.decided.issuperset(self._need)):
            q.reported = True  # answered in full (the common case)
            return
        state = self._state()
        if q.followed:  # a newer question came within its horizon: the node owes that one what is missing here
            self._wrong_whatever(q)
        elif (q.answered or self._state_outs) and q.owed and not q.settled and not q.reported:
            values = {**q.inputs, **state, **q.answer}
            for k in self._asked:
                if k in q.decided or k in q.waiting or not self._reads_out[k] or not self._owes(q, k) or \
                        self._trigger.get(k) in q.passed:
                    continue
                judged = self._judge(k, values)
                if judged.truth is not True:
                    q.waiting[k] = (q.last_out or q.event, judged.reason or f"guarantee {k} is false",
                                    {x: v for x, v in values.items() if x.startswith("out.")})
        for k in [k for k in q.waiting if self._trigger.get(k) in q.passed]:
            del q.waiting[k]  # the next question owes it now
        judged_now = bool(q.waiting)
        for k, (ev, why, outs) in sorted(q.waiting.items()):
            self._partial(q, k, ev, why, {**state, **outs}, end)
        q.waiting.clear()
        was, q.reported = q.reported, True  # closed: superseded no more
        if q.answered or q.settled or was or judged_now:
            return
        if (self.stream.skew or self._wins) and self._recent:
            self._early_answer(q)
        if end:
            self._verdict("open", q.event, reason=f"unanswered when the run ended, within {self.horizon} s")
            return
        if not self.heard_answer:
            self._verdict("before first answer", q.event, reason=f"unanswered within {self.horizon} s, before any "
                          "output of the node was heard: the monitor's readers of its outputs may have matched "
                          "after this question (a monitor started after the publishers, a latched input delivered "
                          "on matching); not counted (docs/semantics.md, \"Steps\")")
            return
        self._verdict("inconclusive", q.event, reason=f"unanswered: no output within {self.horizon} s of the "
                      f"question at {q.event.where} (a finite run cannot show the answer never comes; a deadline "
                      "`triggered by ... within` would fail)")

    def _wrong_whatever(self, q: Question) -> None:
        """Question ``q`` was followed by a newer one within its horizon, with
        guarantees still waiting for outputs: what is missing is owed to the
        newer question, but an answer already false whatever the missing
        outputs are is ``violated`` now (the sensor's ``orange`` for a reading
        of 300 fails whatever ``inspected`` is), and one false with the outputs
        received within the transport skew before ``q`` is ``inconclusive``
        (:meth:`_early_part`)."""
        state = self._state()
        for k, (ev, why, outs) in sorted(q.waiting.items()):
            values = {**q.inputs, **state, **outs}
            if self._false_whatever_missing(k, values):
                self._violation(ev, k, values, f"guarantee {k} is false on the outputs published after the question "
                                f"at {q.event.where} (the last at {ev.where}) whatever the value of the outputs not "
                                f"published before the next question ({why})", "", q.event)
            elif (self.stream.skew or self._wins) and self._recent:
                self._early_part(q, k, values)
        q.waiting.clear()

    def _early_part(self, q: Question, k: int, values: Mapping[str, object]) -> None:
        """Guarantee ``k`` of question ``q`` waited for outputs ``q`` got no
        message of before a newer question followed it.  Outputs stamped within
        the transport skew before ``q`` were taken as (part of) the answer to the
        question at their stamp, but they may be the missing part of ``q``'s:
        the sensor's ``orange`` for the reading of 300, received 0.2 ms before
        the reading, and its ``inspected`` after it.  Where ``k`` is false on
        ``q``'s answer completed by them (its own outputs first), the two
        readings disagree: ``inconclusive`` on the early output (docs/semantics.md,
        "Transport skew"), never a question dropped with no verdict."""
        cands = self._early(q)
        if not cands:
            return
        early: dict[str, object] = {}
        for _, _, mine, _ in cands:
            early.update(mine)
        completed = {**early, **values}  # its own answer first; the early outputs fill what it lacks
        if not set(early).difference(values) or self._judge(k, completed).truth is not False:
            return
        ev, stamped = cands[-1][0], cands[-1][1]
        self._forget(cands)
        gap = max(q.stamp - stamped, 0.0) * 1000
        self._verdict("inconclusive", ev, guarantee=k, values=self._rendered(completed),
                      reason=f"the output at {ev.where} was stamped {gap:.2f} ms before the question at "
                             f"{q.event.where}, {self._within(ev)}, and that "
                             f"question's answer lacks what it published: as the rest of that answer, guarantee {k} "
                             f"is false; taken for the question at its stamp, it left that answer incomplete; the "
                             f"two readings disagree (docs/semantics.md, \"Transport skew\")", question=q.event.where)

    def _partial(self, q: Question, k: int, ev: Event, why: str, outs: Mapping[str, object], end: bool) -> None:
        """A partial answer: guarantee ``k`` waited for an output that never came
        after the question; false whatever it is -> ``violated``, else undecided."""
        values = {**q.inputs, **outs}  # outs: the state outputs at its horizon and the answer
        if self._false_whatever_missing(k, values):
            self._violation(ev, k, values, f"guarantee {k} is false on the outputs published after the question "
                            f"at {q.event.where} (the last at {ev.where}) whatever the value of the outputs not "
                            f"published after it ({why})", "", q.event)
            return
        missing = why.split(" ", 3)[-1].split(",")[0] if why.startswith("no value for ") else why
        reason = (f"guarantee {k} is undecided on the outputs published after the question at {q.event.where} "
                  f"(the last at {ev.where}): {why}; nothing published within {self.horizon} s completed the answer "
                  f"(if {missing} keeps its value between messages, declare its topic `state: true` in the mapping)")
        self._verdict("open" if end else "inconclusive", ev, guarantee=k, values=self._rendered(values),
                      reason=reason, question=q.event.where)

    def _false_whatever_missing(self, k: int, values: Mapping[str, object]) -> bool:
        import z3  # deferred: start-up (Z3 only for a question whose answer stays incomplete)
        from rclverify.semantics.concrete import false_whatever_the_rest  # deferred: start-up (loads z3, the encoder and the type checker only when called)
        known = {q: v for q, v in values.items() if v is not None}
        try:
            return false_whatever_the_rest(self.guarantees[k - 1], self.checked, self.node, known)
        except (KeyError, ValueError, z3.Z3Exception):
            return False


__all__ = ["Closing"]
