"""The transport skew in the deadline rule (backends/monitors/deadline_skew.py; docs/semantics.md,
"Deadlines"): an output stamped within the skew before its trigger that satisfies the guarantee on the
trigger's inputs may be its answer, so the trigger left without an answer of its own is ``undecided``
(with why), never ``false``.  Controls: the same output 30 ms before the trigger (beyond a 20 ms skew),
an early output that does not satisfy the guarantee, a truly late answer and a mapping with ``skew: 0``
all leave the deadline ``false``; an answer of its own in time still meets it.  The batch deadline judge
gives the streaming monitor's verdicts and result on random runs with the skew on (it streams a chunk
the rule touches)."""
from __future__ import annotations

import random
from typing import Any

from rclverify.backends.monitors.batch_deadlines import BatchDeadlines, deadline_monitor
from rclverify.backends.monitors.deadline_records import DeadlineVerdict
from rclverify.backends.monitors.deadlines import DeadlineMonitor
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.traces.events import Event
from rclverify.traces.mapping import load_rules

RELAY = """
node Relay {
  inputs( x : REAL )
  outputs( r : REAL )
  topics( std_msgs/Float32 s matches(in.x), sensor_msgs/Range r matches(out.r) )
  guarantee( out.r == in.x ) triggered by in.x within 100 ms
}
"""
CHECKED = check([parse_text(RELAY, "relay.rcl")])
NODE = CHECKED.nodes["Relay"]


def _rules(skew: float | None) -> Any:
    rules = load_rules({"s": {"fields": ["data"]}, "r": {"fields": ["data"]}})
    rules.skew = skew
    return rules


def _ev(i: int, t: float, topic: str, value: float, stamped: bool = False) -> Event:
    fields: dict[str, Any] = {"data": value}
    if stamped:  # a header stamp of its own: the event's time is the stamp, whenever it was heard
        sec = int(t)
        fields["header"] = {"stamp": {"sec": sec, "nanosec": round((t - sec) * 1e9)}}
    return Event(i, t, topic, fields, f"run:{i + 1}")


def _judge(run: list[Event], skew: float | None = 0.02) -> tuple[dict[str, int], dict[str, int], list[DeadlineVerdict],
                                                                  Any]:
    seen: list[DeadlineVerdict] = []
    mon = DeadlineMonitor(CHECKED, NODE, _rules(skew), seen.append)
    for ev in run:
        mon.feed(ev)
    res = mon.finish()
    return res.counts, res.unaccepted, seen, res.first_unaccepted


def _relay(early_by: float, value: float = 2.0, answer_at: float | None = None) -> list[Event]:
    """Reading 1 at 1.0 s answered at 1.001 s; reading 2 at 1.2 s, with the relay's answer ``value`` heard
    before it, stamped ``early_by`` s before it (and, with ``answer_at``, an answer of its own then); a tick
    at 2 s passes every deadline."""
    run = [_ev(0, 1.0, "s", 1.0), _ev(1, 1.001, "r", 1.0), _ev(2, 1.2 - early_by, "r", value),
           _ev(3, 1.2, "s", 2.0)]
    if answer_at is not None:
        run.append(_ev(4, answer_at, "r", 2.0))
    return run + [_ev(len(run), 2.0, "s", 3.0)]


def test_an_answer_stamped_within_the_skew_before_its_trigger_leaves_it_undecided_not_false() -> None:
    counts, unaccepted, seen, first = _judge(_relay(0.0003))
    assert counts["false"] == 0 and counts["true"] == 1 and unaccepted["undecided"] == 1
    assert not any(v.verdict == "false" for v in seen)
    assert first is not None and first["where"] == "run:4" and "within the transport skew of 20 ms" in first["reason"]
    assert "run:3" in first["reason"] and "300 us before the trigger" in first["reason"]
    # the same answer at the trigger's own stamp, heard before it: the skew's "at s but heard after it"
    counts, unaccepted, _, _ = _judge(_relay(0.0))
    assert counts["false"] == 0 and unaccepted["undecided"] == 1


