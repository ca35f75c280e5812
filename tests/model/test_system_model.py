"""System model: connections by name, topic and plan; environment inputs; loops."""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.semantics.encode import Encoder
from rclverify.semantics.query import prove
from rclverify.model.plan.load import Connection
from rclverify.lang import ast
from rclverify.lang.errors import RclError
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check, load
from rclverify.model.system.model import Link, SystemModel, build

ROOT = Path(__file__).resolve().parents[2]
CASE_STUDY = ROOT / "contracts" / "remote_inspection.rcl"


@pytest.fixture(scope="module")
def model() -> SystemModel:
    return build(load([CASE_STUDY]))


def links(m: SystemModel) -> set[tuple[str, str, str, str, str]]:
    return {(l.from_node, l.from_var, l.to_node, l.to_var, l.via) for l in m.links}


def test_case_study_links(model: SystemModel) -> None:
    assert model.nodes == ("Localisation", "Navigation", "Agent", "RadiationSensor")
    assert links(model) == {
        ("Localisation", "position", "Navigation", "position", "name"),
        ("Navigation", "at", "Agent", "at", "name"),
        ("RadiationSensor", "radiationStatus", "Agent", "radiationStatus", "name"),
        ("RadiationSensor", "inspected", "Agent", "inspected", "name"),
        ("Agent", "command", "Navigation", "command", "name"),
        ("Agent", "command", "RadiationSensor", "command", "name"),
    }


def test_case_study_environment_inputs(model: SystemModel) -> None:
    assert {(n, v) for n, v, _ in model.env_inputs} == {
        ("Localisation", "sensors"), ("Agent", "wayP"), ("RadiationSensor", "r")}
    types = {(n, v): t for n, v, t in model.env_inputs}
    assert types[("Localisation", "sensors")] == "SensorsType"
    assert types[("RadiationSensor", "r")] == "REAL"
    assert types[("Agent", "wayP")] == "REAL x REAL --> NATURAL"


def test_case_study_loop_and_cones(model: SystemModel) -> None:
    assert model.loops == (("Agent", "Navigation", "RadiationSensor"),)
    assert model.loop_of("Navigation") == ("Agent", "Navigation", "RadiationSensor")
    assert model.loop_of("Localisation") is None
    assert model.upstream("Localisation") == ["Localisation"]
    assert model.upstream("Agent") == ["Localisation", "Navigation", "Agent", "RadiationSensor"]
    assert model.upstream("RadiationSensor") == ["Localisation", "Navigation", "Agent", "RadiationSensor"]
    assert model.producers("Navigation") == ["Localisation", "Agent"]
    assert model.consumers("Agent") == ["Navigation", "RadiationSensor"]
    assert model.internal_inputs("Agent") == {"at", "radiationStatus", "inspected"}


def test_alias_maps_inputs_to_producer_outputs(model: SystemModel) -> None:
    alias = model.alias()
    assert alias[("Agent", "in", "at")] == "Navigation.out.at"
    assert alias[("RadiationSensor", "in", "command")] == "Agent.out.command"
    assert alias[("Navigation", "in", "command")] == "Agent.out.command"
    assert ("Agent", "in", "wayP") not in alias and ("RadiationSensor", "in", "r") not in alias
    assert len(alias) == 6


def test_alias_discharges_navigation_assumption_from_localisation() -> None:
    from rclverify.semantics import world
    world.fresh()  # Z3's answer on the quantifiers depends on the context's history: up to two 10 s time-outs
    checked = load([CASE_STUDY])
    loc, nav = checked.nodes["Localisation"], checked.nodes["Navigation"]
    enc = Encoder(checked.env, build(checked).alias())
    g = enc.formula(loc.node.guarantees[0].formula, loc)
    a = enc.formula(nav.node.assumes[0].formula, nav)
    assert "Navigation.in.position" not in enc.symbols and "Localisation.out.position" in enc.symbols
    assert prove(a, [g], enc, timeout_ms=10_000).status == "proved"
    # Without the system model's aliases the two positions are unrelated.
    plain = Encoder(checked.env)
    r = prove(plain.formula(nav.node.assumes[0].formula, nav), [plain.formula(loc.node.guarantees[0].formula, loc)],
              plain, timeout_ms=10_000)
    # Z3 may refute it or give up on the quantifiers depending on its history in
    # the process; either way the assumption must not follow.
    assert r.status in ("refuted", "inconclusive")


