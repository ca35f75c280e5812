"""Cone summaries (issue 51; calculus/summary.py, docs/calculus.md): the
oracle is the whole cone's check.  On small random chains, branches, joins
(disjoint and reconverging) and loops, every side condition's verdict with
summaries equals its verdict reading the whole cone; every summary is
implied by its cone; the chain's proofs name the premises they rest on."""
from __future__ import annotations

import random
from fractions import Fraction
from typing import Any

from hypothesis import given, settings
from hypothesis import strategies as st

from _chain import chain_rcl
from rclverify.calculus.compose import IN_CONTEXT, compose_node, environment_conjuncts
from rclverify.calculus.context import ConeContext
from rclverify.calculus.summary import summary_of
from rclverify.semantics import world
from rclverify.lang.parser import parse_formula, parse_text
from rclverify.lang.typecheck import check
from rclverify.model.system.model import build

X0 = {"N0": [parse_formula("0 <= in.x0 and in.x0 <= 50")]}


def _system(text: str):  # type: ignore[no-untyped-def]
    checked = check([parse_text(text, "sys.rcl")])
    return checked, build(checked)


def _verdicts(checked, model, facts, summaries: bool):  # type: ignore[no-untyped-def]
    out = {}
    for n in checked.nodes:
        world.fresh()
        for sc in compose_node(checked, model, n, facts=facts, summaries=summaries).side_conditions:
            out[sc.id] = sc
    return out


def test_the_chain_is_proved_from_summaries_naming_the_cone_premises() -> None:
    checked, model = _system(chain_rcl(30, bound=300))
    fast, full = _verdicts(checked, model, X0, True), _verdicts(checked, model, X0, False)
    assert {k: v.verdict for k, v in fast.items()} == {k: v.verdict for k, v in full.items()}
    for i in range(1, 30):
        sc = fast[f"N{i}.sc2"]
        assert sc.verdict == IN_CONTEXT and sc.context["summaries"] == [f"N{i - 1}"]
        assert sc.context["used_nodes"] == [f"N{j}" for j in range(i)]  # named as the whole cone's proof names them
        assert "N0 environment fact 1" in sc.context["used"] and "summaries of the cones" in sc.explanation
        assert "(check-sat)" in sc.smt2 and "N0 guarantee" not in sc.smt2.split("(reset)")[-1]  # no cone read
        assert "summaries" not in (full[f"N{i}.sc2"].context or {})


def test_a_failing_side_condition_keeps_the_whole_cones_counterexample() -> None:
    checked, model = _system(chain_rcl(8, weak={3: 70}))
    fast, full = _verdicts(checked, model, X0, True), _verdicts(checked, model, X0, False)
    for k in fast:  # the same verdict, a counterexample over the same values of the whole cone (the values
        # may differ: the summaries' query ran first in the node's solver session, calculus/summary.py)
        assert (fast[k].verdict, sorted(fast[k].model or {}), fast[k].context and fast[k].context["violated"]) == \
               (full[k].verdict, sorted(full[k].model or {}), full[k].context and full[k].context["violated"])
    assert fast["N4.sc2"].verdict == "failed" and "N0.in.x0" in fast["N4.sc2"].model
    m = {k: Fraction(v) for k, v in fast["N4.sc2"].model.items()}  # and it is one: every guarantee holds, x5 > 70
    x = [m["N0.in.x0"]] + [m[f"N{i}.out.x{i + 1}"] for i in range(4)]
    assert 0 <= x[0] <= 50 and all(0 <= x[i + 1] <= x[i] + (70 if i == 3 else 1) for i in range(4)), m
    assert x[4] > 100, m  # N4's assumption in.x4 <= 100 violated


