"""Confirm a lasso on its concrete values before it refutes a requirement.

A lasso found by :mod:`.lasso` is a model of the composed system's query;
before the requirement is reported ``refuted`` its trace is checked again,
independently of that query, by the evaluator the monitors and property
tests use (:func:`rclverify.logic.decide.decide`: direct evaluation, Z3 on
the concrete values where direct evaluation cannot decide).  Every rule of
the transition relation (docs/requirements.md, "The transition relation")
is evaluated on the trace:

* every value conforms to its type (:func:`rclverify.values.conforms`);
* in every state, each node's environment assumptions and facts hold, and
  where its internal assumption holds all its guarantees hold;
* at step 0 every state variable satisfies its ``init``;
* every step: each connection carries the producer's output to the
  consumer's next input; a node whose internal assumption fails on the next
  input keeps its outputs; each state variable takes its ``next`` value;
* the requirement's ``assuming:`` holds in every state and the goal of
  ``eventually`` holds in none;
* the last state equals the loop state.

Any check that fails or that the evaluator cannot decide makes the
confirmation fail, with the first such check named: the verdict then stays
``inconclusive`` (never a wrong refutation).
"""
from __future__ import annotations

from typing import Any, Mapping, Sequence

from ..calculus.compose import split_assumption
from ..logic.decide import decide
from ..plan.formal import Formal
from ..plan.load import Plan
from ..plan.state import parse_state_formula
from ..rcl import ast
from ..rcl.printer import expr_to_rcl
from ..rcl.types import Checked, CheckedNode, Type
from ..system.model import SystemModel
from ..values import conforms

#: Z3's budget per formula when direct evaluation cannot decide it (ms, a safety net).
CONFIRM_TIMEOUT_MS = 5_000


class _Unconfirmed(Exception):
    pass


def _holds(e: ast.Expr, checked: Checked, scope: CheckedNode, values: Mapping[str, Any], what: str) -> bool:
    vals = {k: v for k, v in values.items()
            if (k.startswith("in.") and k[3:] in scope.inputs) or (k.startswith("out.") and k[4:] in scope.outputs)}
    try:
        r, why = decide(e, checked, scope, vals, timeout_ms=CONFIRM_TIMEOUT_MS)
    except Exception as exc:  # noqa: BLE001 - a value the evaluator refuses is an unconfirmed trace, not a crash
        raise _Unconfirmed(f"{what}: the evaluator refused the trace's values ({exc})") from exc
    if r is None:
        raise _Unconfirmed(f"{what}: undecided on the trace's values ({why})")
    return r


def confirm_lasso(trace: Sequence[Mapping[str, Any]], loop: int, cone: Sequence[str], variables: Mapping[str, tuple[str, str, str]],
                  types: Mapping[str, Type], checked: Checked, model: SystemModel, plan: Plan,
                  goal: Formal, assuming: Sequence[Formal]) -> str | None:
    """Check the lasso ``trace`` (one ``{variable: value}`` per step, the
    last equal to step ``loop``) against every rule of the module docstring.
    ``goal`` is ``F`` of ``eventually F``.  Returns ``None`` when every check
    holds, else a sentence naming the first check that failed or was not
    decided.  Never raises."""
    try:
        _confirm(trace, loop, cone, variables, types, checked, model, plan, goal, assuming)
    except _Unconfirmed as exc:
        return str(exc)
    return None


def _node_values(state: Mapping[str, Any], node: str) -> dict[str, Any]:
    out = {}
    for name, v in state.items():
        n, _, rest = name.partition(".")
        if n == node:
            out[rest] = v  # "in.x" / "out.y" / "state.v"
    return out


