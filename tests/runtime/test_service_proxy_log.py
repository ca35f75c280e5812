"""The ROS 1 service proxy's log and the live ROS 1 run's decoding, without a master
(``runtime/service_proxy.py``, "The log"; ``runtime/live_ros1.py``).

* The proxy's log is a trace the offline check reads: its calls as message lines, its own lines on
  ``rclverify/proxy``; ``rclverify monitor`` on it gives the proxy's deadline verdicts.  The control: the
  same events written as the proxy's own lines only, a line without a topic, are refused, located.
* A live run counts the proxy's events as the calls it heard (``call``), never as messages.  Inside it
  the proxy judges nothing: the run's deadline checks give each call's deadline verdict once (the log, the
  record, the verdict topic), an unanswered call's ``false`` at the run's timer; the control, a proxy given
  monitors to judge beside them, is refused.
* The run warns once per node whose clock by the mapping contradicts ``/use_sim_time``, naming both; the
  controls, nodes whose clock agrees or is not said and a ``/use_sim_time`` not known, get no line.
* A request stamped 0 (the proxy's ROS clock not yet set: under ``/use_sim_time`` before its first
  ``/clock``) has its deadline ``undecided``, saying so, in the log and the summary; the control, the
  same call stamped once the clock is set, is judged.  The proxy waits for its clock to be set, bounded.
* A message rospy decoded itself (a ``/clock`` subscription shared with rospy's own under
  ``/use_sim_time``) is flattened as it is; the control, raw bytes of another type, is counted a decode
  error.
"""
from __future__ import annotations

import importlib
import io
import json
import time
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.deadlines import DeadlineMonitor
from rclverify.cli.commands import main
from rclverify.lang.typecheck import load
from rclverify.runtime.service_proxy import PROXY_LOG_TOPIC, UNSET_CLOCK, ProxyRun, wait_clock
from rclverify.traces.jsonl import read_jsonl
from rclverify.traces.events import TraceError

RCL = """\
node Base {
  inputs( req : BOOL )
  outputs( ok : BOOL )
  services( std_srvs/SetBool estop serves(in.req, out.ok) )
  assume( TRUE )
  guarantee( in.req -> out.ok ) triggered by in.req within 400 ms
}
"""
#: (request time, response time) s: in time (300 ms), late (500 ms), in time (100 ms)
CALLS = [(10.0, 10.3), (11.0, 11.5), (12.0, 12.1)]


def _workspace(tmp: Path) -> Path:
    ws = tmp / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/sys.rcl").write_text(RCL)
    (ws / "contracts/plan.yaml").write_text("contracts: [contracts/sys.rcl]\n")
    (ws / "mapping.yaml").write_text("topics: {}\n")
    return ws


def _proxy_log(ws: Path, log: Path) -> list[dict[str, Any]]:
    """The proxy's run of :data:`CALLS` written to ``log``; its deadline verdicts."""
    checked = load([str(ws / "contracts/sys.rcl")])
    run = ProxyRun([DeadlineMonitor(checked, checked.nodes["Base"], {}, clock=False)], log)
    for asked, answered in CALLS:
        run.event("estop/request", {"data": True}, asked)
        run.tick(asked + 0.2)
        run.event("estop/response", {"success": True, "message": ""}, answered)
        run.tick(answered + 0.5)
    run.close()
    return [x for x in map(json.loads, log.read_text().splitlines()) if x.get("kind") == "verdict"]


