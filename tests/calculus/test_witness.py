"""Finite-table witnesses (calculus/health/witness.py) against brute force.

A witness asked of the ``simplify``/``qe-light`` tactics first
(``simplified=True``) meets the contract, evaluated here on its tables, and
is found whenever the default strategy finds one.

A witness of a contract's consistency fixes every function-typed input to a
table and every variable to a value; ``extend`` asks whether a premise over
new witness variables holds in that same model.  With everything else fixed
the answer is a finite search, enumerated here: on random contracts the
extension is ``sat`` exactly when some instance of the premise holds in the
witness's tables, and the variable it reports is one such instance.
"""
from __future__ import annotations

import random
import re
from typing import Any

import pytest

from rclverify.calculus.health.node_health import NodeHealth
from rclverify.calculus.health.witness import extend, finite_witness, points_for
from rclverify.semantics import world
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check

CONTEXT = "context { T : INTEGER --> INTEGER ; }\n"


def _contract(rng: random.Random) -> tuple[str, int]:
    return _parts(rng)[:2]  # type: ignore[return-value]


def _parts(rng: random.Random) -> tuple[str, int, Any]:
    """A random contract's text, the bound ``a`` of guarantee 1's premise, and
    the contract as a Python predicate on ``(f table, x, y)``."""
    a, b, c = rng.randint(-3, 3), rng.randint(-2, 2), rng.randint(-2, 4)
    x0, k, op, v = rng.randint(-2, 2), rng.randint(0, 3), rng.choice(['<', '>=', '==']), rng.randint(-3, 3)
    text = (CONTEXT + "node n { inputs( f : T, x : INTEGER ) outputs( y : INTEGER )\n"
            f"  assume( in.x >= {x0} )\n"
            f"  guarantee( forall(i in INTEGER | 0 <= i and i <= 3 and in.f(i) >= {a} -> out.y >= in.f(i) + {b}) )\n"
            f"  guarantee( out.y <= {c} )\n"
            f"  guarantee( in.f({k}) {op} {v} )\n"
            "}\n")
    compare = {"<": lambda p, q: p < q, ">=": lambda p, q: p >= q, "==": lambda p, q: p == q}[op]

    def holds(f: dict[int, int], x: int, y: int) -> bool:
        return (x >= x0 and all(y >= f[i] + b for i in range(4) if f[i] >= a) and y <= c
                and compare(f[k], v))
    return text, a, holds


def _table(text: str) -> dict[int, int]:
    rows = {int(k): int(v) for k, v in re.findall(r"\((-?\d+)\) -> (-?\d+)", text)}
    default = int(re.search(r"else -> (-?\d+)", text).group(1))  # type: ignore[union-attr]
    return {k: rows.get(k, default) for k in range(4)}


@pytest.mark.parametrize("seed", range(30))
def test_extension_holds_exactly_where_an_instance_fires(seed: int) -> None:
    rng = random.Random(seed)
    text, a = _contract(rng)
    checked = check([parse_text(text, "w.rcl")])
    world.fresh()
    h = NodeHealth(checked, checked.nodes["n"], (), None, 2000)
    w = finite_witness(h.enc, [f for _, f in h.labelled()], points_for(None))
    if w.status != "sat":
        assert w.found is None
        return  # an inconsistent contract: nothing to extend
    assert w.model is not None
    f = _table(w.model["n.in.f"])
    premise = h.premise(1)
    assert premise is not None
    got = extend(w, h.enc, [x for _, x in premise[0]])
    fires = [i for i in range(4) if f[i] >= a]
    assert (got.status == "sat") == bool(fires), (seed, text, w.model, got)
    if got.status == "sat":
        assert got.model is not None
        i = int(got.model["i (witness for guarantee 1)"])
        assert i in fires
        # the earlier symbols keep the witness's values
        assert {k: v for k, v in got.model.items() if k in w.model} == w.model


def test_a_witness_with_an_untabled_function_is_not_extended() -> None:
    """A function over an enumeration is not a table here: its interpretation
    is not fixed, so the witness offers no extension (never a wrong sat)."""
    text = ("context { C : {red, green} ; F : C --> INTEGER ; G : INTEGER --> INTEGER ; }\n"
            "node n { inputs( f : F, g : G ) outputs( y : INTEGER )\n"
            "  guarantee( forall(i in INTEGER | in.g(i) > 0 -> out.y == in.f(red)) ) }\n")
    checked = check([parse_text(text, "w.rcl")])
    world.fresh()
    h = NodeHealth(checked, checked.nodes["n"], (), None, 2000)
    w = finite_witness(h.enc, [f for _, f in h.labelled()], points_for(None))
    assert w.status == "sat" and w.found is None
    premise = h.premise(1)
    assert premise is not None
    assert extend(w, h.enc, [x for _, x in premise[0]]).status == "inconclusive"


@pytest.mark.parametrize("seed", range(30))
def test_a_simplified_witness_meets_the_contract_and_loses_none(seed: int) -> None:
    rng = random.Random(seed)
    text, _, holds = _parts(rng)
    checked = check([parse_text(text, "w.rcl")])
    found = {}
    for simplified in (False, True):
        world.fresh()
        h = NodeHealth(checked, checked.nodes["n"], (), None, 2000)
        found[simplified] = finite_witness(h.enc, [f for _, f in h.labelled()], points_for(None),
                                           simplified=simplified)
    if found[False].status == "sat":
        assert found[True].status == "sat"
    w = found[True]
    if w.status == "sat":
        assert w.model is not None
        assert holds(_table(w.model["n.in.f"]), int(w.model["n.in.x"]), int(w.model["n.out.y"])), (text, w.model)
