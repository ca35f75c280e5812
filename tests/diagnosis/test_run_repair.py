"""The parts of a monitor violation's code repair that need no ROS 2 (diagnosis/rerun.py, run_repair.py;
docs/diagnosis.md "Monitor violations: a node re-run on its recorded run"): the questions read from a live
log, the run written again with a re-run's answers, the reproduction check, the candidates of a callback
(its own expressions and the values of the names it reads from its enclosing function) and the rule that
keeps a candidate."""
from __future__ import annotations

import json
from fractions import Fraction
from pathlib import Path
from typing import Any

import pytest

from rclverify.diagnosis.rerun import (Endpoint, RerunError, RunLine, questions, read_run, recorded_answers,
                                       reproduces, rewritten)
from rclverify.diagnosis.run_repair import _kept, candidate_edits

LOG = Path(__file__).parent / "data" / "manipulator_charge_lt.jsonl"
TOPIC = Endpoint("topic", ("battery",), ("low",))
SERVICE = Endpoint("service", name="estop", ros_type="std_srvs/SetBool")


def _call(part: str, n: int, fields: dict[str, object]) -> RunLine:
    return RunLine.of({"topic": "rclverify/call", "kind": "call", "link": "estop", "part": part, "time": float(n),
                       "key": ["ev", "g", n], "fields": fields})


CALLS = [_call("request", 1, {"data": True}), _call("response", 1, {"success": True, "message": ""}),
         _call("request", 2, {"data": False}), _call("response", 2, {"success": True, "message": ""})]


def test_the_questions_and_answers_of_a_recorded_live_log() -> None:
    lines = read_run(LOG)
    asked = questions(lines, TOPIC)
    assert [round(q["percentage"], 2) for q in asked] == [0.55, 0.21, 0.2, 0.19, 0.2, 0.35]
    # the defect (`<` at the float32 0.2): the two readings of exactly 0.2 were answered `false`
    assert [a["data"] for a in recorded_answers(lines, TOPIC)] == [False, False, False, True, False, False]
    assert questions(CALLS, SERVICE) == [{"data": True}, {"data": False}]


def test_a_rewritten_run_carries_the_rerun_answers_at_the_recorded_times() -> None:
    lines = read_run(LOG)
    new = [[{"topic": "low", "fields": {"data": p <= 0.2}}] for p in (0.55, 0.21, 0.2, 0.19, 0.2, 0.35)]
    out = rewritten(lines, TOPIC, new)
    lows = [x for x in out if x["topic"] == "low"]
    assert [x["data"] for x in lows] == [False, False, True, True, True, False]
    assert [x["time"] for x in lows] == [x.obj["time"] for x in lines if x.topic == "low"]
    assert not any(x["topic"] == "rclverify/verdict" for x in out)  # the live verdicts are judged again
    assert reproduces(lines, TOPIC, [[{"topic": "low", "fields": {"data": a["data"]}}]
                                     for a in recorded_answers(lines, TOPIC)])
    assert not reproduces(lines, TOPIC, new)  # control: other answers are not the recorded ones
    with pytest.raises(RerunError, match="answers 5 messages where 6 were recorded"):
        rewritten(lines, TOPIC, new[:5])


def test_a_service_response_is_replaced_by_its_own_call() -> None:
    out = rewritten(CALLS, SERVICE, [{"success": True, "message": ""}, {"success": False, "message": ""}])
    assert [x["fields"] for x in out if x["part"] == "response"] == [{"success": True, "message": ""},
                                                                     {"success": False, "message": ""}]
    assert reproduces(CALLS, SERVICE, [{"success": True, "message": ""}] * 2)
    assert not reproduces(CALLS, SERVICE, [{"success": True, "message": ""}, {"success": False, "message": ""}])


ROBOT = '''import rclpy


def build(defects):
    node = rclpy.node.Node("gov")
    cap = 1.2 if "cap" in defects else 1.0
    other = 7.5

    def govern(m):
        out = min(m.x, cap)
        pub.publish(out)
    node.create_subscription(object, "cmd_in", govern, 10)
    node.create_subscription(object, "dock", lambda m: dock.publish(m.data < other), 10)

    def estop(req, resp):
        resp.success = True if "estop" in defects else req.data
        n = defects.count("x")
        return resp
'''


def _edits(line: int, name: str, free: list[str], numbers: list[Fraction]) -> list[tuple[int, str]]:
    """Each candidate as (the line it edits, that line edited)."""
    return [(e.line, e.apply(ROBOT).splitlines()[e.line - 1].strip())
            for e in candidate_edits(ROBOT, "robot.py", line, name, free, numbers)]


def test_a_callbacks_candidates_reach_the_value_it_reads_from_its_enclosing_function() -> None:
    got = _edits(9, "govern", ["cap", "pub"], [Fraction(1)])
    assert (10, "out = max(m.x, cap)") in got  # the callback's own expression
    # the value `cap` is made with, put to the contract's number
    assert (6, 'cap = 1.0 if "cap" in defects else 1.0') in got
    assert got.index((10, "out = max(m.x, cap)")) < got.index((6, 'cap = 1.0 if "cap" in defects else 1.0'))
    assert not any(line == 7 for line, _ in got)  # control: `other` is not read by govern


