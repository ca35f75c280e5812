"""FRET's ``FTP`` on a node another node feeds (issue 113; docs/requirements.md,
"FRET's semantics, translated"): FRET's first time point is the first step of
the component's own trace, the step whose values of its inputs are the first
published, so the importer writes it ``first(Node.in.x)`` over the node's fed
inputs.  Checked against FRET's past-time formalisation on random finite
traces: a system trace whose first ``k`` steps carry no value of the fed input
(its producer has not published yet, so no value of the node is published
either: rclverify reads a statement on published values only) and FRET's trace,
the node's own, starting at step ``k``.  The control: the reading before, a
state variable true at the system's first step only, disagrees with FRET
whenever ``k > 0``."""
from __future__ import annotations

import random
from typing import Any

import msgspec
import pytest

from rclverify.lang import ast
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.model.plan.formal import Formal
from rclverify.model.plan.fret.export import FretExport, FretRequirement, FretSemantics, FretVariable
from rclverify.model.plan.fret.requirements import Options, import_export, ports_of
from rclverify.model.plan.state import parse_state_formula, state_types
from rclverify.model.plan.temporal import Temporal, parse_temporal, shape
from rclverify.semantics.evaluate import evaluate

CONTRACT = """
node Planner { inputs( goal : REAL ) outputs( cmd : REAL )
  topics( std_msgs/Float64 goal matches(in.goal), std_msgs/Float64 cmd matches(out.cmd) )
  guarantee( TRUE ) }
node Rover { inputs( asked : REAL, obstacle : BOOL ) outputs( braking : BOOL )
  topics( std_msgs/Float64 cmd matches(in.asked), std_msgs/Bool obstacle matches(in.obstacle),
          std_msgs/Bool braking matches(out.braking) )
  guarantee( TRUE ) }
"""
VARS = {"asked": ("Input", "double"), "obstacle": ("Input", "boolean"), "braking": ("Output", "boolean")}
#: (reqid, condition, timing, pre_condition, post_condition, FRET's ptExpanded)
CASES = [
    ("FTP-IF-THEN", "null", "always", None, "(if FTP then braking)", "(H ((Z FALSE) -> braking))"),
    ("FTP-OR", "noTrigger", "immediately", "(FTP | obstacle)", "(braking)",
     "(H (((Z FALSE) | obstacle) -> braking))"),
]


def _export() -> FretExport:
    reqs = []
    for k, (rid, cond, timing, pre, post, pt) in enumerate(CASES):
        sem: dict[str, Any] = {"scope": {"type": "null"}, "condition": cond, "timing": timing,
                               "response": "satisfaction", "component_name": "rover", "post_condition": post,
                               "ptExpanded": pt}
        if pre is not None:
            sem.update(pre_condition=pre, regular_condition=pre)
        reqs.append(FretRequirement(rid, rid, "rover", msgspec.convert(sem, FretSemantics), ast.Loc("x.json", k + 1, 1),
                                    "", {}))
    variables = {("rover", n): FretVariable("rover", n, i, d, "") for n, (i, d) in VARS.items()}
    return FretExport("x.json", tuple(reqs), variables)


def _fret(pt: str, tr: list[dict[str, Any]]) -> bool:
    """FRET's formula of CASES at the last step of the node's own trace ``tr`` (``Z FALSE``: the first step)."""
    def at(i: int) -> bool:
        first, s = i == 0, tr[i]
        if pt.startswith("(H ((Z FALSE) ->"):
            return (not first) or s["braking"]
        return not (first or s["obstacle"]) or s["braking"]
    return all(at(i) for i in range(len(tr)))


def _verdict(t: Temporal, checked: Any, system: list[dict[str, Any]], k: int, states: list[dict[str, Any]]) -> bool:
    """rclverify's ``always F`` on the system trace: F at every step whose values are published (from ``k``),
    ``first(Rover.in.asked)`` TRUE at step ``k``."""
    assert shape(t, None) == "always"
    f = t.args[0]
    assert isinstance(f, Formal)
    for i in range(k, len(system)):
        values: dict[str, object] = {f"{p}.Rover.{p}.{n}": v for n, v in system[i].items()
                                     for p in ["in" if VARS[n][0] == "Input" else "out"]}
        values["first(in.Rover.in.asked)"] = i == k
        values.update({f"in.Rover.state.{s}": v for s, v in states[i].items()})
        got = evaluate(f.expr, checked, f.scope, values)
        assert got is not None
        if not got:
            return False
    return True