def test_json_round_trip(model: SystemModel) -> None:
    d = model.to_json()
    assert d["connections"][0].keys() == {"from_node", "from_var", "to_node", "to_var", "via"}
    assert SystemModel.from_json(d) == model


SRC_TOPIC = """context { T : REAL x REAL --> BOOL ; }
node P { inputs(a : REAL) outputs(pos : T) topics(geo/Pose p matches(out.pos)) guarantee(TRUE) }
node Q { inputs(where : T) outputs(b : REAL) topics(geo/Pose p matches(in.where)) guarantee(TRUE) }
"""


def test_connection_by_topic_when_names_differ() -> None:
    m = build(check([parse_text(SRC_TOPIC, "topic.rcl")]))
    assert m.links == (Link("P", "pos", "Q", "where", "topic"),)
    assert m.env_inputs == (("P", "a", "REAL"),)
    assert m.loops == ()


def test_topic_field_must_match() -> None:
    src = SRC_TOPIC.replace("geo/Pose p matches(in.where)", "geo/Pose q matches(in.where)")
    m = build(check([parse_text(src, "topic.rcl")]))
    assert m.links == ()
    assert ("Q", "where", "REAL x REAL --> BOOL") in m.env_inputs


def test_name_match_needs_equal_types() -> None:
    src = """node P { inputs(a : REAL) outputs(v : INTEGER) guarantee(TRUE) }
node C { inputs(v : REAL) outputs(w : REAL) guarantee(TRUE) }
"""
    m = build(check([parse_text(src, "t.rcl")]))
    assert m.links == () and ("C", "v", "REAL") in m.env_inputs


AMBIGUOUS = """node P1 { inputs(a : REAL) outputs(v : REAL) guarantee(TRUE) }
node P2 { inputs(a : REAL) outputs(v : REAL) guarantee(TRUE) }
node C { inputs(v : REAL) outputs(w : REAL) guarantee(TRUE) }
"""


def test_ambiguous_input_is_a_located_error() -> None:
    with pytest.raises(RclError) as info:
        build(check([parse_text(AMBIGUOUS, "amb.rcl")]))
    (d,) = info.value.diagnostics
    assert d.code == "E-connection"
    assert str(d) == ("amb.rcl:3:17: error: input 'v' of C could be fed by P1, P2; "
                      "name the producer under 'connections' in the plan")


def test_explicit_connection_resolves_an_ambiguity() -> None:
    c = check([parse_text(AMBIGUOUS, "amb.rcl")])
    m = build(c, [Connection("P2", "v", "C", "v", ast.Loc("plan.yaml", 3, 5))])
    assert m.links == (Link("P2", "v", "C", "v", "plan"),)


def test_explicit_connection_wins_over_names() -> None:
    src = """node P1 { inputs(a : REAL) outputs(v : REAL) guarantee(TRUE) }
node P2 { inputs(a : REAL) outputs(u : REAL) guarantee(TRUE) }
node C { inputs(v : REAL) outputs(w : REAL) guarantee(TRUE) }
"""
    c = check([parse_text(src, "t.rcl")])
    assert links(build(c)) == {("P1", "v", "C", "v", "name")}
    m = build(c, [Connection("P2", "u", "C", "v", ast.Loc("plan.yaml", 1, 1))])
    assert links(m) == {("P2", "u", "C", "v", "plan")}
    assert m.producers("C") == ["P2"] and m.consumers("P1") == []


def test_self_loop_and_empty_type() -> None:
    src = """context { Hw : {} ; }
node A { inputs(h : Hw, x : REAL) outputs(y : REAL) guarantee(TRUE) }
node B { inputs(y : REAL) outputs(x : REAL) guarantee(TRUE) }
node S { inputs(z : REAL) outputs(q : REAL) guarantee(TRUE) }
"""
    m = build(check([parse_text(src, "t.rcl")]),
              [Connection("S", "q", "S", "z", ast.Loc("plan.yaml", 1, 1))])
    assert m.loops == (("A", "B"), ("S",))
    assert ("A", "h", "Hw") in m.env_inputs