def test_a_lambdas_candidates_and_a_truth_value_put_to_a_field_the_callback_reads() -> None:
    got = _edits(13, "<lambda>", ["dock", "other"], [])
    assert (13, 'node.create_subscription(object, "dock", lambda m: dock.publish(m.data <= other), 10)') in got
    assert (7, "other = 6.5") in got  # a number moved by one, where the value the lambda reads is made
    got = _edits(15, "estop", ["defects"], [])
    assert (16, 'resp.success = req.data if "estop" in defects else req.data') in got
    assert (16, 'resp.success = False if "estop" in defects else req.data') in got
    assert not any("defects.count" in text for _, text in got)  # control: only a parameter's fields
    assert _edits(99, "govern", [], []) == []  # control: no callback at that line


def test_a_candidate_is_kept_only_when_the_node_is_repaired_and_no_other_verdict_moves() -> None:
    before = {"A": ("failed", (("satisfied", 4), ("violated", 2))), "B": ("discharged", (("satisfied", 6),)),
              "A call deadlines": ("failed", (("false", 2), ("true", 4)))}
    fixed = {**before, "A": ("discharged", (("satisfied", 6), ("violated", 0))),
             "A call deadlines": ("discharged", (("false", 0), ("true", 6)))}
    assert _kept("A", before, fixed)
    assert not _kept("A", before, {**fixed, "B": ("discharged", (("satisfied", 5),))})  # another node moved
    assert not _kept("A", before, {**fixed, "A call deadlines": ("failed", (("false", 1), ("true", 5)))})
    assert not _kept("B", before, before)  # a node with nothing failed is not repaired
    assert json.dumps(sorted(fixed)) == json.dumps(sorted(before))


CHARGE_WS = Path(__file__).parent / "data" / "charge_ws"


def test_the_report_asks_the_rerun_only_of_an_entry_naming_its_implementation_and_says_why_not() -> None:
    """diagnosis/monitor_repair.py before any ROS 2 is started: no implementation named, nothing asked and
    nothing said (the control); named without a ROS 2 Python, or on a bag, one sentence why none is searched."""
    from rclverify.app.pipeline import Workspace
    from rclverify.backends.monitors.payload import MonitorsPayload
    from rclverify.diagnosis.monitor_repair import MonitorRepairs, entry_of, monitor_repairs
    ws = Workspace(CHARGE_WS)
    data = {"entry": 0, "trace": "runs/charge.jsonl", "mapping": "contracts/mapping.yaml"}
    assert monitor_repairs(ws, "ChargeMonitor", data, MonitorsPayload(), Path("python3")) == MonitorRepairs()
    named = {**data, "implementation": "charge.py:build"}
    got = monitor_repairs(ws, "ChargeMonitor", named, MonitorsPayload(), None)
    assert got.repairs == [] and got.why.startswith("no repair is searched: re-running charge.py:build needs a "
                                                    "Python with rclpy")
    bag = monitor_repairs(ws, "ChargeMonitor", {**named, "trace": "runs/charge.mcap"}, MonitorsPayload(),
                          Path("python3"))
    assert "runs/charge.mcap is not a JSON-lines log" in bag.why
    entry = entry_of(ws, "ChargeMonitor", data)
    assert entry is not None and entry.config["implementation"] == "charge.py:build"
    assert entry_of(ws, "ChargeMonitor", {"entry": 5, "trace": "runs/other.jsonl"}) is None


def test_a_call_violation_is_told_from_a_topic_violation() -> None:
    """The payload as the monitors backend writes it: the first violation in ``monitoring``, the calls'
    own in the ``calls`` part beside it (a real run's: tests/backends/test_log_calls.py)."""
    from rclverify.backends.monitors.payload import monitors_payload
    from rclverify.diagnosis.monitor_repair import is_call_violation
    fv = {"where": "run.jsonl:4", "guarantee": 1}

    def payload(details: dict[str, object]) -> Any:
        p = monitors_payload("monitors", details)
        assert p is not None
        return p
    assert is_call_violation(payload({"monitoring": {"first_violation": fv}, "calls": {"first_violation": dict(fv)}}))
    assert not is_call_violation(payload({"monitoring": {"first_violation": fv}, "calls": {"counts": {}}}))
    assert not is_call_violation(payload({"monitoring": {"first_violation": fv}}))
    # calls inside the monitoring part (where the report's evidence row holds the run) is no payload's shape
    assert monitors_payload("monitors", {"monitoring": {"first_violation": fv, "calls": {}}}) is None


@pytest.mark.parametrize("value, said", [
    ("charge.py:nope", "contracts/plan.yaml:13:25: error: implementation charge.py defines no top-level function 'nope'"),
    ("charge.py", "13:25: error: implementation is '<file>.py:<function>', the function that makes the robot's rclpy nodes"),
])
def test_an_implementation_naming_no_function_of_a_python_file_is_a_located_plan_error(
        tmp_path: Path, value: str, said: str) -> None:
    import shutil

    from rclverify.app.pipeline import Workspace
    from rclverify.backends.monitors.backend import MonitorsBackend
    from rclverify.lang.errors import RclError
    work = tmp_path / "ws"
    shutil.copytree(CHARGE_WS, work)
    plan = work / "contracts/plan.yaml"
    plan.write_text(plan.read_text(encoding="utf-8").replace("charge.py:build", value), encoding="utf-8")
    with pytest.raises(RclError) as err:
        MonitorsBackend().export(Workspace(work).target("ChargeMonitor", 0))
    assert said in str(err.value)
    plan.write_text(plan.read_text(encoding="utf-8").replace(value, "charge.py:build"), encoding="utf-8")
    [ob] = MonitorsBackend().export(Workspace(work).target("ChargeMonitor", 0))  # the control: as named
    assert ob.data["implementation"] == "charge.py:build" and "charge.py" in ob.inputs
