"""Retries of unknown answers (semantics/retry.py)."""
from __future__ import annotations

import z3

from rclverify.semantics.retry import FINITE, MBQI, attempts, expand_finite


def test_quantifiers_over_enumerations_are_written_out_equivalently():
    color, (red, green) = z3.EnumSort("Color", ["red", "green"])
    f = z3.Function("f", color, z3.IntSort())
    c = z3.Const("c", color)
    x = z3.Int("x")
    q = z3.ForAll([c], z3.Exists([x], f(c) > x))
    e = expand_finite(q)
    assert not z3.is_quantifier(e)                      # the enum quantifier is gone
    assert "red" in str(e) and "green" in str(e)
    s = z3.Solver()
    s.add(z3.Not(e == q))
    assert s.check() == z3.unsat                        # and the rewrite is an equivalence


def test_attempts_apply_only_to_quantified_queries():
    color, (red, green) = z3.EnumSort("Color2", ["red", "green"])
    c = z3.Const("c", color)
    d = z3.Const("d", color)
    assert attempts([d == red], 1000) == []
    names = [n for n, _, _ in attempts([z3.ForAll([c], c == d)], 1000)]
    assert names == [FINITE, MBQI]
    r = z3.Real("r")
    assert [n for n, _, _ in attempts([z3.ForAll([r], r * r >= 0)], 1000)] == [MBQI]
