"""Space margins against RTAMT 0.4.10, Reelay 25 and mstlo 0.2.2 (the ``bench`` extra) on the
formulas RCL shares with signal temporal logic (docs/semantics.md, "Margins").

Each pair is an STL formula and its RCL counterpart, checked on two traces
(the issue's x = 3, 2.5, 1.5, 2, 4, 5, 0.5, 2 with a y beside it, and 40
seeded random samples): the margin rclverify computes
(:func:`rclverify.semantics.robustness.margin`) equals each peer's
robustness at every sample time whose window lies in the trace, within
float tolerance.

Where RCL's meaning differs, and how the pairs are made:

* **Stream semantics.**  RCL judges each answer on the values in force at
  its question (a state formula); the peers judge a signal at each sample
  time.  A time window is no operator of an RCL guarantee (RCL's temporal
  requirements count steps, not time), so a window is a value a message
  carries: at time t the inputs are ``in.x(k) = x[t + k]`` for the offsets
  k of the window (a function from offsets to samples, as a message holding
  a trajectory or a scan), and STL's ``G[0,h]`` and ``F[0,h]`` are RCL's
  ``forall`` and ``exists`` over ``<0 upto h>``.  A pointwise formula uses
  the offset 0 alone.  The peers' figures at times whose window runs past
  the trace's end (RTAMT's partial windows) have no RCL counterpart: a
  message carries its whole window.
* **Reelay** monitors past time only: ``G[0,h] p`` at t is its
  ``historically[0:h] p`` at t + h, and ``p U[0,h] q`` at t is its
  ``p since[0:h] q`` on the trace read backwards.
* **Until.**  RTAMT and Reelay need ``p`` on ``[t, t')`` before ``q`` at
  ``t'``, mstlo on ``[t, t']``: RCL states either (``i < j`` or
  ``i <= j`` over the offsets), and the test shows the two differ on the
  issue's trace, so agreeing with one is no accident.

A peer that cannot be imported is skipped with the reason.
"""
from __future__ import annotations

import random
from dataclasses import dataclass
from typing import Any

import pytest

from rclverify.lang.parser import parse_formula, parse_text
from rclverify.lang.typecheck import check
from rclverify.semantics.robustness import margin
from rclverify.semantics.values import FiniteFunction

CHECKED = check([parse_text("node W { inputs( x : NATURAL --> REAL, y : NATURAL --> REAL ) outputs( o : BOOL ) "
                            "guarantee( TRUE ) }")])
NODE = CHECKED.nodes["W"]
ISSUE_X = [3.0, 2.5, 1.5, 2.0, 4.0, 5.0, 0.5, 2.0]
ISSUE_Y = [1.0, 5.0, 2.0, 6.0, 3.0, 3.0, 7.0, 2.0]
_rnd = random.Random(98)
RANDOM_X = [round(_rnd.uniform(-1.0, 6.0), 3) for _ in range(40)]
RANDOM_Y = [round(_rnd.uniform(0.0, 8.0), 3) for _ in range(40)]
TRACES = {"issue": (ISSUE_X, ISSUE_Y), "random": (RANDOM_X, RANDOM_Y)}
UNTIL_RCL = "exists(j in <0 upto 3> | in.y(j) > 4 and forall(i in <0 upto 3> | i {} j -> in.x(i) > 1))"


@dataclass(frozen=True)
class Pair:
    """One STL formula in each tool's syntax and its RCL counterpart over the window ``<0 upto h>``."""

    name: str
    rcl: str
    h: int
    rtamt: str
    reelay: str
    reelay_read: str  # "shift": past-time at t + h; "reverse": on the trace read backwards
    mstlo: str
    mstlo_rcl: str = ""  # RCL's formula for mstlo's meaning where it differs from RTAMT's


