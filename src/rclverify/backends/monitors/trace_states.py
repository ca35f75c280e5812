"""The steps of a recorded run and their states, for a temporal requirement
checked on it (:mod:`.temporal_trace`).

A step is a step of the composed system (docs/semantics.md, "Steps"):
:class:`~.step_clock.StepClock` gives each message its step over the topics of a
statement's cone (:func:`~.step_clock.cone_of`).

The inputs and outputs of the nodes a statement reads are mapped from the
messages on their topics (:mod:`rclverify.traces.mapping`); a declared state
variable (the plan's ``state:``, :mod:`rclverify.model.plan.state`) takes the
value its ``init`` (step 0) or ``next`` (from step i's values) defines,
found by Z3 on the concrete values (:func:`solve_value`) and used only when
the formula defines exactly one value.
"""
from __future__ import annotations

from fractions import Fraction
from typing import Any, Iterable, Mapping

import z3

from rclverify.semantics.concrete import finite_interpretation, to_z3
from rclverify.semantics.encode import EncodingError, Encoder
from rclverify.model.plan.state import StateFormula, StateVar, parse_state_formula
from rclverify.lang.types import Checked, EnumT, FuncT, Scalar, Type
from rclverify.traces.events import Event
from rclverify.traces.mapping import MappingError, TopicRule, initial_value, map_value, rule_for
from rclverify.semantics.values import FiniteFunction
from rclverify.semantics import wallclock
from rclverify.backends.monitors.verdicts import LINK_TOPICS
from rclverify.backends.monitors.first_messages import NO_START

#: :func:`solve_value`'s answer when a value the formula reads is not observed yet.
MISSING = object()
#: Z3's budget per state update (ms).
TIMEOUT_MS = 2_000


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