def test_controls_beyond_the_skew_a_wrong_early_answer_a_late_answer_and_no_skew_are_false() -> None:
    for run, skew in ((_relay(0.030), 0.02),            # 30 ms before its trigger, beyond the 20 ms skew
                      (_relay(0.0003, value=5.0), 0.02),  # within the skew, but not its answer's value
                      (_relay(0.0003), 0.0),              # the mapping's skew: 0
                      (_relay(0.0003), None)):             # no skew declared (a proxy's rules)
        counts, unaccepted, seen, _ = _judge(run, skew)
        assert counts["false"] == 1 and unaccepted["undecided"] == 0, (run[2], skew)
        assert [v.trigger_where for v in seen if v.verdict == "false"] == ["run:4"]
    # a truly late answer (150 ms after its trigger, no answer before it) is false as before
    run = [_ev(0, 1.0, "s", 1.0), _ev(1, 1.001, "r", 1.0), _ev(2, 1.2, "s", 2.0), _ev(3, 1.35, "r", 2.0),
           _ev(4, 2.0, "s", 3.0)]
    counts, unaccepted, seen, _ = _judge(run)
    assert counts["false"] == 1 and unaccepted["undecided"] == 0
    assert any(v.verdict == "false" and "past the deadline" in v.reason for v in seen)


def test_an_answer_of_its_own_in_time_meets_a_trigger_the_skew_marked() -> None:
    counts, unaccepted, _, first = _judge(_relay(0.0003, answer_at=1.25))
    assert counts["true"] == 2 and counts["false"] == 0 and unaccepted["undecided"] == 0 and first is None


def test_a_stamped_answer_heard_after_its_trigger_but_stamped_within_the_skew_before_it() -> None:
    run = [_ev(0, 1.0, "s", 1.0), _ev(1, 1.001, "r", 1.0, stamped=True), _ev(2, 1.2, "s", 2.0),
           _ev(3, 1.1997, "r", 2.0, stamped=True), _ev(4, 2.0, "s", 3.0)]
    counts, unaccepted, _, _ = _judge(run)
    assert counts["false"] == 0 and unaccepted["undecided"] == 1
    run[3] = _ev(3, 1.17, "r", 2.0, stamped=True)  # control: stamped 30 ms before, beyond the skew
    counts, unaccepted, _, _ = _judge(run)
    assert counts["false"] == 1 and unaccepted["undecided"] == 0


def test_a_late_answer_of_its_own_stamped_in_time_decides_an_undecided_trigger() -> None:
    # the answer of its own is stamped in time but heard after the clock passed the deadline
    run = _relay(0.0003)[:-1] + [_ev(4, 1.5, "tick", 0.0), _ev(5, 1.25, "r", 2.0, stamped=True),
                                 _ev(6, 2.0, "s", 3.0)]
    counts, unaccepted, seen, first = _judge(run)
    assert counts["false"] == 0 and unaccepted["undecided"] == 0 and first is None
    assert any(v.verdict == "true" and v.trigger_where == "run:4" and v.answer_where == "run:6" for v in seen)


def _random_run(rng: random.Random, n: int) -> list[Event]:
    """Readings and answers at random times 0-40 ms apart, answers sometimes the reading's value, some stamped."""
    out: list[Event] = []
    t, x = 1.0, 0.0
    for i in range(n):
        t += rng.choice([0.0, 0.0003, 0.001, 0.005, 0.019, 0.021, 0.04, 0.15])
        if rng.random() < 0.45:
            x = float(rng.randrange(4))
            out.append(_ev(i, t, "s", x))
        else:
            out.append(_ev(i, t, "r", rng.choice([x, x, x + 1.0])))
    return out


def test_the_batch_deadline_judge_gives_the_streaming_verdicts_with_the_skew() -> None:
    rng = random.Random(331)
    undecided = batched = 0
    for case in range(80):
        run = _random_run(rng, rng.randrange(1, 40))
        seen: list[DeadlineVerdict] = []
        stream = DeadlineMonitor(CHECKED, NODE, _rules(0.02), seen.append)
        got: list[DeadlineVerdict] = []
        batch = deadline_monitor(CHECKED, NODE, _rules(0.02), got.append, chunk=rng.randrange(1, 10))
        assert isinstance(batch, BatchDeadlines)
        for ev in run:
            stream.feed(ev)
            batch.feed(ev)
        a, b = stream.finish().to_json(), batch.finish().to_json()
        assert (got, b) == (seen, a), f"case {case}"
        undecided += a["unaccepted"]["undecided"]
        batched += batch.stats["batched"]
    assert undecided > 10 and batched > 300  # the rule was met, and chunks were still judged in batch
