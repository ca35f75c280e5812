"""A temporal requirement checked on a recorded run (docs/monitors.md, "Temporal requirements on traces").

The statement is one of the decided shapes of
:func:`rclverify.model.plan.temporal.shape` (``always F``, ``always next F``,
``eventually F``, ``eventually[<= N] F``, ``next F``, ``F until G``) over
``Node.in.x``/``Node.out.y``/``Node.state.v``.

**Steps of a trace.**  The nodes the statement reads have a state, the
latest value of each input and output mapped from the messages on their
topics (:mod:`rclverify.traces.mapping`, as the node monitors of
:mod:`.check` keep it: outputs persist until changed, the stream model of
paper lines 462-495).  Every message on one of those topics is one *step*:
step i is the state after the i-th such message (messages on other topics
change nothing the statement reads and are no step).  A declared state
variable (the plan's ``state:``, :mod:`rclverify.model.plan.state`) has at step 0
the value its ``init`` defines and at step i+1 the value its ``next``
defines from step i's state and the node's inputs and outputs at step i,
as in the composed system (:mod:`rclverify.calculus.requirements.transition`).  Both
are found by Z3 on the concrete values, and used only when the formula
defines exactly one value (else the variable has no value from there on,
and what reads it is undecided).

**Operands** are decided at each step by the judgement of the node monitors
(:func:`rclverify.semantics.floatsem.judge`: direct evaluation, Z3 on concrete
values when it cannot, then the nodes' double arithmetic and the mapping's
tolerance, docs/monitors.md "Numbers on the wire"; a witness of an operand
that held only there names the semantics).  A variable not observed yet has
no value, and an operand reading one is not evaluated at that step (the one
stream model, docs/semantics.md, issue 47): ``always F`` constrains
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
from fractions import Fraction
from typing import Any, Iterable, Mapping

import z3

from rclverify.semantics.concrete import finite_interpretation, to_z3
from rclverify.semantics.floatsem import judge
from rclverify.semantics.encode import EncodingError, Encoder
from rclverify.model.plan.formal import Formal
from rclverify.model.plan.state import StateFormula, StateVar, parse_state_formula, state_type
from rclverify.model.plan.temporal import Temporal, shape
from rclverify.backends.monitors.response_trace import ResponseTracker
from rclverify.lang.types import Checked, EnumT, FuncT, Scalar, Type
from rclverify.traces.events import Event
from rclverify.traces.mapping import MappingError, TopicRule, initial_value, map_value, rule_for
from rclverify.semantics.values import FiniteFunction, render

VERDICTS = ("true", "false", "currently_false", "inconclusive")
#: :func:`solve_value`'s answer when a value the formula reads is not observed yet.
MISSING = object()
#: Z3's budget per state update (ms).
TIMEOUT_MS = 2_000


@dataclass
class TraceVerdict:
    """The verdict of one temporal statement on one trace (module table).

    ``verdict`` one of :data:`VERDICTS`; ``step``/``time``/``where`` where it
    was decided (``None`` when at the end of the trace); ``steps`` the
    number of steps; ``witness`` ``[{"step", "time", "where", "operand",
    "holds", "values"}]``; ``reason`` one sentence.
    """

    verdict: str
    steps: int
    reason: str
    step: int | None = None
    time: float | None = None
    where: str = ""
    witness: list[dict[str, Any]] = field(default_factory=list)

    def to_json(self) -> dict[str, Any]:
        return {"verdict": self.verdict, "steps": self.steps, "reason": self.reason, "step": self.step,
                "time": self.time, "where": self.where, "witness": self.witness}


def _from_z3(v: z3.ExprRef, t: Type) -> Any:
    """A Z3 model value as a value of :mod:`rclverify.semantics.values` (None if not a literal)."""
    if isinstance(t, Scalar):
        if t.name == "BOOL":
            return True if z3.is_true(v) else False if z3.is_false(v) else None
        if z3.is_int_value(v):
            return v.as_long()
        if z3.is_rational_value(v):
            f = Fraction(v.numerator_as_long(), v.denominator_as_long())
            return int(f) if f.denominator == 1 and t.name != "REAL" else f
        return None
    if isinstance(t, EnumT):
        return str(v) if z3.is_const(v) and v.num_args() == 0 else None
    return None


def _numbers(v: Any, out: set[Any]) -> None:
    """Every number in a value (table keys and results, constructor arguments)."""
    if isinstance(v, bool):
        return
    if isinstance(v, (int, float, Fraction)):
        out.add(v)
    elif isinstance(v, FiniteFunction):
        for k, r in v.table.items():
            _numbers(k, out)
            _numbers(r, out)
    elif isinstance(v, (tuple, list, frozenset, set)):
        for x in v:
            _numbers(x, out)
    elif hasattr(v, "args") and isinstance(getattr(v, "args"), tuple):
        _numbers(v.args, out)


def _function_value(m: z3.ModelRef, decl: z3.FuncDeclRef, t: FuncT, values: Mapping[str, Any],
                    enc: Encoder) -> FiniteFunction | None:
    """A candidate finite table for function ``decl`` in model ``m``: its
    value at every point built from the numbers of ``values`` and at one
    point beyond them (the default).  The caller checks it is the only
    solution, so a wrong candidate is never used.  Unary functions over
    numbers only (else ``None``)."""
    if len(t.args) != 1 or not isinstance(t.args[0], Scalar) or t.args[0].name == "BOOL":
        return None
    a = t.args[0]
    nums: set[Any] = set()
    _numbers(list(values.values()), nums)
    pts = {x if a.name == "REAL" else int(x) for x in nums if a.name == "REAL" or Fraction(x).denominator == 1}
    pts = {x for x in pts if a.name != "NATURAL" or x >= 0}
    beyond = max(pts, default=0) + 1
    at = lambda x: _from_z3(m.eval(decl(to_z3(x, a, enc)), model_completion=True), t.result)  # noqa: E731
    default = at(beyond)
    if default is None:
        return None
    table = {}
    for x in sorted(pts):
        r = at(x)
        if r is None:
            return None
        if r != default:
            table[(x,)] = r
    return FiniteFunction(table, default, 1)


def solve_value(sf: StateFormula, checked: Checked, target: str, values: Mapping[str, Any]) -> Any:
    """The one value of ``target`` (``"state.v"`` for ``init``, ``"next.v"``
    for ``next``) that makes ``sf`` true with every other variable at its
    value in ``values`` (keyed ``"in.x"``, ``"out.y"``, ``"state.v"``).
    Returns :data:`MISSING` when a value it reads is not observed yet,
    ``None`` when Z3 cannot decide, or the
    formula does not define exactly one value (docs/plan.md, "state": a
    ``next`` must be a definition).  Never raises."""
    enc = Encoder(checked.env)
    try:
        phi = enc.formula(sf.expr, sf.scope)
        consts, funcs, goal = [], [], None
        for sym in enc.symbols.values():
            name = sym.z3name.split(".", 1)[1]  # "<Node>.in.state.v" -> "in.state.v"
            bare = name[3:] if name.startswith(("in.state.", "in.next.")) else name
            if bare == target:
                goal = sym
                continue
            v = values.get(bare)
            if v is None:
                return MISSING
            t = sym.type
            if isinstance(t, FuncT):
                if not isinstance(v, FiniteFunction):
                    return None
                funcs.append((sym.decl, finite_interpretation(v, t, enc)))
            else:
                consts.append((sym.decl, to_z3(v, t, enc)))
        if goal is None:
            return None
        if consts:
            phi = z3.substitute(phi, *consts)
        if funcs:
            phi = z3.substitute_funs(phi, *funcs)
        s = z3.Solver()
        s.set("timeout", TIMEOUT_MS)
        s.add(phi)
        if s.check() != z3.sat:
            return None
        m = s.model()
        t = goal.type
        if isinstance(t, FuncT):
            value = _function_value(m, goal.decl, t, values, enc)
            if value is None:
                return None
            xs = [z3.FreshConst(d) for d in [goal.decl.domain(k) for k in range(goal.decl.arity())]]
            body = finite_interpretation(value, t, enc)
            differs = z3.And(goal.decl(*xs) != z3.substitute_vars(body, *reversed(xs)),
                             *[x >= 0 for x, a in zip(xs, t.args) if isinstance(a, Scalar) and a.name == "NATURAL"])
        else:
            value = _from_z3(m.eval(goal.decl, model_completion=True), t)
            if value is None:
                return None
            differs = goal.decl != to_z3(value, t, enc)
        s.add(differs)  # unique: no other value satisfies the formula
        return value if s.check() == z3.unsat else None
    except (EncodingError, ValueError, TypeError, KeyError, z3.Z3Exception):
        return None


class TraceStates:
    """The states of the steps of a trace for the nodes ``nodes`` (module
    docstring): :meth:`feed` one event, ``values`` the state (keyed as the
    statement's scope reads them: ``"in.Node.in.x"``, ``"out.Node.out.y"``,
    ``"in.Node.state.v"``)."""

    def __init__(self, checked: Checked, nodes: Iterable[str], states: tuple[StateVar, ...],
                 rules: Mapping[str, TopicRule]) -> None:
        self.checked, self.rules = checked, rules
        self.nodes = list(nodes)
        self.topics: dict[str, list[tuple[str, str, Type]]] = {}  # topic -> [(node, "in.x", type)]
        self.io: dict[str, dict[str, Any]] = {n: {} for n in self.nodes}
        for n in self.nodes:
            cn = checked.nodes[n]
            for t in cn.node.topics:
                typ = cn.io_type(t.match) if t.match is not None else None
                if typ is None:
                    continue
                inp = t.match.prefix == "in" or (t.match.prefix is None and t.match.name in cn.inputs)
                key = ("in." if inp else "out.") + t.match.name
                topic = t.field.lstrip("/")
                self.topics.setdefault(topic, []).append((n, key, typ))
                self.io[n][key] = initial_value(typ, rule_for(rules, topic, key))
        self.vars = [sv for sv in states if sv.node in self.nodes]
        self.formulas = {(sv.node, sv.name): (parse_state_formula(sv, "init", checked, states),
                                              parse_state_formula(sv, "next", checked, states)) for sv in self.vars}
        self.state: dict[tuple[str, str], Any] = {}
        self.steps = 0
        self.problem = ""
        #: scope keys (``"in.Node.in.x"``) whose last message could not be read (a string for a REAL, NaN, a
        #: bool): no value, and what reads them is undecided, never judged on the value before (issue 63, row 5)
        self.unreadable: dict[str, str] = {}

    def _node_values(self, n: str) -> dict[str, Any]:
        out = {k: v for k, v in self.io[n].items() if v is not None}
        out.update({f"state.{v}": x for (m, v), x in self.state.items() if m == n and x is not None})
        return out

    def feed(self, ev: Event) -> bool:
        """Apply one event; returns whether it is a step (on a topic of the nodes)."""
        vs = self.topics.get(ev.topic.lstrip("/"))
        if not vs:
            return False
        before = {n: self._node_values(n) for n in {sv.node for sv in self.vars}} if self.steps else {}
        for n, key, typ in vs:
            p, _, name = key.partition(".")
            try:
                self.io[n][key] = map_value(typ, ev.fields, rule_for(self.rules, ev.topic, key), self.io[n].get(key))
                self.unreadable.pop(f"{p}.{n}.{p}.{name}", None)
            except MappingError as exc:
                self.io[n][key] = None
                self.unreadable[f"{p}.{n}.{p}.{name}"] = f"{ev.where}: {n}.{key}: {exc}"
                self.problem = self.problem or f"{ev.where}: {n}.{key}: {exc}"
        for sv in self.vars:
            init, nxt = self.formulas[(sv.node, sv.name)]
            if self.steps == 0:
                v = solve_value(init, self.checked, f"state.{sv.name}", {})
            else:  # the node has not produced what next reads yet: no step of the node, the state is kept
                v = solve_value(nxt, self.checked, f"next.{sv.name}", before[sv.node])
                if v is MISSING:
                    continue
            self.state[(sv.node, sv.name)] = None if v is MISSING else v
        self.steps += 1
        return True

    def values(self) -> dict[str, Any]:
        """The state of the current step, keyed for a statement's scope."""
        out: dict[str, Any] = {}
        for n in self.nodes:
            for k, v in self.io[n].items():
                if v is not None:
                    p, _, name = k.partition(".")
                    out[f"{p}.{n}.{p}.{name}"] = v
        for (n, v), x in self.state.items():
            if x is not None:
                out[f"in.{n}.state.{v}"] = x
        return out


