"""A stamped output's ``periodic( out.x, P ms )`` on a simulated ``/clock`` whose real-time factor
changes mid-run or which pauses (backends/monitors/periods.py, "A simulated clock may change its rate or
pause"; docs/semantics.md, "Event time").

Sensor0 publishes on its simulated timer (every 500 ms of its clock, declared periodic every 800 ms), its
stamps set aside in another clock; the run's end comes after its last message.  Its gaps are judged on
its stamps whatever the factor; its tail, after its last message, is not measured by anything it
carries.  The tail is carried from the latest stamp of that clock heard after it (Sensor2 publishing
every 100 ms of the wall clock in the same clock, stamped as it publishes): the clock falling from x2 to
x0.5 after the last message leaves it 0.45 s of its time (``true``; at x2 throughout, 1.8 s: ``false``,
the control), a pause leaves it none (``true``).  Without a later stamp the tail carried at the rate
measured is over the period and cannot be told from a clock that slowed or paused: ``inconclusive``,
never ``false`` (it was ``false``: a violation made by an assumed rate).  The runs are judged as a bag
gives them (raw simulated stamps) and as the live monitor logs them (the stamps set aside), alike."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Callable

import pytest

from rclverify.cli.commands import main
from rclverify.traces.event_time import without_stamp

from test_periods_node_clock import MAPPING, RCL as _RCL, WALL0  # the same three nodes: one workspace

RCL = _RCL.replace("PERIOD", "800")
START = 100.0


def _clock(segments: list[tuple[float, float]]) -> Callable[[float], float]:
    """The simulated time (s) at wall-clock ``w``: ``START`` at ``WALL0``, then each segment's factor
    from its wall-clock second after ``WALL0`` (0: paused)."""
    def sim(w: float) -> float:
        s, at, r = START, 0.0, segments[0][1]
        for seg_at, seg_rate in segments[1:]:
            if WALL0 + seg_at >= w:
                break
            s, at, r = s + r * (seg_at - at), seg_at, seg_rate
        return s + r * (w - WALL0 - at)
    return sim


def _wall(sim: Callable[[float], float], target: float) -> float:
    """The first wall-clock time (s, to the microsecond) at which ``sim`` reaches ``target``."""
    lo, hi = WALL0, WALL0 + 100.0
    while hi - lo > 1e-6:
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if sim(mid) < target else (lo, mid)
    return hi


def _stamp(s: float) -> dict[str, int]:
    ns = round(s * 1e9)
    return {"sec": ns // 10**9, "nanosec": ns % 10**9}


def _run(segments: list[tuple[float, float]], last_sim: float, end_wall: float, beside: bool, logged: bool,
         sim_gaps: list[float] | None = None) -> list[dict[str, Any]]:
    """Sensor0 on its simulated timer, every 500 ms of its clock (or ``sim_gaps`` apart) from 0.05 s after
    ``START`` until ``START + last_sim``; unstamped readings and answers every 100 ms of the wall clock
    until ``end_wall`` s after ``WALL0``; with ``beside``, Sensor2 every 100 ms of the wall clock too,
    stamped in the same clock (it publishes through a pause, its stamps standing still)."""
    sim = _clock(segments)
    rows: list[dict[str, Any]] = []

    def stamped(topic: str, w: float) -> None:
        fields: dict[str, Any] = {"header": {"stamp": _stamp(sim(w)), "frame_id": "sonar"}, "range": 1.0}
        rows.append({"topic": topic, "time": w, **(without_stamp(fields) if logged else fields)})
    due, k = START + 0.05, 0
    while due <= START + last_sim + 1e-9:
        stamped("s0", _wall(sim, due))
        due += sim_gaps[k % len(sim_gaps)] if sim_gaps else 0.5
        k += 1
    u = WALL0
    while u <= WALL0 + end_wall + 1e-9:
        rows += [{"topic": "u1", "time": u, "data": 3}, {"topic": "a1", "time": u + 0.01, "data": True}]
        if beside:
            stamped("s2", u + 0.005)
        u += 0.1
    return sorted(rows, key=lambda r: float(r["time"]))


def _judge(tmp_path: Path, rows: list[dict[str, Any]], capsys: pytest.CaptureFixture[str]) -> dict[str, Any]:
    ws = tmp_path / "ws"
    (ws / "contracts").mkdir(parents=True, exist_ok=True)
    (ws / "contracts/r.rcl").write_text(RCL)
    (ws / "contracts/plan.yaml").write_text("contracts: [contracts/r.rcl]\n")
    (ws / "mapping.yaml").write_text(MAPPING)
    (ws / "run.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    capsys.readouterr()
    main(["monitor", "-w", str(ws), "--mapping", "mapping.yaml", "--horizon", "1.0", "--json", str(ws / "run.jsonl")])
    out = json.loads(capsys.readouterr().out)
    row = next(d for r in out if r["node"] == "Sensor0" for d in r.get("declarations", []))
    assert row["declaration"] == "periodic out.x"
    periods = next(r for r in out if r["node"] == "Sensor0" and "periods" in r)
    return {**row, "status": periods["status"]}


#: x2 for the first 5 s of the wall clock, then x0.5 (the sensor's last message at 10.05 s of its clock, 5.1 s of the
#: wall clock; its next would be 1 s of the wall clock later, after the run's end at 5.9 s: 0.4 s of its clock)
DROP = [(0.0, 2.0), (5.0, 0.5)]
#: x1 until 5 s, then paused to the run's end
PAUSE = [(0.0, 1.0), (5.0, 0.0)]
LOGGED = pytest.mark.parametrize("logged", [False, True], ids=["raw stamps (a bag)", "stamps set aside (the live log)"])


@LOGGED
@pytest.mark.parametrize("segments, last_sim, end_wall, beside, verdict, words", [
    (DROP, 10.05, 5.9, True, "true", "no gap over 800 ms"),
    ([(0.0, 2.0)], 10.05, 5.9, True, "false", "until the run's end, over the period of 800 ms"),
    (DROP, 10.05, 5.9, False, "inconclusive", "it may have slowed or paused"),
    (PAUSE, 4.95, 6.5, True, "true", "no gap over 800 ms"),
    (PAUSE, 4.95, 6.5, False, "inconclusive", "it may have slowed or paused"),
], ids=["x2 to x0.5 after the last message, the clock heard", "x2 throughout (control)",
        "x2 to x0.5, no later stamp", "paused after the last message, the clock heard", "paused, no later stamp"])
def test_a_tail_after_a_rate_change_or_a_pause_is_never_red_unless_the_clock_shows_it(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], logged: bool, segments: list[tuple[float, float]],
        last_sim: float, end_wall: float, beside: bool, verdict: str, words: str) -> None:
    row = _judge(tmp_path, _run(segments, last_sim, end_wall, beside, logged), capsys)
    assert row["verdict"] == verdict and words in row["reason"], row
    assert row["status"] == {"true": "discharged", "false": "failed", "inconclusive": "inconclusive"}[verdict], row


@LOGGED
@pytest.mark.parametrize("sim_gaps, verdict", [([0.5] * 6 + [0.7], "true"), ([0.5] * 6 + [0.9], "false")],
                         ids=["700 ms of its clock across the drop (1.05 s of the wall)", "900 ms (control)"])
def test_gaps_across_a_rate_change_are_its_clocks(tmp_path: Path, capsys: pytest.CaptureFixture[str], logged: bool,
                                                  sim_gaps: list[float], verdict: str) -> None:
    """Gaps are measured on the stamps whatever the factor: across the drop from x2 to x0.5, 700 ms of its
    clock take over a second of the wall clock and keep the period; 900 ms break it."""
    rows = _run([(0.0, 2.0), (2.0, 0.5)], 5.9, 6.0, True, logged, sim_gaps)
    row = _judge(tmp_path, rows, capsys)
    assert row["verdict"] == verdict, row
