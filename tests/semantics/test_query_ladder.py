"""Decide first with what decides (issue 44): a query's first attempt with a
small budget, then the retries of semantics/retry.py in the laddered order.

The oracle: small random first-order formulas over a three-valued
enumeration and one binary relation, decided by brute force over every
interpretation (the relation's 512 and the constant's 3), against
``prove`` with a first budget of a few Z3 steps (so the ladder runs), with
the model-building strategies first, and as before."""
from __future__ import annotations

import itertools
import random
from typing import Any

import pytest
import z3

from rclverify.semantics import world
from rclverify.semantics.query import prove
from rclverify.semantics.retry import DEFAULT, FINITE, MBQI, MBQI_SIMPLIFIED, TABLES, reasons_text, retry_order

DOMAIN = (0, 1, 2)


def _formula(rng: random.Random, bound: list[str], depth: int) -> Any:
    """A random formula as a tuple: atoms over the constant ``c`` and bound variables."""
    terms = ["c"] + bound
    if depth == 0 or rng.random() < 0.3:
        if rng.random() < 0.7:
            return ("R", rng.choice(terms), rng.choice(terms))
        return ("eq", rng.choice(terms), rng.choice(terms))
    op = rng.choice(["and", "or", "not", "implies", "forall", "exists", "forall", "exists"])
    if op in ("forall", "exists"):
        v = f"v{len(bound)}"
        return (op, v, _formula(rng, bound + [v], depth - 1))
    if op == "not":
        return ("not", _formula(rng, bound, depth - 1))
    return (op, _formula(rng, bound, depth - 1), _formula(rng, bound, depth - 1))


def _z3(f: Any, env: dict[str, Any], sort: Any, rel: Any) -> Any:
    tag = f[0]
    if tag == "R":
        return rel(env[f[1]], env[f[2]])
    if tag == "eq":
        return env[f[1]] == env[f[2]]
    if tag == "not":
        return z3.Not(_z3(f[1], env, sort, rel))
    if tag in ("forall", "exists"):
        x = z3.Const(f[1], sort)
        body = _z3(f[2], {**env, f[1]: x}, sort, rel)
        return z3.ForAll([x], body) if tag == "forall" else z3.Exists([x], body)
    a, b = _z3(f[1], env, sort, rel), _z3(f[2], env, sort, rel)
    return {"and": z3.And, "or": z3.Or, "implies": z3.Implies}[tag](a, b)


def _holds(f: Any, env: dict[str, int], rel: frozenset[tuple[int, int]]) -> bool:
    tag = f[0]
    if tag == "R":
        return (env[f[1]], env[f[2]]) in rel
    if tag == "eq":
        return env[f[1]] == env[f[2]]
    if tag == "not":
        return not _holds(f[1], env, rel)
    if tag == "forall":
        return all(_holds(f[2], {**env, f[1]: d}, rel) for d in DOMAIN)
    if tag == "exists":
        return any(_holds(f[2], {**env, f[1]: d}, rel) for d in DOMAIN)
    a, b = _holds(f[1], env, rel), _holds(f[2], env, rel)
    return {"and": a and b, "or": a or b, "implies": (not a) or b}[tag]


def _valid(hyps: list[Any], goal: Any) -> bool:
    """Brute force: ``hyps => goal`` in every interpretation of R and c."""
    pairs = list(itertools.product(DOMAIN, DOMAIN))
    for bits in range(1 << len(pairs)):
        rel = frozenset(p for k, p in enumerate(pairs) if bits >> k & 1)
        for c in DOMAIN:
            env = {"c": c}
            if all(_holds(h, env, rel) for h in hyps) and not _holds(goal, env, rel):
                return False
    return True


def _case(seed: int) -> tuple[list[Any], Any]:
    rng = random.Random(seed)
    hyps = [_formula(rng, [], 3) for _ in range(rng.randint(1, 2))]
    return hyps, _formula(rng, [], 3)


@pytest.mark.parametrize("seed", range(40))
def test_the_ladder_decides_as_brute_force_does(seed: int) -> None:
    hyps, goal = _case(seed)
    expected = "proved" if _valid(hyps, goal) else "refuted"
    for deterministic in (False, True):
        for kw in ({}, {"first_ms": 0.001}, {"first_ms": 0.001, "likely_sat": lambda: True}):
            world.fresh()
            sort, _ = z3.EnumSort(f"E{seed}", ["e0", "e1", "e2"])
            rel = z3.Function("R", sort, sort, z3.BoolSort())
            env = {"c": z3.Const("k", sort)}
            r = prove(_z3(goal, env, sort, rel), [_z3(h, env, sort, rel) for h in hyps], timeout_ms=2000,
                      deterministic=deterministic, **kw)  # type: ignore[arg-type]
            assert r.status == expected, (seed, deterministic, kw, r.status, r.reason)
            if r.status == "refuted":
                assert r.model is not None


