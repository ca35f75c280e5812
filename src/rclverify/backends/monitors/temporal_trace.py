"""A temporal requirement checked on a recorded run (docs/monitors.md, "Temporal requirements on traces").

The statement is one of the decided shapes of
:func:`rclverify.model.plan.temporal.shape` (``always F``, ``always next F``,
``eventually F``, ``eventually[<= N] F``, ``next F``, ``F until G``) over
``Node.in.x``/``Node.out.y``/``Node.state.v``.

**Steps of a trace.**  A step is a step of the composed system, as in the
proofs (docs/semantics.md, "Steps"): :class:`~.step_clock.StepClock`
gives each message on a topic of the statement's cone
(:func:`~.step_clock.cone_of`: the nodes it reads and every node
upstream of them; other messages are no step) its step: a question and
its answer are one step, a node reads another node's output in the step
after it, inputs that come at once are one instant.  The nodes the
statement reads have a state, the latest value of each input and output
mapped from the messages on their topics (:mod:`rclverify.traces.mapping`,
as the node monitors of :mod:`.check` keep it: outputs persist until
changed, the stream model of paper lines 462-495); step i is judged on the
state after its last message, an output another node reads being that
node's input from the next step on.  A declared state variable (the
plan's ``state:``, :mod:`rclverify.model.plan.state`) has at step 0 the value its
``init`` defines and at step i+1 the value its ``next`` defines from step
i's state and the node's inputs and outputs at step i, as in the composed
system (:mod:`rclverify.calculus.requirements.transition`).  Both are found by Z3
on the concrete values, and used only when the formula defines exactly
one value (else the variable has no value from there on, and what reads
it is undecided).

**Operands** are decided at each step by the judgement of the node monitors
(:func:`rclverify.semantics.floatsem.judge`: direct evaluation, Z3 on concrete
values when it cannot, then the nodes' double arithmetic and the mapping's
tolerance, docs/monitors.md "Numbers on the wire"; a witness of an operand
that held only there names the semantics).  A variable not observed yet has
no value, and an operand reading one is not evaluated at that step (the one
stream model, docs/semantics.md): ``always F`` constrains
published values only, ``eventually F`` (``next``, the right of ``until``)
needs ``F`` on published values; a declared state variable without a value
leaves what reads it undecided.

**Finite-trace verdicts** (docs/requirements.md, "Temporal requirements";
what each shape checks at a step: :mod:`.temporal_steps`):

===============  ===========================================================
``false``        ``always``/``always next``: F false at a step; ``next``: F
                 false at step 1; ``until``: F false before any G;
                 ``eventually[<= N]``: no step 0..N has F and the trace has
                 step N (the bound passed)
``true``         ``eventually``/``until``: F (G) at a step; ``next`` F at
                 step 1; ``always``: F at every step of this trace (a trace
                 is evidence for ``always``, never a proof)
``currently_false``  ``eventually``/``until``: not reached when the trace
                 ended (an infinite run may still reach it): inconclusive
``inconclusive`` an operand undecided where the verdict depends on it, or
                 ``next`` on a trace of one step
===============  ===========================================================

The verdict carries the step and time stamp where it was decided and the
witness steps (the step that refutes or meets it, with the values the
operand read there).
"""
from __future__ import annotations

import math

from typing import Any, Iterable, Mapping

from rclverify.model.plan.state import StateVar, state_type
from rclverify.model.plan.temporal import Temporal, shape
from rclverify.backends.monitors.response_trace import ResponseTracker
from rclverify.backends.monitors.dds_calls import CALL_LOG_TOPIC
from rclverify.backends.monitors.declarations import call_part
from rclverify.backends.monitors.step_clock import StepClock, cone_of
from rclverify.backends.monitors.temporal_steps import STEPS, VERDICTS, StepRun, TraceVerdict, operand_text
from rclverify.backends.monitors.trace_states import TraceStates
from rclverify.backends.monitors.run_origin import is_run_start
from rclverify.calculus.requirements.published import first_inputs
from rclverify.lang.types import Checked
from rclverify.model.plan.formal import Formal
from rclverify.traces.events import Event
from rclverify.traces.mapping import TopicRule
from rclverify.backends.monitors.shapes import StepPlace


def _operands(t: Temporal, kind: str) -> tuple[list[Formal], ResponseTracker | None]:
    """The state formulas statement ``t`` of shape ``kind`` reads, and the
    response pattern's tracker."""
    if kind == "always next":
        return [t.args[0].args[0]], None  # type: ignore[union-attr, list-item]
    if kind == "response":  # always (P -> eventually[<= N] Q) / always (P -> next Q)
        trig, resp = t.args[0].args  # type: ignore[union-attr]
        tracker = ResponseTracker((math.inf if resp.bound is None else resp.bound)  # type: ignore[union-attr]
                                  if resp.op == "eventually" else None)  # type: ignore[union-attr]
        return [trig, resp.args[0]], tracker  # type: ignore[list-item, union-attr]
    return list(t.args), None  # type: ignore[arg-type]


