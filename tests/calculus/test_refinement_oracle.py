"""The refinement check against brute force (issue 44 changed the order in
which it asks Z3: a small first budget, then a finite-table counterexample,
which refutes the side with its model; each such model is evaluated here).  Random contracts over an enumeration, a Boolean and a
function-typed input read at two points, whose every valuation can be
enumerated: "B refines A" holds exactly when ``A_A => A_B`` and
``A_A and G_B => G_A`` hold in every valuation.  Asked as the pipeline asks
it, and with a first budget of a few steps so that every step of the
ladder runs."""
from __future__ import annotations

import itertools
import random
import re
from typing import Any

import pytest

from rclverify.calculus import refinement
from rclverify.calculus.refinement import check_refinement
from rclverify.semantics import world
from rclverify.semantics.retry import TABLES
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check

COLORS = ("red", "green", "blue")
CONTEXT = "context { Color : {red, green, blue} ; Idx : INTEGER --> Color ; }\n"


def _atom(rng: random.Random) -> tuple[str, Any]:
    c = rng.choice(COLORS)
    k = rng.choice((0, 1))
    return rng.choice([
        (f"in.x == {c}", lambda v: v["x"] == c),
        (f"out.y == {c}", lambda v: v["y"] == c),
        ("out.b == TRUE", lambda v: v["b"]),
        (f"in.f({k}) == {c}", lambda v: v["f"][k] == c),
        ("out.y == in.x", lambda v: v["y"] == v["x"]),
        (f"out.y == in.f({k})", lambda v: v["y"] == v["f"][k]),
        (f"exists(c in Color | in.f({k}) == c and out.y != c)", lambda v: v["y"] != v["f"][k]),
        (f"forall(c in Color | in.x == c -> in.f({k}) != c)", lambda v: v["x"] != v["f"][k]),
    ])


def _formula(rng: random.Random, depth: int) -> tuple[str, Any]:
    if depth == 0 or rng.random() < 0.35:
        return _atom(rng)
    op = rng.choice(["and", "or", "->", "not"])
    if op == "not":
        t, f = _formula(rng, depth - 1)
        return f"not ({t})", lambda v: not f(v)
    (ta, fa), (tb, fb) = _formula(rng, depth - 1), _formula(rng, depth - 1)
    fn = {"and": lambda v: fa(v) and fb(v), "or": lambda v: fa(v) or fb(v),
          "->": lambda v: (not fa(v)) or fb(v)}[op]
    return f"({ta}) {op} ({tb})", fn


def _contract(rng: random.Random, name: str) -> tuple[str, list[Any], list[Any]]:
    assumes = [_formula(rng, 2) for _ in range(rng.randint(0, 1))]
    guars = [_formula(rng, 2) for _ in range(rng.randint(1, 2))]
    text = (f"node {name} {{ inputs( x : Color, f : Idx ) outputs( y : Color, b : BOOL )\n"
            + "".join(f"  assume( {t} )\n" for t, _ in assumes)
            + "".join(f"  guarantee( {t} )\n" for t, _ in guars) + "}\n")
    return text, [f for _, f in assumes], [f for _, f in guars]


def _valuations() -> Any:
    for x, f0, f1, y, b in itertools.product(COLORS, COLORS, COLORS, COLORS, (False, True)):
        yield {"x": x, "f": (f0, f1), "y": y, "b": b}


def _expected(aa: list[Any], ga: list[Any], ab: list[Any], gb: list[Any]) -> tuple[str, str]:
    vals = list(_valuations())
    assumption = all(all(f(v) for f in ab) for v in vals if all(f(v) for f in aa))
    guarantee = all(all(f(v) for f in ga) for v in vals if all(f(v) for f in aa) and all(f(v) for f in gb))
    return ("proved" if assumption else "refuted"), ("proved" if guarantee else "refuted")


@pytest.mark.parametrize("seed", range(20))
def test_refinement_agrees_with_brute_force(seed: int, monkeypatch: pytest.MonkeyPatch) -> None:
    rng = random.Random(seed)
    ta, aa, ga = _contract(rng, "A")
    tb, ab, gb = _contract(rng, "B")
    checked = check([parse_text(CONTEXT + ta + tb, "r.rcl")])
    want = _expected(aa, ga, ab, gb)
    for first_ms in (refinement.FIRST_MS, 0.001):  # as the pipeline asks; every strategy of the ladder
        monkeypatch.setattr(refinement, "FIRST_MS", first_ms)
        world.fresh()
        r = check_refinement(checked.nodes["A"], checked.nodes["B"], checked.env, timeout_ms=2000)
        got = (r.assumption.status, r.guarantee.status)
        assert got == want, (seed, first_ms, ta, tb, r)
        assert r.verdict == ("refines" if want == ("proved", "proved") else "does not refine")
        for side, hyps, goal in ((r.assumption, aa, ab), (r.guarantee, aa + gb, ga)):
            if side.strategy == TABLES:  # a finite-table counterexample: it must refute the side
                assert side.model is not None
                v = _valuation(side.model)
                assert all(f(v) for f in hyps) and not all(f(v) for f in goal), (seed, side.model)


def _valuation(model: dict[str, str]) -> dict[str, Any]:
    """A counterexample as the report prints it, as a valuation of :func:`_valuations`'s shape
    (a variable the model leaves out may take any value: the first)."""
    def table_at(text: str, k: int) -> str:
        rows = dict(re.findall(r"\((-?\d+)\) -> (\w+)", text))
        return rows.get(str(k), re.search(r"else -> (\w+)", text).group(1))  # type: ignore[union-attr]
    return {"x": model.get("in.x", COLORS[0]), "y": model.get("out.y", COLORS[0]),
            "b": model.get("out.b", "FALSE") == "TRUE",
            "f": tuple(table_at(model["in.f"], k) if "in.f" in model else COLORS[0] for k in (0, 1))}
