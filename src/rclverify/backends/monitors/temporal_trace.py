"""A temporal requirement checked on a recorded run (docs/monitors.md, "Temporal requirements on traces").

The statement is one of the decided shapes of
:func:`rclverify.model.plan.temporal.shape` (``always F``, ``always next F``,
``eventually F``, ``eventually[<= N] F``, ``next F``, ``F until G``) over
``Node.in.x``/``Node.out.y``/``Node.state.v``.

**Steps of a trace.**  A step is a step of the composed system, as in the
proofs (docs/semantics.md, "Steps"): :class:`~.trace_states.StepClock`
gives each message on a topic of the statement's cone
(:func:`~.trace_states.cone_of`: the nodes it reads and every node
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

**Finite-trace verdicts** (docs/requirements.md, "Temporal requirements"):

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

from dataclasses import dataclass, field
from typing import Any, Iterable, Mapping

import z3

from rclverify.semantics.floatsem import judge
from rclverify.semantics.encode import EncodingError
from rclverify.model.plan.formal import Formal
from rclverify.model.plan.state import StateVar, state_type
from rclverify.model.plan.temporal import Temporal, shape
from rclverify.backends.monitors.response_trace import ResponseTracker
from rclverify.backends.monitors.dds_calls import CALL_LOG_TOPIC
from rclverify.backends.monitors.declarations import call_part
from rclverify.backends.monitors.trace_states import StepClock, TraceStates, cone_of
from rclverify.backends.monitors.run_origin import is_run_start
from rclverify.calculus.requirements.published import first_inputs
from rclverify.lang.types import Checked
from rclverify.traces.events import Event
from rclverify.traces.mapping import TopicRule
from rclverify.semantics.values import render
from rclverify.lang.printer import expr_to_rcl
from rclverify.backends.monitors.shapes import StepPlace, TraceVerdictJson, Witness

VERDICTS = ("true", "false", "currently_false", "inconclusive")


@dataclass
class TraceVerdict:
    """The verdict of one temporal statement on one trace (module table).

    ``verdict`` one of :data:`VERDICTS`; ``step``/``time``/``where`` where it
    was decided (``None`` when at the end of the trace); ``steps`` the
    number of steps; ``witness`` ``[{"step", "time", "where", "operand",
    "holds", "values"}]``; ``reason`` one sentence; ``spare`` the steps to
    spare of a bounded ``eventually[<= N]`` (N less the step it held at) or
    response (N less the longest wait of an answered trigger) judged
    ``true``, else ``None`` (docs/semantics.md, "Margins in steps").
    """

    verdict: str
    steps: int
    reason: str
    step: int | None = None
    time: float | None = None
    where: str = ""
    witness: list[Witness] = field(default_factory=list)
    spare: int | None = None

    def to_json(self) -> TraceVerdictJson:
        out: TraceVerdictJson = {"verdict": self.verdict, "steps": self.steps, "reason": self.reason,
                                 "step": self.step, "time": self.time, "where": self.where, "witness": self.witness}
        if self.spare is not None:
            out["spare"] = self.spare
        return out



def _truth(f: Formal, checked: Checked, values: Mapping[str, object], tolerance: Any = None,
           semantics: dict[int, str] | None = None) -> bool | None:
    """Operand ``f``'s truth on the step's values, judged as the node monitors
    judge (:func:`rclverify.semantics.floatsem.judge`: exact, then the nodes'
    double arithmetic, then a declared ``tolerance``); the semantics that
    decided goes to ``semantics[id(f)]``."""
    mine = {k: v for k, v in values.items() if k.partition(".")[2] in f.scope.inputs or
            k.partition(".")[2] in f.scope.outputs or k.startswith("first(")}
    try:
        j = judge(f.expr, checked, f.scope, mine, tolerance)
    except (KeyError, ValueError, TypeError, EncodingError, z3.Z3Exception):
        return None
    if semantics is not None:
        semantics[id(f)] = j.semantics
    return j.truth


def _published(f: Formal, values: Mapping[str, object]) -> bool:
    """Whether every input and output operand ``f`` mentions has been
    published on this trace (docs/semantics.md: a state formula over a value
    never published is not evaluated; a state variable without a value stays
    undecided instead)."""
    for n, p, v in f.mentions:
        if p in ("in", "out") and f"{p}.{n}.{p}.{v}" not in values:
            return False
    return True


def _shown(f: Formal, values: Mapping[str, object]) -> dict[str, str]:
    names = {f"{n}.{p}.{v}" for n, p, v in f.mentions}
    return {k.partition(".")[2]: render(v) for k, v in sorted(values.items()) if k.partition(".")[2] in names}


@dataclass
class _Run:
    """One statement's check on one trace, step by step: the operands
    ``ops``, the state of the run so far (the trace states ``st``, the step
    ``i`` and its event ``last``, the values ``vals`` at it) and the first
    undecided operand's witness (``undecided``)."""

    kind: str
    ops: list[Formal]
    bound: int | None
    checked: Checked
    st: TraceStates
    tol: Any
    tracker: ResponseTracker | None = None
    sems: dict[int, str] = field(default_factory=dict)
    undecided: Witness | None = None
    i: int = -1
    last: Event | None = None
    vals: Mapping[str, object] = field(default_factory=dict)
    #: why a first(...) the statement reads is unknown on this run (first_messages.py), once an operand needed it
    first_why: str = ""

    def decide(self, f: Formal, unpublished: bool | None) -> bool | None:
        """``f``'s truth at this step: undecided when a value it reads was unreadable in its last message,
        ``unpublished`` when one was never published, else judged."""
        if any(f"{p}.{n}.{p}.{v}" in self.st.unreadable for n, p, v in f.mentions):
            return None
        got = _truth(f, self.checked, self.vals, self.tol, self.sems) if _published(f, self.vals) else unpublished
        if got is None and not self.first_why:
            self.first_why = next((v for k, v in self.vals.items() if k.startswith("first(") and isinstance(v, str)), "")
        return got

    def wit(self, f: Formal, holds: bool | None) -> Witness:
        """The witness of operand ``f`` at this step."""
        ev = self.last
        assert ev is not None
        out: Witness = {"step": self.i, "time": ev.time, "where": ev.where, "operand": _text(f),
               "holds": holds, "values": _shown(f, self.vals)}
        bad = [self.st.unreadable[k] for n, p, v in f.mentions if (k := f"{p}.{n}.{p}.{v}") in self.st.unreadable]
        if bad:
            out["unreadable"] = bad
        if holds and self.sems.get(id(f), "exact") != "exact":  # held only in double arithmetic or the tolerance
            out["semantics"] = self.sems[id(f)]
        return out

    def at(self, verdict: str, why: str, w: list[Witness]) -> TraceVerdict:
        """The verdict decided at this step."""
        ev = self.last
        assert ev is not None
        return TraceVerdict(verdict, self.i + 1, why, self.i, ev.time, ev.where, w)

    def note(self, f: Formal, h: bool | None) -> None:
        """Remember ``f`` as the first undecided operand when ``h`` is undecided and none was before."""
        if h is None and self.undecided is None:
            self.undecided = self.wit(f, None)

    def where(self) -> str:
        ev = self.last
        assert ev is not None
        return f"{ev.where}, t = {ev.time} s"


