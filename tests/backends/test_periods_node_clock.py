"""A stamped output's ``periodic( out.x, P ms )`` judged in the clock of the node that stamps it
(backends/monitors/periods.py, "The node's clock"; docs/monitors.md "Periodic outputs").

A sensor on a simulated ``/clock`` stamps its readings in simulated time, which the judge sets aside
(another clock) and places each message at its source time.  Its period is judged on the stamps it
set aside, the run's end carried into its clock at its measured rate: at a real-time factor of 2, a
sensor publishing every 250 ms of the wall clock publishes every 500 ms of its own, so a gap of 550 ms
of the wall clock (1,100 ms of its clock) breaks a period of 800 ms (the control: judged on the wall
clock it would hold), and at a factor of 0.5 a gap of 600 ms of the wall clock (300 ms of its own)
keeps a period of 400 ms (judged on the wall clock it would be a false red).  The run is judged as a
bag gives it (the raw simulated stamps) and as the live monitor logs it (the stamps set aside), alike;
a driver stamping 2 s behind (rate 1) keeps its period, and a run going on past a period of the
node's clock after its last message, carried at its measured rate, is not judged unless a later stamp
of its clock shows it (backends/monitors/periods.py: the clock may have slowed or paused)."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from rclverify.cli.commands import main
from rclverify.traces.event_time import with_stamp, without_stamp

RCL = """node Sensor0 {
  inputs(  )
  outputs( x : REAL )
  topics( sensor_msgs/Range s0 matches(out.x) )
  assume( TRUE )
  guarantee( 0 <= out.x and out.x <= 2 )
  periodic( out.x, PERIOD ms )
}

node Sensor2 {
  inputs(  )
  outputs( y : REAL )
  topics( sensor_msgs/Range s2 matches(out.y) )
  assume( TRUE )
  guarantee( 0 <= out.y and out.y <= 2 )
}

node Alarm1 {
  inputs( n : INTEGER )
  outputs( ok : BOOL )
  topics( std_msgs/UInt8 u1 matches(in.n), std_msgs/Bool a1 matches(out.ok) )
  assume( TRUE )
  guarantee( out.ok <=> (in.n >= 0) )
}
"""
MAPPING = "topics:\n  s0: {fields: [range]}\n  s2: {fields: [range]}\n  u1: {fields: [data]}\n  a1: {fields: [data]}\nhorizon: 1.0\n"
WALL0 = 1_764_000_000.0


def _stamp(s: float) -> dict[str, int]:
    ns = round(s * 1e9)
    return {"sec": ns // 10**9, "nanosec": ns % 10**9}


def _run(gaps_wall: list[float], rate: float, start: float, tail_wall: float, logged: bool,
         twin: bool = False) -> list[dict[str, Any]]:
    """A run of Sensor0 stamping in a clock ``start + rate * (wall - WALL0)`` s, its messages ``gaps_wall``
    apart on the wall clock, with an unstamped reading and answer every 100 ms beside it until ``tail_wall``
    s after its last message.  ``logged``: each stamp set aside as the live monitor logs it.  ``twin``:
    Sensor2 publishes 2 ms before each message of Sensor0 with the same stamp (one tick of a simulated
    clock), so Sensor0's message is placed as a copy of Sensor2's, its stamp carried into the run's clock."""
    rows: list[dict[str, Any]] = []
    t = WALL0 + 0.05
    times = [t]
    for g in gaps_wall:
        t += g
        times.append(t)
    for k, w in enumerate(times):
        fields: dict[str, Any] = {"header": {"stamp": _stamp(start + rate * (w - WALL0)), "frame_id": "sonar"},
                                  "range": 1.0}
        if twin:
            rows.append({"topic": "s2", "time": w - 0.002, **(without_stamp(fields) if logged else fields)})
        placed = with_stamp(fields, w - 0.002) if twin else without_stamp(fields)
        rows.append({"topic": "s0", "time": w, **(placed if logged else fields)})
    end = times[-1] + tail_wall
    u = WALL0
    while u <= end:
        rows += [{"topic": "u1", "time": u, "data": 3}, {"topic": "a1", "time": u + 0.01, "data": True}]
        u += 0.1
    return sorted(rows, key=lambda r: float(r["time"]))


