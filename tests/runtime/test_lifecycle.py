"""Managed nodes judged by their lifecycle state (runtime/lifecycle.py, docs/monitors.md "Lifecycle nodes"),
in process through the live run's gate: an output published outside ``active`` is a violation of the
lifecycle contract, an input heard while the node is not active is no question, a transition event heard
after an output still decides it; each with its control.  tests/runtime/test_lifecycle_live.py holds the
same against a real rclpy LifecycleNode."""
from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.config import load_mapping
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.runtime.lifecycle import LifecycleGate, event_topic
from rclverify.runtime.live import LiveRun

RCL = """\
node Battery {
  inputs( request : REAL )
  outputs( level : REAL )
  topics( std_msgs/Float64 request matches(in.request), std_msgs/Float64 level matches(out.level) )
  assume( in.request >= 0 )
  guarantee( out.level >= in.request )
}
"""
EVENTS = event_topic("/battery")


def _event(goal: int, at: float) -> dict[str, Any]:
    """lifecycle_msgs/msg/TransitionEvent as the DDS reader decodes it (nested; timestamp in ns)."""
    return {"timestamp": int(at * 1e9), "transition": {"id": 0, "label": ""}, "start_state": {"id": 0, "label": ""},
            "goal_state": {"id": goal, "label": ""}}


def _run(tmp: Path, script: list[tuple[float, str, Any]], gated: bool = True, horizon: float = 1.0) -> dict[str, Any]:
    checked = check([parse_text(RCL, "sys.rcl")])
    cfg = load_mapping(tmp, None, horizon)
    live = LiveRun(checked, list(checked.nodes.values()), cfg.rules, cfg.horizon, tmp / f"{len(script)}{gated}.jsonl",
                   reorder_window=0.0)
    if gated:
        live.gate = LifecycleGate({"Battery": "/battery"}, live.nodes)
    for t, topic, v in script:
        live.tick(t)
        live.push(topic, _event(v, t) if topic == EVENTS else {"data": v}, t)
    live.tick(script[-1][0] + 2)
    return live.stop()


#: configured at 1 s (inactive), active from 2 s to 3 s, inactive after
LIFE = [(1.0, EVENTS, 10), (1.0, EVENTS, 2), (2.0, EVENTS, 13), (2.0, EVENTS, 3), (3.0, EVENTS, 14), (3.0, EVENTS, 2)]


def _merged(*parts: list[tuple[float, str, Any]]) -> list[tuple[float, str, Any]]:
    return sorted((x for p in parts for x in p), key=lambda x: x[0])


def test_an_output_outside_active_is_red_and_inside_is_not(tmp_path: Path) -> None:
    quiet = [(2.2, "request", 1.0), (2.3, "level", 5.0)]
    rec = _run(tmp_path, _merged(LIFE, quiet, [(1.5, "level", 5.0), (3.5, "level", 5.0)]))
    [node] = rec["lifecycle"]["nodes"]
    assert node["status"] == "failed" and node["outputs_judged"] == 3 and node["transitions"] == 6
    assert [(v["time"], v["state"]) for v in node["violations"]] == [(1.5, "inactive"), (3.5, "inactive")]
    assert "/battery published on /level while inactive" in node["violations"][0]["reason"]
    assert rec["nodes"][0]["status"] == "failed" and "2 output(s) published outside active" in \
        rec["nodes"][0]["explanation"], rec["nodes"][0]
    # control: the node publishes only while active
    fine = _run(tmp_path, _merged(LIFE, quiet))
    ok = fine["lifecycle"]["nodes"][0]
    assert ok["status"] == "discharged" and ok["outputs_judged"] == 1 and ok["violations"] == []
    assert fine["nodes"][0]["status"] == "discharged", fine["nodes"][0]


def test_before_its_first_transition_a_managed_node_is_unconfigured(tmp_path: Path) -> None:
    [node] = _run(tmp_path, [(0.5, "level", 5.0), (1.0, EVENTS, 10)])["lifecycle"]["nodes"]
    assert [v["state"] for v in node["violations"]] == ["unconfigured"]


def test_an_input_while_inactive_is_no_question(tmp_path: Path) -> None:
    # a request of 1 while active, answered by 5; one of 9 after the deactivation, answered by nothing
    script = _merged(LIFE, [(2.2, "request", 1.0), (2.3, "level", 5.0), (3.5, "request", 9.0)])
    rec = _run(tmp_path, script, horizon=0.5)
    assert rec["lifecycle"]["not_questions"] == {"request": 1}
    [res] = rec["nodes"]
    assert res["status"] == "discharged" and res["counts"]["satisfied"] == 1, res["counts"]
    assert res["counts"]["inconclusive"] == 0, res["counts"]
    # control: without the gate the inactive node's request is a question, unanswered: not green
    [plain] = _run(tmp_path, script, gated=False, horizon=0.5)["nodes"]
    assert plain["status"] == "inconclusive" and plain["counts"]["inconclusive"] == 1, plain["counts"]


