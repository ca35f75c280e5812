"""The calculus on the case study (derivation D1) and on the non-ROS rover
architecture with a branch (R2) and a join (R3), paper lines 556-768, 1183-1280, 1763-1846."""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.calculus.compose import compose_node, conjuncts, split_assumption
from rclverify.lang.parser import parse_formula, parse_text
from rclverify.lang.typecheck import check, load
from rclverify.model.system.model import build

ROOT = Path(__file__).resolve().parents[2]
ROVER = Path(__file__).parent.parent / "data" / "rover_navigation.rcl"


@pytest.fixture(scope="module")
def case_study():
    checked = load([ROOT / "contracts" / "remote_inspection.rcl"])
    return checked, build(checked)


def test_d1_side_condition_for_the_agent_is_discharged(case_study):
    checked, model = case_study
    comp = compose_node(checked, model, "Agent")
    assert comp.producers == ("Navigation", "RadiationSensor")
    assert "R3" in comp.rules and "R4" in comp.rules
    [sc] = comp.side_conditions
    assert sc.conjunct == "in.radiationStatus in {red, orange, green}"
    assert sc.status == "discharged"
    assert "(check-sat)" in sc.smt2
    # the R3 instance's conclusion is the paper's derived property (line 1244)
    [inst] = comp.instances
    assert inst["rule"] == "R3"
    assert inst["conclusion"] == ("(exists_unique(x, y in REAL | in.position(x, y) == TRUE)) and (0 <= in.r)"
                                  " => <> G_Agent")
    assert comp.loop_assumption and "terminates" in comp.loop_assumption


def test_environment_assumptions_are_left_to_the_user(case_study):
    checked, model = case_study
    internal, env = split_assumption(checked, model, "RadiationSensor")
    assert internal == []
    assert [str(e.operands[1].qualified) for e in env] == ["in.r"]
    comp = compose_node(checked, model, "Agent")
    assert comp.derived_property == "(0 <= in.r) => <> G_Agent"


def test_rover_branch_and_join():
    checked = load([ROVER])
    model = build(checked)
    rules = {n: compose_node(checked, model, n).rules for n in checked.nodes}
    assert rules["GRA"] == ()
    # a branch (GRA.goal is read by both planners) is R2, not R1 (paper lines 612-640)
    assert rules["ComputePlan2Charging"] == ("R2",)
    assert rules["ComputePlan2Destination"] == ("R2",)
    assert rules["Interface"] == ("R3",)
    for n in checked.nodes:
        for sc in compose_node(checked, model, n).side_conditions:
            assert sc.status == "discharged", (sc.id, sc.model)
    iface = compose_node(checked, model, "Interface")
    assert len(iface.side_conditions) == 2  # the assumption's two conjuncts
    assert iface.derived_property.startswith("(0 <= in.battery and in.battery <= 100")


def test_broken_link_is_refuted_with_a_model_in_rcl_names():
    text = ROVER.read_text().replace("out.dest_plan <= 20", "out.dest_plan <= 25")
    checked = check([parse_text(text, "rover.rcl")])
    model = build(checked)
    comp = compose_node(checked, model, "Interface")
    sc = comp.side_conditions[0]
    assert sc.status == "failed"
    assert sc.model is not None
    total = int(sc.model["ComputePlan2Charging.out.charge_plan"]) + int(sc.model["ComputePlan2Destination.out.dest_plan"])
    assert total > 30
    assert "not correctly linked" in sc.explanation


def test_conjuncts_split_only_top_level_and():
    e = parse_formula("a and (b or c) and d")
    assert len(conjuncts(e)) == 3
