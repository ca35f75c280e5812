"""A recorded run of a managed node judged as the live run judges it (runtime/lifecycle.py, ``judge_recorded``
in cli/lifecycle_runs.py, traces/lifecycle_events.py; docs/monitors.md "Lifecycle nodes in a recorded run"):
a JSON-lines log holding the node's transition events, read back and replayed through the same gate and
judge.  A guarantee is not asked while the node is inactive, an output while inactive is red, a
transition deadline is met, missed or open; each with its control, and the log's verdicts equal the live
run's on the same messages.  tests/runtime/test_lifecycle_live.py judges the bag a live run of a real
rclpy LifecycleNode recorded."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.config import load_mapping
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.cli.lifecycle_runs import judge_recorded
from rclverify.runtime.lifecycle import LifecycleGate, event_topic
from rclverify.runtime.live import LiveRun
from rclverify.traces.lifecycle_events import read_run

RCL = """\
node Battery {
  inputs( request : REAL )
  outputs( level : REAL )
  topics( std_msgs/Float64 request matches(in.request), std_msgs/Float64 level matches(out.level),
          lifecycle_msgs/TransitionEvent battery/transition_event )
  assume( in.request >= 0 )
  guarantee( out.level >= in.request )
}
"""
EVENTS = event_topic("/battery")


def _event(start: int, goal: int, at: float, flat: bool) -> dict[str, Any]:
    """lifecycle_msgs/msg/TransitionEvent as a log line holds it: flattened as a bag reader gives it, or nested."""
    if flat:
        return {"timestamp": int(at * 1e9), "transition.id": 0, "transition.label": "", "start_state.id": start,
                "start_state.label": "", "goal_state.id": goal, "goal_state.label": ""}
    return {"timestamp": int(at * 1e9), "transition": {"id": 0, "label": ""}, "start_state": {"id": start, "label": ""},
            "goal_state": {"id": goal, "label": ""}}


#: configured at 1 s, activating at 2.0 s, active at 2.08 s, deactivated at 3 s: (time, start, goal)
LIFE = [(1.0, 1, 10), (1.0, 10, 2), (2.0, 2, 13), (2.08, 13, 3), (3.0, 3, 14), (3.0, 14, 2)]
#: requests every 0.25 s from 0.5 s, each answered 20 ms later with level 5: too low for the requests 9 at
#: 1.0 s (inactive) and 2.5 s (active)
TRAFFIC = [x for k in range(12) for x in ((0.5 + 0.25 * k, "request", 9.0 if k in (2, 8) else 1.0),
                                          (0.52 + 0.25 * k, "level", 5.0))]


def _script(life: list[tuple[float, int, int]] = LIFE, traffic: list[tuple[float, str, float]] = TRAFFIC
            ) -> list[tuple[float, str, Any]]:
    return sorted([(t, EVENTS, (s, g)) for t, s, g in life] + list(traffic), key=lambda x: x[0])


def _log(tmp: Path, script: list[tuple[float, str, Any]], flat: bool = True) -> Path:
    path = tmp / f"run{len(list(tmp.glob('run*.jsonl')))}.jsonl"
    path.write_text("".join(json.dumps({"topic": topic, "time": t, **(_event(*v, t, flat) if topic == EVENTS
                                                                        else {"data": v})}) + "\n"
                            for t, topic, v in script), encoding="utf-8")
    return path


def _judge(tmp: Path, log: Path, deadlines: dict[str, dict[str, float]] | None = None) -> dict[str, Any]:
    checked = check([parse_text(RCL, "sys.rcl")])
    cfg = load_mapping(tmp, None, 1.0)
    events, _ = read_run(log)
    return judge_recorded(checked, list(checked.nodes.values()), cfg.rules, cfg.horizon, events,
                          tmp / f"{log.stem}.judged.jsonl", deadlines=deadlines)


def _node(rec: dict[str, Any]) -> dict[str, Any]:
    [node] = rec["lifecycle"]["nodes"]
    return node


def test_the_log_reads_the_transitions_nested_or_flattened(tmp_path: Path) -> None:
    for flat in (True, False):
        _, got = read_run(_log(tmp_path, _script(), flat))
        assert [(t.node, t.time, t.start, t.goal) for t in got] == [("/battery", t, s, g) for t, s, g in LIFE]
        assert str(got[3]).endswith("/battery activating -> active at 2.080 s")


def test_a_guarantee_is_not_asked_while_inactive_and_an_output_then_is_red(tmp_path: Path) -> None:
    rec = _judge(tmp_path, _log(tmp_path, _script()))
    node, [res] = _node(rec), rec["nodes"]
    # requests at 2.25, 2.5, 2.75 (active) are asked, the 2.5 one (9 > 5) violated; the others are no questions,
    # the one at 1.0 s (9 > 5 too) among them
    assert rec["lifecycle"]["not_questions"] == {"request": 9}
    assert res["counts"]["violated"] == 1 and res["first_violation"]["values"]["in.request"] == "9.0", res
    assert res["first_violation"]["trigger_time"] == 2.5
    # control: the same log, the contract not naming its transition topic: every request asked, both red
    plain = check([parse_text(RCL.replace(",\n          lifecycle_msgs/TransitionEvent battery/transition_event", ""),
                              "p.rcl")])
    events, _ = read_run(tmp_path / "run0.jsonl")
    cfg = load_mapping(tmp_path, None, 1.0)
    from rclverify.runtime.live import LiveRun as Run
    run = Run(plain, list(plain.nodes.values()), cfg.rules, cfg.horizon, tmp_path / "plain.jsonl", reorder_window=0.0)
    for e in events:
        run.tick(e.time)
        run.push(e.topic, e.fields, e.time)
    run.tick(10.0)
    assert run.stop()["nodes"][0]["counts"]["violated"] == 2
    # the outputs outside 2.0-3.0 s are red, 0.52 ... 1.77 and 3.27; 3.02 is within 50 ms of the deactivation
    assert [v["time"] for v in node["violations"]] == [0.52, 0.77, 1.02, 1.27, 1.52, 1.77, 3.27] and {v["state"] for v in node["violations"]} == {"unconfigured", "inactive"}
    assert res["status"] == "failed" and "published outside active" in res["explanation"]
    # control: the node answers only while active: no lifecycle violation, the same one guarantee violation
    quiet = [x for x in TRAFFIC if x[1] == "request" or 2.0 <= x[0] <= 3.0]
    fine = _judge(tmp_path, _log(tmp_path, _script(traffic=quiet)))
    assert _node(fine)["violations"] == [] and _node(fine)["status"] == "discharged"
    assert fine["nodes"][0]["counts"]["violated"] == 1 and "outside active" not in fine["nodes"][0]["explanation"]


def test_the_log_is_judged_as_the_live_run_judged_the_same_messages(tmp_path: Path) -> None:
    script = _script()
    checked = check([parse_text(RCL, "sys.rcl")])
    cfg = load_mapping(tmp_path, None, 1.0)
    live = LiveRun(checked, list(checked.nodes.values()), cfg.rules, cfg.horizon, tmp_path / "live.jsonl",
                   reorder_window=0.0)
    live.gate = LifecycleGate({"Battery": "/battery"}, live.nodes)
    for t, topic, v in script:
        live.tick(t)
        live.push(topic, _event(*v, t, False) if topic == EVENTS else {"data": v}, t)
    live.tick(script[-1][0] + 2)
    live_rec = live.stop()
    rec = _judge(tmp_path, _log(tmp_path, script))
    assert rec["lifecycle"] == live_rec["lifecycle"]
    assert rec["nodes"][0]["counts"] == live_rec["nodes"][0]["counts"]
    assert rec["nodes"][0]["status"] == live_rec["nodes"][0]["status"] == "failed"


@pytest.mark.parametrize("within, status", [(0.1, "met"), (0.05, "missed")])
def test_an_activation_deadline_met_and_missed(tmp_path: Path, within: float, status: str) -> None:
    quiet = [x for x in TRAFFIC if x[1] == "request" or 2.1 <= x[0] <= 3.0]
    rec = _judge(tmp_path, _log(tmp_path, _script(traffic=quiet)), {"Battery": {"activate": within}})
    node = _node(rec)
    [d] = node["deadlines"]
    assert (d["transition"], d["start"], d["end"], d["seconds"], d["status"]) == ("activate", 2.0, 2.08, 0.08, status)
    assert node["status"] == ("discharged" if status == "met" else "failed")
    assert ("transition deadline(s) missed" in rec["nodes"][0]["explanation"]) == (status == "missed")
    if status == "missed":
        assert "/battery's activate from 2.000 s reached active after 0.080 s (over its 0.05 s)" in d["reason"]


def test_an_activation_that_fails_or_never_ends_misses_its_deadline(tmp_path: Path) -> None:
    failed = [(1.0, 1, 10), (1.0, 10, 2), (2.0, 2, 13), (2.05, 13, 2)]  # on_activate failed: back to inactive
    [d] = _node(_judge(tmp_path, _log(tmp_path, _script(failed, [])), {"Battery": {"activate": 0.5}}))["deadlines"]
    assert d["status"] == "missed" and "ended in inactive, not active" in d["reason"]
    hung = [(1.0, 1, 10), (1.0, 10, 2), (2.0, 2, 13)]
    late = _script(hung, [(3.0, "request", 1.0)])  # heard 1 s after the activation began: over 0.5 s
    [d] = _node(_judge(tmp_path, _log(tmp_path, late), {"Battery": {"activate": 0.5}}))["deadlines"]
    assert d["status"] == "missed" and d["end"] is None
    # control: the run ends 0.2 s after the activation began, within 0.5 s: not decided
    early = _script(hung, [(2.2, "request", 1.0)])
    [d] = _node(_judge(tmp_path, _log(tmp_path, early), {"Battery": {"activate": 0.5}}))["deadlines"]
    assert d["status"] == "open"


def test_deadlines_the_gate_refuses(tmp_path: Path) -> None:
    log = _log(tmp_path, _script())
    for bad, said in (({"Nope": {"activate": 1.0}}, "not a managed node"),
                      ({"Battery": {"wake": 1.0}}, "no transition 'wake'"),
                      ({"Battery": {"activate": 0}}, "positive number of seconds")):
        with pytest.raises(ValueError, match=said):
            _judge(tmp_path, log, bad)
    plain = check([parse_text(RCL.replace(",\n          lifecycle_msgs/TransitionEvent battery/transition_event", ""),
                              "p.rcl")])
    with pytest.raises(ValueError, match="no managed node among Battery"):
        judge_recorded(plain, list(plain.nodes.values()), [], 1.0, [], tmp_path / "x.jsonl")


def _workspace(tmp: Path) -> Path:
    ws = tmp / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/b.rcl").write_text(RCL, encoding="utf-8")
    (ws / "contracts/plan.yaml").write_text("contracts: [contracts/b.rcl]\n", encoding="utf-8")
    return ws


def test_rclverify_monitor_judges_a_managed_nodes_log_as_live(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from rclverify.cli.commands import main
    ws = _workspace(tmp_path)
    quiet = [x for x in TRAFFIC if x[1] == "request" and x[2] == 1.0 or 2.1 <= x[0] <= 3.0 and x[1] == "level"]
    log = str(_log(tmp_path, _script(traffic=quiet)))
    assert main(["monitor", "-w", str(ws), log, "--horizon", "1", "--transition-deadline", "Battery:activate=100ms"]) == 0
    out = capsys.readouterr().out
    assert f"{log}: Battery: discharged" in out and "lifecycle /battery: 6 transition(s) heard, last inactive; " \
           "3 output(s) judged, 0 outside active; deadlines: 1 met" in out, out
    assert "no question (heard while its readers were outside their lifecycle scope: active): /request 8" in out
    # control: a deadline the activation (80 ms) does not meet; the node fails, the reason printed
    assert main(["monitor", "-w", str(ws), log, "--horizon", "1", "--transition-deadline", "Battery:activate=50ms"]) == 1
    out = capsys.readouterr().out
    assert f"{log}: Battery: failed: 1 transition deadline(s) missed (lifecycle)" in out
    assert "    missed: /battery's activate from 2.000 s reached active after 0.080 s (over its 0.05 s)" in out
    for bad, said in (("Battery:activate", "write NODE:TRANSITION=DURATION"), ("Battery:wake=1s", "no transition 'wake'")):
        assert main(["monitor", "-w", str(ws), log, "--transition-deadline", bad]) == 2
        err = capsys.readouterr().err
        assert said in err and err.count("\n") == 1 and "Traceback" not in err


def _judge_rcl(tmp: Path, rcl: str, log: Path, deadlines: dict[str, dict[str, float]] | None = None) -> dict[str, Any]:
    checked = check([parse_text(rcl, "sys.rcl")])
    cfg = load_mapping(tmp, None, 1.0)
    events, _ = read_run(log)
    return judge_recorded(checked, list(checked.nodes.values()), cfg.rules, cfg.horizon, events,
                          tmp / f"{log.stem}.scoped.jsonl", deadlines=deadlines)


def test_a_guarantee_scoped_to_inactive_or_active_is_asked_while_inactive(tmp_path: Path) -> None:
    """``while inactive or active``: the requests heard while the node is inactive are questions too, the
    one of 9 at 1.0 s (answered 5) red beside the one at 2.5 s; ``while active`` is the unscoped meaning."""
    log = _log(tmp_path, _script())
    unscoped = _judge(tmp_path, log)
    active = _judge_rcl(tmp_path, RCL.replace("in.request )\n}", "in.request ) while active\n}"), log)
    wide = _judge_rcl(tmp_path, RCL.replace("in.request )\n}", "in.request ) while inactive or active\n}"), log)
    for rec in (unscoped, active):  # the unscoped guarantee is judged while active
        assert rec["lifecycle"]["not_questions"] == {"request": 9} and rec["nodes"][0]["counts"]["violated"] == 1
        assert _node(rec)["scope"] == ["active"]
    assert _node(wide)["scope"] == ["inactive", "active"]
    # held back: the two requests before the node was configured (0.5, 0.75 s) and the one at 2.0 s, when it
    # was activating; the 1.0 s one is asked (configured to inactive at 1.0 s), and so are those after 3.0 s
    assert wide["lifecycle"]["not_questions"] == {"request": 3}, wide["lifecycle"]
    assert wide["nodes"][0]["counts"]["violated"] == 2
    # the outputs outside active are red whatever the scope: a managed node publishes only while active
    assert _node(wide)["violations"] == _node(unscoped)["violations"]


def test_a_transition_deadline_stated_in_rcl_is_judged(tmp_path: Path) -> None:
    """``ready within 100 ms of activate`` met by the 80 ms activation, ``50 ms`` missed with the clause's
    place; a ``--transition-deadline`` for the same transition replaces the contract's (control)."""
    quiet = [x for x in TRAFFIC if x[1] == "request" or 2.1 <= x[0] <= 3.0]
    log = _log(tmp_path, _script(traffic=quiet))
    def within(bound: str) -> str:
        return RCL.replace("in.request )\n}", f"in.request ) while active\n  ready within {bound} of activate\n}}")
    met = _node(_judge_rcl(tmp_path, within("100 ms"), log))
    [d] = met["deadlines"]
    assert (d["status"], d["within"], d["stated"]) == ("met", 0.1, "sys.rcl:8:3") and met["status"] == "discharged"
    rec = _judge_rcl(tmp_path, within("50 ms"), log)
    [d] = _node(rec)["deadlines"]
    assert (d["status"], d["within"], d["stated"]) == ("missed", 0.05, "sys.rcl:8:3")
    assert rec["nodes"][0]["status"] == "failed" and "transition deadline(s) missed" in rec["nodes"][0]["explanation"]
    [d] = _node(_judge_rcl(tmp_path, within("50 ms"), log, {"Battery": {"activate": 0.1}}))["deadlines"]
    assert d["status"] == "met" and "stated" not in d
    assert "deadlines" not in _node(_judge(tmp_path, log))  # control: no deadline stated, none judged


