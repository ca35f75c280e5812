"""Issue 47's cases, each failing before the one stream model (docs/semantics.md)
and passing with it: outputs that were never judged (wrong greens) and values
nobody published (false alarms)."""
from __future__ import annotations

from pathlib import Path
from typing import Any

from rclverify.backends.monitors.backend import verdict_status
from rclverify.backends.monitors.check import check_trace
from rclverify.backends.monitors.deadlines import check_deadlines
from rclverify.lang.typecheck import load
from rclverify.traces.events import Event

RANGER = """node Ranger {
  inputs( )
  outputs( range : REAL )
  topics( std_msgs/Float64 range matches(out.range) )
  guarantee( out.range >= 0 )
}
"""

LIMITER = """node Limiter {
  inputs( limit : REAL )
  outputs( speed : REAL )
  topics( std_msgs/Float64 limit matches(in.limit), std_msgs/Float64 speed matches(out.speed) )
  assume( in.limit >= 0 )
  guarantee( out.speed <= in.limit )
}
"""

BRIDGE = """node Bridge {
  inputs( v : REAL, estop : BOOL )
  outputs( w : REAL )
  topics( std_msgs/Float64 cmd_vel matches(in.v), std_msgs/Bool estop_active matches(in.estop),
          std_msgs/Float64 wheel_cmd matches(out.w) )
  assume( 0 <= in.v )
  guarantee( (in.estop -> out.w == 0) and (not in.estop -> out.w == in.v) ) triggered by in.v within 100 ms
}
"""


def _checked(tmp: Path, text: str) -> Any:
    p = tmp / "c.rcl"
    p.write_text(text)
    return load([p])


def _run(checked: Any, node: str, rows: list[tuple[float, str, Any]], horizon: float = 5.0) -> tuple[list, Any]:
    evs = [Event(k, t, topic, {"data": v}, f"run.mcap: message {k}") for k, (t, topic, v) in enumerate(rows)]
    got: list[Any] = []
    _, [res] = check_trace(checked, [checked.nodes[node]], evs, {}, horizon, got.append)
    return got, res


def test_a_node_without_inputs_has_every_output_judged(tmp_path: Path) -> None:
    """Before: each output opened an obligation the next output answered, "5 satisfied", discharged."""
    checked = _checked(tmp_path, RANGER)
    got, res = _run(checked, "Ranger", [(0.1 * k, "range", v) for k, v in enumerate([-1.0, -7.5, 0.5, -3.0, 2.0])])
    assert [v.verdict for v in got] == ["violated", "violated", "satisfied", "violated", "satisfied"]
    assert verdict_status(res, "run.mcap")[0] == "failed"
    assert [v["values"]["out.range"] for v in res.violations] == ["-1.0", "-7.5", "-3.0"]


def test_outputs_after_a_right_answer_are_judged(tmp_path: Path) -> None:
    """Before: ``limit = 1.0`` then speeds 0.5, 1.5, 9.0, 100.0, 1000.0 was "1 satisfied", discharged."""
    checked = _checked(tmp_path, LIMITER)
    got, res = _run(checked, "Limiter", [(0.0, "limit", 1.0)] + [(0.1 * (k + 1), "speed", v) for k, v in
                                                                 enumerate([0.5, 1.5, 9.0, 100.0, 1000.0])])
    assert [v.verdict for v in got] == ["satisfied", "violated", "violated", "violated", "violated"]
    assert res.counts["violated"] == 4 and verdict_status(res, "run.mcap")[0] == "failed"


def test_a_stale_output_is_named_at_its_stamp(tmp_path: Path) -> None:
    """A motor bridge answers /cmd_vel 0.5 with a stale /wheel_cmd 1.6; the right
    value comes on the next cycle.  Before: the untimed check said satisfied."""
    checked = _checked(tmp_path, BRIDGE)
    rows = [(0.0, "estop_active", False), (1.5, "cmd_vel", 1.6), (1.505, "wheel_cmd", 1.6),
            (1.51, "cmd_vel", 0.5), (1.513, "wheel_cmd", 1.6), (1.52, "wheel_cmd", 0.5)]
    got, res = _run(checked, "Bridge", rows)
    bad = [v for v in got if v.verdict == "violated"]
    assert len(bad) == 1 and bad[0].where == "run.mcap: message 4" and bad[0].time == 1.513
    assert bad[0].values["out.w"] == "1.6" and bad[0].values["in.v"] == "0.5"
    assert bad[0].question == "run.mcap: message 3"


def _deadlines(checked: Any, rows: list[tuple[float, str, Any]]) -> tuple[list[str], Any]:
    evs = [Event(k, t, topic, {"data": v}, f"m{k}") for k, (t, topic, v) in enumerate(rows)]
    got: list[Any] = []
    [res] = check_deadlines(checked, [checked.nodes["Bridge"]], evs, {}, got.append)
    return [v.verdict for v in got], res


def test_a_trigger_before_every_input_has_a_value_raises_no_deadline(tmp_path: Path) -> None:
    """Before: /cmd_vel before the first /estop_active failed the deadline ("no value for in.estop")."""
    checked = _checked(tmp_path, BRIDGE)
    verdicts, res = _deadlines(checked, [(0.0, "cmd_vel", 0.5), (0.01, "wheel_cmd", 0.5),
                                         (0.5, "estop_active", False), (1.0, "cmd_vel", 0.4),
                                         (1.01, "wheel_cmd", 0.4), (3.0, "cmd_vel", 0.0)])
    assert verdicts[:1] == ["true"] and "false" not in verdicts
    assert res.unaccepted["incomplete input"] == 1