def _function_value(m: z3.ModelRef, decl: z3.FuncDeclRef, t: FuncT, values: Mapping[str, object],
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

    def at(x: Any) -> Any:
        return _from_z3(m.eval(decl(to_z3(x, a, enc)), model_completion=True), t.result)

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


def solve_value(sf: StateFormula, checked: Checked, target: str, values: Mapping[str, object]) -> Any:
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
        wallclock.limit(s, TIMEOUT_MS)  # steps decide, the clock is a net
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
    docstring): :meth:`feed` each event of a step, :meth:`advance` at the
    step's end, :meth:`values` the state (keyed as the statement's scope
    reads them: ``"in.Node.in.x"``, ``"out.Node.out.y"``,
    ``"in.Node.state.v"``)."""

    def __init__(self, checked: Checked, nodes: Iterable[str], states: tuple[StateVar, ...],
                 rules: Mapping[str, TopicRule], firsts: Iterable[str] = ()) -> None:
        self.checked, self.rules = checked, rules
        #: the inputs (``Node.in.x``) a ``first(...)`` of the statement reads, and which of them took their first
        #: message in this step (docs/semantics.md, "The first published value"; decided only after the
        #: run's start-of-run marker, :meth:`start`)
        self.firsts = {tuple(c.split(".in.", 1)) for c in firsts}
        self.fresh: set[tuple[str, str]] = set()
        self.heard: set[tuple[str, str]] = set()
        self.from_start = False
        self.nodes = list(nodes)
        #: topic -> [(node, "in.x", type, part)]: ``part`` the action message part that carries it (``""``: the
        #: whole message); a link's parts are on ``link/request`` ... ``link/result``, as a live log's call lines
        self.topics: dict[str, list[tuple[str, str, Type, str]]] = {}
        self.io: dict[str, dict[str, object]] = {n: {} for n in self.nodes}
        for n in self.nodes:
            cn = checked.nodes[n]
            bound = [(t.field.lstrip("/"), t.match, "") for t in cn.node.topics if t.match is not None]
            bound += [(f"{lk.name.strip('/')}/{suffix}", v, suffix if lk.kind == "action" else "")
                      for lk in cn.node.links for suffix, v in zip(LINK_TOPICS[lk.kind], lk.parts)]
            for topic, var, part in bound:
                typ = cn.io_type(var)
                if typ is None:
                    continue
                inp = var.prefix == "in" or (var.prefix is None and var.name in cn.inputs)
                key = ("in." if inp else "out.") + var.name
                self.topics.setdefault(topic, []).append((n, key, typ, part))
                self.io[n][key] = initial_value(typ, rule_for(rules, topic, key))
        self.vars = [sv for sv in states if sv.node in self.nodes]
        self.formulas = {(sv.node, sv.name): (parse_state_formula(sv, "init", checked, states),
                                              parse_state_formula(sv, "next", checked, states)) for sv in self.vars}
        self.state: dict[tuple[str, str], Any] = {}
        for sv in self.vars:  # step 0: the value its init defines
            v = solve_value(self.formulas[(sv.node, sv.name)][0], self.checked, f"state.{sv.name}", {})
            self.state[(sv.node, sv.name)] = None if v is MISSING else v
        self.problem = ""
        #: scope keys (``"in.Node.in.x"``) whose last message could not be read (a string for a REAL, NaN, a
        #: bool): no value, and what reads them is undecided, never judged on the value before
        self.unreadable: dict[str, str] = {}
        #: inputs read only from the next step on (an output of another node, :class:`~.step_clock.StepClock`)
        self.pending: dict[tuple[str, str], tuple[object, str | None]] = {}
        self.pending_event: Event | None = None

    def _node_values(self, n: str) -> dict[str, object]:
        out = {k: v for k, v in self.io[n].items() if v is not None}
        out.update({f"state.{v}": x for (m, v), x in self.state.items() if m == n and x is not None})
        return out

    def feed(self, ev: Event, later: Iterable[str] = (), part_fields: Mapping[str, Any] | None = None) -> bool:
        """Apply one event: its values are the state's now, but an input of
        a node of ``later`` is read from the next step on (:meth:`advance`);
        ``part_fields`` a call line's fields (the link part's own).  Returns
        whether a value of the state changed now (on a topic of the nodes,
        not all of it read from the next step on)."""
        vs = self.topics.get(ev.topic.lstrip("/"))
        if not vs:
            return False
        now = False
        for n, key, typ, part in vs:
            p, _, name = key.partition(".")
            fields = part_fields if part_fields is not None else ev.fields.get(part) if part else ev.fields
            if not isinstance(fields, Mapping):
                continue  # an action message without this part
            try:
                value: object = map_value(typ, fields, rule_for(self.rules, ev.topic, key), self.io[n].get(key))
                bad = None
            except MappingError as exc:
                value, bad = None, f"{ev.where}: {n}.{key}: {exc}"
                self.problem = self.problem or bad
            if p == "in" and n in later:
                self.pending[(n, key)] = (value, bad)
                self.pending_event = ev
                continue
            self._set(n, key, value, bad)
            now = True
        return now

    def start(self) -> None:
        """The run's start-of-run marker was read: a topic's first message after it is its first."""
        self.from_start = True

    def _set(self, n: str, key: str, value: object, bad: str | None) -> None:
        p, _, name = key.partition(".")
        self.io[n][key] = value
        if p == "in" and value is not None and (n, name) in self.firsts and (n, name) not in self.heard:
            self.heard.add((n, name))
            self.fresh.add((n, name))
        if bad is None:
            self.unreadable.pop(f"{p}.{n}.{p}.{name}", None)
        else:
            self.unreadable[f"{p}.{n}.{p}.{name}"] = bad

    def advance(self) -> Event | None:
        """The next step: each state variable takes the value its ``next``
        defines from this step's values (kept while a value it reads is not
        observed yet: the node has taken no step), then the inputs read from
        the next step on become current.  Returns the last message whose
        values became current so (``None``: none)."""
        before = {n: self._node_values(n) for n in {sv.node for sv in self.vars}}
        for sv in self.vars:
            v = solve_value(self.formulas[(sv.node, sv.name)][1], self.checked, f"next.{sv.name}", before[sv.node])
            if v is not MISSING:
                self.state[(sv.node, sv.name)] = v
        self.fresh.clear()  # the step judged is over: its first messages are behind
        for (n, key), (value, bad) in self.pending.items():
            self._set(n, key, value, bad)
        self.pending.clear()
        ev, self.pending_event = self.pending_event, None
        return ev

    def values(self) -> dict[str, object]:
        """The state of the current step, keyed for a statement's scope."""
        out: dict[str, object] = {}
        for n in self.nodes:
            for k, v in self.io[n].items():
                if v is not None:
                    p, _, name = k.partition(".")
                    out[f"{p}.{n}.{p}.{name}"] = v
        for (n, v), x in self.state.items():
            if x is not None:
                out[f"in.{n}.state.{v}"] = x
        for n, x in self.firsts:  # first(Node.in.x): a Boolean, or why it is unknown (first_messages.py)
            if (n, x) in self.heard:
                out[f"first(in.{n}.in.{x})"] = (n, x) in self.fresh if self.from_start else NO_START.format(
                    k=f"{n}.in.{x}")
        return out


__all__ = ["MISSING", "TIMEOUT_MS", "TraceStates", "solve_value"]