def test_rclverify_monitor_prints_where_a_missed_deadline_is_stated(tmp_path: Path,
                                                                     capsys: pytest.CaptureFixture[str]) -> None:
    from rclverify.cli.commands import main
    ws = _workspace(tmp_path)
    (ws / "contracts/b.rcl").write_text(RCL.replace("in.request )\n}", "in.request ) while active\n"
                                                    "  ready within 50 ms of activate\n}"), encoding="utf-8")
    quiet = [x for x in TRAFFIC if x[1] == "request" and x[2] == 1.0 or 2.1 <= x[0] <= 3.0 and x[1] == "level"]
    log = str(_log(tmp_path, _script(traffic=quiet)))
    assert main(["monitor", "-w", str(ws), log, "--horizon", "1"]) == 1
    out = capsys.readouterr().out
    assert "    missed: /battery's activate from 2.000 s reached active after 0.080 s (over its 0.05 s) (stated at " \
           "contracts/b.rcl:8:3)\n" in out, out
    assert main(["monitor", "-w", str(ws), log, "--horizon", "1", "--transition-deadline",
                 "Battery:activate=100ms"]) == 0  # control: the command line's deadline replaces it


def test_the_judged_run_decodes_as_its_printer_reads_it(tmp_path: Path) -> None:
    """``rclverify monitor`` prints a managed run from backends/monitors/lifecycle_record.py's classes: the
    gate's record decodes whole, a transition deadline with where it is stated; a record of another shape
    is refused, never read by key."""
    import msgspec
    from rclverify.backends.monitors.lifecycle_record import LifecycleRun
    quiet = [x for x in TRAFFIC if x[1] == "request" or 2.1 <= x[0] <= 3.0]
    rec = _judge(tmp_path, _log(tmp_path, _script(traffic=quiet)), {"Battery": {"activate": 0.05}})
    run = LifecycleRun.of(rec)
    [m] = run.lifecycle.nodes
    [d] = m.deadlines
    assert (m.node, m.ros_node, m.status, d.transition, d.status, d.within) == (
        "Battery", "/battery", "failed", "activate", "missed", 0.05)
    assert run.nodes[0].status == "failed" and d.stated is None  # given on the command line: stated nowhere
    assert run.lifecycle.not_questions == rec["lifecycle"]["not_questions"]
    broken = {**rec, "lifecycle": {**rec["lifecycle"], "nodes": [{**_node(rec), "transitions": "six"}]}}
    with pytest.raises(msgspec.ValidationError, match="transitions"):
        LifecycleRun.of(broken)
