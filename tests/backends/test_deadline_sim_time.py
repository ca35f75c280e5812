"""Deadlines kept in simulated time (backends/monitors/deadline_clock.py; docs/semantics.md,
"Deadlines in simulated time").  A node said to keep ``/clock`` time (the mapping's ``use_sim_time``)
has its ``within d`` judged in simulated time: at a real-time factor of 0.5 an answer 150 ms after its
trigger on the wall clock is 75 ms of simulated time, in time for 100 ms; at a factor of 2 an answer 80 ms
after is 160 ms, late.  Controls: the same runs with the node said to keep the run's clock give the
opposite verdicts; a node whose clock is not said is decided only where both clocks agree, else
``undecided`` naming what decides it.  A paused clock gives no ``false``; a reset, or no ``/clock``
before a trigger of a node said to keep it, is ``undecided`` with why.  An oracle: on random small runs
(random ``/clock`` samples, pauses included, a trigger, an answer or none) the verdict equals the rule
enumerated over every delivery delay of ``/clock`` to the node within the transport skew."""
from __future__ import annotations

import random
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.batch_deadlines import deadline_monitor
from rclverify.backends.monitors.config import ConfigError, load_mapping
from rclverify.backends.monitors.fieldpaths import check_field_paths
from rclverify.backends.monitors.deadline_records import DeadlineVerdict
from rclverify.backends.monitors.deadlines import DeadlineMonitor
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.traces.events import Event
from rclverify.traces.mapping import load_rules, sim_time_of

RELAY = """
node Relay {
  inputs( x : REAL )
  outputs( r : REAL )
  topics( std_msgs/Float32 s matches(in.x), std_msgs/Float32 r matches(out.r) )
  guarantee( out.r == in.x ) triggered by in.x within 100 ms
}
"""
CHECKED = check([parse_text(RELAY, "relay.rcl")])
NODE = CHECKED.nodes["Relay"]


def _rules(sim: Any, skew: float = 0.0) -> Any:
    rules = load_rules({"s": {"fields": ["data"]}, "r": {"fields": ["data"]}})
    rules.skew = skew
    rules.sim_time = sim
    return rules


def _clock(i: int, t_ms: int, value_ms: int) -> Event:
    ns = value_ms * 1_000_000
    return Event(i, t_ms / 1000, "/clock", {"clock": {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}},
                 f"run:{i + 1}")


def _msg(i: int, t_ms: int, topic: str, value: float) -> Event:
    return Event(i, t_ms / 1000, topic, {"data": value}, f"run:{i + 1}")


def _run(rate: float, answer_ms: int | None, end_ms: int = 1000, start_ms: int = 0,
         pause: tuple[int, int] | None = None) -> list[Event]:
    """``/clock`` every 10 ms from ``start_ms`` at real-time factor ``rate`` (standing still over ``pause``,
    wall ms), a reading at 100 ms, the relay's answer at ``answer_ms`` (or none), the run's end at
    ``end_ms``; events in the run's order."""
    timed: list[tuple[int, int, Event]] = []
    value = 0.0
    for t in range(start_ms, end_ms + 1, 10):
        if not (pause and pause[0] <= t < pause[1]) and t > start_ms:
            value += 10 * rate
        timed.append((t, 0, _clock(0, t, round(value))))
    timed.append((100, 1, _msg(0, 100, "s", 1.0)))
    if answer_ms is not None:
        timed.append((answer_ms, 1, _msg(0, answer_ms, "r", 1.0)))
    timed.sort(key=lambda x: (x[0], x[1]))
    return [Event(i, e.time, e.topic, e.fields, f"run:{i + 1}") for i, (_, _, e) in enumerate(timed)]


def _judge(run: list[Event], sim: Any, skew: float = 0.0,
           monitor: Any = DeadlineMonitor) -> tuple[dict[str, int], dict[str, int], list[DeadlineVerdict]]:
    seen: list[DeadlineVerdict] = []
    mon = monitor(CHECKED, NODE, _rules(sim, skew), seen.append)
    for ev in run:
        mon.feed(ev)
    res = mon.finish()
    return res.counts, dict(res.unaccepted), seen