def _states(imp: Any, checked: Any, n: int) -> list[dict[str, Any]]:
    """The statement's state variables along ``n`` system steps (BOOL only here: FTP's old flag)."""
    svs = imp.states
    parsed = {sv.name: (parse_state_formula(sv, "init", checked, svs), parse_state_formula(sv, "next", checked, svs))
              for sv in svs}
    now: dict[str, Any] = {}
    for sv in svs:
        init = parsed[sv.name][0]
        (now[sv.name],) = [c for c in (False, True) if evaluate(init.expr, checked, init.scope, {f"in.state.{sv.name}": c})]
    run = [dict(now)]
    for _ in range(n - 1):
        nxt: dict[str, Any] = {}
        for sv in svs:
            f = parsed[sv.name][1]
            (nxt[sv.name],) = [c for c in (False, True) if evaluate(
                f.expr, checked, f.scope, {**{f"in.state.{s}": v for s, v in now.items()}, f"in.next.{sv.name}": c})]
        now = nxt
        run.append(dict(now))
    return run


def _trace(rng: random.Random) -> tuple[list[dict[str, Any]], int]:
    k = rng.randint(0, 3)
    steps = [{"asked": rng.choice([0, 1, 2]), "obstacle": rng.random() < 0.5, "braking": rng.random() < 0.5}
             for _ in range(k + rng.randint(1, 6))]
    return steps, k


@pytest.fixture(scope="module")
def checked() -> Any:
    return check([parse_text(CONTRACT, "rover.rcl")])


def _disagreements(fed: bool, checked: Any) -> dict[str, int]:
    specs = [parse_text(CONTRACT, "rover.rcl")]
    ports = ports_of(specs)
    if not fed:  # the reading before: FTP a state variable of the system's first step
        ports = type(ports)(ports.nodes, ports.constants, ports.units, {})
    out = {}
    for imp, case in zip(import_export(_export(), Options(components={"rover": "Rover"}), ports), CASES):
        assert imp.refusal is None, imp.refusal
        assert imp.requirement.formal is not None
        assert ("first(Rover.in.asked)" in imp.requirement.formal.text) == fed
        t = parse_temporal(imp.requirement.formal, checked, imp.fret.reqid, state_types(imp.states, checked))
        assert isinstance(t, Temporal)
        rng = random.Random(case[0])
        bad = 0
        for _ in range(150):
            system, k = _trace(rng)
            if _verdict(t, checked, system, k, _states(imp, checked, len(system))) != _fret(case[-1], system[k:]):
                bad += 1
        out[case[0]] = bad
    return out


def test_ports_name_the_inputs_another_node_feeds() -> None:
    ports = ports_of([parse_text(CONTRACT, "rover.rcl")])
    assert dict(ports.fed) == {"Rover": ("asked",)}  # obstacle: no node publishes it; Planner: goal neither


def test_ftp_on_a_fed_node_is_its_first_published_value_as_fret_reads_it(checked: Any) -> None:
    assert _disagreements(True, checked) == {"FTP-IF-THEN": 0, "FTP-OR": 0}


def test_the_system_first_step_read_as_ftp_disagrees_with_fret(checked: Any) -> None:
    bad = _disagreements(False, checked)
    assert all(n > 0 for n in bad.values()), bad


def test_ftp_inside_a_pre_on_a_fed_node_is_refused_with_the_reason() -> None:
    """A pre steps with the system, whose first step is not the node's: refused at its reqid; the control, the
    same requirement on a node nobody feeds, is imported."""
    case = ("FTP-PRE", "null", "always", None, "(preBool(false, FTP) | braking)", "(H ((Y (Z FALSE)) | braking))")
    sem: dict[str, Any] = {"scope": {"type": "null"}, "condition": "null", "timing": "always",
                           "response": "satisfaction", "component_name": "rover", "post_condition": case[4],
                           "ptExpanded": case[5]}
    req = FretRequirement("FTP-PRE", "FTP-PRE", "rover", msgspec.convert(sem, FretSemantics), ast.Loc("x.json", 1, 1),
                          "", {})
    exp = FretExport("x.json", (req,),
                     {("rover", n): FretVariable("rover", n, i, d, "") for n, (i, d) in VARS.items()})
    ports = ports_of([parse_text(CONTRACT, "rover.rcl")])
    (imp,) = import_export(exp, Options(components={"rover": "Rover"}), ports)
    assert imp.refusal is not None and "inside a pre on Rover, which another node feeds" in str(imp.refusal)
    (imp,) = import_export(exp, Options(components={"rover": "Rover"}),
                           type(ports)(ports.nodes, ports.constants, ports.units, {}))
    assert imp.refusal is None
