"""The composed contracts of a requirement's cone as a transition system.

The paper's stream model (lines 462-495): each contract consumes one input
element and produces at most one output element satisfying its guarantee,
and outputs persist.  Read over steps (docs/requirements.md, "The
transition relation"):

* a **state** gives a value to every input and output of every node of the
  cone (``Node.in.x``, ``Node.out.y``; a function-typed variable is a Z3
  array), to every declared state variable (``Node.state.v``,
  :mod:`rclverify.model.plan.state`) and, for every node with an output, to
  ``Node.answers`` (whether the node answers in that step), ``Node.accepts``
  (whether its assumption holds on that step's input; only for a node whose
  assumption reads a produced input) and, for a node with a step bound,
  ``Node.waiting`` (how many steps in a row its assumption has held
  without an answer);
* **in every state** the environment conjuncts of the cone's assumptions
  and the plan's environment facts hold (what the environment is assumed
  to do: every external input meets the assumptions of the nodes that read
  it), and a node that answers has its assumption hold and an output
  satisfying its guarantees over that input;
* **one step** from ``s`` to ``t``: every connection feeds the next input
  element, ``t[Consumer.in.x] == s[Producer.out.y]``; a node that does not
  answer keeps its outputs (they persist); each state variable takes the
  value its ``next`` formula gives from ``s``; the environment's inputs are
  free;
* **progress** (:mod:`rclverify.lang.liveness`): a node may answer late or
  never, unless it declares ``progress( within K steps )`` (no K + 1
  steps in a row at which its assumption holds without an answer; K = 0:
  it answers at every such step) or ``progress( eventually )``; every
  declared progress is also a fairness constraint (:class:`.tsys.Fairness`:
  on an infinite run on which its assumption holds infinitely often the
  node answers infinitely often);
* **initial states**: every declared state variable satisfies its
  ``init``; a node that does not answer at step 0 has outputs satisfying its
  ``initially`` (free without one);
* **published values** (:mod:`.published`, docs/semantics.md): an output
  holds a value only once its node has answered (or from the start, with
  ``initially``); a node answers only once every input another node feeds
  it has been published, and a requirement's state formula is evaluated on
  published values only.
"""
from __future__ import annotations

from typing import Any, Collection, Sequence

import z3

from rclverify.calculus.compose import split_assumption
from rclverify.semantics.connectives import conj, disj
from rclverify.semantics.encode import Encoder, sort_of
from rclverify.model.plan.load import Plan
from rclverify.model.plan.state import parse_state_formula, state_type
from rclverify.lang.liveness import STEP_WORDS, fair, progress_words, step_bound
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.types import BOOL, INTEGER, NATURAL, Checked, DataT, EmptyT, FuncT, Type
from rclverify.model.system.model import SystemModel
from rclverify.calculus.compose import free_io
from rclverify.calculus.requirements.composed import ComposedSystem
from rclverify.calculus.requirements.published import first_inputs, publication
from rclverify.calculus.requirements.temporal import State, TransitionSystem
from rclverify.calculus.requirements.tsys import Fairness, Pred


def _sort(t: Type) -> z3.SortRef:
    if isinstance(t, FuncT):
        return z3.ArraySort(*[sort_of(a) for a in t.args], sort_of(t.result))
    return sort_of(t)


def _typing(v: z3.ExprRef, t: Type) -> z3.BoolRef | None:
    """NATURAL values are >= 0 (the encoder's typing axioms, per step), also
    a constructor's NATURAL argument (``inspect(NATURAL)``: a value kept
    from before the run is still a value of its type)."""
    if t == NATURAL:
        return v >= 0
    if isinstance(t, DataT):
        ds = v.sort()
        parts = []
        for i in range(ds.num_constructors()):
            args = t.ctor(ds.constructor(i).name()) or ()
            parts += [z3.Implies(ds.recognizer(i)(v), ds.accessor(i, j)(v) >= 0)
                      for j, a in enumerate(args) if a == NATURAL]
        return conj(*parts) if parts else None
    if isinstance(t, FuncT) and t.result == NATURAL:
        xs = [z3.Const(f"_t{k}", sort_of(a)) for k, a in enumerate(t.args)]
        return z3.ForAll(xs, z3.Select(v, *xs) >= 0)
    return None


