"""``rclverify monitor --live --ros2``: ROS 2 monitored natively over DDS
(docs/monitors.md, "ROS 2 over DDS").

On 127.0.0.1 only (a Cyclone configuration with the loopback interface,
multicast off, the unicast peer 127.0.0.1) and a random ``ROS_DOMAIN_ID``:
the monitor runs as its own process (killed in the fixture's ``finally``),
and this process plays the ROS 2 system with participants written with
cyclonedds to ROS 2's wire conventions (tests/dds_ros2.py; no ROS 2 node
runs here, none can be installed):

* ``/limiter`` publishes ``/limit`` and its output on the private
  ``/speed_unchecked`` (``--enforce /speed``); a ``/consumer`` reads
  ``/speed``: it must get exactly the messages within the limit;
* ``/ranger`` publishes ``/range`` best-effort: the monitor must hear it;
* ``/base`` serves ``/estop`` (``std_srvs/SetBool``): the first call is
  answered right, the second wrong (``success: false``), the third right but
  400 ms late (the deadline is 200 ms); ``/teleop`` calls it;
* ``/mover`` serves the ``/move`` action, ``/mission`` sends a goal;
* the monitor records the run to an MCAP bag.

Then the monitor's verdicts are compared with what the offline engine
says of the same messages: its log's events checked by ``check_trace``,
the recorded bag by ``rclverify monitor BAG``, its calls replayed through
the same call book.
"""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any, Iterator

import pytest
from _procs import stop, wait_logged

pytest.importorskip("cyclonedds", reason="the cyclonedds binding is not installed (pip install cyclonedds)")

from dds_ros2 import Ros2Participant, dds_env, domain_of, matched, wait_until  # noqa: E402

from rclverify.ros.live.dds_qos import QosProfile  # noqa: E402

from rclverify.backends.monitors.check import check_trace  # noqa: E402
from rclverify.backends.monitors.dds_calls import CallBook, replay  # noqa: E402
from rclverify.runtime.dds.types import TypeBook  # noqa: E402
from rclverify.cli.commands import main  # noqa: E402
from rclverify.lang.typecheck import load  # noqa: E402
from rclverify.traces.jsonl import read_jsonl  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
WS = Path(__file__).parent.parent / "data" / "dds_ws"
SPEEDS = [(1.0, 0.5), (1.1, 1.5), (1.2, 0.8), (1.3, 2.0)]  # (limit, speed): the 2nd and 4th exceed their limit