def test_half_speed_sim_time_an_answer_late_on_the_wall_clock_is_in_time_in_simulated_time() -> None:
    counts, _, seen = _judge(_run(0.5, 250), True)  # 150 ms wall = 75 ms simulated
    assert (counts["true"], counts["false"]) == (1, 0)
    assert "in simulated time (use_sim_time)" in seen[0].reason
    assert seen[0].time_margin == pytest.approx(0.025)  # 100 ms less the 75 ms /clock moved
    counts, _, _ = _judge(_run(0.5, 250), False)  # control: said to keep the run's clock
    assert (counts["true"], counts["false"]) == (0, 1)


def test_double_speed_sim_time_an_answer_in_time_on_the_wall_clock_is_late_in_simulated_time() -> None:
    counts, _, seen = _judge(_run(2.0, 180), True)  # 80 ms wall = 160 ms simulated
    assert (counts["true"], counts["false"]) == (0, 1)
    assert "deadline of 100 ms" in seen[0].reason and "/clock" in seen[0].reason
    counts, _, _ = _judge(_run(2.0, 180), False)  # control
    assert (counts["true"], counts["false"]) == (1, 0)


def test_unanswered_in_simulated_time_is_false_only_once_clock_passes_the_deadline() -> None:
    counts, _, _ = _judge(_run(0.5, None, end_ms=290), True)  # /clock at 95 ms simulated past the trigger
    assert counts["false"] == 0 and counts["currently_false"] == 1
    counts, _, _ = _judge(_run(0.5, None, end_ms=320), True)  # 110 ms simulated past: missed
    assert counts["false"] == 1
    counts, _, _ = _judge(_run(0.5, None, end_ms=290), False)  # control: 190 ms on the run's clock
    assert counts["false"] == 1


def test_a_paused_clock_gives_no_false() -> None:
    counts, _, _ = _judge(_run(1.0, None, end_ms=1000, pause=(120, 2000)), True)
    assert counts["false"] == 0 and counts["currently_false"] == 1
    counts, _, _ = _judge(_run(1.0, 900, end_ms=1000, pause=(120, 2000)), True)  # answered during the pause
    assert (counts["true"], counts["false"]) == (1, 0)
    counts, _, _ = _judge(_run(1.0, 900, end_ms=1000, pause=(120, 2000)), False)  # control
    assert counts["false"] == 1


def test_not_said_is_decided_only_where_both_clocks_agree() -> None:
    counts, unaccepted, seen = _judge(_run(0.5, 250), None)  # in time simulated, late on the wall clock
    assert (counts["true"], counts["false"], unaccepted["undecided"]) == (0, 0, 1)
    assert seen[0].verdict == "undecided" and "use_sim_time" in seen[0].reason
    assert _judge(_run(0.5, 150), None)[0]["true"] == 1  # in time in both
    assert _judge(_run(0.5, 350), None)[0]["false"] == 1  # 250 ms wall, 125 ms simulated: late in both
    # no /clock before the trigger: placed on the run's clock, never false once /clock is heard
    counts, unaccepted, seen = _judge(_run(0.5, 250, start_ms=150), None)
    assert (counts["false"], unaccepted["undecided"]) == (0, 1) and "before /clock was first heard" in seen[0].reason
    run = sorted([*_run(0.5, None, start_ms=400, end_ms=600), _msg(0, 300, "other", 0.0)], key=lambda e: e.time)
    counts, unaccepted, seen = _judge(run, None)  # false given at 300 ms on the run's clock, withdrawn at 400 ms
    assert (counts["false"], unaccepted["undecided"]) == (0, 1) and "the false given is withdrawn" in seen[-1].reason
    assert _judge(_run(0.5, 150, start_ms=150), None)[0]["true"] == 1  # in time on the run's clock
    assert _judge(_run(0.5, 250, start_ms=300), None)[0]["false"] == 1  # answered late before /clock: stands


