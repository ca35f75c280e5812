"""Side conditions in context (issue 43; docs/calculus.md): the chain of the
issue, loops opened as rule R4 does, and the oracle: on small random linear
systems over small integer domains, the in-context verdict equals
brute-force enumeration."""
from __future__ import annotations

import itertools
import random
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from _chain import chain_rcl
from rclverify.calculus.compose import IN_CONTEXT, compose_node, split_assumption
from rclverify.calculus.cone_paths import opened_links
from rclverify.calculus.context import ConeContext
from rclverify.semantics import world
from rclverify.lang.parser import parse_formula, parse_text
from rclverify.lang.typecheck import check
from rclverify.model.system.model import build

X0 = {"N0": [parse_formula("0 <= in.x0 and in.x0 <= 50")]}


def _system(text: str):  # type: ignore[no-untyped-def]
    checked = check([parse_text(text, "chain.rcl")])
    return checked, build(checked)


def _compose_all(text: str, facts=X0):  # type: ignore[no-untyped-def]
    checked, model = _system(text)
    out = {}
    for n in checked.nodes:
        world.fresh()
        for sc in compose_node(checked, model, n, facts=facts).side_conditions:
            out[sc.id] = sc
    return out


def test_the_chain_of_ten_is_discharged_in_context_with_its_upstream_guarantees_named() -> None:
    scs = _compose_all(chain_rcl(10))
    assert len(scs) == 18 and all(sc.status == "discharged" for sc in scs.values())
    for i in range(1, 10):
        low, high = scs[f"N{i}.sc1"], scs[f"N{i}.sc2"]
        assert low.verdict == "discharged" and low.context is None  # 0 <= x_i: N{i-1}'s guarantee as written
        assert high.verdict == IN_CONTEXT and high.variant == "in context"
        # every upstream node's guarantee is used (x_i <= 50 + i needs the whole chain) and named
        assert high.context["used_nodes"] == [f"N{j}" for j in range(i)]
        assert "N0 environment fact 1" in high.context["used"]
        assert any(h.startswith(f"N{i - 1} guarantee 1: out.x{i} <= in.x{i - 1} + 1") for h in high.hypotheses)
        assert high.context["local"]["status"] == "failed"  # the premise of R1 as printed does not hold
        assert "Discharged in context" in high.explanation and "N0 guarantee 1" in high.explanation


def test_a_weakened_guarantee_fails_in_context_with_a_counterexample_from_x0() -> None:
    scs = _compose_all(chain_rcl(10, weak={3: 70}))
    assert [k for k, sc in scs.items() if sc.verdict == IN_CONTEXT] == ["N1.sc2", "N2.sc2", "N3.sc2"]
    sc = scs["N4.sc2"]
    assert sc.status == "failed" and sc.verdict == "failed" and sc.variant == "in context"
    m = sc.model
    assert m is not None and set(m) == {"N0.in.x0", "N0.out.x1", "N1.out.x2", "N2.out.x3", "N3.out.x4"}
    x = [float(m["N0.in.x0"])] + [float(m[f"N{i - 1}.out.x{i}"]) for i in range(1, 5)]
    assert 0 <= x[0] <= 50  # from the environment fact ...
    assert all(0 <= x[i] <= x[i - 1] + 1 for i in (1, 2, 3)) and x[4] <= x[3] + 70 and x[4] > 100  # ... to x4
    assert sc.context["violated"] == []  # every upstream assumption holds: the weak guarantee is the cause
    # downstream, the counterexample violates N4's assumption: named as the cause
    assert scs["N5.sc2"].status == "failed" and scs["N5.sc2"].context["violated"] == ["N4"]


def test_beyond_51_nodes_the_chain_fails_in_context_where_x_i_may_exceed_100() -> None:
    scs = _compose_all(chain_rcl(53))
    assert scs["N50.sc2"].verdict == IN_CONTEXT  # x50 <= 100
    assert scs["N51.sc2"].verdict == "failed" and float(scs["N51.sc2"].model["N50.out.x51"]) > 100


def test_inconsistent_premises_discharge_nothing() -> None:
    facts = {"N0": [parse_formula("0 <= in.x0 and in.x0 <= 50"), parse_formula("in.x0 > 60")]}
    scs = _compose_all(chain_rcl(3), facts)
    assert scs["N1.sc2"].status == "inconclusive" and "contradict" in scs["N1.sc2"].explanation


