"""Deadlines of timed guarantees checked offline against message stamps
(issue 33): verdicts true / currently_false / false, header stamps as the
clock, service calls and actionlib topics, and the monitors' evidence."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from rclverify.backends.monitors.deadline_text import deadline_status
from rclverify.backends.monitors.deadlines import DeadlineMonitor, check_deadlines
from rclverify.cli.commands import main
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.traces import read_trace
from rclverify.traces.events import Event

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "examples" / "safety_stop"


@pytest.fixture(scope="module")
def checked():  # type: ignore[no-untyped-def]
    return check([parse_text((EXAMPLE / "contracts" / "safety_stop.rcl").read_text(), "s.rcl")])


def _ev(i: int, topic: str, t: float, stamp: float | None = None, **fields: object) -> Event:
    if stamp is not None:
        secs = int(stamp)
        fields["header"] = {"stamp": {"secs": secs, "nsecs": round((stamp - secs) * 1e9)}}
    return Event(i, t, topic, fields, f"run:{i + 1}")


def test_the_late_service_response_is_false_with_the_calls_stamps(checked) -> None:  # type: ignore[no-untyped-def]
    seen = []
    res = check_deadlines(checked, [checked.nodes["Base"], checked.nodes["Mover"]],
                          read_trace(EXAMPLE / "traces" / "late_stop.jsonl"), {}, seen.append)
    base, mover = res
    assert base.counts == {"true": 1, "currently_false": 0, "false": 1}
    f = base.first_false
    assert f is not None and (f.guarantee, f.trigger_stamp, f.due, f.answer) == (1, 3.0, 3.2, 3.35)
    assert f.trigger_where.endswith("late_stop.jsonl:4") and f.answer_where.endswith("late_stop.jsonl:5")
    assert f.reason == "answered after 350 ms, 150 ms past the deadline of 200 ms"
    # the action: two goals answered by feedback in time, the third's feedback fails the formula
    # (progress -1) and the run ends before its 2 s expire
    assert mover.counts == {"true": 2, "currently_false": 1, "false": 0}
    assert [v.verdict for v in seen if v.node == "Mover"] == ["true", "true", "currently_false"]
    status, text = deadline_status(base, "late_stop.jsonl")
    assert status == "failed" and "due 3.200 s, answered at 3.350 s" in text


def test_header_stamps_are_the_clock_not_the_receipt_time(checked) -> None:  # type: ignore[no-untyped-def]
    base = checked.nodes["Base"]
    # received 10 ms apart, but stamped 300 ms apart: late by the stamps
    late = [_ev(0, "estop/request", 5.00, 1.0, data=True), _ev(1, "estop/response", 5.01, 1.3, success=True)]
    assert check_deadlines(checked, [base], late, {})[0].counts["false"] == 1
    # no header: the trace's time is the clock
    plain = [_ev(0, "estop/request", 1.0, data=True), _ev(1, "estop/response", 1.15, success=True)]
    assert check_deadlines(checked, [base], plain, {})[0].counts == {"true": 1, "currently_false": 0, "false": 0}


def test_currently_false_until_the_deadline_expires_then_false(checked) -> None:  # type: ignore[no-untyped-def]
    got = []
    m = DeadlineMonitor(checked, checked.nodes["Base"], {}, got.append)
    m.feed(_ev(0, "/estop/request", 10.0, 10.0, data=True))
    m.advance(10.15)
    assert [(v.verdict, v.trigger_stamp, v.due) for v in m.pending_verdicts()] == [("currently_false", 10.0, 10.2)]
    assert got == []
    m.advance(10.25)  # a live monitor's timer: expired with no answer
    assert m.pending_verdicts() == [] and [(v.verdict, v.answer) for v in got] == [("false", None)]
    assert got[0].reason.startswith("no answer within the deadline of 200 ms")


def test_an_answer_that_breaks_the_formula_does_not_count(checked) -> None:  # type: ignore[no-untyped-def]
    mover = checked.nodes["Mover"]
    evs = [_ev(0, "move/goal", 0.0, goal={"target": 1.0}), _ev(1, "move/feedback", 0.5, feedback={"progress": -2.0}),
           _ev(2, "move/feedback", 2.5, feedback={"progress": 0.5})]
    r = check_deadlines(checked, [mover], evs, {})[0]
    assert r.counts["false"] == 1 and r.first_false is not None and r.first_false.answer == 2.5


def _copy(tmp_path: Path) -> Path:
    ws = tmp_path / "ws"
    shutil.copytree(EXAMPLE, ws, ignore=shutil.ignore_patterns("artifacts", "reports", "__pycache__"))
    return ws


def test_monitor_command_reports_the_deadlines(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ws = _copy(tmp_path)
    assert main(["monitor", "-w", str(ws), str(ws / "traces" / "late_stop.jsonl")]) == 1
    out = capsys.readouterr().out
    assert "Base deadlines: 1 true, 1 false" in out
    assert "Mover deadlines: 2 true, 1 currently_false" in out
    assert main(["monitor", "-w", str(ws), str(ws / "traces" / "nominal.jsonl")]) == 0


def test_monitors_evidence_carries_the_deadlines(tmp_path: Path) -> None:
    ws = _copy(tmp_path)
    plan = ws / "contracts" / "plan.yaml"
    plan.write_text(plan.read_text().replace("traces: [traces/nominal.jsonl]\n  Mover",
                                             "traces: [traces/late_stop.jsonl]\n  Mover"))
    main(["verify", "-w", str(ws)])
    base = json.loads((ws / "artifacts" / "evidence" / "Base.g0.monitors.late_stop_jsonl.json").read_text())
    assert base["status"] == "failed"
    assert base["explanation"].startswith("deadlines: 1 trigger event(s) of traces/late_stop.jsonl missed Base's "
                                          "deadline; the first: guarantee 1")
    assert base["details"]["deadlines"]["first_false"]["answer"] == 3.35
    mover = json.loads((ws / "artifacts" / "evidence" / "Mover.g0.monitors.nominal_jsonl.json").read_text())
    # the action's goal, feedback and result are the untimed check's events too (issue 40): the goal is
    # answered by the feedback and the result, each judged (issue 47), so guarantee 2 (untimed) is checked
    # on both and holds
    assert mover["status"] == "discharged" and mover["details"]["deadlines"]["counts"]["true"] == 1
    assert mover["details"]["monitoring"]["counts"]["satisfied"] == 2


def test_a_trigger_without_deadline_is_bounded_by_the_horizon() -> None:
    text = """node Echo {
  inputs( x : REAL )
  outputs( y : REAL )
  topics( std_msgs/Float64 x matches(in.x), std_msgs/Float64 y matches(out.y) )
  guarantee( out.y == in.x ) triggered by in.x
}"""
    checked = check([parse_text(text, "e.rcl")])
    echo = checked.nodes["Echo"]
    evs = [_ev(0, "x", 0.0, data=1.0), _ev(1, "y", 0.4, data=1.0), _ev(2, "x", 1.0, data=2.0), _ev(3, "y", 3.0, data=2.0)]
    r = check_deadlines(checked, [echo], evs, {}, horizon=1.0)[0]
    assert r.counts == {"true": 1, "currently_false": 0, "false": 1}
    assert r.first_false is not None and r.first_false.answer == 3.0
    assert check_deadlines(checked, [echo], evs, {})[0].counts["true"] == 0  # no horizon: not checked
