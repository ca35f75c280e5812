"""semantics/subterms.py against a plain tree walk: the same distinct terms, each once."""
from __future__ import annotations

import random

import z3

from rclverify.semantics.subterms import subterms


def _tree(e: z3.ExprRef) -> list[z3.ExprRef]:
    """Every subterm by a tree walk (shared terms many times)."""
    out = [e]
    kids = [e.body()] if z3.is_quantifier(e) else e.children() if z3.is_app(e) else []
    for k in kids:
        out += _tree(k)
    return out


def test_each_distinct_subterm_once_quantifier_bodies_included() -> None:
    rnd = random.Random(5)
    x, y = z3.Ints("x y")
    f = z3.Function("f", z3.IntSort(), z3.IntSort())
    atoms = [x, y, f(x), z3.IntVal(3), x + 1]
    for _ in range(60):
        terms = list(atoms)
        for _ in range(rnd.randint(1, 8)):
            a, b = rnd.choice(terms), rnd.choice(terms)
            terms.append(rnd.choice([a + b, a * 2, f(b)]))
        body = z3.And(terms[-1] > 0, rnd.choice(terms) == rnd.choice(terms))
        formulas = [z3.ForAll([x], body) if rnd.random() < 0.5 else body, rnd.choice(terms) < 7]
        got = list(subterms(formulas))
        ids = [t.get_id() for t in got]
        assert len(ids) == len(set(ids))
        assert set(ids) == {t.get_id() for g in formulas for t in _tree(g)}