def test_no_clock_before_the_trigger_of_a_node_said_to_keep_it_is_undecided() -> None:
    counts, unaccepted, seen = _judge(_run(1.0, 150, start_ms=150), True)
    assert (counts["true"], counts["false"], unaccepted["undecided"]) == (0, 0, 1)
    assert "no /clock message was heard before it" in seen[0].reason


def test_a_clock_reset_leaves_open_obligations_undecided() -> None:
    run = [_clock(0, 0, 5000), _msg(1, 100, "s", 1.0), _clock(2, 110, 5010), _clock(3, 120, 0),
           _clock(4, 400, 290)]
    counts, unaccepted, seen = _judge(run, True)
    assert counts["false"] == 0 and unaccepted["undecided"] == 1
    assert "went back" in seen[0].reason
    counts, _, _ = _judge(run, False)  # control: the run's clock
    assert counts["false"] == 1


def test_an_answer_within_the_skew_after_clock_passed_the_deadline_is_undecided() -> None:
    # factor 1: /clock passes 100 ms simulated past the trigger at wall 210 ms; the answer at 212 ms
    counts, unaccepted, seen = _judge(_run(1.0, 212), True, skew=0.005)
    assert unaccepted["undecided"] == 1 and "within the transport skew" in seen[0].reason
    assert _judge(_run(1.0, 216), True, skew=0.005)[0]["false"] == 1  # control: past the skew
    assert _judge(_run(1.0, 209), True, skew=0.005)[0]["true"] == 1


def _oracle(samples: list[tuple[int, int]], q: int, a: int | None, end: int, d: int, skew: int,
            mode: bool | None) -> str:
    """The verdict by enumeration (integer ms): the node's /clock read at wall time t with a delivery delay
    delta in [0, skew] is the value of the last sample at or before t - delta."""
    def clock(t: int) -> int | None:
        got = [v for (w, v) in samples if w <= t]
        return got[-1] if got else None
    sq = clock(q)
    if sq is None and mode is True:
        return "undecided"
    if sq is None and mode is None:  # placed on the run's clock; /clock first heard at `first`
        first = samples[0][0]
        if a is not None:
            return "true" if a <= q + d else "false" if a < first else "undecided"
        return "undecided" if end > q + d else "currently_false"
    sim_mode = mode is not False and sq is not None

    def sim_states(t: int) -> set[bool]:  # late in simulated time at t, for each delay
        assert sq is not None
        return {(v is not None and v > sq + d) for v in (clock(t - delta) for delta in range(skew + 1))}
    if a is not None:
        wall_late = a > q + d
        if not sim_mode:
            return "false" if wall_late else "true"
        late = sim_states(a)
        if mode is True:
            return "false" if late == {True} else "true" if late == {False} else "undecided"
        if late == {False} and not wall_late:
            return "true"
        if late == {True} and wall_late:
            return "false"
        return "undecided"
    wall_passed = end > q + d
    if not sim_mode:
        return "false" if wall_passed else "currently_false"
    passed = sim_states(end) == {True}
    return "false" if passed and (mode is True or wall_passed) else "currently_false"


@pytest.mark.parametrize("seed", range(12))
def test_oracle_random_runs_match_the_rule_enumerated(seed: int) -> None:
    rnd = random.Random(seed)
    for case in range(60):
        samples, value = [], rnd.randrange(0, 50)
        for t in sorted(rnd.sample(range(0, 700), rnd.randrange(1, 60))):
            value += rnd.choice((0, 0, 5, 10, 20, 40))
            samples.append((t, value))
        skew = rnd.choice((0, 2, 5))
        q = rnd.randrange(0, 300)
        a = rnd.choice((None, q + rnd.randrange(0, 250)))
        end = max(q, a or 0) + rnd.randrange(0, 200)
        mode = rnd.choice((True, False, None))
        timed = [(w, 0, _clock(0, w, v)) for w, v in samples] + [(q, 1, _msg(0, q, "s", 1.0))]
        if a is not None:
            timed.append((a, 2, _msg(0, a, "r", 1.0)))
        timed.append((end, 3, _msg(0, end, "other", 0.0)))
        timed.sort(key=lambda x: (x[0], x[1]))
        run = [Event(i, e.time, e.topic, e.fields, f"run:{i + 1}") for i, (_, _, e) in enumerate(timed)]
        counts, unaccepted, seen = _judge(run, mode, skew / 1000)
        got = ("undecided" if unaccepted["undecided"] else
               next((v for v in ("true", "false", "currently_false") if counts[v]), "none"))
        want = _oracle(samples, q, a, max(end, samples[-1][0]), 100, skew, mode)  # the run's last event
        assert got == want, (seed, case, samples, q, a, end, skew, mode, [v.reason for v in seen])


