"""Confirm a lasso on its concrete values before it refutes a requirement.

A lasso found by :mod:`.lasso` is a model of the composed system's query;
before the requirement is reported ``refuted`` its trace is checked again,
independently of that query, by the evaluator the monitors and property
tests use (:func:`rclverify.semantics.decide.decide`: direct evaluation, Z3 on
the concrete values where direct evaluation cannot decide).  Every rule of
the transition relation (docs/requirements.md, "The transition relation")
is evaluated on the trace:

* every value conforms to its type (:func:`rclverify.semantics.values.conforms`);
* in every state, each node's environment assumptions and facts hold; its
  ``accepts`` is whether its internal assumption holds; where it answers,
  its assumption and all its guarantees hold (a node without an output:
  where its assumption holds); with ``progress( within K steps )`` its
  ``waiting`` counts the steps in a row it accepted without answering, at
  most K (K = 0: it answers wherever it accepts);
* at step 0 every state variable satisfies its ``init``, a node that does
  not answer satisfies its ``initially``, and ``waiting`` is at most 1;
* every step: each connection carries the producer's output to the
  consumer's next input; a node that does not answer keeps its outputs;
  each state variable takes its ``next`` value;
* the requirement's ``assuming:`` holds in every state and the goal of
  ``eventually`` holds in none;
* the last state equals the loop state, and every node held to fairness
  (``fair``) that accepts at a step of the loop answers at one of them.

Any check that fails or that the evaluator cannot decide makes the
confirmation fail, with the first such check named: the verdict then stays
``inconclusive`` (never a wrong refutation).
"""
from __future__ import annotations

from typing import Any, Mapping, Sequence

from rclverify.calculus.compose import split_assumption
from rclverify.semantics.decide import decide
from rclverify.model.plan.formal import Formal
from rclverify.model.plan.load import Plan
from rclverify.model.plan.state import parse_state_formula
from rclverify.lang import ast
from rclverify.lang.liveness import step_bound
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.types import Checked, CheckedNode, Type
from rclverify.model.system.model import SystemModel
from rclverify.calculus.requirements.published import Publication, confirm_flags
from rclverify.semantics.values import conforms

#: Z3's budget per formula when direct evaluation cannot decide it (ms, a safety net).
CONFIRM_TIMEOUT_MS = 5_000


class _Unconfirmed(Exception):
    pass


def _holds(e: ast.Expr, checked: Checked, scope: CheckedNode, values: Mapping[str, Any], what: str) -> bool:
    vals = {k: v for k, v in values.items()
            if (k.startswith("in.") and k[3:] in scope.inputs) or (k.startswith("out.") and k[4:] in scope.outputs)
            or k.startswith("first(")}
    try:
        r, why = decide(e, checked, scope, vals, timeout_ms=CONFIRM_TIMEOUT_MS)
    except Exception as exc:  # noqa: BLE001 - a value the evaluator refuses is an unconfirmed trace, not a crash
        raise _Unconfirmed(f"{what}: the evaluator refused the trace's values ({exc})") from exc
    if r is None:
        raise _Unconfirmed(f"{what}: undecided on the trace's values ({why})")
    return r


def confirm_lasso(trace: Sequence[Mapping[str, Any]], loop: int, cone: Sequence[str], variables: Mapping[str, tuple[str, str, str]],
                  types: Mapping[str, Type], checked: Checked, model: SystemModel, plan: Plan,
                  goal: Formal, assuming: Sequence[Formal], fair: Sequence[str] = (),
                  pub: Publication | None = None) -> str | None:
    """Check the lasso ``trace`` (one ``{variable: value}`` per step, the
    last equal to step ``loop``) against every rule of the module docstring.
    ``goal`` is ``F`` of ``eventually F``; ``fair`` the nodes held to
    fairness in the loop; ``pub`` the system's published-value flags
    (:mod:`.published`: they follow their rules, a node answers only when
    every input it reads was published, the goal counts only on published
    values).  Returns ``None`` when every check holds, else a
    sentence naming the first check that failed or was not decided.  Never
    raises."""
    pub = pub or Publication()
    try:
        _confirm(trace, loop, cone, variables, types, checked, model, plan, goal, assuming, fair, pub)
    except _Unconfirmed as exc:
        return str(exc)
    return None


def _check_waiting(n: str, cn: CheckedNode, trace: Sequence[Mapping[str, Any]], i: int, accepts: bool,
                   answers: bool) -> None:
    """The progress rules of node ``n`` at step ``i`` (module docstring)."""
    k = step_bound(cn.node)
    if k == 0 and accepts and not answers:
        raise _Unconfirmed(f"step {i}: {n} accepts its input but does not answer (progress within 0 steps)")
    if not k:
        return
    w = trace[i][f"{n}.waiting"]
    want = 0 if answers or not accepts else (1 if i == 0 else trace[i - 1][f"{n}.waiting"] + 1)
    if w != want or w > k:
        raise _Unconfirmed(f"step {i}: {n}.waiting is {w}, not {want} <= {k}")