def _truth(f: Formal, checked: Checked, values: Mapping[str, Any], tolerance: Any = None,
           semantics: dict[int, str] | None = None) -> bool | None:
    """Operand ``f``'s truth on the step's values, judged as the node monitors
    judge (:func:`rclverify.semantics.floatsem.judge`: exact, then the nodes'
    double arithmetic, then a declared ``tolerance``); the semantics that
    decided goes to ``semantics[id(f)]``."""
    mine = {k: v for k, v in values.items() if k.partition(".")[2] in f.scope.inputs or
            k.partition(".")[2] in f.scope.outputs}
    try:
        j = judge(f.expr, checked, f.scope, mine, tolerance)
    except (KeyError, ValueError, TypeError, EncodingError, z3.Z3Exception):
        return None
    if semantics is not None:
        semantics[id(f)] = j.semantics
    return j.truth


def _published(f: Formal, values: Mapping[str, Any]) -> bool:
    """Whether every input and output operand ``f`` mentions has been
    published on this trace (docs/semantics.md: a state formula over a value
    never published is not evaluated; a state variable without a value stays
    undecided instead)."""
    for n, p, v in f.mentions:
        if p in ("in", "out") and f"{p}.{n}.{p}.{v}" not in values:
            return False
    return True


def _shown(f: Formal, values: Mapping[str, Any]) -> dict[str, str]:
    names = {f"{n}.{p}.{v}" for n, p, v in f.mentions}
    return {k.partition(".")[2]: render(v) for k, v in sorted(values.items()) if k.partition(".")[2] in names}