PAIRS = [
    Pair("x > 1", "in.x(0) > 1", 0, "x > 1", "{x > 1}", "shift", "x > 1"),
    Pair("x <= 2.5", "in.x(0) <= 2.5", 0, "x <= 2.5", "{x <= 2.5}", "shift", "x <= 2.5"),
    Pair("not", "not (in.x(0) > 3)", 0, "not (x > 3)", "not {x > 3}", "shift", "!(x > 3)"),
    Pair("and", "in.x(0) > 1 and in.y(0) < 4", 0, "(x > 1) and (y < 4)", "{x > 1} and {y < 4}", "shift",
         "x > 1 && y < 4"),
    Pair("or", "in.x(0) > 1 or in.y(0) > 4", 0, "(x > 1) or (y > 4)", "{x > 1} or {y > 4}", "shift",
         "x > 1 || y > 4"),
    Pair("implies", "in.x(0) > 1 -> in.y(0) > 4", 0, "(x > 1) implies (y > 4)", "{x > 1} implies {y > 4}",
         "shift", "x > 1 -> y > 4"),
    Pair("G[0,2]", "forall(k in <0 upto 2> | in.x(k) > 1)", 2, "always[0,2](x > 1)", "historically[0:2]{x > 1}",
         "shift", "G[0,2](x > 1)"),
    Pair("F[0,2]", "exists(k in <0 upto 2> | in.x(k) > 4)", 2, "eventually[0,2](x > 4)", "once[0:2]{x > 4}",
         "shift", "F[0,2](x > 4)"),
    Pair("G[0,2] and", "forall(k in <0 upto 2> | in.x(k) > 1 and in.y(k) < 6.5)", 2,
         "always[0,2]((x > 1) and (y < 6.5))", "historically[0:2]({x > 1} and {y < 6.5})", "shift",
         "G[0,2](x > 1 && y < 6.5)"),
    Pair("F[0,3] and", "exists(k in <0 upto 3> | in.x(k) > 4 and in.y(k) > 2)", 3,
         "eventually[0,3]((x > 4) and (y > 2))", "once[0:3]({x > 4} and {y > 2})", "shift",
         "F[0,3](x > 4 && y > 2)"),
    Pair("G[0,1] F[0,2]", "forall(i in <0 upto 1> | exists(j in <0 upto 2> | in.x(i + j) > 3))", 3,
         "always[0,1](eventually[0,2](x > 3))", "historically[0:1](once[0:2]{x > 3})", "shift",
         "G[0,1](F[0,2](x > 3))"),
    Pair("U[0,3]", UNTIL_RCL.format("<"), 3, "(x > 1) until[0,3] (y > 4)", "{x > 1} since[0:3] {y > 4}", "reverse",
         "(x > 1) U[0,3] (y > 4)", UNTIL_RCL.format("<=")),
]


def rcl_margins(formula: str, h: int, xs: list[float], ys: list[float]) -> list[float]:
    """rclverify's margin at each time t whose window t..t+h lies in the trace."""
    f = parse_formula(formula)
    out = []
    for t in range(len(xs) - h):
        values = {"in.x": FiniteFunction({(k,): xs[t + k] for k in range(h + 1)}, 0.0),
                  "in.y": FiniteFunction({(k,): ys[t + k] for k in range(h + 1)}, 0.0)}
        out.append(margin(f, CHECKED, NODE, values, "double").value)
    return out


def rtamt_margins(p: Pair, xs: list[float], ys: list[float]) -> list[float]:
    rtamt = pytest.importorskip("rtamt", reason="RTAMT is not installed (pip install '.[bench]')")
    spec = rtamt.StlDiscreteTimeSpecification()
    spec.declare_var("x", "float")
    spec.declare_var("y", "float")
    spec.spec = p.rtamt
    spec.parse()
    got = spec.evaluate({"time": list(range(len(xs))), "x": xs, "y": ys})
    return [float(r) for _, r in got][:len(xs) - p.h]


