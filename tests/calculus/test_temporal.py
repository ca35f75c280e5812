"""Temporal properties over transition systems: BMC, k-induction, bounded
response and ranking functions (docs/requirements.md, Temporal requirements)."""

import pytest
import z3

from rclverify.semantics.world import fresh
from rclverify.calculus.requirements.temporal import (
    TransitionSystem, check_always, check_eventually, check_eventually_within)

I = z3.IntSort()


@pytest.fixture(autouse=True)
def _fresh_z3_world() -> None:
    """Each test builds its terms in a fresh Z3 context, as a pipeline unit of
    work does (semantics/world.py): a sort made in the context of an earlier test
    cannot be mixed with the terms of a later one."""
    global I
    fresh()
    I = z3.IntSort()


def saturating_counter():
    # x starts at 0, counts up to 10 and stays there
    return TransitionSystem(
        {"x": I}, lambda s: s["x"] == 0,
        lambda s, t: t["x"] == z3.If(s["x"] < 10, s["x"] + 1, s["x"]))


def test_always_proved_by_1_induction():
    v = check_always(saturating_counter(), lambda s: s["x"] <= 10)
    assert (v.status, v.method, v.k) == ("proved", "k-induction", 1)


def test_shift_register_needs_k_3():
    # x is 0 from step 1 on; y follows x, z follows y: z <= 0 is 3-inductive
    ts = TransitionSystem(
        {"x": I, "y": I, "z": I},
        lambda s: z3.And(s["x"] == 0, s["y"] == 0, s["z"] == 0),
        lambda s, t: z3.And(t["x"] == 0, t["y"] == s["x"], t["z"] == s["y"]))
    v = check_always(ts, lambda s: s["z"] <= 0)
    assert (v.status, v.k) == ("proved", 3)
    # and not by a smaller k
    assert check_always(ts, lambda s: s["z"] <= 0, max_k=2).status == "inconclusive"


def test_always_refuted_at_depth_7_with_trace():
    ts = TransitionSystem({"x": I}, lambda s: s["x"] == 0,
                          lambda s, t: t["x"] == s["x"] + 1)
    v = check_always(ts, lambda s: s["x"] <= 6)
    assert v.status == "refuted" and v.bound == 7
    assert [st["x"] for st in v.trace] == [str(i) for i in range(8)]


def test_always_inconclusive_when_not_inductive_within_k():
    # x stays 0, so y stays 0 and y <= 0 holds; but from the unreachable
    # states with x = 1, y climbs through any k non-positive values to 1
    ts = TransitionSystem(
        {"x": I, "y": I}, lambda s: z3.And(s["x"] == 0, s["y"] == 0),
        lambda s, t: z3.And(t["x"] == s["x"], t["y"] == s["y"] + s["x"]))
    v = check_always(ts, lambda s: s["y"] <= 0, max_k=3)
    assert v.status == "inconclusive" and v.bound == 2


def test_bounded_eventually_met_within_and_refuted_beyond():
    c = saturating_counter()
    met = check_eventually_within(c, lambda s: s["x"] >= 5, 5)
    assert met.status == "met" and met.bound == 5
    short = check_eventually_within(c, lambda s: s["x"] >= 5, 4)
    assert short.status == "refuted"
    assert [st["x"] for st in short.trace] == ["0", "1", "2", "3", "4"]


def test_unbounded_eventually_needs_a_ranking_function():
    # x starts anywhere in [0, 1000] and counts down to 0
    ts = TransitionSystem(
        {"x": I}, lambda s: z3.And(s["x"] >= 0, s["x"] <= 1000),
        lambda s, t: t["x"] == z3.If(s["x"] > 0, s["x"] - 1, 0))
    goal = lambda s: s["x"] == 0  # noqa: E731
    without = check_eventually(ts, goal, bound=5)
    assert without.status == "inconclusive" and without.bound == 5 and without.trace
    inv = lambda s: s["x"] >= 0  # noqa: E731
    proved = check_eventually(ts, goal, ranking=lambda s: s["x"], invariant=inv)
    assert (proved.status, proved.method) == ("proved", "ranking")
    # a wrong ranking function proves nothing
    bad = check_eventually(ts, goal, ranking=lambda s: -s["x"], invariant=inv, bound=5)
    assert bad.status == "inconclusive"


def test_unbounded_eventually_never_reached_is_not_proved():
    ts = TransitionSystem({"x": I}, lambda s: s["x"] == 0,
                          lambda s, t: t["x"] == s["x"])
    v = check_eventually(ts, lambda s: s["x"] == 1, ranking=lambda s: s["x"], bound=3)
    # x stays 0: the run s0 -> s1 == s0 repeats forever, a lasso (a counterexample to liveness)
    assert (v.status, v.method, v.loop) == ("refuted", "lasso", 0)


# --- the statement layer over RCL formulas (model/plan/temporal.py) ---------------

import pytest  # noqa: E402

from rclverify.model.plan.formal import Formal, Source  # noqa: E402
from rclverify.model.plan.temporal import Temporal, parse_temporal  # noqa: E402
from rclverify.lang.errors import RclError  # noqa: E402
from rclverify.lang.typecheck import load  # noqa: E402


@pytest.fixture(scope="module")
def checked():
    return load(["contracts/remote_inspection.rcl"])


def _p(text, checked):
    return parse_temporal(Source(text, 3, 12, "plan.yaml"), checked)


def test_state_statement_stays_a_formal(checked):
    assert isinstance(_p("RadiationSensor.out.radiationStatus == red", checked), Formal)


def test_temporal_operators_nest_with_bound_and_until(checked):
    t = _p("always (eventually[<= 4] (RadiationSensor.out.radiationStatus == red))", checked)
    assert t.op == "always" and isinstance(t.args[0], Temporal)
    inner = t.args[0]
    assert (inner.op, inner.bound) == ("eventually", 4) and isinstance(inner.args[0], Formal)
    u = _p("RadiationSensor.out.radiationStatus == green until "
           "RadiationSensor.out.radiationStatus == red", checked)
    assert u.op == "until" and all(isinstance(a, Formal) for a in u.args)
    n = _p("next previous RadiationSensor.in.r > 0", checked)
    assert (n.op, n.args[0].op) == ("next", "previous")


def test_errors_in_an_operand_keep_the_plan_column(checked):
    with pytest.raises(RclError) as e:
        _p("always Nobody.out.x = 1", checked)
    assert "plan.yaml:3:19" in str(e.value)
    with pytest.raises(RclError) as e:
        _p("eventually[<= many] RadiationSensor.in.r > 0", checked)
    assert "natural number" in str(e.value) and "plan.yaml:3:26" in str(e.value)
    with pytest.raises(RclError):
        _p("always", checked)
