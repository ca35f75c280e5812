"""How the verdict engine (:mod:`.engine`) judges guarantees on values.

One formula's judgement is the compiled code where it decides alone, else
:func:`rclverify.semantics.floatsem.judge` (exact, double, tolerance),
remembered per (formula, values of the variables it reads).  A set of
guarantees judged on one reading gives one :class:`.outcome.Outcome`: the
first false one, else undecided, else satisfied in the weakest arithmetic
any of them needed (one arithmetic for the whole contract per message),
else ``none``; a guarantee that reads an output not yet published waits for
it (docs/semantics.md).
"""
from __future__ import annotations

from typing import Any, Callable, Mapping

from rclverify.semantics.floatsem import Judgement, holds_in, judge
from rclverify.semantics.robustness import Margin, MarginUndefined, margin
from rclverify.semantics.values import render
from rclverify.traces.events import Event
from rclverify.traces.questions import Question
from rclverify.backends.monitors.outcome import Outcome
from rclverify.backends.monitors.verdicts import WEAK as _WEAK
from rclverify.backends.monitors.engine_state import EngineState


def _always(k: int) -> bool:
    return True


class Judging(EngineState):
    """The judging part of :class:`~.engine.NodeMonitor` (module docstring).

    ``margins`` (False unless :func:`.check.check_trace` is asked for them):
    every guarantee judged true or false on an answer has its space margin
    computed (:func:`_note_margin`), counted in the result and given to the
    message's verdict."""

    margins = False
    #: (event index, the least margin of the guarantees judged on that message so far)
    _margin_now: tuple[int, float | None] = (-1, None)
    _margin_cache: dict[tuple[Any, ...], tuple[float, str, str, str] | None] | None = None

    def _note_margin(self, k: int, values: Mapping[str, object], judged: Judgement, ev: Event,
                     q: Question | None) -> None:
        """Guarantee ``k``'s margin on ``values``, counted in the result's margins
        and in the message's: in double arithmetic where its sign is the
        verdict's (a verdict decided exactly: the exact margin differs from it
        only by the rounding of the terms), else in the arithmetic that decided
        ``judged`` (exact for a violation); none for a verdict decided within a
        tolerance (docs/semantics.md, "Margins")."""
        sem = judged.semantics
        arith = "exact" if judged.truth is False or sem == "exact" else "double" if sem == "double" else ""
        cache = self._margin_cache
        if cache is None:
            cache = self._margin_cache = {}
        key = (k, arith, tuple([values.get(d) for d in self._deps[k]]))
        got: tuple[float, str, str, str] | None
        if key in cache:
            got = cache[key]
        else:
            got = None
            formula = self._guaranteed[k]
            m: Margin | None = None
            if arith:
                try:
                    m = margin(formula, self.checked, self.node, values, "double")
                except MarginUndefined:
                    pass
            if arith == "exact" and (m is None or not (m.value > 0 if judged.truth else m.value < 0)):
                try:
                    m = margin(formula, self.checked, self.node, values, "exact")
                except MarginUndefined:
                    m = None
            if m is not None:
                got = (m.value, m.unit, m.atom, m.arithmetic)
            if len(cache) >= 4096:
                cache.clear()
            cache[key] = got
        at = (ev.index, ev.time, ev.where, q.event.where if q is not None else "")
        if got is None:
            self.result.note_margin(k, self._texts[k], None, "", "", "", at)
            return
        value = got[0]
        self.result.note_margin(k, self._texts[k], value, got[1], got[2], got[3], at)
        index, least = self._margin_now
        if index != ev.index or least is None or value < least:
            self._margin_now = (ev.index, value)

    def _message_margin(self, ev: Event, verdict: str) -> float | None:
        """The margin of the message ``ev`` whose verdict is ``verdict`` (``None``
        without margins, for another verdict, or when no guarantee had one)."""
        if not self.margins or verdict not in ("satisfied", "violated"):
            return None
        index, least = self._margin_now
        return least if index == ev.index else None

    def _judge(self, k: Any, values: Mapping[str, object]) -> Judgement:
        """The judgement of guarantee ``k`` (``("A", j)``: assumption ``j``) on
        ``values``: the compiled code where it decides alone, else
        :func:`~rclverify.semantics.floatsem.judge`, remembered per (formula,
        values of the variables it reads)."""
        hit: Judgement | None = self._judges[k].quick(values)
        if hit is not None:
            return hit
        ck = (k, tuple([values.get(d) for d in self._deps[k]]))
        hit = self._cache.get(ck)
        if hit is not None:
            return hit
        formula = self._guaranteed[k] if isinstance(k, int) else self.assumption[k[1]]
        j = judge(formula, self.checked, self.node, values, self.tolerance)
        if self.cache_size:
            if len(self._cache) >= self.cache_size:
                self._cache.clear()
            self._cache[ck] = j
        return j

    def _rendered(self, values: Mapping[str, object]) -> dict[str, str]:
        out = {}
        for k, v in sorted(values.items()):
            if v is None:
                continue
            hit = self._renders.get(id(v))
            if hit is None or hit[0] is not v:
                if len(self._renders) >= 256:
                    self._renders.clear()
                if isinstance(v, tuple):  # <a, b>
                    from rclverify.traces.typed_text import render_as  # deferred: start-up (only for a tuple value)
                    typ = (self.node.inputs if k.startswith("in.") else self.node.outputs).get(k.split(".", 1)[-1])
                    hit = (v, render_as(v, typ))
                else:
                    hit = (v, render(v))
                self._renders[id(v)] = hit
            out[k] = hit[1]
        return out

    def _note_inexact(self, ev: Event, judged: Judgement, what: str, values: Mapping[str, object]) -> None:
        if self.result.first_inexact is None:
            self.result.first_inexact = {"event": ev.index, "time": ev.time, "where": ev.where,
                                         "semantics": judged.semantics, "formula": what,
                                         "values": self._rendered(values), "reason": judged.reason}

    def _owes(self, q: Question, k: int) -> bool:
        trig = self._trigger.get(k)
        return trig is None or trig in q.triggers

    def _alone_outcome(self, ev: Event, ks: list[int]) -> Outcome:
        """The guarantees over outputs only that ``ev`` touches, on the outputs as they stand."""
        if not ks:
            return Outcome("none")
        values = {k: v for k, v in self.values.items() if v is not None}
        return self._outcome(ks, values, lambda k: True, None, ev)

    def _outcome(self, ks: list[int], values: Mapping[str, object], owed: Callable[[int], bool],
                 q: Question | None, ev: Event, weakest: str = "exact") -> Outcome:
        """Guarantees ``ks`` (those ``owed``) judged on ``values``: the first
        false one, else undecided, else satisfied, else ``none``."""
        decided, undecided = False, None
        held: list[tuple[int, str]] = []
        if q is not None and ev.time > q.due and not self._at_due(ev.time, q.due):
            q = None  # judged against it, but past its horizon: no part of its answer
        first_inexact = None
        for k in ks:
            if not owed(k):
                continue
            if q is not None and k in self._trigger:
                q.mark("answered_triggers", self._trigger[k])
            judged = self._judge(k, values)
            if self.margins and judged.truth is not None:
                self._note_margin(k, values, judged, ev, q)
            if judged.truth is False:
                if q is not None:
                    q.waiting.pop(k, None)
                    q.decided.add(k)
                return Outcome("violated", k, judged.semantics, values=dict(values))
            if judged.truth is None:
                if judged.reason.startswith("no value for out."):  # waits for that output
                    if q is not None:
                        q.waiting[k] = (ev, judged.reason, {x: v for x, v in values.items() if x.startswith("out.")})
                    continue
                undecided = undecided or (k, judged.reason)
                continue
            if q is not None:
                q.waiting.pop(k, None)
                q.decided.add(k)
            decided = True
            held.append((k, judged.semantics))
            if judged.semantics != "exact":
                first_inexact = first_inexact or (k, judged)
                if _WEAK.get(judged.semantics, 0) > _WEAK[weakest]:
                    weakest = judged.semantics
        if undecided is not None:
            k, why = undecided
            return Outcome("inconclusive", k, reason=f"guarantee {k}: {why}" + self._unbound_note(why))
        if decided and weakest != "exact":  # one arithmetic per message for the whole contract
            for k, sem in held:
                if _WEAK.get(sem, 0) < _WEAK[weakest] and holds_in(weakest, self._guaranteed[k], self.checked,
                                                                  self.node, values, self.tolerance) is False:
                    other = next(j for j, s2 in held if s2 == weakest)
                    return Outcome("violated", k, weakest, values=dict(values),
                                   reason=f"guarantee {other} holds only in {weakest} arithmetic and guarantee {k} "
                                          f"is false in it: no one arithmetic makes the node's guarantees hold on "
                                          f"the message")
        if decided:
            if first_inexact is not None:
                k, judged = first_inexact
                self._note_inexact(ev, judged, f"guarantee {k} ({self._texts[k]})", values)
            return Outcome("satisfied", semantics=weakest)
        return Outcome("none")

    def _question_outcome(self, q: Question | None, ev: Event, ks: list[int], outs: Mapping[str, object],
                          state: Mapping[str, object], keep: bool = True) -> Outcome:
        """Output ``ev`` judged against question ``q``; ``keep``: it is the
        question ``ev`` answered (not another reading within the skew), whose
        decided and waiting guarantees it updates."""
        if q is None:
            return Outcome("unasked")
        if not q.owed:
            return Outcome("none")
        if not state and outs is q.answer and q.view is not None:
            values = q.view  # inputs and answer, kept by _output: no copy
        else:
            values = dict(q.inputs)
            if state:
                values.update(state)
            values.update(outs)
        return self._outcome(ks, values, self._owes_fn(q), q if keep else None, ev,
                             q.info)

    def _owes_fn(self, q: Question) -> Callable[[int], bool]:
        """Which guarantees ``q`` is owed (all of them when none has a trigger)."""
        if not self._trigger:
            return _always
        return lambda k: self._owes(q, k)
