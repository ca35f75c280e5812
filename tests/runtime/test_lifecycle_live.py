"""A real rclpy LifecycleNode (``rclpy.lifecycle``) on Fast DDS, monitored live by ``rclverify monitor --live
--ros2 --source rclpy`` (tests/_ros2.py; runtime/lifecycle.py, docs/monitors.md "Lifecycle nodes").

The node ``/battery`` publishes its ``level`` every 50 ms from a timer; a second node sends a ``request``
every 100 ms.  Its contract names ``battery/transition_event``, so the monitor reads its transitions: it is
configured (inactive) for 1 s, active for 1 s, deactivated for 1 s.  The correct node publishes through a
lifecycle publisher, which is silent outside ``active``: no lifecycle violation, and the requests sent while
it is inactive are no questions (its guarantee is scoped ``while active``).  The defective node publishes
through a plain publisher, whatever its state: its outputs while inactive are red, with their state; those
while active are not.  The contract states ``ready within 200 ms of activate``, judged live: the correct
node activates in a few ms, the defective one sleeps 0.3 s in ``on_activate``."""
from __future__ import annotations

import json
import signal
from pathlib import Path
from typing import Any, Iterator

import pytest

from _procs import stop, wait_for, wait_logged
from _ros2 import rclverify, ros2_env, ros2_python, start_node

HORIZON = 1.0  # seconds: the monitor's --horizon
RCL = """\
node Battery {
  inputs( request : REAL )
  outputs( level : REAL )
  topics( std_msgs/Float64 request matches(in.request), std_msgs/Float64 level matches(out.level),
          lifecycle_msgs/TransitionEvent battery/transition_event )
  assume( in.request >= 0 )
  guarantee( out.level >= in.request ) while active
  ready within 200 ms of activate
}
"""

NODES = """\
import sys, time
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.lifecycle import LifecycleNode
from rclpy.node import Node
from std_msgs.msg import Float64

DEFECT = sys.argv[1] == "defect"
rclpy.init()
class Battery(LifecycleNode):
    def on_activate(self, state):
        time.sleep(0.3 if DEFECT else 0.0)  # the defective node is slow to activate
        return super().on_activate(state)


battery = Battery("battery")
pub = (battery.create_publisher if DEFECT else battery.create_lifecycle_publisher)(Float64, "level", 10)
battery.create_timer(0.05, lambda: pub.publish(Float64(data=10.0)))
requester = Node("requester")
req = requester.create_publisher(Float64, "request", 10)
requester.create_timer(0.1, lambda: req.publish(Float64(data=1.0)))
ex = SingleThreadedExecutor()
ex.add_node(battery)
ex.add_node(requester)
print("ready", flush=True)
until = time.monotonic() + 40  # the monitor's readers matched, the transition topic's too
while time.monotonic() < until and not (pub.get_subscription_count() and req.get_subscription_count()
                                        and battery.get_subscriptions_info_by_topic("/battery/transition_event")):
    ex.spin_once(timeout_sec=0.05)
steps = [(1.0, battery.trigger_configure), (2.0, battery.trigger_activate), (3.0, battery.trigger_deactivate),
         (4.0, None)]
t0 = time.monotonic()
for at, step in steps:  # every transition and every publication in the executor's one thread
    while time.monotonic() < t0 + at:
        ex.spin_once(timeout_sec=0.01)
    if step is not None:
        print(step.__name__, step(), flush=True)
print("done", flush=True)
while rclpy.ok():
    ex.spin_once(timeout_sec=0.1)
"""


def _settled(log: list[dict[str, Any]]) -> bool:
    """The node's six transition events (configure, activate, deactivate: two each) are in the monitor's log,
    and a request released more than the horizon after the last of them: the last question asked while
    active (at the latest with the deactivation) is decided, not left open by the stop."""
    events = [x for x in log if x.get("topic") == "battery/transition_event"]
    return len(events) >= 6 and any(x.get("topic") == "request" and x["time"] > events[5]["time"] + HORIZON
                                    for x in log)