def _other_layout() -> type:
    """``std_msgs::msg::dds_::Float64_`` whose ``data`` is a string: the contract's type name, another
    layout (a cyclonedds IDL class made with ``type()``, so its annotation is the type itself)."""
    import cyclonedds.idl as idl
    return type("Float64_", (idl.IdlStruct,), {"__annotations__": {"data": str}, "__module__": __name__,
                                                "__idl_typename__": "std_msgs::msg::dds_::Float64_"})


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    tmp = tmp_path_factory.mktemp("dds")
    env = dds_env(tmp)
    mp = pytest.MonkeyPatch()
    for k, v in env.items():
        mp.setenv(k, v)
    out = tmp / "monitor.out"
    # a 300 ms lateness bound: each limit and its speed, each request and its reply, at their writers' source
    # times (with none, at their receipt, in the order heard, which a loaded machine's delivery may change)
    monitor = subprocess.Popen(
        [sys.executable, "-m", "rclverify.cli.commands", "monitor", "-w", str(WS), "--live", "--ros2", "--interfaces",
         "interfaces", "--enforce", "/speed", "--record", str(tmp / "run.mcap"), "--log", str(tmp / "live.jsonl"),
         "--evidence", str(tmp / "live.json"), "--horizon", "1.0", "--reorder-window", "0.3", "--status", "0",
         "--duration", "60"],
        env={**os.environ, **env, "PYTHONPATH": str(REPO / "src")}, cwd=tmp, stdout=out.open("wb"),
        stderr=subprocess.STDOUT, start_new_session=True)
    ros = other = None
    try:
        wait_until(lambda: "monitoring" in out.read_text() or monitor.poll() is not None, 30, "the monitor started")
        assert monitor.poll() is None, out.read_text()
        types = TypeBook([WS / "interfaces"])
        ros = Ros2Participant(types, domain_of(env))
        limiter, ranger, consumer = ros.node("limiter"), ros.node("ranger"), ros.node("consumer")
        base, teleop = ros.node("base"), ros.node("teleop")
        mover, mission = ros.node("mover"), ros.node("mission")
        limit = ros.publisher(limiter, "/limit", "std_msgs/Float64")
        speed = ros.publisher(limiter, "/speed_unchecked", "std_msgs/Float64")
        rng = ros.publisher(ranger, "/range", "std_msgs/Float32", reliable=False)
        heard = ros.subscriber(consumer, "/speed", "std_msgs/Float64")
        ros.serve(base, "/estop", "std_srvs/SetBool",
                  lambda k, req: ({"success": k != 2, "message": f"call {k}"}, 0.4 if k == 3 else 0.0))
        call = ros.client(teleop, "/estop", "std_srvs/SetBool")
        served = ros.action_server(mover, "/move", "rclverify_examples/Move",
                                   lambda goal: ([(0.3, {"progress": 0.5})], {"arrived": True}))
        send = ros.action_client(mission, "/move", "rclverify_examples/Move")
        echo = ros.subscriber(ros.node("echo"), "/rclverify/verdict", "std_msgs/String")  # `ros2 topic echo`
        # another participant publishes /range with another type: its messages cannot be heard, and that is said
        other = Ros2Participant(types, domain_of(env))
        imposter = other.publisher(other.node("imposter"), "/range", "std_msgs/Float64")
        # and a node that was not remapped writes the guarded /speed beside the gate (issue 47): said, and the
        # evidence of what reads /speed cannot be discharged while it does
        rogue = other.publisher(other.node("rogue"), "/speed", "std_msgs/Float64")
        # and one publishes /limit with the contract's type name but another layout: named, never heard
        other.writer(other.node("mislaid"), "rt/limit", _other_layout(), QosProfile(reliable=True, depth=10))
        other.announce()
        ros.announce()
        # the monitor's readers are made when it discovers a publisher: wait until they are matched
        # (an action's writers are matched by its peer and by the monitor: two each)
        wait_until(lambda: all(matched(w) >= 1 for w in (limit, speed, rng))
                   and all(matched(w) >= 2 for w in (*send.writers, *served, call.writer))
                   and len(heard.get_matched_publications()) >= 1, 20,
                   "the monitor's readers and its republisher of /speed matched")
        String = types.message("std_msgs/Float64")
        F32 = types.message("std_msgs/Float32")
        for v in (1.0, 2.0, 3.0):
            rng.write(F32(data=v))
            time.sleep(0.02)
        for lim, sp in SPEEDS:
            limit.write(String(data=lim))
            time.sleep(0.05)
            speed.write(String(data=sp))
            time.sleep(0.05)
        replies = [call({"data": True}, 5.0) for _ in range(3)]
        feedbacks, result = send({"target": 2.0}, 5.0)
        wait_logged(tmp / "live.jsonl", _judged, 30)  # every call, goal and limit judged, whatever the load
        # the sensor goes on publishing: the recorded bag, checked offline, reaches past the horizon too
        rng.write(F32(data=4.0))
        wait_logged(tmp / "live.jsonl", lambda log: sum(x.get("topic") == "range" for x in log) >= 4, 30)
        got: list[float] = []
        wait_until(lambda: got.extend(s.data for s in heard.take(N=16)) or len(got) >= 2, 5, "the released speeds")
        time.sleep(0.3)
        got.extend(s.data for s in heard.take(N=16))
        echoed = [json.loads(m.data) for m in echo.take(N=1000)]
        imposter_heard = matched(imposter)  # no reader of the monitor matches it
        # a subscriber that comes late still gets each node's last verdict (transient-local: ROS 2's latching)
        late = ros.reader(ros.node("late"), "rt/rclverify/Limiter/last_verdict", types.message("std_msgs/String"),
                          QosProfile(reliable=True, durability="transient_local", depth=1))
        latched: list[Any] = []
        wait_until(lambda: latched.extend(late.take(N=4)) or bool(latched), 5, "the latched last verdict")
        stop(monitor, signal.SIGINT, grace=15)
        code = monitor.returncode
    except BaseException:
        print(out.read_text())
        raise
    finally:
        stop(monitor, signal.SIGKILL, grace=15)
        for p in (ros, other):
            if p is not None:
                p.close()
        mp.undo()
    log = [json.loads(x) for x in (tmp / "live.jsonl").read_text().splitlines()]
    yield {"tmp": tmp, "code": code, "out": out.read_text(), "log": log, "consumer": got, "replies": replies,
           "echoed": echoed, "latched": json.loads(latched[-1].data), "imposter": imposter_heard,
           "feedbacks": feedbacks, "result": result, "record": json.loads((tmp / "live.json").read_text())}