LOOP_UPSTREAM = """
node P { inputs( q : INTEGER ) outputs( p : INTEGER ) assume( TRUE ) guarantee( out.p == in.q + 1 ) }
node Q { inputs( p : INTEGER ) outputs( q : INTEGER ) assume( TRUE ) guarantee( out.q == in.p ) }
node R { inputs( p : INTEGER ) outputs( r : INTEGER ) assume( in.p <= 0 ) guarantee( out.r == in.p ) }
"""


def test_a_loop_upstream_is_opened_so_its_fixpoint_proves_nothing() -> None:
    """On one snapshot ``p == q + 1 and q == p`` has no solution and would
    prove anything; R4 composes the loop opened at one link, where the
    value read is arbitrary (and over time p grows: the failure is real)."""
    checked, model = _system(LOOP_UPSTREAM)
    assert [(l.from_node, l.to_node) for l in opened_links(model, "R")] == [("P", "Q")]
    [sc] = compose_node(checked, model, "R").side_conditions
    assert sc.status == "failed" and sc.context["opened"] == ["P.out.p -> Q.in.p"]
    assert "opened" in sc.explanation and "R4" in sc.explanation


LOOP_SELF = """
node P { inputs( q : INTEGER ) outputs( p : INTEGER ) assume( in.q >= 0 ) guarantee( out.p >= 0 ) }
node Q { inputs( p : INTEGER ) outputs( q : INTEGER ) assume( TRUE ) guarantee( out.q == in.p ) }
"""


def test_a_guarantee_never_discharges_its_own_premise() -> None:
    """P's guarantee ``p >= 0`` holds only when ``q >= 0``; using it to show
    ``q >= 0`` would be circular (paper line 712)."""
    checked, model = _system(LOOP_SELF)
    [sc] = compose_node(checked, model, "P").side_conditions
    assert sc.status == "failed" and sc.verdict == "failed"
    assert sc.context["opened"] == ["P.out.p -> Q.in.p"]


def test_a_locally_discharged_side_condition_reads_no_cone() -> None:
    scs = _compose_all(chain_rcl(4))
    assert scs["N2.sc1"].context is None and scs["N2.sc1"].verdict == "discharged"


# ---- the oracle: ConeContext.decide against brute-force enumeration ---------------------------------

D = 3  # every variable ranges over 0..D (plan facts bound each one, so Z3's integers are these too)


def _atom(rng: random.Random, ins: list[str], out: str | None) -> tuple[str, object]:
    """A random linear atom as (RCL text, evaluator over a valuation)."""
    a = rng.choice(ins)
    c = rng.randint(-1, D)
    if out is None:  # an assumption conjunct over inputs
        kind = rng.choice(["le", "ge", "sum"] if len(ins) > 1 else ["le", "ge"])
        if kind == "le":
            return f"in.{a} <= {c}", lambda v, a=a, c=c: v[a] <= c
        if kind == "ge":
            return f"in.{a} >= {c}", lambda v, a=a, c=c: v[a] >= c
        b = rng.choice([x for x in ins if x != a])
        return f"in.{a} + in.{b} <= {c + 2}", lambda v, a=a, b=b, c=c: v[a] + v[b] <= c + 2
    kind = rng.choice(["le", "ge", "eq", "const"])
    if kind == "le":
        return f"out.{out} <= in.{a} + {abs(c)}", lambda v, a=a, o=out, c=abs(c): v[o] <= v[a] + c
    if kind == "ge":
        return f"out.{out} + {abs(c)} >= in.{a}", lambda v, a=a, o=out, c=abs(c): v[o] + c >= v[a]
    if kind == "eq":
        return f"out.{out} == in.{a}", lambda v, a=a, o=out: v[o] == v[a]
    return f"out.{out} <= {c}", lambda v, o=out, c=c: v[o] <= c