def _confirm(trace: Sequence[Mapping[str, Any]], loop: int, cone: Sequence[str], variables: Mapping[str, tuple[str, str, str]],
             types: Mapping[str, Type], checked: Checked, model: SystemModel, plan: Plan,
             goal: Formal, assuming: Sequence[Formal]) -> None:
    if not trace or not 0 <= loop < len(trace) - 1:
        raise _Unconfirmed("the trace is not a lasso")
    if dict(trace[-1]) != dict(trace[loop]):
        raise _Unconfirmed(f"the last state differs from the loop state {loop}")
    states = [sv for sv in plan.states if sv.node in cone]
    parsed = {sv: (parse_state_formula(sv, "init", checked, plan.states),
                   parse_state_formula(sv, "next", checked, plan.states)) for sv in states}
    split = {n: split_assumption(checked, model, n) for n in cone}
    facts = {n: [f.expr for f in plan.facts.get(n, ())] for n in cone}
    links = [(f"{c}.in.{v}", p) for (c, _, v), p in model.alias().items() if c in cone and p in variables]
    for i, st in enumerate(trace):
        for name in variables:
            if name not in st:
                raise _Unconfirmed(f"step {i}: no value for {name}")
            bad = conforms(st[name], types[name])
            if bad:
                raise _Unconfirmed(f"step {i}: {name}: {bad}")
        for n in cone:
            cn, vals = checked.nodes[n], _node_values(st, n)
            internal, env = split[n]
            for k, e in enumerate([*env, *facts[n]], 1):
                if not _holds(e, checked, cn, vals, f"step {i}: {n} environment assumption/fact {expr_to_rcl(e)}"):
                    raise _Unconfirmed(f"step {i}: {n}'s environment assumption or fact {k} does not hold")
            if all(_holds(a, checked, cn, vals, f"step {i}: {n} assumption") for a in internal):
                for k, g in enumerate(cn.node.guarantees, 1):
                    if not _holds(g.formula, checked, cn, vals, f"step {i}: {n} guarantee {k}"):
                        raise _Unconfirmed(f"step {i}: {n}'s guarantee {k} does not hold")
        # the statement's pseudo node names Node.out.y an output, every other variable an input (plan/formal.py)
        pseudo = {f"{'out' if variables[name][1] == 'out' else 'in'}.{name}": v
                  for name, v in st.items() if name in variables}
        for k, a in enumerate(assuming, 1):
            if not _holds(a.expr, checked, a.scope, pseudo, f"step {i}: assuming {k}"):
                raise _Unconfirmed(f"step {i}: the requirement's assuming {k} does not hold")
        if _holds(goal.expr, checked, goal.scope, pseudo, f"step {i}: the goal"):
            raise _Unconfirmed(f"step {i}: the goal holds")
    for sv in states:
        vals = {f"in.state.{o.name}": trace[0][f"{o.node}.state.{o.name}"] for o in states if o.node == sv.node}
        f = parsed[sv][0]
        if not _holds(f.expr, checked, f.scope, vals, f"{sv.node}.state.{sv.name} init"):
            raise _Unconfirmed(f"step 0: {sv.node}.state.{sv.name} does not satisfy its init")
    for i in range(len(trace) - 1):
        s, t = trace[i], trace[i + 1]
        for c, p in links:
            if t[c] != s[p]:
                raise _Unconfirmed(f"step {i + 1}: {c} is not the value {p} had at step {i}")
        for n in cone:
            cn, internal = checked.nodes[n], split[n][0]
            if internal and not all(_holds(a, checked, cn, _node_values(t, n), f"step {i + 1}: {n} assumption")
                                    for a in internal):
                for v in cn.outputs:
                    name = f"{n}.out.{v}"
                    if name in variables and t[name] != s[name]:
                        raise _Unconfirmed(f"step {i + 1}: {name} changed although {n}'s assumption fails")
        for sv in states:
            vals = {k: v for k, v in _node_values(s, sv.node).items() if not k.startswith("state.")}
            for o in states:
                if o.node == sv.node:
                    vals[f"in.state.{o.name}"] = s[f"{o.node}.state.{o.name}"]
                    vals[f"in.next.{o.name}"] = t[f"{o.node}.state.{o.name}"]
            f = parsed[sv][1]
            if not _holds(f.expr, checked, f.scope, vals, f"step {i}: {sv.node}.state.{sv.name} next"):
                raise _Unconfirmed(f"step {i + 1}: {sv.node}.state.{sv.name} is not the value its next gives")