def _step_always(r: _Run) -> TraceVerdict | None:
    """``always F`` and ``always next F``: false at the first step where F is false."""
    if r.kind == "always next" and r.i == 0:
        return None
    f = r.ops[0]
    h = r.decide(f, True)  # a value it reads never published: not evaluated (docs/semantics.md)
    if h is False:
        return r.at("false", f"{_text(f)} is false at step {r.i} ({r.where()})", [r.wit(f, False)])
    r.note(f, h)
    return None


def _step_response(r: _Run) -> TraceVerdict | None:
    """The response pattern (response_trace.py): false when a trigger goes unanswered in time."""
    assert r.tracker is not None
    said = r.tracker.step(r.i, r.decide(r.ops[0], False), r.decide(r.ops[1], False))
    if said is not None and said[0] == "false":
        return r.at("false", f"{_text(r.ops[0])} held at step {said[1]} and {_text(r.ops[1])} did not hold in "
                             f"time, by step {r.i} ({r.where()})", [r.wit(r.ops[1], False)])
    if said is not None and r.undecided is None:
        r.undecided = r.wit(r.ops[said[1]], None)
    return None


def _step_next(r: _Run) -> TraceVerdict | None:
    """``next F``: decided at step 1."""
    if r.i != 1:
        return None
    h = r.decide(r.ops[0], False)
    v = {True: "true", False: "false", None: "inconclusive"}[h]
    return r.at(v, f"{_text(r.ops[0])} is {v if h is not None else 'undecided'} at step 1", [r.wit(r.ops[0], h)])


