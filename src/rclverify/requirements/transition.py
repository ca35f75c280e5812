"""The composed contracts of a requirement's cone as a transition system.

The paper's stream model (lines 462-495): each contract consumes one input
element and produces at most one output element satisfying its guarantee,
and outputs persist.  Read over steps (docs/requirements.md, "The
transition relation"):

* a **state** gives a value to every input and output of every node of the
  cone (``Node.in.x``, ``Node.out.y``; a function-typed variable is a Z3
  array) and to every declared state variable (``Node.state.v``,
  :mod:`rclverify.plan.state`);
* **in every state** the environment conjuncts of the cone's assumptions
  and the plan's environment facts hold (what the environment is known or
  assumed to do, as in a state requirement), and every node whose internal
  assumption holds on its current input produces an output satisfying its
  guarantees over that input;
* **one step** from ``s`` to ``t``: every connection feeds the next input
  element, ``t[Consumer.in.x] == s[Producer.out.y]``; a node whose internal
  assumption fails on ``t``'s input produces nothing and its outputs keep
  their value (they persist); each state variable takes the value its
  ``next`` formula gives from ``s``; the environment's inputs are free;
* **initial states**: every declared state variable satisfies its ``init``;
  the first input elements are otherwise unconstrained (they come from
  before the run), so nothing is assumed about them that the contracts do
  not say.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Sequence

import z3

from ..calculus.compose import split_assumption
from ..logic.encode import Encoder, sort_of
from ..plan.load import Plan
from ..plan.state import parse_state_formula, state_type
from ..rcl.printer import expr_to_rcl
from ..rcl.types import NATURAL, Checked, EmptyT, FuncT, Type
from ..system.model import SystemModel
from .temporal import State, TransitionSystem


def _sort(t: Type) -> z3.SortRef:
    if isinstance(t, FuncT):
        return z3.ArraySort(*[sort_of(a) for a in t.args], sort_of(t.result))
    return sort_of(t)


def _typing(v: z3.ExprRef, t: Type) -> z3.BoolRef | None:
    """NATURAL values are >= 0 (the encoder's typing axioms, per step)."""
    if t == NATURAL:
        return v >= 0
    if isinstance(t, FuncT) and t.result == NATURAL:
        xs = [z3.Const(f"_t{k}", sort_of(a)) for k, a in enumerate(t.args)]
        return z3.ForAll(xs, z3.Select(v, *xs) >= 0)
    return None


@dataclass
class ComposedSystem:
    """The transition system of a cone and how to read it.

    ``ts``        the :class:`~.temporal.TransitionSystem` (variables named
                  ``Node.in.x`` / ``Node.out.y`` / ``Node.state.v``);
    ``cone``      the nodes, in source order;
    ``variables`` ``{name: (node, "in"|"out"|"state", var)}``;
    ``premises``  what the system is made of, for the record: ``{label,
                  kind, node, index, text, source}`` per guarantee,
                  assumption, fact and state declaration.
    """

    ts: TransitionSystem
    cone: list[str]
    variables: dict[str, tuple[str, str, str]]
    premises: list[dict[str, Any]] = field(default_factory=list)

    def statement_symbols(self, s: State) -> dict[str, Any]:
        """The encoder's symbols of a requirement statement at state ``s``
        (:mod:`rclverify.plan.formal` names ``Node.in.x`` an input of its
        pseudo node, so the key is ``"in.Node.in.x"``)."""
        out = {}
        for name, (_, p, _) in self.variables.items():
            out[f"{'out' if p == 'out' else 'in'}.{name}"] = s[name]
        return out


def variable_types(sys: ComposedSystem, checked: Checked, plan: Plan) -> dict[str, Type]:
    """The RCL type of each variable of ``sys`` (``{name: type}``)."""
    out: dict[str, Type] = {}
    declared = {(sv.node, sv.name): sv for sv in plan.states}
    for name, (n, p, v) in sys.variables.items():
        cn = checked.nodes[n]
        out[name] = state_type(declared[(n, v)], checked) if p == "state" else (cn.inputs if p == "in" else cn.outputs)[v]
    return out


def build_system(cone: Sequence[str], checked: Checked, model: SystemModel, plan: Plan) -> ComposedSystem:
    """The transition system of ``cone`` (module docstring).

    Raises :class:`~rclverify.rcl.errors.RclError` for a state declaration
    that does not check (the plan's ``resolve`` reports those first).
    """
    enc = Encoder(checked.env)
    sorts: dict[str, z3.SortRef] = {}
    types: dict[str, Type] = {}
    variables: dict[str, tuple[str, str, str]] = {}
    premises: list[dict[str, Any]] = []
    for n in cone:
        cn = checked.nodes[n]
        for p, table in (("in", cn.inputs), ("out", cn.outputs)):
            for v, t in table.items():
                if isinstance(t, EmptyT):  # no value to hold (the encoder refuses any formula using it)
                    continue
                name = f"{n}.{p}.{v}"
                sorts[name], types[name], variables[name] = _sort(t), t, (n, p, v)
    states = [sv for sv in plan.states if sv.node in cone]
    for sv in states:
        name = f"{sv.node}.state.{sv.name}"
        t = state_type(sv, checked)
        sorts[name], types[name], variables[name] = _sort(t), t, (sv.node, "state", sv.name)

    def where(e: Any) -> str:
        return f"{e.loc.file}:{e.loc.line}:{e.loc.col}"

    guarantees, internal, env, facts = {}, {}, {}, {}
    for n in cone:
        cn = checked.nodes[n]
        guarantees[n] = [g.formula for g in cn.node.guarantees]
        internal[n], env[n] = split_assumption(checked, model, n)
        facts[n] = [f.expr for f in plan.facts.get(n, ())]
        for k, g in enumerate(guarantees[n], 1):
            premises.append({"label": f"{n} guarantee {k}", "kind": "guarantee", "node": n, "index": k,
                             "text": expr_to_rcl(g), "source": where(g)})
        for k, a in enumerate(internal[n], 1):
            premises.append({"label": f"{n} assumption {k}", "kind": "internal assumption", "node": n, "index": k,
                             "text": expr_to_rcl(a), "source": where(a)})
        for k, a in enumerate(env[n], 1):
            premises.append({"label": f"{n} environment assumption {k}", "kind": "environment assumption", "node": n,
                             "index": k, "text": expr_to_rcl(a), "source": where(a)})
        for k, f in enumerate(plan.facts.get(n, ()), 1):
            premises.append({"label": f"{n} environment fact {k}", "kind": "environment fact", "node": n,
                             "index": k, "text": f.text, "source": where(f.expr)})
    parsed = {}
    for sv in states:
        parsed[sv] = (parse_state_formula(sv, "init", checked, plan.states),
                      parse_state_formula(sv, "next", checked, plan.states))
        for which, src in (("init", sv.init), ("next", sv.next)):
            premises.append({"label": f"{sv.node}.state.{sv.name} {which}", "kind": "state declaration",
                             "node": sv.node, "index": 0, "text": " ".join(src.text.split()),
                             "source": f"{src.file}:{src.loc.line}:{src.loc.col}"})

    def node_symbols(n: str, s: State) -> dict[str, Any]:
        cn = checked.nodes[n]
        return {**{f"in.{v}": s[f"{n}.in.{v}"] for v in cn.inputs if f"{n}.in.{v}" in s},
                **{f"out.{v}": s[f"{n}.out.{v}"] for v in cn.outputs if f"{n}.out.{v}" in s}}

    def holds(n: str, e: Any, s: State) -> z3.BoolRef:
        return enc.formula(e, checked.nodes[n], node_symbols(n, s))

    def assumed(n: str, s: State) -> z3.BoolRef:
        return z3.And(*[holds(n, a, s) for a in internal[n]]) if internal[n] else z3.BoolVal(True)

    # what valid/trans encode is a function of the states' terms: encoded once per state (pair).  The
    # cache keeps the terms it is keyed by alive, so their ids cannot be reused for other terms.
    memo: dict[tuple[int, ...], tuple[list[z3.ExprRef], z3.BoolRef]] = {}

    def cached(tag: int, states_: tuple[State, ...], make: Any) -> z3.BoolRef:
        terms = [st[name] for st in states_ for name in sorts]
        key = (tag, *[x.get_id() for x in terms])
        hit = memo.get(key)
        if hit is None:
            hit = memo[key] = (terms, make())
        return hit[1]

    def valid(s: State) -> z3.BoolRef:
        return cached(0, (s,), lambda: _valid(s))

    def _valid(s: State) -> z3.BoolRef:
        parts = [c for c in (_typing(s[name], types[name]) for name in sorts) if c is not None]
        for n in cone:
            parts += [holds(n, a, s) for a in env[n]] + [holds(n, f, s) for f in facts[n]]
            if guarantees[n]:
                parts.append(z3.Implies(assumed(n, s), z3.And(*[holds(n, g, s) for g in guarantees[n]])))
        return z3.And(*parts)

    alias = model.alias()
    links = [(f"{c}.in.{v}", producer) for (c, p, v), producer in alias.items()
             if c in cone and producer in sorts]

    def state_syms(sv: Any, s: State, t: State | None) -> dict[str, Any]:
        out = node_symbols(sv.node, s) if t is not None else {}
        for o in states:
            if o.node == sv.node:
                out[f"in.state.{o.name}"] = s[f"{o.node}.state.{o.name}"]
                if t is not None:
                    out[f"in.next.{o.name}"] = t[f"{o.node}.state.{o.name}"]
        return out

    def init(s: State) -> z3.BoolRef:
        return z3.And(valid(s), *[enc.formula(parsed[sv][0].expr, parsed[sv][0].scope, state_syms(sv, s, None))
                                  for sv in states])

    def trans(s: State, t: State) -> z3.BoolRef:
        return cached(1, (s, t), lambda: _trans(s, t))

    def _trans(s: State, t: State) -> z3.BoolRef:
        parts = [valid(s), valid(t)] + [t[c] == s[p] for c, p in links]
        for n in cone:
            outs = [t[f"{n}.out.{v}"] == s[f"{n}.out.{v}"] for v in checked.nodes[n].outputs if f"{n}.out.{v}" in s]
            if internal[n] and outs:
                parts.append(z3.Implies(z3.Not(assumed(n, t)), z3.And(*outs)))
        parts += [enc.formula(parsed[sv][1].expr, parsed[sv][1].scope, state_syms(sv, s, t)) for sv in states]
        return z3.And(*parts)

    return ComposedSystem(TransitionSystem(sorts, init, trans), list(cone), variables, premises)