def check_temporal_trace(t: Temporal, checked: Checked, states: tuple[StateVar, ...], events: Iterable[Event],
                         rules: Mapping[str, TopicRule]) -> TraceVerdict:
    """The verdict of statement ``t`` on the recorded run ``events`` (module
    docstring).  ``states`` the plan's state declarations, ``rules`` the
    topic mapping.  Raises :class:`~rclverify.lang.errors.RclError` for a
    shape that is not decided and whatever the event source raises
    (:class:`~rclverify.traces.TraceError`)."""
    kind = shape(t, None)
    tracker: ResponseTracker | None = None
    if kind == "always next":
        ops: list[Formal] = [t.args[0].args[0]]  # type: ignore[union-attr]
    elif kind == "response":  # always (P -> eventually[<= N] Q) / always (P -> next Q)
        trig, resp = t.args[0].args  # type: ignore[union-attr]
        ops = [trig, resp.args[0]]  # type: ignore[list-item, union-attr]
        tracker = ResponseTracker((math.inf if resp.bound is None else resp.bound)  # type: ignore[union-attr]
                                  if resp.op == "eventually" else None)  # type: ignore[union-attr]
    else:
        ops = list(t.args)  # type: ignore[arg-type]
    nodes = list(dict.fromkeys(n for f in ops for n in f.nodes))
    for sv in states:
        state_type(sv, checked)
    st = TraceStates(checked, nodes, states, rules)
    tol = getattr(rules, "tolerance", None)  # the mapping's tolerance of recorded numbers
    sems: dict[int, str] = {}
    undecided: dict[str, Any] | None = None
    i = -1
    last: Event | None = None
    def decide(f: Formal, unpublished: bool | None) -> bool | None:
        """``f``'s truth at this step: undecided when a value it reads was unreadable in its last message,
        ``unpublished`` when one was never published, else judged."""
        if any(f"{p}.{n}.{p}.{v}" in st.unreadable for n, p, v in f.mentions):
            return None
        return _truth(f, checked, vals, tol, sems) if _published(f, vals) else unpublished

    for ev in events:
        if not st.feed(ev):
            continue
        i, last = i + 1, ev
        vals = st.values()

        def wit(f: Formal, holds: bool | None) -> dict[str, Any]:
            out = {"step": i, "time": ev.time, "where": ev.where, "operand": f.expr and _text(f),
                   "holds": holds, "values": _shown(f, vals)}
            bad = [st.unreadable[k] for n, p, v in f.mentions if (k := f"{p}.{n}.{p}.{v}") in st.unreadable]
            if bad:
                out["unreadable"] = bad
            if holds and sems.get(id(f), "exact") != "exact":  # held only in double arithmetic or the tolerance
                out["semantics"] = sems[id(f)]
            return out

        def at(verdict: str, why: str, w: list[dict[str, Any]]) -> TraceVerdict:
            return TraceVerdict(verdict, i + 1, why, i, ev.time, ev.where, w)
        if kind in ("always", "always next"):
            if kind == "always next" and i == 0:
                continue
            h = decide(ops[0], True)  # a value it reads never published: not evaluated (docs/semantics.md)
            if h is False:
                return at("false", f"{_text(ops[0])} is false at step {i} ({ev.where}, t = {ev.time} s)",
                          [wit(ops[0], False)])
            if h is None and undecided is None:
                undecided = wit(ops[0], None)
        elif tracker is not None:  # the response pattern (response_trace.py)
            said = tracker.step(i, decide(ops[0], False), decide(ops[1], False))
            if said is not None and said[0] == "false":
                return at("false", f"{_text(ops[0])} held at step {said[1]} and {_text(ops[1])} did not hold in "
                                   f"time, by step {i} ({ev.where}, t = {ev.time} s)", [wit(ops[1], False)])
            if said is not None and undecided is None:
                undecided = wit(ops[said[1]], None)
        elif kind == "next":
            if i == 1:
                h = decide(ops[0], False)
                v = {True: "true", False: "false", None: "inconclusive"}[h]
                return at(v, f"{_text(ops[0])} is {v if h is not None else 'undecided'} at step 1", [wit(ops[0], h)])
        elif kind == "eventually":  # reached only on published values
            h = decide(ops[0], False)
            if h is True:
                return at("true", f"{_text(ops[0])} holds at step {i} ({ev.where}, t = {ev.time} s)",
                          [wit(ops[0], True)])
            if h is None and undecided is None:
                undecided = wit(ops[0], None)
            if t.bound is not None and i >= t.bound:
                if undecided is not None:
                    return at("inconclusive", f"not met within {t.bound} steps, but undecided at step "
                                              f"{undecided['step']}", [undecided])
                return at("false", f"{_text(ops[0])} does not hold at any step 0..{t.bound}: the bound passed "
                                   f"at step {i} ({ev.where}, t = {ev.time} s)", [wit(ops[0], False)])
        else:  # until
            g = decide(ops[1], False)
            if g is True and undecided is None:
                return at("true", f"{_text(ops[1])} holds at step {i}, {_text(ops[0])} at every step before",
                          [wit(ops[1], True)])
            if g is None and undecided is None:
                undecided = wit(ops[1], None)
            if g is not True:
                f = decide(ops[0], True)
                if f is False and undecided is None:
                    return at("false", f"{_text(ops[0])} is false at step {i} before {_text(ops[1])} held",
                              [wit(ops[0], False)])
                if f is None and undecided is None:
                    undecided = wit(ops[0], None)
    n = i + 1
    end = {"step": i if n else None, "time": last.time if last else None, "where": last.where if last else ""}
    if n == 0:
        return TraceVerdict("inconclusive", 0, "the trace has no message on the topics of "
                                               f"{', '.join(nodes)}: nothing was checked")
    if undecided is not None and kind != "eventually":
        why = (f"a value it reads could not be read ({undecided['unreadable'][0]}), and the value before never "
               "stands in" if undecided.get("unreadable") else "a value it reads is not observed or not decidable there")
        return TraceVerdict("inconclusive", n, f"an operand is undecided at step {undecided['step']} "
                                               f"({undecided['where']}): {why}", undecided["step"], undecided["time"],
                            undecided["where"], [undecided])
    if kind in ("always", "always next"):
        return TraceVerdict("true", n, f"{_text(ops[0])} holds at every step of this trace ({n} steps): "
                                       "evidence for the requirement, not a proof", **end)
    if tracker is not None and tracker.pending is None:
        return TraceVerdict("true", n, f"every step where {_text(ops[0])} held was answered by {_text(ops[1])} in "
                                       f"time in this trace ({n} steps): evidence for the requirement, not a proof",
                            **end)
    if tracker is not None:
        return TraceVerdict("currently_false", n, f"{_text(ops[0])} held at step {tracker.pending} and {_text(ops[1])} has "
                                                  f"not held since when the trace ended after {n} steps (a longer run "
                                                  "may still answer it in time): inconclusive", **end)
    if kind == "next":
        return TraceVerdict("inconclusive", n, "the trace ended before step 1", **end)
    also = (f"; undecided at some steps, the first {undecided['step']} ({undecided['where']})"
            if undecided is not None else "")
    return TraceVerdict("currently_false", n, f"{_text(ops[-1])} has not held when the trace ended after {n} "
                                              f"steps (a longer run may still reach it): inconclusive{also}",
                        **end, witness=[undecided] if undecided else [])


def _text(f: Formal) -> str:
    from rclverify.lang.printer import expr_to_rcl
    return expr_to_rcl(f.expr)


__all__ = ["TraceStates", "TraceVerdict", "VERDICTS", "check_temporal_trace", "solve_value"]
