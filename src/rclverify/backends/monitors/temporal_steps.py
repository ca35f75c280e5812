"""One temporal statement judged step by step on a recorded run
(:mod:`.temporal_trace`, whose module docstring gives the finite-trace
verdicts): the verdict (:class:`TraceVerdict`), the operands' truth at a
step judged as the node monitors judge (:func:`rclverify.semantics.floatsem.judge`),
the run's state as the steps go (:class:`StepRun`), and what each decided
shape checks at one step (:data:`STEPS`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping

import z3

from rclverify.semantics.floatsem import judge
from rclverify.semantics.encode import EncodingError
from rclverify.model.plan.formal import Formal
from rclverify.backends.monitors.response_trace import ResponseTracker
from rclverify.backends.monitors.trace_states import TraceStates
from rclverify.lang.types import Checked
from rclverify.traces.events import Event
from rclverify.semantics.values import render
from rclverify.lang.printer import expr_to_rcl
from rclverify.backends.monitors.shapes import TraceVerdictJson, Witness


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
class StepRun:
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
        out: Witness = {"step": self.i, "time": ev.time, "where": ev.where, "operand": operand_text(f),
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



def _step_always(r: StepRun) -> TraceVerdict | None:
    """``always F`` and ``always next F``: false at the first step where F is false."""
    if r.kind == "always next" and r.i == 0:
        return None
    f = r.ops[0]
    h = r.decide(f, True)  # a value it reads never published: not evaluated (docs/semantics.md)
    if h is False:
        return r.at("false", f"{operand_text(f)} is false at step {r.i} ({r.where()})", [r.wit(f, False)])
    r.note(f, h)
    return None



def _step_response(r: StepRun) -> TraceVerdict | None:
    """The response pattern (response_trace.py): false when a trigger goes unanswered in time."""
    assert r.tracker is not None
    said = r.tracker.step(r.i, r.decide(r.ops[0], False), r.decide(r.ops[1], False))
    if said is not None and said[0] == "false":
        return r.at("false", f"{operand_text(r.ops[0])} held at step {said[1]} and {operand_text(r.ops[1])} did not hold in "
                             f"time, by step {r.i} ({r.where()})", [r.wit(r.ops[1], False)])
    if said is not None and r.undecided is None:
        r.undecided = r.wit(r.ops[said[1]], None)
    return None



def _step_next(r: StepRun) -> TraceVerdict | None:
    """``next F``: decided at step 1."""
    if r.i != 1:
        return None
    h = r.decide(r.ops[0], False)
    v = {True: "true", False: "false", None: "inconclusive"}[h]
    return r.at(v, f"{operand_text(r.ops[0])} is {v if h is not None else 'undecided'} at step 1", [r.wit(r.ops[0], h)])



def _step_eventually(r: StepRun) -> TraceVerdict | None:
    """``eventually[<= N] F``: true at the first step where F holds (reached only on published values)."""
    f = r.ops[0]
    h = r.decide(f, False)
    if h is True:
        v = r.at("true", f"{operand_text(f)} holds at step {r.i} ({r.where()})", [r.wit(f, True)])
        v.spare = None if r.bound is None else r.bound - r.i
        return v
    r.note(f, h)
    if r.bound is not None and r.i >= r.bound:
        if r.undecided is not None:
            return r.at("inconclusive", f"not met within {r.bound} steps, but undecided at step "
                                        f"{r.undecided['step']}", [r.undecided])
        return r.at("false", f"{operand_text(f)} does not hold at any step 0..{r.bound}: the bound passed "
                             f"at step {r.i} ({r.where()})", [r.wit(f, False)])
    return None



def _step_until(r: StepRun) -> TraceVerdict | None:
    """``F until G``: true when G holds with F at every step before, false when F fails first."""
    f_op, g_op = r.ops[0], r.ops[1]
    g = r.decide(g_op, False)
    if g is True and r.undecided is None:
        return r.at("true", f"{operand_text(g_op)} holds at step {r.i}, {operand_text(f_op)} at every step before",
                    [r.wit(g_op, True)])
    r.note(g_op, g)
    if g is not True:
        f = r.decide(f_op, True)
        if f is False and r.undecided is None:
            return r.at("false", f"{operand_text(f_op)} is false at step {r.i} before {operand_text(g_op)} held",
                        [r.wit(f_op, False)])
        r.note(f_op, f)
    return None



#: What each decided shape (model/plan/temporal.py, ``shape``) checks at one step.
STEPS = {"always": _step_always, "always next": _step_always, "response": _step_response, "next": _step_next,
          "eventually": _step_eventually, "until": _step_until}



def operand_text(f: Formal) -> str:
    return expr_to_rcl(f.expr)