def _step_eventually(r: _Run) -> TraceVerdict | None:
    """``eventually[<= N] F``: true at the first step where F holds (reached only on published values)."""
    f = r.ops[0]
    h = r.decide(f, False)
    if h is True:
        v = r.at("true", f"{_text(f)} holds at step {r.i} ({r.where()})", [r.wit(f, True)])
        v.spare = None if r.bound is None else r.bound - r.i
        return v
    r.note(f, h)
    if r.bound is not None and r.i >= r.bound:
        if r.undecided is not None:
            return r.at("inconclusive", f"not met within {r.bound} steps, but undecided at step "
                                        f"{r.undecided['step']}", [r.undecided])
        return r.at("false", f"{_text(f)} does not hold at any step 0..{r.bound}: the bound passed "
                             f"at step {r.i} ({r.where()})", [r.wit(f, False)])
    return None


def _step_until(r: _Run) -> TraceVerdict | None:
    """``F until G``: true when G holds with F at every step before, false when F fails first."""
    f_op, g_op = r.ops[0], r.ops[1]
    g = r.decide(g_op, False)
    if g is True and r.undecided is None:
        return r.at("true", f"{_text(g_op)} holds at step {r.i}, {_text(f_op)} at every step before",
                    [r.wit(g_op, True)])
    r.note(g_op, g)
    if g is not True:
        f = r.decide(f_op, True)
        if f is False and r.undecided is None:
            return r.at("false", f"{_text(f_op)} is false at step {r.i} before {_text(g_op)} held",
                        [r.wit(f_op, False)])
        r.note(f_op, f)
    return None


#: What each decided shape (model/plan/temporal.py, ``shape``) checks at one step.
_STEPS = {"always": _step_always, "always next": _step_always, "response": _step_response, "next": _step_next,
          "eventually": _step_eventually, "until": _step_until}


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
    # the steps of the composed system, over the statement's cone (trace_states.StepClock)
    clock = StepClock(checked, cone_of(checked, nodes), getattr(rules, "skew", None) or 0.0)
    # the mapping's tolerance of recorded numbers
    r = _Run(kind, ops, t.bound, checked, st, getattr(rules, "tolerance", None), tracker)
    step = _STEPS[kind]
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


def _close(r: _Run, step: Any, i: int) -> TraceVerdict | None:
    """Step ``i`` judged on its state: the values after its last message."""
    r.i, r.vals = i, r.st.values()
    verdict: TraceVerdict | None = step(r)
    return verdict


def _at_end(r: _Run, nodes: list[str]) -> TraceVerdict:
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
        return TraceVerdict("true", n, f"{_text(ops[0])} holds at every step of this trace ({n} steps): "
                                       "evidence for the requirement, not a proof", **end)
    if tracker is not None and tracker.pending is None:
        return TraceVerdict("true", n, f"every step where {_text(ops[0])} held was answered by {_text(ops[1])} in "
                                       f"time in this trace ({n} steps): evidence for the requirement, not a proof",
                            **end, spare=tracker.spare())
    if tracker is not None:
        return TraceVerdict("currently_false", n, f"{_text(ops[0])} held at step {tracker.pending} and {_text(ops[1])} has "
                                                  f"not held since when the trace ended after {n} steps (a longer run "
                                                  "may still answer it in time): inconclusive", **end)
    if r.kind == "next":
        return TraceVerdict("inconclusive", n, "the trace ended before step 1", **end)
    also = (f"; undecided at some steps, the first {undecided['step']} ({undecided['where']})"
            if undecided is not None else "")
    return TraceVerdict("currently_false", n, f"{_text(ops[-1])} has not held when the trace ended after {n} "
                                              f"steps (a longer run may still reach it): inconclusive{also}",
                        **end, witness=[undecided] if undecided else [])


def _text(f: Formal) -> str:
    return expr_to_rcl(f.expr)


__all__ = ["TraceVerdict", "VERDICTS", "check_temporal_trace"]