def test_no_summary_across_a_loop_or_a_reconverging_join() -> None:
    text = """
node A { inputs( e : INTEGER ) outputs( a : INTEGER ) assume( 0 <= in.e and in.e <= 5 ) guarantee( out.a == in.e ) }
node P { inputs( a : INTEGER ) outputs( p : INTEGER ) assume( in.a <= 5 ) guarantee( out.p == in.a ) }
node B { inputs( p : INTEGER ) outputs( b : INTEGER ) assume( in.p <= 5 ) guarantee( out.b == in.p ) }
node C { inputs( a : INTEGER ) outputs( c : INTEGER ) assume( in.a <= 5 ) guarantee( out.c == 0 - in.a ) }
node D { inputs( b : INTEGER, c : INTEGER ) outputs( d : INTEGER ) assume( in.b + in.c == 0 ) guarantee( out.d == 0 ) }
"""
    checked, model = _system(text)
    env = lambda m: environment_conjuncts(checked, model, m)  # noqa: E731
    assert summary_of(checked, model, "B", env) is not None and summary_of(checked, model, "D", env) is None
    fast, full = _verdicts(checked, model, {}, True), _verdicts(checked, model, {}, False)
    assert fast["D.sc1"].verdict == full["D.sc1"].verdict == IN_CONTEXT  # b + c == 0 needs the shared a
    assert "summaries" not in fast["D.sc1"].context  # the B and C summaries forget it: the whole cone decided


# ---- the oracle: random systems, summaries against the whole cone ----------------------------------------

def _atom(rng: random.Random, ins: list[str], out: str | None, d: int) -> str:
    """A random linear atom: an assumption conjunct over inputs (``out``
    ``None``; its bounds often hold in context and never locally) or a
    guarantee of ``out``."""
    a = rng.choice(ins)
    if out is None:
        kind = rng.choice(["le", "le", "ge", "sum"] if len(ins) > 1 else ["le", "le", "ge"])
        if kind == "sum":
            b = rng.choice([x for x in ins if x != a])
            return f"in.{a} + in.{b} <= {rng.randint(d, 4 * d)}"
        if kind == "le":
            return f"in.{a} <= {rng.randint(d - 1, 3 * d)}"
        return f"in.{a} >= {rng.randint(-2, 1)}"
    c = rng.randint(0, 2)
    kind = rng.choice(["le", "ge", "eq", "const", "two"] if len(ins) > 1 else ["le", "ge", "eq", "const"])
    if kind == "le":
        return f"out.{out} <= in.{a} + {c}"
    if kind == "ge":
        return f"out.{out} + {c} >= in.{a}"
    if kind == "eq":
        return f"out.{out} == in.{a}"
    if kind == "two":
        b = rng.choice([x for x in ins if x != a])
        return f"out.{out} <= in.{a} + in.{b}"
    return f"out.{out} >= {rng.randint(-1, 1)}"


def _random_system(seed: int):  # type: ignore[no-untyped-def]
    """A chain, branches (one output read twice), joins and, now and then,
    a loop (a node reading a later node's output); INTEGER or REAL."""
    rng = random.Random(seed)
    k = rng.randint(3, 7)
    typ = rng.choice(["INTEGER", "REAL"])
    d = rng.randint(2, 6)
    ins_of: list[list[str]] = []
    for i in range(k):
        earlier = [f"y{j}" for j in range(max(0, i - 3), i)]
        ins = sorted(set(rng.sample(earlier, min(len(earlier), rng.choice([1, 1, 1, 2])))) if earlier else [])
        if not ins or rng.random() < 0.2:
            ins.append(f"e{i}")
        ins_of.append(ins)
    if k > 2 and rng.random() < 0.3:  # a loop
        i = rng.randrange(0, k - 1)
        ins_of[i] = sorted(set(ins_of[i]) | {f"y{rng.randrange(i + 1, k)}"})
    nodes, facts = [], {}
    for i, ins in enumerate(ins_of):
        assume = " and ".join(_atom(rng, ins, None, d) for _ in range(rng.randint(1, 2)))
        guar = " ".join(f"guarantee( {_atom(rng, ins, f'y{i}', d)} )" for _ in range(rng.randint(1, 3)))
        nodes.append(f"node N{i} {{ inputs( {', '.join(f'{x} : {typ}' for x in ins)} ) outputs( y{i} : {typ} ) "
                     f"assume( {assume} ) {guar} }}")
        env_ins = [x for x in ins if x.startswith("e")]
        if env_ins and rng.random() < 0.85:
            facts[f"N{i}"] = [parse_formula(f"0 <= in.{x} and in.{x} <= {d}") for x in env_ins]
    return "\n".join(nodes), facts