def test_the_batch_path_streams_a_run_with_clock_and_gives_the_same_verdicts() -> None:
    for sim in (True, None, False):
        for rate, answer in ((0.5, 250), (2.0, 180), (1.0, 150)):
            run = _run(rate, answer)
            assert _judge(run, sim, monitor=deadline_monitor) == _judge(run, sim)


def test_the_mapping_says_which_nodes_keep_simulated_time_and_refuses_a_bad_value(tmp_path: Path) -> None:
    (tmp_path / "m.yaml").write_text("topics: {}\n")
    assert sim_time_of(load_mapping(tmp_path, "m.yaml").rules, "Relay") is None  # not said
    (tmp_path / "m.yaml").write_text("topics: {}\nuse_sim_time: true\n")
    assert sim_time_of(load_mapping(tmp_path, "m.yaml").rules, "Relay") is True
    (tmp_path / "m.yaml").write_text("topics: {}\nuse_sim_time: [Planner]\n")
    rules = load_mapping(tmp_path, "m.yaml").rules
    assert (sim_time_of(rules, "Planner"), sim_time_of(rules, "Relay")) == (True, False)
    for bad in ("fast", "3", "[1, 2]", "{Relay: true}"):
        (tmp_path / "m.yaml").write_text(f"topics: {{}}\nuse_sim_time: {bad}\n")
        with pytest.raises(ConfigError, match=r"m\.yaml:2:15: error: use_sim_time must be true, false or a list"):
            load_mapping(tmp_path, "m.yaml")


def test_a_use_sim_time_name_that_is_no_contract_node_is_refused_where_it_is_written(tmp_path: Path) -> None:
    (tmp_path / "m.yaml").write_text("topics: {}\nuse_sim_time:\n  - Relay\n  - Realy\n")
    diags = check_field_paths(tmp_path, "m.yaml", [], CHECKED)
    assert [(d.loc.line, d.loc.col) for d in diags] == [(4, 5)] and "'Realy' is no contract node" in diags[0].message
    (tmp_path / "m.yaml").write_text("topics: {}\nuse_sim_time: [Relay]\n")  # control
    assert check_field_paths(tmp_path, "m.yaml", [], CHECKED) == []


def test_a_clock_message_heard_late_expires_what_it_shows_passed_at_the_clock() -> None:
    """Live, a ``/clock`` message heard after later messages were released comes at the engine's clock with
    its publication as its stamp (``Event.stamped``); the deadline it shows passed is ``false`` then, as
    the run read in stamp order gives it, not left ``currently_false``."""
    run = [e for e in _run(1.0, None, end_ms=190) if e.topic == "s" or e.time <= 0.15]
    late = _clock(0, 215, 215)
    run += [_msg(0, 240, "other", 0.0),
            Event(0, 0.240, late.topic, late.fields, "late clock", stamp=0.215, source=0.215, late=0.025)]
    counts, _, _ = _judge(run, True)
    assert (counts["false"], counts["currently_false"]) == (1, 0)
    in_order = sorted(run[:-1] + [late], key=lambda e: e.time)  # the control: the same run in stamp order
    assert _judge(in_order, True)[0]["false"] == 1