def _random_system(seed: int):  # type: ignore[no-untyped-def]
    rng = random.Random(seed)
    k = rng.randint(2, 4)
    nodes = []  # (name, inputs, output, assumption atoms, guarantee atoms)
    for i in range(k):
        earlier = [f"y{j}" for j in range(i)]
        ins = sorted(set(rng.sample(earlier, min(len(earlier), rng.randint(1, 2))) if earlier else []))
        if not ins or rng.random() < 0.3:
            ins.append(f"e{i}")
        out = f"y{i}"
        assume = [_atom(rng, ins, None) for _ in range(rng.randint(1, 2))]
        guar = [_atom(rng, ins, out) for _ in range(rng.randint(1, 2))]
        nodes.append((f"N{i}", ins, out, assume, guar))
    text = "\n".join(
        f"node {n} {{ inputs( {', '.join(f'{x} : INTEGER' for x in ins)} ) outputs( {out} : INTEGER ) "
        f"assume( {' and '.join(t for t, _ in a)} ) "
        + " ".join(f"guarantee( {t} )" for t, _ in g) + " }"
        for n, ins, out, a, g in nodes)
    return nodes, text


def _bounds(nodes) -> dict[str, list]:  # type: ignore[no-untyped-def]
    """Plan facts bounding every variable of every node to 0..D."""
    out = {}
    for n, ins, o, _, _ in nodes:
        out[n] = [parse_formula(f"0 <= in.{x} and in.{x} <= {D}") for x in ins] + \
                 [parse_formula(f"0 <= out.{o} and out.{o} <= {D}")]
    return out


def _brute(nodes, node: str, cone: list[str], goal) -> str:  # type: ignore[no-untyped-def]
    """``holds`` when ``goal`` holds in every valuation over 0..D of the
    cone's variables satisfying: each cone node's guarantees where its
    assumption holds (the consumer's own excluded), every environment
    conjunct (over environment inputs only) of the cone's assumptions;
    ``vacuous`` when no valuation satisfies them; else ``fails``."""
    spec = {n: (ins, o, a, g) for n, ins, o, a, g in nodes}
    names = sorted({x for n in cone for x in spec[n][0]} | {spec[n][1] for n in cone})
    some = False
    for vals in itertools.product(range(D + 1), repeat=len(names)):
        v = dict(zip(names, vals))
        ok = True
        for n in cone:
            ins, o, a, g = spec[n]
            env_only = [f for t, f in a if all(x.startswith("e") for x in ins if f"in.{x}" in t)]
            if not all(f(v) for f in env_only):
                ok = False
                break
            if n != node and all(f(v) for _, f in a) and not all(f(v) for _, f in g):
                ok = False
                break
        some = some or ok
        if ok and not goal(v):
            return "fails"
    return "holds" if some else "vacuous"


@settings(max_examples=40, deadline=None, derandomize=True)
@given(seed=st.integers(0, 10**6))
def test_in_context_verdict_equals_brute_force_enumeration(seed: int) -> None:
    nodes, text = _random_system(seed)
    checked, model = _system(text)
    facts = _bounds(nodes)
    spec = {n: (ins, o, a, g) for n, ins, o, a, g in nodes}
    for n, ins, _, a, _ in nodes:
        internal, _env = split_assumption(checked, model, n)
        if not internal:
            continue
        world.fresh()
        ctx = ConeContext(checked, model, n, lambda m: split_assumption(checked, model, m)[1], facts)
        by_text = {t: f for t, f in a}
        for c in internal:
            from rclverify.lang.printer import expr_to_rcl
            goal = by_text[expr_to_rcl(c)]
            r = ctx.decide(c, "oracle", 5000)
            # the encoder's way (every formula through the Z3 API) decides the same
            slow = ConeContext(checked, model, n, lambda m: split_assumption(checked, model, m)[1], facts, fast=False)
            assert ctx.all_text and not slow.all_text
            assert slow.decide(c, "oracle", 5000).status == r.status
            expected = _brute(nodes, n, ctx.cone, goal)
            # premises no valuation satisfies prove nothing: inconclusive, or proved from a consistent part
            allowed = {"holds": {"proved"}, "fails": {"refuted"}, "vacuous": {"proved", "inconclusive"}}[expected]
            assert r.status in allowed, (text, n, expr_to_rcl(c), r)
            if r.status == "refuted":  # the counterexample is one: it violates the conjunct
                assert r.model is not None
                v = {}
                for key, val in r.model.items():
                    node_name, pre, var = key.split(".")
                    v[var] = int(val)
                assert not goal(v), (text, r.model)
    assert spec  # the system was built