def test_a_transition_heard_after_the_output_still_decides_it(tmp_path: Path) -> None:
    # activated at 2.0 (stamped so), the event heard at 2.1, the output at 2.08: within settle, not red
    late = [(1.0, EVENTS, 2), (2.08, "level", 5.0)]
    gate_run = _merged(late, [(2.1, EVENTS, 3)])
    checked = check([parse_text(RCL, "sys.rcl")])
    gate = LifecycleGate({"Battery": "/battery"}, list(checked.nodes.values()))
    for t, topic, v in gate_run:
        gate.admit(topic, _event(v, 2.0 if v == 3 else t) if topic == EVENTS else {"data": v}, t)
    assert gate.record()["nodes"][0]["violations"] == []
    # control: the same output with the activation stamped at 2.2, after it and its skew: red
    gate = LifecycleGate({"Battery": "/battery"}, list(checked.nodes.values()))
    for t, topic, v in gate_run:
        gate.admit(topic, _event(v, 2.2 if v == 3 else t) if topic == EVENTS else {"data": v}, t)
    assert [v["state"] for v in gate.record()["nodes"][0]["violations"]] == ["inactive"]


def test_an_output_while_activating_is_not_red(tmp_path: Path) -> None:
    """A managed publisher is enabled in on_activate, while the node is activating (rclpy, rclcpp)."""
    steps = [(1.0, EVENTS, 2), (2.0, EVENTS, 13), (2.5, "level", 5.0), (3.0, EVENTS, 3), (4.0, EVENTS, 14),
             (4.5, "level", 5.0), (5.0, EVENTS, 2), (5.5, "level", 5.0)]
    [node] = _run(tmp_path, steps)["lifecycle"]["nodes"]
    assert [(v["time"], v["state"]) for v in node["violations"]] == [(5.5, "inactive")]  # control: after it, red


def test_a_managed_node_that_is_not_monitored_is_refused(tmp_path: Path) -> None:
    checked = check([parse_text(RCL, "sys.rcl")])
    with pytest.raises(ValueError, match="managed node 'Batery' is not monitored"):
        LifecycleGate({"Batery": "/battery"}, list(checked.nodes.values()))


def test_a_contract_naming_its_transition_topic_is_a_managed_node(tmp_path: Path) -> None:
    """``lifecycle_msgs/TransitionEvent battery/transition_event`` (no matches) declares the node managed,
    and under an instance's namespace it resolves there; the contract without it is the control."""
    from rclverify.model.instances import instantiate
    from rclverify.model.plan.instances import read_instances
    from rclverify.runtime.lifecycle import managed_of
    managed = RCL.replace("matches(out.level) )", "matches(out.level),\n"
                          "          lifecycle_msgs/TransitionEvent battery/transition_event )")
    checked = check([parse_text(managed, "sys.rcl")])
    cfg = load_mapping(tmp_path, None, 1.0)
    live = LiveRun(checked, list(checked.nodes.values()), cfg.rules, cfg.horizon, tmp_path / "m.jsonl")
    assert live.gate is not None and {n: m.fqn for n, m in live.gate.managed.items()} == {"Battery": "/battery"}
    live.stop()
    fleet, _ = read_instances({"Battery": ["/r1", "/r2"]}, {}, "plan.yaml")
    assert managed_of(list(instantiate(checked, fleet).nodes.values())) == {"Battery_r1": "/r1/battery",
                                                                           "Battery_r2": "/r2/battery"}
    plain = check([parse_text(RCL, "sys.rcl")])
    control = LiveRun(plain, list(plain.nodes.values()), cfg.rules, cfg.horizon, tmp_path / "p.jsonl")
    assert control.gate is None
    control.stop()


def test_a_transition_event_heard_after_the_output_was_judged_withdraws_its_violation(tmp_path: Path) -> None:
    """Activated at 2.0 (stamped so) but the event heard at 3.5, after the outputs at 2.3 and 2.9 were judged
    (each 0.5 s after it): both were published while active, so the late event withdraws both violations, with
    why, and the node is not red (a late message never adds a violation).  Control: the activation stamped at
    2.4, after the first output and its skew: that violation stands (the node red), the second is withdrawn."""
    checked = check([parse_text(RCL, "sys.rcl")])
    run = [(1.0, EVENTS, 2), (2.3, "level", 5.0), (2.9, "level", 6.0), (3.5, EVENTS, 3)]
    for activated, red, withdrawn in ((2.0, [], [2.3, 2.9]), (2.4, [2.3], [2.9])):
        gate = LifecycleGate({"Battery": "/battery"}, list(checked.nodes.values()))
        for t, topic, v in run:
            gate.admit(topic, _event(v, activated if v == 3 else t) if topic == EVENTS else {"data": v}, t)
        node = gate.record()["nodes"][0]
        assert [v["time"] for v in node["violations"]] == red, node
        assert node["status"] == ("failed" if red else "discharged"), node
        assert [w["time"] for w in node["withdrawn"]] == withdrawn, node
        assert "heard after that output was judged" in node["withdrawn"][0]["reason"]