def reelay_margins(p: Pair, xs: list[float], ys: list[float]) -> list[float]:
    reelay = pytest.importorskip("reelay", reason="Reelay is not installed (pip install '.[bench]')")
    mon = reelay.discrete_timed_monitor(pattern=p.reelay, semantics="robustness", condense=False)
    rows = list(zip(xs, ys)) if p.reelay_read == "shift" else list(zip(xs, ys))[::-1]
    got = [float(mon.update({"time": i, "x": x, "y": y})["value"]) for i, (x, y) in enumerate(rows)]
    return got[p.h:] if p.reelay_read == "shift" else got[::-1][:len(xs) - p.h]


def mstlo_margins(p: Pair, xs: list[float], ys: list[float]) -> list[float]:
    mstlo = pytest.importorskip("mstlo_python", reason="mstlo is not installed (pip install '.[bench]')")
    mon = mstlo.Monitor(mstlo.parse_formula(p.mstlo), semantics="DelayedQuantitative")
    got = mon.update_batch({"x": [(x, float(t)) for t, x in enumerate(xs)],
                            "y": [(y, float(t)) for t, y in enumerate(ys)]}).verdicts()
    return [float(r) for _, r in got]


TOLERANCE = {"rel": 1e-9, "abs": 1e-12}
CASES = [pytest.param(p, trace, id=f"{p.name}-{trace}") for p in PAIRS for trace in TRACES]


@pytest.mark.parametrize("pair, trace", CASES)
def test_rtamt(pair: Pair, trace: str) -> None:
    xs, ys = TRACES[trace]
    assert rcl_margins(pair.rcl, pair.h, xs, ys) == pytest.approx(rtamt_margins(pair, xs, ys), **TOLERANCE)


@pytest.mark.parametrize("pair, trace", CASES)
def test_reelay(pair: Pair, trace: str) -> None:
    xs, ys = TRACES[trace]
    assert rcl_margins(pair.rcl, pair.h, xs, ys) == pytest.approx(reelay_margins(pair, xs, ys), **TOLERANCE)


@pytest.mark.parametrize("pair, trace", CASES)
def test_mstlo(pair: Pair, trace: str) -> None:
    xs, ys = TRACES[trace]
    want = mstlo_margins(pair, xs, ys)
    assert len(want) == len(xs) - pair.h
    assert rcl_margins(pair.mstlo_rcl or pair.rcl, pair.h, xs, ys) == pytest.approx(want, **TOLERANCE)


def test_the_issue_figures() -> None:
    """``G[0,2](x > 1)`` on the issue's x: 0.5, 0.5, 0.5, 1.0, -0.5, -0.5 at t = 0..5, in RCL and in each peer."""
    want = [0.5, 0.5, 0.5, 1.0, -0.5, -0.5]
    g = PAIRS[6]
    assert rcl_margins(g.rcl, 2, ISSUE_X, ISSUE_Y) == want
    for peer in (rtamt_margins, reelay_margins, mstlo_margins):
        assert peer(g, ISSUE_X, ISSUE_Y) == pytest.approx(want)


def test_control_the_until_conventions_differ() -> None:
    """The two readings of until give other figures on the issue's trace (at t = 3 and 4), so each
    tool's agreement with its RCL formula shows the comparison tells margins apart."""
    strict = rcl_margins(UNTIL_RCL.format("<"), 3, ISSUE_X, ISSUE_Y)
    closed = rcl_margins(UNTIL_RCL.format("<="), 3, ISSUE_X, ISSUE_Y)
    assert strict == [1.0, 1.0, 0.5, 2.0, 3.0] and closed == [1.0, 1.0, 0.5, 1.0, -0.5]
    until = PAIRS[-1]
    assert rtamt_margins(until, ISSUE_X, ISSUE_Y) != pytest.approx(closed)
    assert mstlo_margins(until, ISSUE_X, ISSUE_Y) != pytest.approx(strict)


def test_every_pair_has_a_distinct_reading() -> None:
    """No two pairs give the same margins on the random trace: twelve formulas, not one counted twelve times."""
    seen = {tuple(rcl_margins(p.rcl, p.h, RANDOM_X, RANDOM_Y)) for p in PAIRS}
    assert len(seen) == len(PAIRS)