def build_system(cone: Sequence[str], checked: Checked, model: SystemModel, plan: Plan, *,
                 without_initially: Collection[str] = (), firsts: Collection[str] = ()) -> ComposedSystem:
    """The transition system of ``cone`` (module docstring); the nodes of
    ``without_initially`` are built as if they declared no ``initially``
    (nothing published before their first answer), to ask whether a proof
    needs their declarations (:mod:`.temporal_check`); ``firsts`` the inputs
    (``C.in.x``) a statement's ``first(...)`` reads, each given a flag
    (:mod:`.published`) beside those the cone's contracts read.

    Raises :class:`~rclverify.lang.errors.RclError` for a state declaration
    that does not check (the plan's ``resolve`` reports those first).
    """
    b = _Builder(cone, checked, model, plan, without_initially)
    b.firsts = firsts
    return b.build()


def _where(e: Any) -> str:
    return f"{e.loc.file}:{e.loc.line}:{e.loc.col}"


class _Builder:
    """The composed system of one cone, built step by step
    (:func:`build_system`): the variables (inputs and outputs, declared
    states, the answering nodes' run variables, publication), the premises
    listed for the report, then the encodings of a valid state, the initial
    states and a step."""

    def __init__(self, cone: Sequence[str], checked: Checked, model: SystemModel, plan: Plan,
                 without_initially: Collection[str]) -> None:
        self.cone, self.checked, self.model, self.plan = cone, checked, model, plan
        self.without_initially = without_initially
        self.firsts: Collection[str] = ()
        self.enc = Encoder(checked.env)
        self.sorts: dict[str, z3.SortRef] = {}
        self.types: dict[str, Type] = {}
        self.variables: dict[str, tuple[str, str, str]] = {}
        self.premises: list[dict[str, Any]] = []
        # what valid/trans encode is a function of the states' terms: encoded once per state (pair).  The
        # cache keeps the terms it is keyed by alive, so their ids cannot be reused for other terms.
        self.memo: dict[tuple[int, ...], tuple[list[z3.ExprRef], z3.BoolRef]] = {}

    def add(self, name: str, sort: z3.SortRef, t: Type, var: tuple[str, str, str]) -> None:
        self.sorts[name], self.types[name], self.variables[name] = sort, t, var

    def premise(self, label: str, kind: str, node: str, index: int, text: str, source: str) -> None:
        self.premises.append({"label": label, "kind": kind, "node": node, "index": index, "text": text,
                              "source": source})

    def build(self) -> ComposedSystem:
        checked, cone = self.checked, self.cone
        self.io_and_state_variables()
        self.contract_premises()
        self.run_variables()
        self.state_premises()
        alias = self.model.alias()
        self.links = [(f"{c}.in.{v}", producer) for (c, p, v), producer in alias.items()
                      if c in cone and producer in self.sorts]
        reads = {n: {v for f in [*self.internal[n], *self.env[n], *self.guarantees[n]] for p, v in free_io(f)
                     if p in ("in", None) and v in checked.nodes[n].inputs} for n in cone}
        self.pub = publication(self.answering, self.links, reads, [n for n in self.answering if self.initially[n]])
        contracts = [first_inputs([*self.internal[n], *self.env[n], *self.guarantees[n]], n) for n in cone]
        for c in dict.fromkeys([*(c for cs in contracts for c in cs), *self.firsts]):
            self.pub.first[c] = "{}.first.{}".format(*c.split(".in.", 1))
        for name, var in self.pub.variables():
            self.add(name, z3.BoolSort(), BOOL, var)
        declared = tuple(self.progress_of(n) for n in self.answering if fair(checked.nodes[n].node))
        everyone = tuple(self.progress_of(n) for n in self.answering)
        return ComposedSystem(TransitionSystem(self.sorts, self.init, self.trans, declared), list(cone),
                              self.variables, self.premises, everyone, self.links, self.bounds,
                              {n: self.initial_of(n) for n in self.answering if self.initially[n]}, self.pub)

    # -- the variables and the premises ------------------------------------------------
    def io_and_state_variables(self) -> None:
        """Each node's inputs and outputs (but of the empty type), then the declared state variables."""
        for n in self.cone:
            cn = self.checked.nodes[n]
            for p, table in (("in", cn.inputs), ("out", cn.outputs)):
                for v, t in table.items():
                    if isinstance(t, EmptyT):  # no value to hold (the encoder refuses any formula using it)
                        continue
                    self.add(f"{n}.{p}.{v}", _sort(t), t, (n, p, v))
        self.states = [sv for sv in self.plan.states if sv.node in self.cone]
        for sv in self.states:
            t = state_type(sv, self.checked)
            self.add(f"{sv.node}.state.{sv.name}", _sort(t), t, (sv.node, "state", sv.name))

    def contract_premises(self) -> None:
        """Each node's guarantees, assumptions (internal and environment) and environment facts."""
        self.guarantees: dict[str, list[Any]] = {}
        self.internal: dict[str, list[Any]] = {}
        self.env: dict[str, list[Any]] = {}
        self.facts: dict[str, list[Any]] = {}
        for n in self.cone:
            cn = self.checked.nodes[n]
            self.guarantees[n] = [g.formula for g in cn.node.guarantees]
            self.internal[n], self.env[n] = split_assumption(self.checked, self.model, n)
            self.facts[n] = [f.expr for f in self.plan.facts.get(n, ())]
            for k, g in enumerate(self.guarantees[n], 1):
                self.premise(f"{n} guarantee {k}", "guarantee", n, k, expr_to_rcl(g), _where(g))
            for k, a in enumerate(self.internal[n], 1):
                self.premise(f"{n} assumption {k}", "internal assumption", n, k, expr_to_rcl(a), _where(a))
            for k, a in enumerate(self.env[n], 1):
                self.premise(f"{n} environment assumption {k}", "environment assumption", n, k, expr_to_rcl(a),
                             _where(a))
            for k, f in enumerate(self.plan.facts.get(n, ()), 1):
                self.premise(f"{n} environment fact {k}", "environment fact", n, k, f.text, _where(f.expr))

    def run_variables(self) -> None:
        """Answering (module docstring): which nodes answer, accept, count their waiting; their
        ``initially`` and ``progress`` premises."""
        checked, cone, wo = self.checked, self.cone, self.without_initially
        self.bounds = {n: step_bound(checked.nodes[n].node) for n in cone}
        self.initially = {n: [c.formula for c in checked.nodes[n].node.initially] if n not in wo else []
                          for n in cone}
        self.answering = [n for n in cone if any(f"{n}.out.{v}" in self.sorts for v in checked.nodes[n].outputs)]
        for n in self.answering:
            node = checked.nodes[n].node
            self.add(f"{n}.answers", z3.BoolSort(), BOOL, (n, "run", "answers"))
            if self.internal[n]:
                self.add(f"{n}.accepts", z3.BoolSort(), BOOL, (n, "run", "accepts"))
            if self.bounds[n]:
                self.add(f"{n}.waiting", z3.IntSort(), INTEGER, (n, "run", "waiting"))
            for k, c in enumerate(node.initially if n not in wo else (), 1):
                self.premise(f"{n} initially {k}", "initial value", n, k, expr_to_rcl(c.formula), _where(c))
            if fair(node):
                self.premise(f"{n} progress", "progress", n, 0, progress_words(node),
                             _where(node.progress[0] if node.progress else
                                    next(p for p in node.periodic if p.unit in STEP_WORDS)))

    def state_premises(self) -> None:
        """The declared state variables' ``init`` and ``next`` formulas, parsed."""
        self.parsed = {}
        for sv in self.states:
            self.parsed[sv] = (parse_state_formula(sv, "init", self.checked, self.plan.states),
                               parse_state_formula(sv, "next", self.checked, self.plan.states))
            for which, src in (("init", sv.init), ("next", sv.next)):
                self.premise(f"{sv.node}.state.{sv.name} {which}", "state declaration", sv.node, 0,
                             " ".join(src.text.split()), f"{src.file}:{src.loc.line}:{src.loc.col}")

    # -- the encodings ----------------------------------------------------------------------
    def node_symbols(self, n: str, s: State) -> dict[str, z3.ExprRef]:
        cn = self.checked.nodes[n]
        return {**{f"first(in.{c.split('.in.', 1)[1]})": s[f] for c, f in self.pub.first.items()
                   if c.startswith(f"{n}.in.") and f in s},
                **{f"in.{v}": s[f"{n}.in.{v}"] for v in cn.inputs if f"{n}.in.{v}" in s},
                **{f"out.{v}": s[f"{n}.out.{v}"] for v in cn.outputs if f"{n}.out.{v}" in s}}

    def holds(self, n: str, e: Any, s: State) -> z3.BoolRef:
        return self.enc.formula(e, self.checked.nodes[n], self.node_symbols(n, s))

    def assumed(self, n: str, s: State) -> z3.BoolRef:
        return conj(*[self.holds(n, a, s) for a in self.internal[n]]) if self.internal[n] else z3.BoolVal(True)

    def cached(self, tag: int, states_: tuple[State, ...], make: Any) -> z3.BoolRef:
        terms = [st[name] for st in states_ for name in self.sorts]
        key = (tag, *[x.get_id() for x in terms])
        hit = self.memo.get(key)
        if hit is None:
            hit = self.memo[key] = (terms, make())
        return hit[1]

    def valid(self, s: State) -> z3.BoolRef:
        return self.cached(0, (s,), lambda: self._valid(s))

    def accepted(self, n: str, s: State) -> z3.BoolRef:
        """The node's assumption holds on ``s``'s input (its ``accepts`` variable, TRUE without one)."""
        return s[f"{n}.accepts"] if f"{n}.accepts" in s else z3.BoolVal(True)

    def enabled(self, n: str, s: State) -> z3.BoolRef:
        """The node has a question it owes an answer: every input it reads published, its assumption holding."""
        return conj(self.accepted(n, s), self.pub.ready(n, s))

    @staticmethod
    def answers_in(n: str, s: State) -> z3.BoolRef:
        return s[f"{n}.answers"]

    def _valid(self, s: State) -> z3.BoolRef:
        holds, types = self.holds, self.types
        parts = [c for c in (_typing(s[name], types[name]) for name in self.sorts) if c is not None]
        for n in self.cone:
            parts += [holds(n, a, s) for a in self.env[n]] + [holds(n, f, s) for f in self.facts[n]]
            if f"{n}.accepts" in s:
                parts.append(s[f"{n}.accepts"] == self.assumed(n, s))
            guarantees = self.guarantees[n]
            promise = conj(*[holds(n, g, s) for g in guarantees]) if guarantees else z3.BoolVal(True)
            if f"{n}.answers" not in s:  # no output to answer with: its guarantee holds where its assumption does
                if guarantees:
                    parts.append(z3.Implies(self.assumed(n, s), promise))
                continue
            answers = s[f"{n}.answers"]
            parts.append(z3.Implies(answers, conj(self.enabled(n, s), promise)))
            k = self.bounds[n]
            if k == 0:
                parts.append(z3.Implies(self.enabled(n, s), answers))
            elif k:
                w = s[f"{n}.waiting"]
                parts.append(z3.If(disj(answers, z3.Not(self.enabled(n, s))), w == 0, conj(w >= 1, w <= k)))
        return conj(*parts)

    def state_syms(self, sv: Any, s: State, t: State | None) -> dict[str, z3.ExprRef]:
        out = self.node_symbols(sv.node, s) if t is not None else {}
        for o in self.states:
            if o.node == sv.node:
                out[f"in.state.{o.name}"] = s[f"{o.node}.state.{o.name}"]
                if t is not None:
                    out[f"in.next.{o.name}"] = t[f"{o.node}.state.{o.name}"]
        return out

    def init(self, s: State) -> z3.BoolRef:
        enc, parsed = self.enc, self.parsed
        parts = [self.valid(s), self.pub.init(s, self.answers_in),
                 *[enc.formula(parsed[sv][0].expr, parsed[sv][0].scope, self.state_syms(sv, s, None))
                   for sv in self.states]]
        for n in self.answering:
            if self.initially[n]:
                parts.append(z3.Implies(z3.Not(s[f"{n}.answers"]),
                                        conj(*[self.holds(n, f, s) for f in self.initially[n]])))
            if self.bounds[n]:
                parts.append(s[f"{n}.waiting"] <= 1)
        return conj(*parts)

    def trans(self, s: State, t: State) -> z3.BoolRef:
        return self.cached(1, (s, t), lambda: self._trans(s, t))

    def _trans(self, s: State, t: State) -> z3.BoolRef:
        parts = [self.valid(s), self.valid(t), self.pub.trans(s, t, self.answers_in)] + [
            t[c] == s[p] for c, p in self.links]
        for n in self.answering:
            outs = [t[f"{n}.out.{v}"] == s[f"{n}.out.{v}"] for v in self.checked.nodes[n].outputs
                    if f"{n}.out.{v}" in s]
            parts.append(z3.Implies(z3.Not(t[f"{n}.answers"]), conj(*outs)))
            if self.bounds[n]:
                parts.append(z3.Implies(conj(z3.Not(t[f"{n}.answers"]), self.enabled(n, t)),
                                        t[f"{n}.waiting"] == s[f"{n}.waiting"] + 1))
        parts += [self.enc.formula(self.parsed[sv][1].expr, self.parsed[sv][1].scope, self.state_syms(sv, s, t))
                  for sv in self.states]
        return conj(*parts)

    def initial_of(self, n: str) -> Pred:
        outs = [f"{n}.out.{v}" for v in self.checked.nodes[n].outputs if f"{n}.out.{v}" in self.sorts]
        types, holds, initially = self.types, self.holds, self.initially
        return lambda s: conj(*[c for c in (_typing(s[o], types[o]) for o in outs) if c is not None],
                                *[holds(n, f, s) for f in initially[n]])

    def progress_of(self, n: str) -> Fairness:
        return Fairness(n, lambda s: self.enabled(n, s), lambda s: s[f"{n}.answers"])