def _judge(tmp_path: Path, period_ms: int, rows: list[dict[str, Any]],
           capsys: pytest.CaptureFixture[str]) -> dict[str, Any]:
    ws = tmp_path / "ws"
    (ws / "contracts").mkdir(parents=True, exist_ok=True)
    (ws / "contracts/r.rcl").write_text(RCL.replace("PERIOD", str(period_ms)))
    (ws / "contracts/plan.yaml").write_text("contracts: [contracts/r.rcl]\n")
    (ws / "mapping.yaml").write_text(MAPPING)
    (ws / "run.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    capsys.readouterr()
    main(["monitor", "-w", str(ws), "--mapping", "mapping.yaml", "--horizon", "1.0", "--json", str(ws / "run.jsonl")])
    out = json.loads(capsys.readouterr().out)
    row = next(d for r in out if r["node"] == "Sensor0" for d in r.get("declarations", []))
    assert row["declaration"] == "periodic out.x"
    return dict(row)


REGULAR = [0.25] * 30


@pytest.mark.parametrize("logged", [False, True], ids=["raw stamps (a bag)", "stamps set aside (the live log)"])
@pytest.mark.parametrize("gaps, rate, start, period_ms, tail, verdict, words", [
    (REGULAR, 2.0, 100.0, 800, 0.2, "true", "31 messages, no gap over 800 ms (in the node's clock"),
    (REGULAR[:10] + [0.55] + REGULAR[10:], 2.0, 100.0, 800, 0.2, "false", "a gap of 1100 ms"),
    ([0.25, 0.6] * 12, 0.5, 5000.0, 400, 0.2, "true", "no gap over 400 ms"),
    ([0.25, 0.9] * 12, 0.5, 5000.0, 400, 0.2, "false", "a gap of 450 ms"),
    # no later stamp of its clock shows it got past the period: it may have slowed or paused (false with one:
    # tests/backends/test_periods_clock_rate_change.py)
    (REGULAR, 2.0, 0.0, 800, 0.5, "inconclusive", "it may have slowed or paused"),
    (REGULAR, 2.0, 0.0, 800, 0.3, "true", "no gap over 800 ms"),
], ids=["x2 regular", "x2 skip (wall 550 ms)", "x0.5 600 ms of the wall", "x0.5 900 ms of the wall",
        "x2 stops 500 ms before the end", "x2 stops 300 ms before the end"])
def test_a_simulated_clock_period_is_judged_in_the_nodes_clock(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], logged: bool, gaps: list[float], rate: float,
        start: float, period_ms: int, tail: float, verdict: str, words: str) -> None:
    row = _judge(tmp_path, period_ms, _run(gaps, rate, start, tail, logged), capsys)
    assert row["verdict"] == verdict and words in row["reason"], row


def test_a_drivers_offset_leaves_the_period_as_the_wall_clock_shows_it(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A driver 2 s behind (another clock, rate 1): its gaps and its tail are the wall clock's, never
    the 2 s between its last stamp and the run's end (the control: the same run with a period its tail
    of 350-450 ms breaks)."""
    rows = _run(REGULAR, 1.0, WALL0 - 2.0, 0.45, False)
    assert _judge(tmp_path, 600, rows, capsys)["verdict"] == "true"
    assert _judge(tmp_path, 300, rows, capsys)["verdict"] == "false"


@pytest.mark.parametrize("logged", [False, True], ids=["raw stamps (a bag)", "stamps placed (the live log)"])
def test_a_sensor_stamping_alike_with_another_keeps_its_clock(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], logged: bool) -> None:
    """Two sensors on one simulated clock stamp alike within one of its ticks; the second's message is
    placed as a copy of the first's, its stamp carried into the run's clock (traces/event_time.py,
    ``CopiedStamps``), and its own stamp is still the one its period is judged on (generated seed 952,
    ``/clock`` x2 from 0 s: a gap of 1,795,903,192 s between a simulated and a wall-clock stamp).  The
    control: the same run with a skip of 550 ms of the wall clock is ``false``."""
    row = _judge(tmp_path, 800, _run(REGULAR, 2.0, 0.0, 0.2, logged, twin=True), capsys)
    assert row["verdict"] == "true" and "no gap over 800 ms (in the node's clock" in row["reason"], row
    row = _judge(tmp_path, 800, _run(REGULAR[:10] + [0.55] + REGULAR[10:], 2.0, 0.0, 0.2, logged, twin=True), capsys)
    assert row["verdict"] == "false" and "a gap of 1100 ms" in row["reason"], row