def _offline(ws: Path, log: Path, capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    capsys.readouterr()
    code = main(["monitor", "-w", str(ws), "--mapping", "mapping.yaml", "--json", str(log)])
    out, err = capsys.readouterr()
    return code, out, err


def test_the_proxy_log_replayed_offline_gives_its_verdicts(tmp_path: Path,
                                                           capsys: pytest.CaptureFixture[str]) -> None:
    ws = _workspace(tmp_path)
    log = tmp_path / "proxy.jsonl"
    verdicts = _proxy_log(ws, log)
    finals = {v["trigger_stamp"]: v["verdict"] for v in verdicts}
    assert finals == {10.0: "true", 11.0: "false", 12.0: "true"}, verdicts
    lines = [json.loads(x) for x in log.read_text().splitlines()]
    own = [x for x in lines if x["topic"] == PROXY_LOG_TOPIC]
    assert {x["kind"] for x in own} == {"event", "verdict", "summary"}
    assert [x["call"] for x in own if x["kind"] == "event"] == ["estop/request", "estop/response"] * 3
    assert all(log.read_text().splitlines()[i].startswith('{"topic": ') for i in range(len(lines)))
    # the message lines: what the offline check reads, each call's request and response at the proxy's stamps
    messages = [(x["topic"], x["time"]) for x in lines if x["topic"] != PROXY_LOG_TOPIC]
    assert messages == [(t, s) for a, b in CALLS for t, s in (("estop/request", a), ("estop/response", b))]
    code, out, err = _offline(ws, log, capsys)
    (dl,) = [e["deadlines"] for e in json.loads(out) if "deadlines" in e and e["node"] == "Base"]
    assert (dl["counts"]["true"], dl["counts"]["false"], dl["unaccepted"]["undecided"]) == (2, 1, 0), out + err
    assert code == 1  # the late call: a violation, as the proxy said


def test_the_control_a_log_of_the_proxys_own_lines_only_is_refused_located(tmp_path: Path,
                                                                           capsys: pytest.CaptureFixture[str]) -> None:
    ws = _workspace(tmp_path)
    log = tmp_path / "proxy.jsonl"
    _proxy_log(ws, log)
    # the control: the proxy's lines as they would be without their topic, a line the reader cannot place
    bare = [{k: v for k, v in json.loads(x).items() if k != "topic"} for x in log.read_text().splitlines()
            if json.loads(x)["topic"] == PROXY_LOG_TOPIC]
    wrong = tmp_path / "bare.jsonl"
    wrong.write_text("".join(json.dumps(x) + "\n" for x in bare))
    with pytest.raises(TraceError, match=r"bare\.jsonl:1:1: error: the event has no string 'topic'"):
        list(read_jsonl(wrong))
    code, out, err = _offline(ws, wrong, capsys)
    assert code == 2 and "bare.jsonl:1:1: error:" in err and "Traceback" not in err
    assert len(list(read_jsonl(log))) == len(log.read_text().splitlines())  # the proxy's log reads whole


def test_a_live_run_counts_the_proxys_events_as_calls_heard(tmp_path: Path) -> None:
    from rclverify.runtime.live import LiveRun
    ws = _workspace(tmp_path)
    checked = load([str(ws / "contracts/sys.rcl")])
    nodes = list(checked.nodes.values())
    published: list[dict[str, Any]] = []
    live = LiveRun(checked, nodes, {}, 1.0, tmp_path / "live.jsonl", publish=lambda text: published.append(json.loads(text)))
    run = ProxyRun([], write=live.note, forward=live.push, judge=False)  # as proxy_factory makes it
    run.event("estop/request", {"data": True}, 10.0)
    run.event("estop/response", {"success": True, "message": ""}, 10.1)
    run.event("estop/request", {"data": True}, 11.0)  # unanswered: false once the run's timer passes 11.4
    live.tick(11.3)
    assert [(p["verdict"], p["answer"]) for p in published if p.get("kind") == "deadline"] == [("true", 10.1)]
    live.tick(11.5)
    deadlines = [p for p in published if p.get("kind") == "deadline"]
    assert [(p["verdict"], p["answer"]) for p in deadlines] == [("true", 10.1), ("false", None)], deadlines
    run.event("estop/response", {"success": True, "message": ""}, 11.6)  # the late answer: an update
    live.tick(12.0)
    assert live.calls_heard == {"estop/request": 2, "estop/response": 2}
    run.close()
    record = live.stop()
    # the deadline checks of the live log judge each call once: the proxy's own lines are no messages
    (res,) = [e["deadlines"] for e in record["topic_deadlines"] if e["node"] == "Base"]
    assert (res["counts"]["true"], res["counts"]["false"], sum(res["unaccepted"].values())) == (1, 1, 0), res
    deadlines = [p for p in published if p.get("kind") == "deadline"]
    assert [(p["verdict"], p["update"]) for p in deadlines] == [("true", False), ("false", False), ("false", True)]
    lines = [json.loads(x) for x in (tmp_path / "live.jsonl").read_text().splitlines()]
    logged = [x["verdict"] for x in lines if x.get("kind") == "deadline"]
    assert logged == [{k: v for k, v in p.items() if k != "kind"} for p in deadlines]  # published as logged
    # the proxy's lines: its events only, no deadline verdict or summary of its own
    assert [x["kind"] for x in lines if x["topic"] == PROXY_LOG_TOPIC] == ["event"] * 4
    # the control: a proxy that judges nothing takes no monitors (a second judge of the same calls)
    with pytest.raises(ValueError, match="takes no deadline monitors"):
        ProxyRun([DeadlineMonitor(checked, nodes[0], {}, clock=False)], write=live.note, judge=False)


def test_the_run_warns_of_a_node_whose_clock_contradicts_use_sim_time(tmp_path: Path) -> None:
    from rclverify.runtime.live_ros1 import clock_warnings
    from rclverify.traces.mapping import load_rules
    rcl = tmp_path / "sys.rcl"  # Base and Halt with a deadline; Plain without one
    rcl.write_text(RCL + RCL.replace("Base", "Halt").replace("estop", "halt") + "node Plain {\n  inputs( a : BOOL )\n"
                   "  outputs( b : BOOL )\n  assume( TRUE )\n  guarantee( out.b == in.a )\n}\n")
    nodes = list(load([str(rcl)]).nodes.values())
    assert [n.name for n in nodes] == ["Base", "Halt", "Plain"]
    rules = load_rules({})
    rules.sim_time = frozenset({"Base"})  # Base on /clock, Halt on the wall clock
    (line,) = clock_warnings(rules, nodes, True)
    assert "node Halt keeps the wall clock by the mapping's use_sim_time but /use_sim_time is true" in line, line
    (line,) = clock_warnings(rules, nodes, False)
    assert "node Base keeps simulated time (/clock) by the mapping's use_sim_time but /use_sim_time is false" in line
    rules.sim_time = True  # every node on /clock: those with a deadline warned of, not Plain
    assert clock_warnings(rules, nodes, True) == []
    assert [x.split("node ")[1].split()[0] for x in clock_warnings(rules, nodes, False)] == ["Base", "Halt"]
    rules.sim_time = None  # not said: no line, whatever ROS says
    assert clock_warnings(rules, nodes, True) == clock_warnings(rules, nodes, False) == []
    rules.sim_time = frozenset({"Base"})
    assert clock_warnings(rules, nodes, None) == []  # /use_sim_time not known: nothing made up


def test_a_message_rospy_decoded_itself_is_flattened_as_it_is() -> None:
    from rclverify.runtime.live_ros1 import _decoder
    from rclverify.runtime.ros1 import RosUnavailable, import_rospy
    try:
        rospy = import_rospy()
        Clock = importlib.import_module("rosgraph_msgs.msg").Clock  # beside rospy (no type information)
    except (RosUnavailable, ImportError) as exc:
        pytest.skip(f"ROS 1 unavailable: {exc}")
    errors: dict[str, int] = {}
    decode = _decoder({"/clock": Clock}, errors)
    msg = Clock(clock=rospy.Time(1000, 5_000_000))
    assert decode("/clock", msg) == {"clock": {"secs": 1000, "nsecs": 5_000_000}} and errors == {}
    # the same message as raw bytes (an AnyMsg subscription of its own) decodes alike
    buf = io.BytesIO()
    msg.serialize(buf)
    raw = rospy.AnyMsg()
    raw.deserialize(buf.getvalue())
    assert decode("/clock", raw) == {"clock": {"secs": 1000, "nsecs": 5_000_000}} and errors == {}
    # the control: bytes that are no Clock are a decode error, counted
    bad = rospy.AnyMsg()
    bad.deserialize(b"\x01")
    assert decode("/clock", bad) is None and errors == {"/clock": 1}


def test_a_request_stamped_before_the_clock_was_set_is_undecided(tmp_path: Path) -> None:
    ws = _workspace(tmp_path)
    checked = load([str(ws / "contracts/sys.rcl")])
    for first, want in ((0.0, "undecided"), (1000.0, "true")):  # the control: stamped once the clock is set
        log = tmp_path / f"p{first:g}.jsonl"
        run = ProxyRun([DeadlineMonitor(checked, checked.nodes["Base"], {}, clock=False)], log)
        run.event("estop/request", {"data": True}, first)  # 0: rospy's clock before its first /clock
        run.tick(1000.0)
        run.event("estop/response", {"success": True, "message": ""}, 1000.3)
        run.event("estop/request", {"data": True}, 1001.0)  # a late call, judged: false
        run.event("estop/response", {"success": True, "message": ""}, 1001.6)
        run.tick(1002.0)
        summary = run.close()
        verdicts = [x for x in map(json.loads, log.read_text().splitlines()) if x.get("kind") == "verdict"]
        firsts = [v for v in verdicts if v["trigger_stamp"] == first]
        assert {v["verdict"] for v in firsts} == {want}, verdicts
        assert (firsts[0]["reason"] == UNSET_CLOCK) == (want == "undecided")
        assert [v["verdict"] for v in verdicts if v["trigger_stamp"] == 1001.0][-1] == "false"
        assert len(summary["results"]) == 1
        res: Any = summary["results"][0]
        assert (res["counts"]["true"], res["counts"]["false"], res["unaccepted"]["undecided"]) == \
            ((0, 1, 1) if want == "undecided" else (1, 1, 0)), res
        assert summary["false"] == 1 and res["first_false"]["trigger_stamp"] == 1001.0
        assert (res["first_unaccepted"] or {}).get("reason") == (UNSET_CLOCK if want == "undecided" else None)


def test_the_proxy_waits_for_its_clock_to_be_set_bounded() -> None:
    readings = iter([0.0, 0.0, 0.0, 1000.005])
    assert wait_clock(lambda: next(readings), 5.0)  # set at the fourth reading
    t0 = time.monotonic()
    assert not wait_clock(lambda: 0.0, 0.1)  # the control: never set, given up after the bound
    assert 0.1 <= time.monotonic() - t0 < 1.0
