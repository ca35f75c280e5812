"""Periods kept in simulated time (backends/monitors/period_clock.py, periods.py; docs/semantics.md,
"Deadlines in simulated time").  An unstamped output of a node said to keep ``/clock`` time is judged
on ``/clock``: at a real-time factor of 0.5, messages 150 ms apart on the wall clock are 75 ms of
simulated time, within a 100 ms period; at a factor of 2, 80 ms apart are 160 ms, over it.  Controls:
the same runs with the node said to keep the run's clock.  A node whose clock is not said is decided
only where both clocks agree.  A paused clock makes no tail late; a stamped output's tail is read from
``/clock`` (late where ``/clock`` shows the node's clock went past the period with no message).  An
oracle: on random runs the verdict equals the rule enumerated over every delivery delay of ``/clock``
to the node within the transport skew, for each message."""
from __future__ import annotations

import random
from typing import Any

import pytest

from rclverify.backends.monitors.periods import PeriodMonitor, PeriodResult, period_status
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.traces.event_time import without_stamp
from rclverify.traces.events import Event
from rclverify.traces.mapping import load_rules

RCL = """node Beat {
  inputs(  )
  outputs( x : REAL )
  topics( std_msgs/Float32 beat matches(out.x) )
  assume( TRUE )
  guarantee( TRUE )
  periodic( out.x, 100 ms )
}
"""
NODE = check([parse_text(RCL, "beat.rcl")]).nodes["Beat"]
WALL0 = 1_764_000_000.0


def _rules(sim: Any, skew: float = 0.0) -> Any:
    rules = load_rules({"beat": {"fields": ["data"]}})
    rules.skew, rules.sim_time = skew, sim
    return rules