def _shape(context: Any) -> Any:
    """The in-context check record with each counterexample model reduced to the variables it names."""
    if isinstance(context, dict):
        return {k: sorted(v) if k == "model" and isinstance(v, dict) else _shape(v) for k, v in context.items()}
    if isinstance(context, list):
        return [_shape(v) for v in context]
    return context


@settings(max_examples=25, deadline=None, derandomize=True)
@given(seed=st.integers(0, 10**6))
def test_verdicts_with_summaries_equal_the_whole_cones(seed: int) -> None:
    text, facts = _random_system(seed)
    checked, model = _system(text)
    fast, full = _verdicts(checked, model, facts, True), _verdicts(checked, model, facts, False)
    assert fast.keys() == full.keys()
    for k in fast:
        a, b = fast[k], full[k]
        assert (a.status, a.verdict) == (b.status, b.verdict), (text, k, a.explanation, b.explanation)
        if a.verdict == "failed":  # a counterexample is the whole cone's, traced back as before (its numbers
            # may differ: the summaries' query ran first in the node's solver session, and a loaded machine
            # can make Z3 finish by another tactic: so can the numbers of the in-context check's model)
            assert sorted(a.model or {}) == sorted(b.model or {}) and _shape(a.context) == _shape(b.context)
    # every summary is implied by its cone: the whole cone's check proves it
    env = lambda m: environment_conjuncts(checked, model, m)  # noqa: E731
    for n in checked.nodes:
        s = summary_of(checked, model, n, env, facts)
        if s is None or s.formula == "true":
            continue
        world.fresh()
        ctx = ConeContext(checked, model, n, env, facts)
        import z3
        from rclverify.calculus.context import NEGATED  # noqa: F401
        with_own = [f for f in ctx.tracked]
        sol = z3.Solver()
        sol.add(*ctx.enc.axioms(), *ctx.definitions, *with_own, *ctx.literals)
        # the summary of n speaks of outputs of the cone: n's own guarantees (under A_n) are premises of it
        cn = checked.nodes[n]
        own = [ctx.enc.formula(g.formula, cn) for g in cn.node.guarantees]
        a = [ctx.enc.formula(x.formula, cn) for x in cn.node.assumes]
        if own:
            sol.add(z3.Implies(z3.And(*a), z3.And(*own)) if a else z3.And(*own))
        decls = {str(sym.decl): sym.decl for sym in ctx.enc.symbols.values()}
        summary = z3.parse_smt2_string(f"(assert {s.formula})", decls=decls)
        sol.add(z3.Not(z3.And(*summary)))
        assert sol.check() == z3.unsat, (text, n, s.formula)


@settings(max_examples=25, deadline=None, derandomize=True)
@given(seed=st.integers(0, 10**6))
def test_the_hidden_names_read_off_the_text_are_the_walked_constants(seed: int) -> None:
    """summary_qe._bound's token path (names bare as Z3 prints them, or quoted
    as targets/smtlib.py writes them) binds exactly the constants a walk of the parsed
    formulas finds."""
    from rclverify.calculus import summary_qe as S
    bound, seen = S._bound, []

    def both(ctx, fs, bodies, hidden, sorts):  # type: ignore[no-untyped-def]
        fast, walked = bound(ctx, fs, bodies, hidden, sorts), bound(ctx, fs, bodies, hidden, None)
        assert [str(x) for x in fast] == [str(x) for x in walked], (bodies, hidden)
        seen.append(len(fast))
        return fast

    text, facts = _random_system(seed)
    checked, model = _system(text)
    env = lambda m: environment_conjuncts(checked, model, m)  # noqa: E731
    S._bound = both  # type: ignore[assignment]
    try:
        for n in checked.nodes:
            summary_of(checked, model, n, env, facts)
    finally:
        S._bound = bound  # type: ignore[assignment]
    assert seen or not any(summary_of(checked, model, n, env, facts) for n in checked.nodes)
