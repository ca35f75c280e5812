"""The first ``/clock`` message heard late (backends/monitors/deadline_first_clock.py, ``hold``, ``place_held``,
``record``, ``unsaid_first``; docs/semantics.md, "Deadlines in simulated time").

Live, the monitor's ``/clock`` reader may hear the first message after messages stamped after it (later than
the lateness bound).  A trigger of a node said to keep simulated time that comes before any ``/clock`` is held
(no verdict) until the first ``/clock`` message places it as the run read in stamp order places it: stamped
at or after that message, at the value it shows, then judged with the answer that came meanwhile; stamped
before it, ``undecided`` (no ``/clock`` heard before it).  With no ``/clock`` at all, a held trigger is
``undecided`` as before, once the monitor's clock is the simulated clock's kept window past it, or at the
run's end.  A node whose clock is not said is judged on the run's clock before any ``/clock``, as before;
the first ``/clock`` message heard late gives again, as updates, what it gave to a trigger stamped after that
message (judged in both clocks) and to one answered late after it (``undecided``).  Control: the first
``/clock`` on time gives the verdicts it gave before, in the same order.  An oracle: random small runs whose
first ``/clock`` message (and some others) is delivered late in the live order, for both nodes; the verdicts
after every update, the counts and the time margins equal the stamp order's.  The live run in-process: its
log and its bag read offline give its counts."""
from __future__ import annotations

import random
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors import deadline_first_clock
from rclverify.backends.monitors.deadlines import DeadlineMonitor
from rclverify.traces.events import Event

from test_deadline_sim_time import CHECKED, NODE  # noqa: E402
from test_sim_time_late_clock import (RELAY_RUN, T0, _clock, _feed, _final, _judge, _live, _msg, _offline_deadlines,  # noqa: E402
                                      _result, _rules)