def check_temporal_trace(t: Temporal, checked: Checked, states: tuple[StateVar, ...], events: Iterable[Event],
                         rules: Mapping[str, TopicRule]) -> TraceVerdict:
    """The verdict of statement ``t`` on the recorded run ``events`` (module
    docstring), its steps the composed system's over the statement's cone
    (the mapping's ``skew`` joins inputs that come at once).  ``states`` the
    plan's state declarations, ``rules`` the topic mapping.  Raises :class:`~rclverify.lang.errors.RclError` for a
    shape that is not decided and whatever the event source raises
    (:class:`~rclverify.traces.TraceError`)."""
    kind = shape(t, None)
    ops, tracker = _operands(t, kind)
    nodes = list(dict.fromkeys(n for f in ops for n in f.nodes))
    for sv in states:
        state_type(sv, checked)
    st = TraceStates(checked, nodes, states, rules, first_inputs([f.expr for f in ops]))
    # the steps of the composed system, over the statement's cone (step_clock.StepClock)
    clock = StepClock(checked, cone_of(checked, nodes), getattr(rules, "skew", None) or 0.0)
    # the mapping's tolerance of recorded numbers
    r = StepRun(kind, ops, t.bound, checked, st, getattr(rules, "tolerance", None), tracker)
    step = STEPS[kind]
    now = -1  # the step the messages read so far end in
    for ev in events:
        part: Mapping[str, Any] | None = None
        if ev.topic.strip("/") == CALL_LOG_TOPIC:  # a live log's call line: the event of its link's part
            call = call_part(ev)
            if call is None:
                continue
            ev, part = call
        got = clock.tick(ev)
        if got is None:
            if is_run_start(ev.topic, ev.fields):  # first(...) is decided after it
                st.start()
            continue
        k, later = got
        while 0 <= now < k:  # the steps before this message's are over: each judged on its last state
            verdict = _close(r, step, now)
            if verdict is not None:
                return verdict
            moved = st.advance()
            r.last = moved or r.last  # the step's place: the last message whose values are current in it
            now += 1
        now = k
        if st.feed(ev, later, part) or r.last is None:
            r.last = ev
    if now >= 0:
        verdict = _close(r, step, now)
        if verdict is not None:
            return verdict
        if st.pending:  # outputs read in the step after the last: the readers' step, on what the run recorded
            r.last = st.advance() or r.last
            verdict = _close(r, step, now + 1)
            if verdict is not None:
                return verdict
    return _at_end(r, nodes)


def _close(r: StepRun, step: Any, i: int) -> TraceVerdict | None:
    """Step ``i`` judged on its state: the values after its last message."""
    r.i, r.vals = i, r.st.values()
    verdict: TraceVerdict | None = step(r)
    return verdict


def _at_end(r: StepRun, nodes: list[str]) -> TraceVerdict:
    """The verdict when the trace ended undecided (module table)."""
    ops, tracker, undecided, last = r.ops, r.tracker, r.undecided, r.last
    n = r.i + 1
    end: StepPlace = {"step": r.i if n else None, "time": last.time if last else None,
                           "where": last.where if last else ""}
    if n == 0:
        return TraceVerdict("inconclusive", 0, "the trace has no message on the topics of "
                                               f"{', '.join(nodes)}: nothing was checked")
    if undecided is not None and r.kind != "eventually":
        why = (f"a value it reads could not be read ({undecided['unreadable'][0]}), and the value before never "
               "stands in" if undecided.get("unreadable") else
               r.first_why or "a value it reads is not observed or not decidable there")
        return TraceVerdict("inconclusive", n, f"an operand is undecided at step {undecided['step']} "
                                               f"({undecided['where']}): {why}", undecided["step"], undecided["time"],
                            undecided["where"], [undecided])
    if r.kind in ("always", "always next"):
        return TraceVerdict("true", n, f"{operand_text(ops[0])} holds at every step of this trace ({n} steps): "
                                       "evidence for the requirement, not a proof", **end)
    if tracker is not None and tracker.pending is None:
        return TraceVerdict("true", n, f"every step where {operand_text(ops[0])} held was answered by {operand_text(ops[1])} in "
                                       f"time in this trace ({n} steps): evidence for the requirement, not a proof",
                            **end, spare=tracker.spare())
    if tracker is not None:
        return TraceVerdict("currently_false", n, f"{operand_text(ops[0])} held at step {tracker.pending} and {operand_text(ops[1])} has "
                                                  f"not held since when the trace ended after {n} steps (a longer run "
                                                  "may still answer it in time): inconclusive", **end)
    if r.kind == "next":
        return TraceVerdict("inconclusive", n, "the trace ended before step 1", **end)
    also = (f"; undecided at some steps, the first {undecided['step']} ({undecided['where']})"
            if undecided is not None else "")
    return TraceVerdict("currently_false", n, f"{operand_text(ops[-1])} has not held when the trace ended after {n} "
                                              f"steps (a longer run may still reach it): inconclusive{also}",
                        **end, witness=[undecided] if undecided else [])


__all__ = ["TraceVerdict", "VERDICTS", "check_temporal_trace"]