def test_an_undecided_first_attempt_hands_over_in_the_laddered_order() -> None:
    """A quantifier over an enumeration: with a first budget of two steps, finite instantiation
    (first in the ladder) answers; told the query is satisfiable, MBQI after simplification does.
    Without a first budget the default strategy answers, as before."""
    def ask(**kw: Any) -> Any:
        world.fresh()
        sort, _ = z3.EnumSort("Eladder", ["e0", "e1", "e2"])
        v = z3.Const("v", sort)
        p = z3.Function("p", sort, z3.BoolSort())
        return prove(p(z3.Const("k", sort)), [z3.ForAll([v], p(v))], timeout_ms=2000, deterministic=True, **kw)
    assert (ask().status, ask().strategy) == ("proved", "")
    r = ask(first_ms=0.001)
    assert (r.status, r.strategy) == ("proved", FINITE)
    r = ask(first_ms=0.001, likely_sat=lambda: True)
    assert (r.status, r.strategy) == ("proved", MBQI_SIMPLIFIED)
    asked: list[bool] = []
    r = ask(first_ms=1000, likely_sat=lambda: asked.append(True) or True)
    assert (r.status, r.strategy, asked) == ("proved", "", [])  # decided at once: the hint is never asked


def test_a_counterexample_search_refutes_when_the_first_look_does_not_decide() -> None:
    """``prove``'s ``counterexample``: asked only when the first look did not
    decide; its model refutes the query at once (strategy TABLES); ``None``
    hands the query to the ladder, which decides it as before."""
    def ask(goal_holds: bool, **kw: Any) -> Any:
        world.fresh()
        sort, _ = z3.EnumSort("Ecex", ["e0", "e1", "e2"])
        v = z3.Const("v", sort)
        p = z3.Function("p", sort, z3.BoolSort())
        hyp = z3.ForAll([v], p(v)) if goal_holds else z3.Exists([v], p(v))
        return prove(p(z3.Const("k", sort)), [hyp], timeout_ms=2000, deterministic=True, **kw)
    asked: list[bool] = []
    r = ask(False, first_ms=0.001, counterexample=lambda: asked.append(True) or {"k": "e1", "p": "{else -> FALSE}"})
    assert (r.status, r.strategy, r.model, asked) == ("refuted", TABLES, {"k": "e1", "p": "{else -> FALSE}"}, [True])
    r = ask(False, first_ms=0.001, counterexample=lambda: None)
    assert r.status == "refuted" and r.strategy != TABLES
    r = ask(True, first_ms=0.001, counterexample=lambda: None)
    assert (r.status, r.strategy) == ("proved", FINITE)
    asked.clear()
    r = ask(False, first_ms=1000, counterexample=lambda: asked.append(True) or {})
    assert r.status == "refuted" and r.strategy == "" and asked == []  # decided at once: never asked


def test_retry_order_and_reasons() -> None:
    world.fresh()
    sort, _ = z3.EnumSort("Eorder", ["a", "b"])
    v = z3.Const("v", sort)
    p = z3.Function("p", sort, z3.BoolSort())
    quantified_finite = [z3.ForAll([v], p(v))]
    x = z3.Real("x")
    g = z3.Function("g", z3.RealSort(), z3.RealSort())
    quantified_infinite = [z3.ForAll([x], g(x) > 0)]
    ground = [x > 0]
    assert retry_order(quantified_finite, ladder=False) == [FINITE, MBQI, MBQI_SIMPLIFIED]
    assert retry_order(quantified_infinite, ladder=False) == [MBQI, MBQI_SIMPLIFIED]
    assert retry_order(ground, ladder=False) == []
    assert retry_order(quantified_finite, ladder=True) == [FINITE, MBQI, MBQI_SIMPLIFIED, DEFAULT]
    assert retry_order(quantified_finite, ladder=True, models_first=True) == [MBQI_SIMPLIFIED, MBQI, FINITE, DEFAULT]
    assert retry_order(ground, ladder=True) == [DEFAULT]
    assert reasons_text({DEFAULT: "canceled"}) == "canceled"
    assert reasons_text({MBQI: "b", DEFAULT: "a"}) == f"default: a; {MBQI}: b"