def _run(first_ms: int, answer_ms: int | None, trigger_ms: int = 100, half: bool = False) -> list[Event]:
    """/clock every 10 ms from ``first_ms`` to 300 ms at factor 1 (its value the time; ``half``: at 0.5, half
    the time), a reading at ``trigger_ms`` (due 100 ms later in simulated time), the relay's answer at
    ``answer_ms`` (``None``: none), a last message at 400 ms, in stamp order."""
    run = [_clock(t, t // 2 if half else t) for t in range(first_ms, 301, 10)]
    run += [_msg(trigger_ms, "s", 1.0), _msg(400, "other", 0.0)] + ([_msg(answer_ms, "r", 1.0)] if answer_ms else [])
    return sorted(run, key=lambda e: e.time)


def _first_late(run: list[Event], after: int) -> list[Event]:
    """``run`` as the live engine releases it when its first ``/clock`` message is heard after the next
    ``after`` messages of other writers (the ``/clock`` messages after it held behind it)."""
    return _live(run, {next(i for i, e in enumerate(run) if e.topic == "/clock"): after})


def test_a_trigger_heard_before_the_first_clock_is_placed_by_it_and_judged() -> None:
    run = _run(50, 150)
    live = _first_late(run, 2)
    order = [e.where for e in live]
    assert order.index("s@100") < order.index("r@150") < order.index("clock@50")
    counts, unaccepted, seen = _judge(live, True)
    assert (counts, unaccepted) == _judge(run, True)[:2]
    assert counts == {"true": 1, "currently_false": 0, "false": 0} and unaccepted["undecided"] == 0
    (v,) = seen
    assert v.verdict == "true" and "in simulated time (use_sim_time)" in v.reason
    assert "held until the first /clock message (clock@50" in v.reason and "past the lateness bound" in v.reason
    assert _result(live, True, 0)[2] == _result(run, True, 0)[2]  # the margin measured on the later /clock


def test_late_in_simulated_time_the_later_clock_messages_make_it_false() -> None:
    """The answer at 235 ms: the first /clock placed the trigger (in time on its one sample), the /clock
    messages held behind it pass the simulated deadline at 210 ms: ``false``, an update, as in stamp order."""
    run = _run(50, 235)
    live = _first_late(run, 2)
    counts, unaccepted, seen = _judge(live, True)
    offline = _judge(run, True)
    assert (counts, unaccepted) == offline[:2] == ({"true": 0, "currently_false": 0, "false": 1}, unaccepted)
    assert _final(seen) == _final(offline[2]) == {"s@100": "false"}
    assert [(v.verdict, v.update) for v in seen] == [("true", False), ("false", True)]


def test_control_the_first_clock_on_time_gives_the_same_verdicts_in_the_same_order() -> None:
    for answer in (150, 235, 215):
        run = _run(50, answer)
        live = _live(run, {})
        assert [e.where for e in live] == [e.where for e in run]
        counts, unaccepted, seen = _judge(live, True)
        assert (counts, unaccepted, seen) == _judge(run, True)
        assert not any("held until" in v.reason for v in seen)
    # a trigger stamped before the first /clock: undecided, late first /clock or not (stamp order the same)
    run = _run(120, 150)
    for live in (run, _first_late(run, 2)):
        counts, unaccepted, seen = _judge(live, True)
        assert counts == {"true": 0, "currently_false": 0, "false": 0} and unaccepted["undecided"] == 1
        assert [v.reason for v in seen] == [
            "its node keeps simulated time (use_sim_time) and no /clock message was heard before it: "
            "its simulated time is not known"]
    # the run's clock said: /clock is not read, the trigger judged at once on the run's clock
    live = _first_late(_run(50, 150), 2)
    seen = _judge(live, False)[2]
    assert [(v.verdict, "held" in v.reason) for v in seen] == [("true", False)]


def test_with_no_clock_a_held_trigger_is_undecided_after_the_kept_window_or_at_the_end() -> None:
    """No /clock at all: each trigger ``undecided`` as before (the same reason), once the monitor's clock is
    the kept window (the longest bound and a minute) past it; those still held at the end, then, and the
    counts final.  Memory: at most ``HELD`` held, the oldest released past it."""
    seen: list[Any] = []
    mon = DeadlineMonitor(CHECKED, NODE, _rules(True), seen.append)
    mon.feed(_msg(100, "s", 1.0))
    mon.feed(_msg(150, "r", 1.0))
    assert not seen and len(mon.unclocked) == 1
    assert [v.verdict for v in mon.pending_verdicts()] == []  # answered: held with its answer
    mon.advance(0.1 + mon.sim.kept_ns / 1e9)  # not past the window yet
    assert not seen
    mon.advance(0.1 + mon.sim.kept_ns / 1e9 + 0.001)
    assert [v.verdict for v in seen] == ["undecided"] and "no /clock message was heard before it" in seen[0].reason
    mon.feed(_msg(200_000, "s", 1.0))  # a second one, held to the end of the run
    assert "no /clock message heard yet" in mon.pending_verdicts()[0].reason
    res = mon.finish()
    assert res.counts == {"true": 0, "currently_false": 0, "false": 0} and res.unaccepted["undecided"] == 2
    assert len(seen) == 2 and not mon.unclocked and not mon.pending
    mon = DeadlineMonitor(CHECKED, NODE, _rules(True), None)
    for t in range(deadline_first_clock.HELD + 10):
        mon.feed(_msg(t, "s", 1.0))
    assert len(mon.unclocked) <= deadline_first_clock.HELD
    assert mon.result.unaccepted["undecided"] == deadline_first_clock.HELD // 4
    assert mon.finish().unaccepted["undecided"] == deadline_first_clock.HELD + 10


def test_not_said_a_false_on_the_run_s_clock_is_given_again_in_both_clocks() -> None:
    """The node's clock not said, /clock at factor 0.5 from 50 ms: the answer at 235 ms is late on the run's
    clock (due at 200 ms) and in time in simulated time (due at 150 ms simulated, /clock at 117 ms then):
    ``undecided`` in stamp order.  Live, the first /clock heard after it, the trigger was judged on the run's
    clock (``false``); that message gives it again: ``undecided``, an update saying why."""
    run = _run(50, 235, half=True)
    live = _first_late(run, 2)
    counts, unaccepted, seen = _judge(live, None)
    offline = _judge(run, None)
    assert (counts, unaccepted) == offline[:2]
    assert counts["false"] == 0 and unaccepted["undecided"] == 1
    assert [(v.verdict, v.update) for v in seen] == [("false", False), ("undecided", True)]
    assert "late on the run's clock, in time in simulated time" in seen[1].reason
    assert "the false given on the run's clock is withdrawn; placed again when the first /clock message (clock@50" \
        in seen[1].reason and "past the lateness bound" in seen[1].reason
    assert _result(live, None, 0)[2] == _result(run, None, 0)[2] == []  # no margin: the late answer's withdrawn


def test_not_said_an_expired_trigger_after_the_first_clock_is_open_again() -> None:
    """Unanswered, expired on the run's clock before the first /clock message (stamped before it) came: its
    ``false`` withdrawn, open (currently_false, an update), as in stamp order where /clock at 0.5 has not
    passed its simulated deadline by the end; it is not counted unanswered twice."""
    run = _run(50, None, half=True)
    live = _first_late(run, 2)
    order = [e.where for e in live]
    assert order.index("other@400") < order.index("clock@50")
    counts, unaccepted, seen = _judge(live, None)
    assert (counts, unaccepted) == _judge(run, None)[:2]
    assert counts == {"true": 0, "currently_false": 1, "false": 0}
    assert [(v.verdict, v.update) for v in seen] == [("false", False), ("currently_false", True),
                                                     ("currently_false", False)]
    assert "the false given when the run's clock passed its deadline is withdrawn" in seen[1].reason
    assert _result(live, None, 0)[2] == _result(run, None, 0)[2]


def test_not_said_control_the_first_clock_on_time_or_a_run_without_clock() -> None:
    """The first /clock on time: the verdicts of the stamp order, nothing given again.  No /clock at all: each
    verdict on the run's clock when it comes (nothing held), none an update; the recorded obligations leave
    once their trigger is the kept window behind the monitor's clock, their margins then settled."""
    for answer in (150, 235, None):
        run = _run(50, answer, half=True)
        counts, unaccepted, seen = _judge(_live(run, {}), None)
        assert (counts, unaccepted, seen) == _judge(run, None)
        assert not any("placed again" in v.reason for v in seen)
    run = [e for e in _run(50, 235) if e.topic != "/clock"]
    given: list[Any] = []
    mon = DeadlineMonitor(CHECKED, NODE, _rules(None), given.append)
    for ev in run[:2]:
        mon.feed(ev)
    assert [(v.verdict, v.update) for v in given] == [("false", False)] and len(mon.unsure) == 1
    assert mon.result.floor == {}  # its margin still withdrawable
    mon.advance(0.1 + mon.sim.kept_ns / 1e9 + 0.001)
    assert not mon.unsure and mon.result.floor[1][0] == -35_000_000
    mon = DeadlineMonitor(CHECKED, NODE, _rules(None), None)
    for t in range(0, 2 * deadline_first_clock.HELD, 2):
        mon.feed(_msg(t, "s", 1.0))
        mon.feed(_msg(t + 1, "r", 1.0))
    assert len(mon.unsure) <= deadline_first_clock.HELD and mon.finish().counts["true"] == deadline_first_clock.HELD


def _random_run(rnd: random.Random) -> tuple[list[Event], dict[int, int]]:
    """/clock samples from a random first one (values never going back, jumps up to 60 ms), one to three
    readings and their answers (or none) before or after it, a last message; every time distinct; the first
    /clock message delivered late in most runs, some others too."""
    times = rnd.sample(range(1, 600), 40)
    first = rnd.randrange(1, 300)
    clocks = [first] + sorted(t for t in times[:rnd.randrange(3, 25)] if t > first)
    value = rnd.randrange(0, 30)
    run = []
    for t in clocks:
        value += rnd.choice((0, 0, 5, 10, 20, 40, 60))
        run.append(_clock(t, value))
    rest = [t for t in times[25:] if t != first]
    for n in range(rnd.randrange(1, 4)):
        run.append(_msg(rest[2 * n], "s", float(n)))
        if rnd.random() < 0.8:
            run.append(_msg(rest[2 * n + 1], "r", float(n)))
    run.append(_msg(700, "other", 0.0))
    run.sort(key=lambda e: e.time)
    i0 = next(i for i, e in enumerate(run) if e.topic == "/clock")
    late = {i: rnd.choice((1, 1, 2)) for i, e in enumerate(run) if e.topic == "/clock" and i > i0 and rnd.random() < 0.2}
    if rnd.random() < 0.7:
        late[i0] = rnd.choice((1, 2, 3, 4))
    return run, late


@pytest.mark.parametrize("seed", range(10))
def test_oracle_the_first_clock_late_gives_the_stamp_orders_verdicts(seed: int) -> None:
    rnd = random.Random(1000 + seed)
    for case in range(80):
        run, late = _random_run(rnd)
        live = _live(run, late)
        for mode in (True, None):
            skew = rnd.choice((0, 3))
            got, want = _result(live, mode, skew), _result(run, mode, skew)
            info = (seed, case, mode, skew, [(e.where, e.stamp) for e in live],
                    [(v.verdict, v.update, v.reason) for v in got[3]])
            assert got[:3] == want[:3], info  # counts, undecided, time margins
            assert _final(got[3]) == _final(want[3]), info


def _live_run(ws: Path, answer_s: float, first_heard_s: float, sim: str, factor: float) -> dict[str, Any]:
    """The live run in-process, as test_sim_time_late_clock's: /clock every 10 ms at ``factor`` from 0.05 s to
    0.4 s (its value the time times the factor), the mapping's ``use_sim_time`` ``sim`` (``""``: not said), a
    reading at 0.1 s, the relay's answer at ``answer_s``; every /clock message stamped before ``first_heard_s``
    heard then (in order).  Returns the live record."""
    (ws / "contracts").mkdir()
    (ws / "contracts" / "c.rcl").write_text(RELAY_RUN)
    (ws / "contracts" / "plan.yaml").write_text("contracts: [contracts/c.rcl]\n")
    (ws / "mapping.yaml").write_text("topics:\n  s: {fields: [data]}\n  r: {fields: [data]}\n"
                                     + (f"use_sim_time: {sim}\n" if sim else ""))
    heard = [(max(t / 1000, first_heard_s), "clock", t / 1000, t * factor / 1000) for t in range(50, 401, 10)]
    heard += [(0.100, "s", 0.100, 1.0), (answer_s, "r", answer_s, 1.0)]
    heard.sort(key=lambda h: (h[0], h[2]))
    return _feed(ws, heard)


@pytest.mark.parametrize("sim, factor, answer_s, want", [("true", 1.0, 0.150, "true"), ("true", 1.0, 0.235, "false"),
                                                        ("", 0.5, 0.235, "undecided")])
def test_the_live_run_its_log_and_its_bag_give_the_same_counts(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                              sim: str, factor: float, answer_s: float,
                                                              want: str) -> None:
    """The first /clock message heard at 0.3 s, after the answer.  Said to keep simulated time, at factor 1:
    the trigger at 0.1 s is placed by it (at 0.1 s simulated), ``true`` for an answer at 0.15 s, ``false`` at
    0.235 s (the /clock messages held behind it pass its deadline at 0.21 s); before, both were
    ``undecided`` live.  Not said, at 0.5: the answer at 0.235 s, late on the run's clock and in time in
    simulated time, ``undecided`` (before, ``false`` live).  Control: the first /clock heard on time."""
    import json

    for heard_s, late in ((0.30, True), (0.05, False)):
        ws = tmp_path / f"{answer_s}-{late}"
        ws.mkdir()
        record = _live_run(ws, answer_s, heard_s, sim, factor)
        (dl,) = record["topic_deadlines"]
        live = {**dl["deadlines"]["counts"], "undecided": dl["deadlines"]["unaccepted"]["undecided"]}
        assert {k for k, n in live.items() if n} == {want}, (late, live)
        assert _offline_deadlines(ws, ws / "live.jsonl", capsys) == live
        assert _offline_deadlines(ws, ws / "bag", capsys) == live
        lines = [json.loads(x) for x in (ws / "live.jsonl").read_text().splitlines()]
        reasons = [x["verdict"]["reason"] for x in lines if x.get("kind") == "deadline"]
        assert any("held until the first /clock message" in r or "placed again" in r for r in reasons) == late, \
            reasons
        assert bool([x for x in lines if "late_s" in x and x["topic"] == "clock"]) == late


def test_a_call_answered_before_the_first_clock_sample_is_placed_by_it() -> None:
    """A server said to keep simulated time (backends/monitors/dds_calls.py): /clock at factor 0.5 from
    50 ms, the request at 100 ms, its reply at 400 ms (150 ms simulated, in time for 200 ms).  The book takes
    the samples up to 420 ms only after its ticks at 410 and 420 ms (heard late): the answered call is kept,
    its request placed by the first sample, ``true`` as with the samples on time (the control), live and
    on the log's replay; before, ``undecided`` (no /clock before it)."""
    from test_call_deadlines_sim_time import _judge as _judge_calls, _run as _calls_run

    run = _calls_run(0.5, 400, start_ms=50)
    on_time = [r for r in run if r[2] != "end" or r[0] > 420] + [(410, 4, "tick", None), (420, 4, "tick", None)]
    on_time.sort(key=lambda r: r[:2])
    late = sorted((r for r in on_time if not (r[2] == "clock" and r[0] <= 420)), key=lambda r: r[:2])
    at = next(i for i, r in enumerate(late) if r[0] == 420 and r[2] == "tick") + 1
    late[at:at] = [r for r in on_time if r[2] == "clock" and r[0] <= 420]
    for order in (on_time, late):
        counts, unaccepted, seen = _judge_calls(order, True)
        assert (counts["true"], counts["false"], unaccepted["undecided"]) == (1, 0, 0), (order is late, seen)
    assert "held until the first /clock message (/clock sample 1" in seen[0]["reason"]