def _run(tmp: Path, variant: str) -> dict[str, Any]:
    py = ros2_python()  # skips, with the reason, without a ROS 2 Python
    ws = tmp / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/b.rcl").write_text(RCL)
    (ws / "contracts/plan.yaml").write_text("contracts: [contracts/b.rcl]\n")
    env = ros2_env(tmp)
    node = monitor = None
    try:
        monitor = rclverify(["monitor", "-w", str(ws), "--live", "--ros2", "--status", "0", "--duration", "90",
                             "--horizon", str(HORIZON), "--source", "rclpy", "--ros2-python", str(py), "--log",
                             str(tmp / "live.jsonl"), "--evidence", str(tmp / "live.json"), "--record",
                             str(tmp / "run_bag")], env, tmp, tmp / "monitor.out")
        node = start_node(tmp, "battery", NODES.replace("sys.argv[1]", repr(variant)), env)
        wait_for(tmp / "battery.log", "done", 80)
        wait_logged(tmp / "live.jsonl", _settled, 30)  # the last transition heard and passed, whatever the load
        stop(monitor, signal.SIGINT)
        out = (tmp / "monitor.out").read_text()
        assert (tmp / "live.json").exists(), out + (tmp / "battery.log").read_text()
        return {"out": out, "record": json.loads((tmp / "live.json").read_text()),
                "node": (tmp / "battery.log").read_text(), "bag": tmp / "run_bag", "tmp": tmp}
    finally:
        for p in (node, monitor):
            if p is not None:
                stop(p)


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, dict[str, Any]]]:
    yield {v: _run(tmp_path_factory.mktemp(v), v) for v in ("correct", "defect")}


def _lifecycle(run: dict[str, Any]) -> dict[str, Any]:
    rec = run["record"]
    assert "lifecycle" in rec and "not judged: topic /battery/transition_event" not in run["out"], run["out"]
    [node] = rec["lifecycle"]["nodes"]
    assert node["ros_node"] == "/battery" and node["transitions"] >= 6, (node, run["node"])
    assert node["state"] == "inactive", node
    return node


def test_a_lifecycle_publisher_is_green_and_requests_while_inactive_are_no_questions(runs: dict[str, Any]) -> None:
    run = runs["correct"]
    node = _lifecycle(run)
    assert node["status"] == "discharged" and node["violations"] == [] and node["outputs_judged"] >= 5, node
    assert run["record"]["lifecycle"]["not_questions"].get("request", 0) >= 5, run["record"]["lifecycle"]
    [res] = run["record"]["nodes"]
    assert res["counts"]["satisfied"] >= 3 and res["counts"]["violated"] == 0, res["counts"]
    assert "lifecycle" not in res["explanation"], res


def test_a_plain_publisher_of_a_lifecycle_node_is_red_while_inactive_only(runs: dict[str, Any]) -> None:
    node = _lifecycle(runs["defect"])
    assert node["status"] == "failed" and len(node["violations"]) >= 10, node
    [res] = runs["defect"]["record"]["nodes"]
    assert res["status"] == "failed" and "published outside active (lifecycle)" in res["explanation"], res
    assert {v["state"] for v in node["violations"]} <= {"unconfigured", "inactive", "configuring"}, node
    assert node["outputs_judged"] > len(node["violations"]), node  # its outputs while active are not red
    assert all("/battery published on /level while" in v["reason"] for v in node["violations"])