def _judged(log: list[dict[str, Any]]) -> bool:
    """The run's end in the monitor's ``log``: /estop's three calls judged and its late answer's deadline
    line (an update), /move's goal answered and its deadline, Limiter's verdict on the last limit (1.3)."""
    calls = [v["node"] for v in _verdicts(log) if v.get("call")]
    deadlines = [x["verdict"] for x in log if x.get("kind") == "deadline"]
    return calls.count("Base") >= 3 and "Mover" in calls and any(v["node"] == "Mover" for v in deadlines) \
        and any(v["node"] == "Base" and v.get("update") for v in deadlines) \
        and any(v["node"] == "Limiter" and v.get("values", {}).get("in.limit") == "1.3" for v in _verdicts(log))


def _verdicts(log: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The verdicts of ``log``'s verdict lines that are not deadline lines."""
    return [x["verdict"] for x in log if x.get("topic") == "rclverify/verdict" and "kind" not in x]


def _call_verdicts(log: list[dict[str, Any]], node: str) -> list[dict[str, Any]]:
    return [x["verdict"] for x in log if x.get("topic") == "rclverify/verdict" and "kind" not in x
            and x["verdict"].get("call") and x["verdict"]["node"] == node]


def test_a_wrong_answer_is_violated_and_the_client_assumption_checked(run: dict[str, Any]) -> None:
    assert [r["success"] for r in run["replies"]] == [True, False, True]
    base = sorted(_call_verdicts(run["log"], "Base"), key=lambda v: v["time"])
    assert [v["verdict"] for v in base] == ["satisfied", "violated", "satisfied"], base
    wrong = base[1]
    assert wrong["guarantee"] == 1 and wrong["values"] == {"in.stop_req": "TRUE", "out.stopped": "FALSE"}
    # Teleop assumes the stop is acknowledged: the wrong answer breaks its assumption, blamed upstream
    teleop = sorted(_call_verdicts(run["log"], "Teleop"), key=lambda v: v["time"])
    assert [v["verdict"] for v in teleop] == ["satisfied", "assumption violated", "satisfied"], teleop
    calls = {n["node"]: n for n in run["record"]["calls"]["nodes"]}
    assert calls["Base"]["status"] == "failed" and calls["Base"]["counts"]["violated"] == 1
    assert run["code"] == 1, run["out"]


def test_a_late_answer_is_false_with_its_stamps(run: dict[str, Any]) -> None:
    lines = [x["verdict"] for x in run["log"] if x.get("kind") == "deadline" and x["verdict"]["node"] == "Base"]
    late = [v for v in lines if v["answer"] is not None and v["verdict"] == "false"]
    assert len(late) == 1, lines
    v = late[0]
    assert v["due"] == pytest.approx(v["trigger_stamp"] + 0.2)
    assert v["answer"] - v["trigger_stamp"] >= 0.4  # the server slept 400 ms
    # the stamps are the request's and the reply's DDS source timestamps, as the call lines logged them
    calls = {x["where"]: x for x in run["log"] if x.get("kind") == "call" and "index" in x}
    assert calls[v["trigger_where"]]["time"] == v["trigger_stamp"]
    assert calls[v["answer_where"]]["time"] == v["answer"]
    assert calls[v["trigger_where"]]["key"] == calls[v["answer_where"]]["key"]  # paired by identity
    assert [x["verdict"] for x in lines if not x["update"]].count("true") == 1
    assert run["record"]["deadlines"]["false"] == 2  # the wrong answer never answered in time either


def test_the_action_goal_feedback_and_result(run: dict[str, Any]) -> None:
    assert run["feedbacks"] == [{"progress": 0.5}] and run["result"] == {"arrived": True}
    mover = _call_verdicts(run["log"], "Mover")
    # the feedback and the result, each judged when it answers the goal (a feedback heard before the goal, a
    # race of the two readers, answers no question and gets no verdict)
    assert 1 <= len(mover) <= 2 and all(v["verdict"] == "satisfied" for v in mover)
    parts = [x["part"] for x in run["log"] if x.get("kind") == "call" and x.get("link") == "move"]
    assert {"goal", "feedback", "result", "status"} <= set(parts)
    dl = [x["verdict"] for x in run["log"] if x.get("kind") == "deadline" and x["verdict"]["node"] == "Mover"]
    assert [v["verdict"] for v in dl] == ["true"] and 0.25 <= dl[0]["answer"] - dl[0]["trigger_stamp"] <= 2.0


def test_enforce_drops_exactly_the_violating_messages(run: dict[str, Any]) -> None:
    assert run["consumer"] == [sp for lim, sp in SPEEDS if sp <= lim]
    blocked = [x for x in run["log"] if x.get("kind") == "blocked"]
    assert [b["verdict"]["values"]["out.speed"] for b in blocked] == ["1.5", "2.0"]
    assert all(b["verdict"]["verdict"] == "violated" and b["verdict"]["guarantee"] == 1 for b in blocked)
    assert run["record"]["enforce"] == {"speed": {"private": "/speed_unchecked", "released": 2, "blocked": 2,
                                                  "policy": "closed"}}


def test_a_best_effort_publisher_is_heard(run: dict[str, Any]) -> None:
    qos = run["record"]["qos"]["range"]
    assert qos["qos"]["reliability"] == "best_effort" and qos["samples"] == 4 and qos["publishers_heard"] == 1
    ranger = next(n for n in run["record"]["nodes"] if n["node"] == "Ranger")
    assert ranger["counts"]["satisfied"] == 4
    # a publisher of another type on the topic: a located warning, never silence
    warnings = [w for w in run["record"]["warnings"] if "/imposter" in w]
    assert len(warnings) == 1 and warnings[0].startswith("contracts/dds.rcl:20:11: warning: range: node /imposter ")
    assert "publishes std_msgs::msg::dds_::Float64_" in warnings[0] and "not heard" in warnings[0]
    assert run["imposter"] == 0 and warnings[0] in run["out"]


def test_another_writer_on_a_guarded_topic_is_named_and_keeps_the_evidence_from_discharged(run: dict) -> None:
    """Issue 47: a node that was not remapped writes /speed beside the gate."""
    rogue = [w for w in run["record"]["warnings"] if "/rogue" in w]
    assert len(rogue) == 1 and ": warning: /speed: node /rogue writes on the guarded topic" in rogue[0]
    assert rogue[0].startswith("contracts/dds.rcl:") and rogue[0] in run["out"]
    assert run["record"]["bypass"] == {"speed": ["node /rogue"]}
    limiter = next(n for n in run["record"]["nodes"] if n["node"] == "Limiter")
    assert any("/rogue also wrote on the guarded topic /speed" in t for t in limiter["trust"])
    assert limiter["status"] != "discharged"


def test_a_publisher_of_the_same_type_name_with_another_layout_is_named_not_heard(run: dict) -> None:
    """Issue 47: the layout is compared member by member with the type object DDS discovery names (never the
    bare type identifier, issue 62), and the field that differs is named."""
    mislaid = [w for w in run["record"]["warnings"] if "/mislaid" in w]
    assert len(mislaid) == 1 and ": warning: limit: node /mislaid publishes std_msgs::msg::dds_::Float64_ with " \
        "another layout than the contract's type: field data: the publisher's is string, the contract's float64" \
        in mislaid[0], mislaid
    assert run["record"]["qos"]["limit"]["publishers_heard"] == 1


def test_verdicts_are_on_the_bus(run: dict[str, Any]) -> None:
    """``rt/rclverify/verdict`` (std_msgs/String JSON) as a ROS 2 subscriber reads it, and the latched
    last verdict per node for a late subscriber."""
    kinds = {(v.get("kind"), v.get("verdict")) for v in run["echoed"]}
    assert {(None, "satisfied"), (None, "violated"), ("deadline", "false"), ("blocked", "violated")} <= kinds
    assert any(v.get("call") and v["node"] == "Base" and v["verdict"] == "violated" for v in run["echoed"])
    # Limiter's last verdict: the limit 1.3 answered by the blocked speed 2.0, judged when the horizon passed
    # (an answer comes after its question: the earlier 0.8 no longer stands in for it)
    assert run["latched"]["node"] == "Limiter" and run["latched"]["verdict"] == "violated"
    assert run["latched"]["values"] == {"in.limit": "1.3", "out.speed": "2.0"}


def test_live_verdicts_equal_the_offline_engines(run: dict[str, Any], capsys: pytest.CaptureFixture[str]) -> None:
    checked = load([WS / "contracts" / "dds.rcl"])
    tmp = run["tmp"]
    # the log's messages through the offline checker: the same verdicts, event by event
    events = [e for e in read_jsonl(tmp / "live.jsonl") if not e.topic.startswith("rclverify/")]
    offline: list[Any] = []
    live = [x["verdict"] for x in run["log"] if x.get("topic") == "rclverify/verdict" and "kind" not in x
            and not x["verdict"].get("call")]
    # the live monitor's clock went on after the last message (its timer decides what the horizon ends):
    # the offline engine is given the same end of the run, the last time the live run logged
    end = max(float(x["time"]) for x in run["log"] if "time" in x)
    check_trace(checked, list(checked.nodes.values()), events, {}, 1.0, offline.append, end=end)
    key = lambda v: (v["node"], v["verdict"], v["topic"], v["time"], v["guarantee"], v["values"])  # noqa: E731
    assert live and sorted(map(key, live), key=str) == sorted((key(v.to_json()) for v in offline), key=str)
    # the recorded bag (MCAP) checked offline by the command: the counts the live run recorded
    bag = run["record"]["bag"]
    assert bag["messages"] == 4 + 2 * len(SPEEDS) and Path(bag["path"], "run.mcap").is_file()
    capsys.readouterr()
    assert main(["monitor", "-w", str(WS), "--horizon", "1.0", "--json", bag["path"]]) == 1  # Limiter violated
    from_bag = {n["node"]: n["counts"] for n in json.loads(capsys.readouterr().out) if "counts" in n}
    assert from_bag == {n["node"]: n["counts"] for n in run["record"]["nodes"]}
    # the calls replayed through the call book: the same summary as the live run's
    book = CallBook(checked, [(n, lk) for n in checked.nodes.values() for lk in n.node.links], {}, 1.0)
    summary = replay(book, run["log"])
    assert summary["counts"] == run["record"]["calls"]["counts"]
    assert {r["node"]: r["counts"] for r in summary["nodes"]} == \
        {n["node"]: n["counts"] for n in run["record"]["calls"]["nodes"]}
    assert summary["false"] == run["record"]["deadlines"]["false"]


def test_the_offline_command_on_the_live_log_judges_its_calls_as_live(run: dict[str, Any],
                                                                      capsys: pytest.CaptureFixture[str]) -> None:
    """``rclverify monitor LOG`` replays the log's call lines through the call book (log_calls.py): the
    live run's call verdicts, call deadlines and exit code."""
    capsys.readouterr()
    code = main(["monitor", "-w", str(WS), "--horizon", "1.0", "--json", str(run["tmp"] / "live.jsonl")])
    report = json.loads(capsys.readouterr().out)
    assert {e["node"]: e["calls"]["counts"] for e in report if "calls" in e} == \
        {n["node"]: n["counts"] for n in run["record"]["calls"]["nodes"]}
    assert {e["node"]: e["call_deadlines"]["counts"] for e in report if "call_deadlines" in e} == \
        {r["node"]: r["counts"] for r in run["record"]["deadlines"]["results"]}
    assert code == run["code"] == 1
