"""A comparison of two exact sides in the column evaluator (targets/columns.py, ``_compare``): sure
wherever both sides are finite, its truth the exact judgement's.

Both sides of ``out.y > in.a``, ``out.y <= 2`` or a window entry against an
input (``out.x(k) > in.r``) are recorded doubles or literals that are
doubles: their error bound is 0, so the certificate's rule ("sure when both
bounds are 0, or the sides further apart than twice their bounds, and both
finite") reduces to "both finite".  Checked against that rule written out
in full and against the exact judgement (semantics/floatsem.py ``judge``)
row by row, on random rows with ties, neighbours one ulp apart, signed
zeros, subnormals, infinities and NaN; the control is a side with a bound
(the inexact literal ``0.1``), whose rows within the bound are not sure.
"""
from __future__ import annotations

import math
import random
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from rclverify.lang.parser import parse_formula
from rclverify.lang.typecheck import load
from rclverify.semantics.floatsem import judge
from rclverify.targets.column_windows import WindowCompiler
from rclverify.targets.columns import ColumnCompiler

CONTRACTS = """\
node Pair {
  inputs( a : REAL )
  outputs( y : REAL )
  topics( std_msgs/Float64 a matches(in.a), std_msgs/Float64 y matches(out.y) )
  guarantee( out.y > in.a )
}
node Window {
  inputs( r : REAL )
  outputs( x : NATURAL --> REAL )
  topics( std_msgs/Float64 limit matches(in.r), std_msgs/Float64MultiArray window matches(out.x) )
  guarantee( forall(k in <0 upto 2> | out.x(k) > in.r) )
}
"""
_REL, _SLACK_REL, _SLACK_ABS = 2.0 ** -52, 2.0 ** -48, 2.0 ** -1000


@pytest.fixture(scope="module")
def checked(tmp_path_factory: Any) -> Any:
    path: Path = tmp_path_factory.mktemp("compare") / "compare.rcl"
    path.write_text(CONTRACTS)
    return load([path])


def _value(rnd: random.Random, near: float) -> float:
    """A double: often ``near`` itself or a neighbour of it, else anything a run may record."""
    pick = rnd.random()
    if pick < 0.25:
        return near
    if pick < 0.45:
        return math.nextafter(near, rnd.choice([math.inf, -math.inf]))
    if pick < 0.55:
        return rnd.choice([0.0, -0.0, 5e-324, -5e-324, math.inf, -math.inf, math.nan, 1e308, -1e308])
    return rnd.uniform(-4.0, 4.0)


def _rule(vx: np.ndarray, bx: float, vy: np.ndarray, by: float) -> np.ndarray:
    """The certificate's rule in full (targets/columns.py, module docstring)."""
    with np.errstate(all="ignore"):
        bound = bx + by
        gap = np.abs(vx - vy)
        sure = (bound == 0) | (gap > 2 * bound + _SLACK_REL * (np.abs(vx) + np.abs(vy)) + _SLACK_ABS)
        return np.asarray(sure & np.isfinite(vx) & np.isfinite(vy))


@pytest.mark.parametrize("text,near,bound", [("out.y > in.a", 1.0, 0.0), ("out.y <= 2", 2.0, 0.0),
                                              ("out.y == in.a", 0.5, 0.0), ("out.y < 0.1", 0.1, 0.1 * _REL + _SLACK_ABS)])
def test_exact_sides_are_sure_where_finite(checked: Any, text: str, near: float, bound: float) -> None:
    node = checked.nodes["Pair"]
    formula = parse_formula(text)
    f = ColumnCompiler(checked, node).compile(formula)
    rnd = random.Random(11)
    rows = [(_value(rnd, near), _value(rnd, near)) for _ in range(600)]
    a = np.array([r[0] for r in rows])
    y = np.array([r[1] for r in rows])
    truth, sure = (np.broadcast_to(v, (len(rows),)) for v in f({"in.a": a, "out.y": y}))
    other = a if "in.a" in text else np.full(len(rows), near)
    want = _rule(y, 0.0, other, bound)
    assert sure.tolist() == want.tolist()
    if bound == 0:
        assert sure.tolist() == (np.isfinite(y) & np.isfinite(other)).tolist()
    else:  # the control: an inexact literal leaves the rows within its bound unsure, finite as they are
        close = np.isfinite(y) & (np.abs(y - 0.1) <= 2 * bound)
        assert close.any() and not sure[close].any()
    for (av, yv), t, ok in zip(rows, truth.tolist(), sure.tolist()):
        if not ok:
            continue
        exact = judge(formula, checked, node, {"in.a": av, "out.y": yv})
        assert exact.semantics.startswith("exact") and exact.truth is t, (text, av, yv)


def test_a_window_entry_against_an_input(checked: Any) -> None:
    """The window guarantee the windowed race judges: sure on every row whose entries and limit are finite;
    a row with a NaN or infinite entry, or a NaN limit, is left to the engine."""
    node = checked.nodes["Window"]
    f = WindowCompiler(checked, node).compile(parse_formula("forall(k in <0 upto 2> | out.x(k) > in.r)"))
    rnd = random.Random(5)
    rows = [([_value(rnd, 1.0) for _ in range(3)], _value(rnd, 1.0)) for _ in range(500)]
    x = np.array([r[0] for r in rows])
    r = np.array([r[1] for r in rows])
    truth, sure = f({"in.r": r, "out.x": x})
    finite = np.isfinite(x).all(axis=1) & np.isfinite(r)
    with np.errstate(invalid="ignore"):
        false_somewhere = ((x <= r[:, None]) & np.isfinite(x) & np.isfinite(r)[:, None]).any(axis=1)
    assert sure.tolist() == (finite | false_somewhere).tolist()
    assert (~sure).any() and sure.any()
    for (xs, rv), t, ok in zip(rows, truth.tolist(), sure.tolist()):
        if ok:
            assert t == all(v > rv for v in xs), (xs, rv)