def _clock(t_ms: int, value_ms: int) -> Event:
    ns = value_ms * 1_000_000
    return Event(0, WALL0 + t_ms / 1000, "/clock", {"clock": {"sec": ns // 10**9, "nanosec": ns % 10**9}}, "c")


def _beat(t_ms: int, stamp_ms: int | None = None) -> Event:
    fields: dict[str, Any] = {"data": 1.0}
    if stamp_ms is not None:  # stamped on /clock, set aside as the engine places it (event_time.py)
        ns = stamp_ms * 1_000_000
        fields = without_stamp({"header": {"stamp": {"sec": ns // 10**9, "nanosec": ns % 10**9}}, "data": 1.0})
    return Event(0, WALL0 + t_ms / 1000, "beat", fields, f"beat at {t_ms} ms")


def _run(rate: float, every_ms: int, stop_ms: int, end_ms: int, pause: tuple[int, int] | None = None,
         stamped: bool = False) -> list[Event]:
    """``/clock`` every 10 ms at factor ``rate`` (standing over ``pause``), a beat every ``every_ms`` from
    20 ms until ``stop_ms`` (stamped with /clock's value when ``stamped``), the run to ``end_ms``."""
    rows: list[tuple[int, int, Event]] = []
    value, values = 0.0, {}
    for t in range(0, end_ms + 1, 10):
        if t and not (pause and pause[0] <= t < pause[1]):
            value += 10 * rate
        values[t] = round(value)
        rows.append((t, 0, _clock(t, round(value))))
    for t in range(20, stop_ms + 1, every_ms):
        rows.append((t, 1, _beat(t, values[t - t % 10] if stamped else None)))
    rows.sort(key=lambda r: (r[0], r[1]))
    return [e for _, _, e in rows]


def _judge(run: list[Event], sim: Any, skew: float = 0.0) -> tuple[str, PeriodResult]:
    mon = PeriodMonitor(NODE, _rules(sim, skew))
    for ev in run:
        mon.feed(ev)
    res = mon.finish()
    return period_status(res, "run")[0], res


def test_half_speed_beats_over_the_period_on_the_wall_clock_are_within_it_in_simulated_time() -> None:
    run = _run(0.5, 150, 900, 950)
    assert _judge(run, True)[0] == "discharged"
    assert _judge(run, False)[0] == "failed"  # control: the run's clock


def test_double_speed_beats_within_the_period_on_the_wall_clock_are_over_it_in_simulated_time() -> None:
    run = _run(2.0, 80, 900, 950)
    status, res = _judge(run, True)
    assert status == "failed" and res.late["out.x"]["gap"] == pytest.approx(0.16)
    assert _judge(run, False)[0] == "discharged"


def test_not_said_is_decided_only_where_both_clocks_agree() -> None:
    status, res = _judge(_run(0.5, 150, 900, 950), None)
    assert status == "inconclusive" and "use_sim_time" in res.undecided["out.x"]
    assert _judge(_run(0.5, 80, 900, 950), None)[0] == "discharged"
    assert _judge(_run(0.5, 250, 900, 950), None)[0] == "failed"  # 125 ms simulated, 250 ms wall


def test_a_paused_clock_makes_no_tail_late_and_a_running_one_does() -> None:
    assert _judge(_run(1.0, 50, 300, 2000, pause=(300, 5000)), True)[0] == "discharged"
    assert _judge(_run(1.0, 50, 300, 2000), True)[0] == "failed"  # control: /clock runs on


def test_a_stamped_outputs_tail_is_read_from_clock() -> None:
    # stamped on /clock at factor 0.5: the last beat at 420 ms, the run goes on 480 ms (240 ms simulated)
    status, res = _judge(_run(0.5, 100, 500, 900, stamped=True), None)
    assert status == "failed" and res.late["out.x"]["to"] is None
    # control: 140 ms on (70 ms simulated) leaves it within the period
    assert _judge(_run(0.5, 100, 500, 560, stamped=True), None)[0] == "discharged"


def _oracle(samples: list[tuple[int, int]], beats: list[int], end: int, skew: int, mode: bool | None) -> str:
    """Brute force (integer ms): each publication at t read /clock at t - delta, delta in [0, skew]."""
    def clock(t: int) -> int | None:
        got = [v for w, v in samples if w <= t]
        return got[-1] if got else None

    def verdict(t1: int, t2: int) -> str:
        gaps: set[int] = set()
        for d1 in range(skew + 1):
            for d2 in range(skew + 1):
                a, b = clock(t1 - d1), clock(t2 - d2)
                if a is None or b is None:
                    return "undecided"
                gaps.add(b - a)
        sim = "late" if min(gaps) > 100 else "ok" if max(gaps) <= 100 else "undecided"
        if mode is True:
            return sim
        wall = "late" if t2 - t1 > 100 else "ok"
        return sim if sim == wall else "undecided"
    first = samples[0][0]
    if mode is None and beats[0] < first:
        return "skip"  # judged on the run's clock until /clock is heard: not this oracle's case
    seen = []
    for t1, t2 in zip(beats, beats[1:] + [end]):
        v = verdict(t1, t2)
        if v == "late":
            return "failed"
        seen.append(v)
    return "inconclusive" if "undecided" in seen else "discharged"


@pytest.mark.parametrize("seed", range(10))
def test_oracle_random_runs_match_the_rule_enumerated(seed: int) -> None:
    rnd = random.Random(seed)
    checked = 0
    for case in range(40):
        samples, value = [], 0
        for t in sorted(rnd.sample(range(0, 600), rnd.randrange(2, 50))):
            value += rnd.choice((0, 0, 10, 20, 40, 80))
            samples.append((t, value))
        beats = sorted(rnd.sample(range(samples[0][0], 600), rnd.randrange(2, 12)))
        end = max(beats[-1], samples[-1][0]) + rnd.randrange(0, 150)
        skew, mode = rnd.choice((0, 2, 5)), rnd.choice((True, None))
        want = _oracle(samples, beats, end, skew, mode)
        if want == "skip":
            continue
        rows = [(w, 0, _clock(w, v)) for w, v in samples] + [(t, 1, _beat(t)) for t in beats]
        rows.append((end, 2, Event(0, WALL0 + end / 1000, "other", {"data": 0.0}, "end")))
        rows.sort(key=lambda r: (r[0], r[1]))
        got = _judge([e for _, _, e in rows], mode, skew / 1000)[0]
        assert got == want, (seed, case, samples, beats, end, skew, mode)
        checked += 1
    assert checked >= 30


def test_a_stamped_outputs_tail_over_a_pause_is_decided_from_clock() -> None:
    # /clock stands from 430 ms: the node's clock never went past the period after its last beat (420 ms)
    status, res = _judge(_run(0.5, 100, 500, 900, pause=(430, 5000), stamped=True), None)
    assert status == "discharged" and not res.unrated
    status, res = _judge(_run(0.5, 100, 500, 900, pause=(430, 5000), stamped=True), False)  # control: no /clock read
    assert status == "inconclusive" and res.unrated == ["out.x"]
