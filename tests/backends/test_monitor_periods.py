"""Periodic outputs on recorded runs (issue 40, backends/monitors/periods.py):
a gap longer than the declared period fails the monitors' evidence with its
stamps, a run that stops refreshing the output before it ends too, a
regular run does not (not even where float stamps make 1.3 - 1.2 exceed
0.1), and a run without the output checks nothing."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from rclverify.backends.monitors.periods import check_periods, has_periods, period_status
from rclverify.cli.commands import main
from rclverify.lang.typecheck import check
from rclverify.lang.parser import parse_text
from rclverify.traces.events import Event

RCL = """node Watchdog {
  inputs( age : REAL )
  outputs( beat : BOOL )
  topics( std_msgs/Float64 age matches(in.age), std_msgs/Bool heartbeat matches(out.beat) )
  assume( in.age >= 0 )
  guarantee( out.beat == (in.age <= 1) )
  periodic( out.beat, 100 ms )
}
"""


def _node():  # type: ignore[no-untyped-def]
    return check([parse_text(RCL, "w.rcl")]).nodes["Watchdog"]


def _events(beats: list[float], end: float | None = None) -> list[Event]:
    out = []
    for t in beats:
        out.append(Event(len(out), t - 0.01, "age", {"data": 0.5}, f"run.jsonl:{len(out) + 1}"))
        out.append(Event(len(out), t, "heartbeat", {"data": True}, f"run.jsonl:{len(out) + 1}"))
    if end is not None:
        out.append(Event(len(out), end, "age", {"data": 0.5}, f"run.jsonl:{len(out) + 1}"))
    return out


@pytest.mark.parametrize("beats, end, status, words", [
    ([1.0, 1.1, 1.2, 1.3, 1.4, 1.5, 1.6, 1.7], None, "discharged", "8 messages, no gap over 100 ms"),
    ([0.0, 0.1, 0.2, 0.45, 0.5], None, "failed", "a message at 0.200 s has the next at 0.450 s (run.jsonl:8): a gap of 250 ms"),
    ([0.0, 0.1, 0.2], 0.9, "failed", "none after it although run goes on to 0.900 s: a gap of 700 ms"),
    ([], 2.0, "pending", "has no message of Watchdog.out.beat"),
], ids=["regular", "gap", "stops", "silent"])
def test_periods_on_a_run(beats: list[float], end: float | None, status: str, words: str) -> None:
    node = _node()
    assert has_periods(node)
    res = check_periods(node, _events(beats, end))
    got, text = period_status(res, "run")
    assert got == status and words in text, text


def test_a_late_heartbeat_fails_the_monitors_evidence(tmp_path: Path) -> None:
    ws = tmp_path / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "traces").mkdir()
    (ws / "contracts/w.rcl").write_text(RCL)
    rows = []
    for t in (0.0, 0.1, 0.2, 0.45, 0.5):
        rows += [{"topic": "age", "time": t - 0.01, "data": 0.5}, {"topic": "heartbeat", "time": t, "data": True}]
    (ws / "traces/late.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    (ws / "contracts/plan.yaml").write_text("contracts: [contracts/w.rcl]\nnodes:\n  Watchdog:\n    evidence:\n"
                                            "      - backend: monitors\n        traces: [traces/late.jsonl]\n")
    assert main(["verify", "-w", str(ws)]) == 0
    ev = json.loads((ws / "artifacts/evidence/Watchdog.g0.monitors.late_jsonl.json").read_text())
    assert ev["status"] == "failed" and "gap of 250 ms" in ev["explanation"]
    assert ev["details"]["periods"]["late"]["out.beat"]["to"] == pytest.approx(0.45)