def _node_values(state: Mapping[str, Any], node: str) -> dict[str, Any]:
    out = {}
    for name, v in state.items():
        n, _, rest = name.partition(".")
        if n == node:
            out[rest] = v  # "in.x" / "out.y" / "state.v"
            if rest.startswith("first."):  # a first(in.x) flag (published.py)
                out[f"first(in.{rest[6:]})"] = v
    return out


def _confirm(trace: Sequence[Mapping[str, Any]], loop: int, cone: Sequence[str], variables: Mapping[str, tuple[str, str, str]],
             types: Mapping[str, Type], checked: Checked, model: SystemModel, plan: Plan,
             goal: Formal, assuming: Sequence[Formal], fair: Sequence[str], pub: Publication) -> None:
    c = _Lasso(trace, loop, cone, variables, types, checked, model, plan, goal, assuming, fair, pub)
    c.shape()
    c.prepare()
    for i, st in enumerate(trace):
        c.state(i, st)
    bad_flag = confirm_flags(trace, pub, lambda st, n: st.get(f"{n}.answers") is True)
    if bad_flag:
        raise _Unconfirmed(bad_flag)
    c.initial_states()
    for i in range(len(trace) - 1):
        c.step(i, trace[i], trace[i + 1])


class _Lasso:
    """The checks of one lasso, in the order :func:`_confirm` runs them; each
    failure raises :class:`_Unconfirmed` with its reason."""

    def __init__(self, trace: Sequence[Mapping[str, Any]], loop: int, cone: Sequence[str],
                 variables: Mapping[str, tuple[str, str, str]], types: Mapping[str, Type], checked: Checked,
                 model: SystemModel, plan: Plan, goal: Formal, assuming: Sequence[Formal], fair: Sequence[str],
                 pub: Publication) -> None:
        self.trace, self.loop, self.cone, self.variables, self.types = trace, loop, cone, variables, types
        self.checked, self.model, self.plan, self.goal, self.assuming = checked, model, plan, goal, assuming
        self.fair, self.pub = fair, pub

    def shape(self) -> None:
        """A lasso whose last state is its loop state, every fair node answering in the loop where it accepts."""
        trace, loop, pub = self.trace, self.loop, self.pub
        if not trace or not 0 <= loop < len(trace) - 1:
            raise _Unconfirmed("the trace is not a lasso")
        if dict(trace[-1]) != dict(trace[loop]):
            raise _Unconfirmed(f"the last state differs from the loop state {loop}")
        for n in self.fair:
            ring = trace[loop:-1]
            accepted = [st.get(f"{n}.accepts", True) is True and all(st.get(f) is True for f in pub.fed.get(n, ()))
                        for st in ring]
            if any(accepted) and not any(st[f"{n}.answers"] is True for st in ring):
                raise _Unconfirmed(f"{n} accepts its input in the loop but never answers there (its progress)")

    def prepare(self) -> None:
        """The cone's state declarations parsed, its assumptions split, its facts and links."""
        checked, plan, cone, model = self.checked, self.plan, self.cone, self.model
        self.states = [sv for sv in plan.states if sv.node in cone]
        self.parsed = {sv: (parse_state_formula(sv, "init", checked, plan.states),
                            parse_state_formula(sv, "next", checked, plan.states)) for sv in self.states}
        self.split = {n: split_assumption(checked, model, n) for n in cone}
        self.facts = {n: [f.expr for f in plan.facts.get(n, ())] for n in cone}
        self.links = [(f"{c}.in.{v}", p) for (c, _, v), p in model.alias().items()
                      if c in cone and p in self.variables]

    def state(self, i: int, st: Mapping[str, Any]) -> None:
        """State ``i``: every variable typed, every node's contract kept, the
        requirement's assumptions holding and its goal not reached."""
        checked, variables, pub = self.checked, self.variables, self.pub
        for name in variables:
            if name not in st:
                raise _Unconfirmed(f"step {i}: no value for {name}")
            bad = conforms(st[name], self.types[name])
            if bad:
                raise _Unconfirmed(f"step {i}: {name}: {bad}")
        for n in self.cone:
            self.node_at(i, st, n)
        # the statement's pseudo node names Node.out.y an output, every other variable an input (model/plan/formal.py)
        pseudo = {f"{'out' if variables[name][1] == 'out' else 'in'}.{name}": v
                  for name, v in st.items() if name in variables}
        pseudo.update({f"first(in.{c})": st[f] for c, f in pub.first.items() if f in st})  # first(Node.in.x)
        for k, a in enumerate(self.assuming, 1):
            if all(st.get(f) is True for f in pub.flags_of(a.mentions)) and \
                    not _holds(a.expr, checked, a.scope, pseudo, f"step {i}: assuming {k}"):
                raise _Unconfirmed(f"step {i}: the requirement's assuming {k} does not hold")
        goal = self.goal
        published = all(st.get(f) is True for f in pub.flags_of(goal.mentions))
        if published and _holds(goal.expr, checked, goal.scope, pseudo, f"step {i}: the goal"):
            raise _Unconfirmed(f"step {i}: the goal holds")

    def node_at(self, i: int, st: Mapping[str, Any], n: str) -> None:
        """Node ``n`` at state ``i``: its environment, its accepting and
        answering, its guarantees when it answers, its waiting, its initial values."""
        checked, variables = self.checked, self.variables
        cn, vals = checked.nodes[n], _node_values(st, n)
        internal, env = self.split[n]
        for k, e in enumerate([*env, *self.facts[n]], 1):
            if not _holds(e, checked, cn, vals, f"step {i}: {n} environment assumption/fact {expr_to_rcl(e)}"):
                raise _Unconfirmed(f"step {i}: {n}'s environment assumption or fact {k} does not hold")
        accepts = all(_holds(a, checked, cn, vals, f"step {i}: {n} assumption") for a in internal)
        ready = all(st.get(f) is True for f in self.pub.fed.get(n, ()))
        if f"{n}.accepts" in variables and st[f"{n}.accepts"] is not accepts:
            raise _Unconfirmed(f"step {i}: {n}.accepts is {st[f'{n}.accepts']} but its assumption "
                               f"{'holds' if accepts else 'fails'}")
        answers = st[f"{n}.answers"] if f"{n}.answers" in variables else accepts
        if answers and not accepts:
            raise _Unconfirmed(f"step {i}: {n} answers although its assumption fails")
        if answers:
            for k, g in enumerate(cn.node.guarantees, 1):
                if not _holds(g.formula, checked, cn, vals, f"step {i}: {n} guarantee {k}"):
                    raise _Unconfirmed(f"step {i}: {n}'s guarantee {k} does not hold")
        if f"{n}.answers" in variables:
            _check_waiting(n, cn, self.trace, i, accepts and ready, answers)
        if i == 0 and f"{n}.answers" in variables and not answers:
            for k, ini in enumerate(cn.node.initially, 1):
                if not _holds(ini.formula, checked, cn, vals, f"step 0: {n} initially {k}"):
                    raise _Unconfirmed(f"step 0: {n} does not answer and its initially {k} does not hold")

    def initial_states(self) -> None:
        """Every declared state variable satisfies its ``init`` at step 0."""
        states, trace = self.states, self.trace
        for sv in states:
            vals = {f"in.state.{o.name}": trace[0][f"{o.node}.state.{o.name}"] for o in states if o.node == sv.node}
            f = self.parsed[sv][0]
            if not _holds(f.expr, self.checked, f.scope, vals, f"{sv.node}.state.{sv.name} init"):
                raise _Unconfirmed(f"step 0: {sv.node}.state.{sv.name} does not satisfy its init")

    def step(self, i: int, s: Mapping[str, Any], t: Mapping[str, Any]) -> None:
        """The step from state ``i`` to ``i + 1``: links carry values, a node
        that does not answer keeps its outputs, state variables follow their ``next``."""
        checked, variables, states = self.checked, self.variables, self.states
        for c, p in self.links:
            if t[c] != s[p]:
                raise _Unconfirmed(f"step {i + 1}: {c} is not the value {p} had at step {i}")
        for n in self.cone:
            cn = checked.nodes[n]
            if f"{n}.answers" in variables and t[f"{n}.answers"] is not True:
                for v in cn.outputs:
                    name = f"{n}.out.{v}"
                    if name in variables and t[name] != s[name]:
                        raise _Unconfirmed(f"step {i + 1}: {name} changed although {n} does not answer")
        for sv in states:
            vals = {k: v for k, v in _node_values(s, sv.node).items() if not k.startswith("state.")}
            for o in states:
                if o.node == sv.node:
                    vals[f"in.state.{o.name}"] = s[f"{o.node}.state.{o.name}"]
                    vals[f"in.next.{o.name}"] = t[f"{o.node}.state.{o.name}"]
            f = self.parsed[sv][1]
            if not _holds(f.expr, checked, f.scope, vals, f"step {i}: {sv.node}.state.{sv.name} next"):
                raise _Unconfirmed(f"step {i + 1}: {sv.node}.state.{sv.name} is not the value its next gives")