def test_the_stated_activation_deadline_is_judged_live(runs: dict[str, Any]) -> None:
    """``ready within 200 ms of activate`` (the contract's line 8), judged by the live run: met by the node
    that activates at once, missed by the one whose ``on_activate`` sleeps 0.3 s (a lower bound: the miss
    does not depend on the machine's load); the live verdict fails the slow node, saying why."""
    [quick] = _lifecycle(runs["correct"])["deadlines"]
    assert (quick["transition"], quick["status"], quick["within"]) == ("activate", "met", 0.2), quick
    assert quick["stated"].endswith("b.rcl:8:3") and quick["seconds"] < 0.2, quick
    [slow] = _lifecycle(runs["defect"])["deadlines"]
    assert slow["status"] == "missed" and slow["seconds"] >= 0.3 and slow["stated"].endswith("b.rcl:8:3"), slow
    [res] = runs["defect"]["record"]["nodes"]
    assert "1 transition deadline(s) missed (lifecycle)" in res["explanation"], res
    [ok] = runs["correct"]["record"]["nodes"]
    assert "transition deadline" not in ok["explanation"], ok  # control: the quick node's verdict says nothing of it


def _bag(run: dict[str, Any]) -> tuple[list[Any], list[Any]]:
    from rclverify.traces.lifecycle_events import read_run
    return read_run(run["bag"])


def _offline(run: dict[str, Any], within: float) -> dict[str, Any]:
    """The run's bag judged offline (cli/lifecycle_runs.judge_recorded) with an activation deadline."""
    from rclverify.backends.monitors.config import load_mapping
    from rclverify.lang.parser import parse_text
    from rclverify.lang.typecheck import check
    from rclverify.cli.lifecycle_runs import judge_recorded
    checked = check([parse_text(RCL, "b.rcl")])
    cfg = load_mapping(run["tmp"], None, 1.0)
    events, transitions = _bag(run)
    assert [STATES[t.goal] for t in transitions][:6] == ["configuring", "inactive", "activating", "active",
                                                         "deactivating", "inactive"], transitions
    return judge_recorded(checked, list(checked.nodes.values()), cfg.rules, cfg.horizon, events,
                          run["tmp"] / "offline.jsonl", deadlines={"Battery": {"activate": within}})


STATES = {1: "unconfigured", 2: "inactive", 3: "active", 10: "configuring", 13: "activating", 14: "deactivating"}


def test_the_recorded_bag_is_judged_as_the_live_run_judged_it(runs: dict[str, Any]) -> None:
    """The bag holds what the recorder heard between its start and its close, which need not be every
    message the live judge heard at the run's two ends (a request or a level a few ms before or after):
    the counts are compared on what the bag holds, at most the messages it lacks apart; a request heard at a
    transition may be decided either way (below)."""
    for variant in ("correct", "defect"):
        live = runs[variant]["record"]
        rec = _offline(runs[variant], 0.2)
        def heard(r: dict[str, Any]) -> int:  # the messages judged, and those held back as no question
            return int(r["events"]) + sum(r["lifecycle"]["not_questions"].values())
        lacks = heard(live) - heard(rec)  # the messages the live judge heard and the bag lacks
        assert 0 <= lacks <= 4, (heard(live), heard(rec))
        [off], [on] = rec["lifecycle"]["nodes"], live["lifecycle"]["nodes"]
        assert off["transitions"] == on["transitions"] and off["status"] == on["status"], (off, on)
        for key in ("outputs_judged", "violations"):
            n_off, n_on = (len(x[key]) if key == "violations" else x[key] for x in (off, on))
            assert n_off <= n_on <= n_off + lacks, (variant, key, n_off, n_on, lacks)
        # a request heard within 0.1 s of a transition may be held back live and asked offline, or the other way:
        # live decides it by the transitions heard before it, the bag by its record order (docs/monitors.md)
        events, transitions = _bag(runs[variant])
        near = sum(1 for e in events if e.topic == "request" and any(abs(e.time - t.time) < 0.1 for t in transitions))
        q_off, q_on = (x["lifecycle"]["not_questions"].get("request", 0) for x in (rec, live))
        assert abs(q_on - q_off) <= lacks + near, (variant, q_off, q_on, lacks, near)
        assert rec["nodes"][0]["status"] == live["nodes"][0]["status"]
        v_off, v_on = (x["nodes"][0]["counts"]["violated"] for x in (rec, live))
        assert v_off <= v_on <= v_off + lacks, (variant, v_off, v_on, lacks)