def test_two_inputs_changing_in_the_same_millisecond_are_one_question(tmp_path: Path) -> None:
    """Before: the answer was judged on the trigger's inputs (e-stop still off) and the deadline failed."""
    checked = _checked(tmp_path, BRIDGE)
    verdicts, res = _deadlines(checked, [(0.0, "estop_active", False), (1.0, "cmd_vel", 0.5),
                                         (1.0005, "estop_active", True), (1.01, "wheel_cmd", 0.0),
                                         (3.0, "estop_active", True)])
    assert verdicts == ["true"] and res.counts["false"] == 0


def test_two_inputs_changing_20_us_apart_are_no_inconclusive(tmp_path: Path) -> None:
    """Before: a correct e-stop node was inconclusive because two inputs changed 20 us apart."""
    checked = _checked(tmp_path, BRIDGE)
    got, res = _run(checked, "Bridge", [(0.0, "estop_active", False), (1.0, "cmd_vel", 0.5),
                                        (1.00002, "estop_active", True), (1.01, "wheel_cmd", 0.0)], horizon=1.0)
    assert [v.verdict for v in got] == ["incomplete input", "superseded", "satisfied"]
    assert verdict_status(res, "run.mcap")[0] == "discharged"


CHAIN = """node Source {
  inputs( )
  outputs( v : REAL )
  guarantee( 0 <= out.v and out.v <= 1.0 )
}
node Motor {
  inputs( v : REAL )
  outputs( w : REAL )
  assume( 0 <= in.v and in.v <= 1.5 )
  guarantee( out.w == in.v )
}
"""


def test_always_on_a_correct_chain_is_not_refuted_by_a_value_nobody_published(tmp_path: Path) -> None:
    """Before: refuted at step 0 by a state in which Motor.in.v = 2 "from before the run"."""
    import json
    from rclverify.app.pipeline import Workspace
    from rclverify.calculus.requirements.check import check_requirement
    (tmp_path / "contracts").mkdir()
    (tmp_path / "contracts/c.rcl").write_text(CHAIN)
    reqs = {"SAFE": "always Motor.out.w <= 1.5", "SOME": "eventually Motor.out.w <= 1.0"}
    (tmp_path / "contracts/plan.yaml").write_text("contracts: [contracts/c.rcl]\nrequirements:\n" + "".join(
        f"  - id: {k}\n    text: {k}\n    formal: {json.dumps(f)}\n" for k, f in reqs.items()))
    w = Workspace(tmp_path)
    got = {r.id: check_requirement(r, w.checked, w.model, w.plan)["temporal"] for r in w.plan.requirements}
    assert got["SAFE"]["status"] == "proved"
    # eventually needs a published value: without progress the Motor may never answer, and the lasso says so
    assert got["SOME"]["status"] == "refuted" and got["SOME"]["missing_progress"]


TWINS = """node Scale {
  inputs( r : REAL )
  outputs( d : REAL )
  topics( std_msgs/Float64 r matches(in.r), std_msgs/Float64 d matches(out.d) )
  guarantee( out.d == 1000 * in.r )
  guarantee( out.d != 1000 * in.r )
}
"""


def test_one_arithmetic_per_message_for_the_whole_contract(tmp_path: Path) -> None:
    """Before: two contradictory guarantees were both "satisfied", one in exact
    arithmetic, the other in the node's double arithmetic."""
    checked = _checked(tmp_path, TWINS)
    got, res = _run(checked, "Scale", [(0.0, "r", 1.2), (0.1, "d", 1000 * 1.2)])
    assert [v.verdict for v in got] == ["violated"]
    assert "no one arithmetic" in got[0].reason and res.counts["satisfied"] == 0


def test_a_split_answer_false_whatever_the_rest_is_violated_when_a_newer_question_follows() -> None:
    """The live case study's other race (issue 47): the sensor publishes inspected(4) for the
    command, then the reading 300 arrives, then orange (wrong: 300 is red) with the reading's
    stamp, then the next command.  The reading's answer lacks inspected (owed to the next
    question), but orange is false whatever inspected is: violated, never a silent green."""
    from rclverify.backends.monitors.config import load_mapping
    repo = Path(__file__).resolve().parents[2]
    checked = load([repo / "contracts" / "remote_inspection.rcl"])
    cfg = load_mapping(repo, "backends/monitors/mapping.yaml", 2.0)
    cmd = {"command": "inspect", "posx": 0.0, "posy": 0.0, "id": 4}
    rows = [(0.0, "r", {"value": 130.0}), (0.5, "command", cmd), (0.52, "inspected", {"id": 4}),
            (0.5202, "r", {"value": 300.0}), (0.5202, "radiationStatus", {"level": "orange"}),
            (0.75, "command", {"command": "move", "posx": 9.0, "posy": 6.5, "id": 0})]
    evs = [Event(k, t, topic, f, f"live: message {k}") for k, (t, topic, f) in enumerate(rows)]
    got: list[Any] = []
    _, [res] = check_trace(checked, [checked.nodes["RadiationSensor"]], evs, cfg.rules, 2.0, got.append)
    bad = [v for v in got if v.verdict == "violated"]
    assert bad and bad[0].values["in.r"] == "300.0" and bad[0].values["out.radiationStatus"] == "orange"
    assert verdict_status(res, "live")[0] == "failed"
