"""Side-condition variants and rule labels on small systems written for the
purpose (issue: findings an engineer can trust; paper lines 556-768)."""
from __future__ import annotations

from fractions import Fraction

from rclverify.calculus.compose import (VARIANT_AS_WRITTEN, VARIANT_WITH_ASSUMPTIONS, compose_node,
                                        instance_rule)
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.model.system.model import build

PIPELINE = """
node P {
  inputs( x : REAL )
  outputs( y : REAL )
  assume( 0 <= in.x )
  guarantee( out.y == in.x )
}
node C {
  inputs( y : REAL )
  outputs( z : REAL )
  assume( %s )
  guarantee( out.z == in.y )
}
"""


def _system(text: str):
    checked = check([parse_text(text, "sys.rcl")])
    return checked, build(checked)


def _num(v: str) -> Fraction:
    return Fraction(v.replace("?", ""))


def test_discharged_only_with_the_producers_assumption_names_that_variant():
    checked, model = _system(PIPELINE % "0 <= in.y")
    comp = compose_node(checked, model, "C")
    [sc] = comp.side_conditions
    assert sc.status == "discharged"
    assert sc.variant == VARIANT_WITH_ASSUMPTIONS
    assert "with the producers' assumptions" in sc.explanation
    assert "P assumption 1: 0 <= in.x" in sc.hypotheses
    assert comp.rules == ("R1",) and comp.instances[0]["rule"] == "R1"


def test_discharged_as_written_when_the_guarantee_suffices():
    checked, model = _system(PIPELINE % "in.y == in.y + 0")
    [sc] = compose_node(checked, model, "C").side_conditions
    assert sc.status == "discharged" and sc.variant == VARIANT_AS_WRITTEN
    assert not any("assumption" in h for h in sc.hypotheses)


def test_counterexample_of_a_failed_side_condition_satisfies_the_producers_assumption():
    checked, model = _system(PIPELINE % "5 <= in.y")
    [sc] = compose_node(checked, model, "C").side_conditions
    assert sc.status == "failed"
    assert sc.model is not None
    assert _num(sc.model["P.in.x"]) >= 0          # the producer's assumption holds in the model
    assert _num(sc.model["P.out.y"]) < 5          # and the consumer's assumption is violated
    assert "P and C are not correctly linked on P.out.y -> C.in.y (via name)" in sc.explanation


BRANCH_AND_JOIN = """
node Src {
  inputs( e : REAL )
  outputs( v : REAL )
  assume( TRUE )
  guarantee( 0 <= out.v )
}
node A {
  inputs( v : REAL )
  outputs( a : REAL )
  assume( 0 <= in.v )
  guarantee( out.a == 1 )
}
node B {
  inputs( v : REAL )
  outputs( b : REAL )
  assume( 0 <= in.v )
  guarantee( out.b == 2 )
}
node D {
  inputs( e2 : REAL )
  outputs( d : REAL )
  assume( TRUE )
  guarantee( out.d == 3 )
}
node Sink {
  inputs( a : REAL, b : REAL, d : REAL )
  outputs( s : REAL )
  assume( in.a + in.b + in.d == 6 )
  guarantee( out.s == in.a )
}
"""


def test_a_producer_feeding_two_consumers_gives_r2_instances():
    checked, model = _system(BRANCH_AND_JOIN)
    for n, other in (("A", "B"), ("B", "A")):
        comp = compose_node(checked, model, n)
        assert instance_rule(model, n) == "R2"
        assert comp.rules == ("R2",)
        [inst] = comp.instances
        assert inst["rule"] == "R2"
        assert other in inst["shape"]
        assert all(sc.rule == "R2" and sc.status == "discharged" for sc in comp.side_conditions)


def test_three_producers_feeding_one_node_give_an_r3_instance():
    checked, model = _system(BRANCH_AND_JOIN)
    comp = compose_node(checked, model, "Sink")
    assert comp.producers == ("A", "B", "D")
    assert comp.rules == ("R3",)
    [inst] = comp.instances
    assert inst["rule"] == "R3"
    [sc] = comp.side_conditions
    assert sc.rule == "R3" and sc.status == "discharged" and sc.variant == VARIANT_AS_WRITTEN


def test_case_study_radiation_sensor_is_a_branch_of_the_agents_command():
    from pathlib import Path
    from rclverify.lang.typecheck import load
    checked = load([Path(__file__).resolve().parents[2] / "contracts" / "remote_inspection.rcl"])
    model = build(checked)
    assert compose_node(checked, model, "RadiationSensor").instances[0]["rule"] == "R2"
    nav = compose_node(checked, model, "Navigation")
    assert nav.instances[0]["rule"] == "R3" and "R2" in nav.rules