def test_an_activation_deadline_met_by_the_quick_node_and_missed_by_the_slow_one(runs: dict[str, Any]) -> None:
    [quick] = _offline(runs["correct"], 0.2)["lifecycle"]["nodes"][0]["deadlines"]
    assert quick["status"] == "met" and quick["seconds"] < 0.2, quick
    slow_rec = _offline(runs["defect"], 0.2)
    [slow] = slow_rec["lifecycle"]["nodes"][0]["deadlines"]
    assert slow["status"] == "missed" and slow["seconds"] >= 0.3, slow  # on_activate sleeps 0.3 s
    assert "transition deadline(s) missed" in slow_rec["nodes"][0]["explanation"]
    # control: the slow node within a deadline it can meet
    [ok] = _offline(runs["defect"], 2.0)["lifecycle"]["nodes"][0]["deadlines"]
    assert ok["status"] == "met", ok


def test_rclverify_monitor_on_the_recorded_bags(runs: dict[str, Any], capsys: pytest.CaptureFixture[str]) -> None:
    from rclverify.cli.commands import main
    codes = {}
    for variant in ("correct", "defect"):
        run = runs[variant]
        codes[variant] = main(["monitor", "-w", str(run["tmp"] / "ws"), str(run["bag"]), "--horizon", "1",
                               "--transition-deadline", "Battery:activate=200ms"])
        out = capsys.readouterr().out
        assert "lifecycle /battery:" in out and (("missed: /battery's activate" in out) == (variant == "defect")), out
    assert codes == {"correct": 0, "defect": 1}


def test_the_live_log_is_judged_as_the_live_run_judged_it(runs: dict[str, Any]) -> None:
    """One judge: the gate decides in the engine's release order, after each message's log line, and the
    log holds the transition events and the requests held back, so the run's own log, judged offline,
    gives the live run's lifecycle record and counts exactly (no message lacking, none decided otherwise
    near a transition).  The control: the same log without its transition events judges the node as
    never configured, every output red."""
    from rclverify.backends.monitors.config import load_mapping
    from rclverify.cli.lifecycle_runs import judge_recorded
    from rclverify.lang.parser import parse_text
    from rclverify.lang.typecheck import check
    from rclverify.traces.lifecycle_events import read_run
    checked = check([parse_text(RCL, "b.rcl")])
    for variant in ("correct", "defect"):
        run = runs[variant]
        live = run["record"]
        cfg = load_mapping(run["tmp"], None, 1.0)
        events, transitions = read_run(run["tmp"] / "live.jsonl")
        assert len(transitions) == live["lifecycle"]["nodes"][0]["transitions"], (len(transitions), live["lifecycle"])
        rec = judge_recorded(checked, list(checked.nodes.values()), cfg.rules, cfg.horizon, events,
                             run["tmp"] / "relog.jsonl")
        [off], [on] = rec["lifecycle"]["nodes"], live["lifecycle"]["nodes"]
        for key in ("transitions", "outputs_judged", "state", "status"):
            assert off[key] == on[key], (variant, key, off[key], on[key])
        assert [(v["topic"], v["state"]) for v in off["violations"]] == \
            [(v["topic"], v["state"]) for v in on["violations"]], variant
        assert rec["lifecycle"]["not_questions"] == live["lifecycle"]["not_questions"], variant
        assert rec["nodes"][0]["counts"] == live["nodes"][0]["counts"], variant
        assert rec["events"] == live["events"], variant
    # control: the log's transition events dropped, the node never leaves `unconfigured`: every output red
    events, _ = read_run(runs["correct"]["tmp"] / "live.jsonl")
    bare = [e for e in events if not e.topic.endswith("transition_event")]
    rec = judge_recorded(checked, list(checked.nodes.values()), cfg.rules, cfg.horizon, bare,
                         runs["correct"]["tmp"] / "bare.jsonl")
    [node] = rec["lifecycle"]["nodes"]
    assert node["status"] == "failed" and {v["state"] for v in node["violations"]} == {"unconfigured"}, node
