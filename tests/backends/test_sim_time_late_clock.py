"""A ``/clock`` message heard late, after an answer already judged ``true`` (backends/monitors/deadline_clock.py;
docs/semantics.md, "Deadlines in simulated time").

Live, the engine releases each writer's messages in stamp order under the lateness bound; a ``/clock``
message ``C`` heard later than the bound comes after an answer stamped after it.  Read in stamp order (the
log, the bag) ``C`` comes first: if its value passes the deadline, the answer is after the tick past due,
``false`` (or ``undecided`` within the transport skew).  The monitor keeps each answer given before
``/clock`` passed its deadline and judges it again when that ``/clock`` message comes, an update that
changes the counts and names the late message.  Control: the same run with ``C`` on time gives the same
verdicts live and in stamp order, with no update.  An oracle: random small runs, some ``/clock`` messages
delivered late in the live order, the verdicts after every update, the counts and the time margins equal
the stamp order's.  The live run in-process: its log and its bag read offline give its counts."""
from __future__ import annotations

import json
import random
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.batch_deadlines import deadline_monitor
from rclverify.backends.monitors.deadline_records import DeadlineVerdict
from rclverify.backends.monitors.deadlines import DeadlineMonitor
from rclverify.traces.events import Event

from test_deadline_sim_time import CHECKED, NODE, RELAY, _rules as _relay_rules  # noqa: E402


def _rules(sim: Any, skew_ms: int = 0) -> Any:
    """The relay's mapping, keeping ``sim`` (``use_sim_time``) with a transport skew of ``skew_ms`` ms."""
    return _relay_rules(sim, skew_ms / 1000)


def _clock(t_ms: int, value_ms: int) -> Event:
    ns = value_ms * 1_000_000
    return Event(0, t_ms / 1000, "/clock", {"clock": {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}},
                 f"clock@{t_ms}")


def _msg(t_ms: int, topic: str, value: float) -> Event:
    return Event(0, t_ms / 1000, topic, {"data": value}, f"{topic}@{t_ms}")


def _live(run: list[Event], late: dict[int, int]) -> list[Event]:
    """``run`` (in stamp order) as the live engine releases it when each ``/clock`` message at an index of
    ``late`` is heard after the next ``late[i]`` messages of other writers: it and the ``/clock`` messages
    after it until then (one writer keeps its order) released after them, at the engine's clock, their
    publication as their stamp (:meth:`.online.OnlineEngine._release`)."""
    order: list[int] = []
    held: list[int] = []
    wait = 0
    for i, e in enumerate(run):
        if e.topic == "/clock" and (held or i in late):
            held.append(i)
            wait = max(wait, late.get(i, 0))
            continue
        order.append(i)
        if held and e.topic != "/clock":
            wait -= 1
            if wait <= 0:
                order += held
                held = []
    order += held
    out, clock = [], float("-inf")
    for i in order:
        e = run[i]
        if e.time < clock:
            out.append(Event(0, clock, e.topic, e.fields, e.where, stamp=e.time, source=e.time,
                             late=round(clock - e.time + 0.05, 6)))
        else:
            clock = e.time
            out.append(e)
    return out


def _judge(run: list[Event], sim: Any, skew_ms: int = 0, monitor: Any = DeadlineMonitor
           ) -> tuple[dict[str, int], dict[str, int], list[DeadlineVerdict]]:
    seen: list[DeadlineVerdict] = []
    mon = monitor(CHECKED, NODE, _rules(sim, skew_ms), seen.append)
    for ev in run:
        mon.feed(ev)
    res = mon.finish()
    return dict(res.counts), dict(res.unaccepted), seen


def _final(seen: list[DeadlineVerdict]) -> dict[str, str]:
    """Each trigger's verdict after every update (trigger place -> verdict)."""
    out: dict[str, str] = {}
    for v in seen:
        out[v.trigger_where] = v.verdict
    return out


def _run(late_clock_ms: int, answer_ms: int) -> list[Event]:
    """/clock every 10 ms at factor 1 up to 200 ms, a reading at 100 ms (due at 200 ms simulated), a /clock
    message at ``late_clock_ms`` showing 205 ms, the relay's answer at ``answer_ms``, in stamp order."""
    run = [_clock(t, t) for t in range(0, 201, 10)] + [_msg(100, "s", 1.0), _clock(late_clock_ms, 205),
                                                       _msg(answer_ms, "r", 1.0), _msg(300, "other", 0.0)]
    return sorted(run, key=lambda e: e.time)


def test_a_late_clock_past_the_deadline_before_the_answer_turns_its_true_false() -> None:
    run = _run(203, 207)
    live = _live(run, {run.index(next(e for e in run if e.where == "clock@203")): 1})
    assert [e.where for e in live].index("r@207") < [e.where for e in live].index("clock@203")
    counts, unaccepted, seen = _judge(live, True)
    offline = _judge(run, True)
    assert counts == offline[0] == {"true": 0, "currently_false": 0, "false": 1}
    assert unaccepted == offline[1]
    assert [(v.verdict, v.update) for v in seen] == [("true", False), ("false", True)]
    assert "the true given when the answer came is withdrawn: the /clock message at clock@203" in seen[1].reason
    assert "past the lateness bound" in seen[1].reason and seen[1].time_margin is not None \
        and seen[1].time_margin < 0
    # in stamp order: false when /clock passed the deadline, the late answer an update of it
    assert [(v.verdict, v.update) for v in offline[2]] == [("false", False), ("false", True)]


def test_within_the_skew_the_true_turns_undecided() -> None:
    run = _run(203, 207)
    live = _live(run, {run.index(next(e for e in run if e.where == "clock@203")): 1})
    counts, unaccepted, seen = _judge(live, True, skew_ms=5)
    offline = _judge(run, True, skew_ms=5)
    assert (counts, unaccepted) == offline[:2]
    assert (counts["true"], counts["false"], unaccepted["undecided"]) == (0, 0, 1)
    assert [(v.verdict, v.update) for v in seen] == [("true", False), ("undecided", True)]
    assert "within the transport skew" in seen[1].reason and "withdrawn" in seen[1].reason


def test_control_the_clock_on_time_or_after_the_answer_changes_nothing() -> None:
    run = _run(203, 207)
    live = _live(run, {})  # C on time: released in stamp order
    assert [e.where for e in live] == [e.where for e in run]
    counts, unaccepted, seen = _judge(live, True)
    assert (counts, unaccepted, seen) == _judge(run, True)  # identical verdicts, nothing withdrawn
    assert counts["false"] == 1 and not any("withdrawn" in v.reason for v in seen)
    run = _run(209, 207)  # C after the answer, heard late after the reading's other message: true stands
    live = _live(run, {run.index(next(e for e in run if e.where == "clock@209")): 1})
    counts, _, seen = _judge(live, True)
    assert counts == _judge(run, True)[0] == {"true": 1, "currently_false": 0, "false": 0}
    assert not any(v.update for v in seen)
    # the run's clock (said): /clock is not read, the late message changes nothing
    live = _live(_run(203, 150), {21: 1})
    assert _judge(live, False)[0] == _judge(_run(203, 150), False)[0]


def test_a_late_clock_places_a_trigger_stamped_after_it_at_the_value_it_shows() -> None:
    """A trigger stamped after the late /clock message was placed at the older value; read in stamp order it
    is placed at the late message's value, and a /clock jump past the old due time does not expire it."""
    run = sorted([_clock(t, t) for t in range(0, 101, 10)] + [_clock(105, 400), _msg(107, "s", 1.0),
                  _msg(150, "r", 1.0), _clock(160, 410), _msg(300, "other", 0.0)], key=lambda e: e.time)
    live = _live(run, {run.index(next(e for e in run if e.where == "clock@105")): 1})
    assert [e.where for e in live].index("s@107") < [e.where for e in live].index("clock@105")
    counts, _, _ = _judge(live, True)
    assert counts == _judge(run, True)[0] == {"true": 1, "currently_false": 0, "false": 0}


def test_an_answer_is_kept_for_a_late_clock_only_until_clock_is_heard_after_it() -> None:
    """/clock stands still (paused) and no deadline passes: an answer leaves the monitor's memory at the next
    /clock message (placed after it: one writer in order, none placed before it comes later); control:
    /clock silent after the answers, they are kept (a late /clock may still come), each leaving once its
    answer is more than the kept window behind the monitor's clock at a /clock message."""
    mon = DeadlineMonitor(CHECKED, NODE, _rules(True), None)
    mon.feed(_clock(0, 0))
    for t in range(10, 200_000, 100):
        mon.feed(_msg(t, "s", 1.0))
        mon.feed(_msg(t + 1, "r", 1.0))
        mon.feed(_clock(t + 2, 0))
    assert not [p for p in mon.awaiting if p.given]
    assert mon.finish().counts["true"] == 2000
    mon = DeadlineMonitor(CHECKED, NODE, _rules(True), None)
    mon.feed(_clock(0, 0))
    for t in range(10, 200_000, 100):  # the control: no /clock after them
        mon.feed(_msg(t, "s", 1.0))
        mon.feed(_msg(t + 1, "r", 1.0))
    assert len([p for p in mon.awaiting if p.given]) == 2000
    late = Event(0, 200.0, "/clock", {"clock": {"sec": 0, "nanosec": 0}}, "late", stamp=0.005, source=0.005,
                 late=199.995)
    mon.feed(late)  # heard late, placed before every answer: the ones outside the kept window leave
    kept = [p for p in mon.awaiting if p.given]
    assert mon.now_ns is not None and all(mon.now_ns - p.answer_ns <= mon.sim.kept_ns for p in kept)
    assert 0 < len(kept) < 2000
    assert mon.finish().counts["true"] == 2000


def _random_run(rnd: random.Random) -> tuple[list[Event], dict[int, int]]:
    """/clock samples (distinct times, values never going back, jumps up to 60 ms), one to three readings and
    their answers (or none), a last message; every time distinct; some /clock messages to deliver late."""
    times = rnd.sample(range(1, 600), 40)
    clocks = [0] + sorted(times[:rnd.randrange(3, 25)])  # the first /clock before every other message
    value = rnd.randrange(0, 30)
    run = []
    for t in clocks:
        value += rnd.choice((0, 0, 5, 10, 20, 40, 60))
        run.append(_clock(t, value))
    rest = times[25:]
    for n in range(rnd.randrange(1, 4)):
        q = rest[2 * n]
        run.append(_msg(q, "s", float(n)))
        if rnd.random() < 0.8:
            a = rest[2 * n + 1]
            run.append(_msg(a, "r", float(n)))
    run.append(_msg(700, "other", 0.0))
    run.sort(key=lambda e: e.time)
    late = {i: rnd.choice((1, 1, 2)) for i, e in enumerate(run) if e.topic == "/clock" and i and rnd.random() < 0.2}
    return run, late


@pytest.mark.parametrize("seed", range(10))
def test_oracle_the_live_order_after_updates_gives_the_stamp_orders_verdicts(seed: int) -> None:
    rnd = random.Random(seed)
    for case in range(80):
        run, late = _random_run(rnd)
        live = _live(run, late)
        assert [e.where for e in live if e.topic == "/clock"] == [e.where for e in run if e.topic == "/clock"]
        for mode in (True, None):
            skew = rnd.choice((0, 3))
            got, want = _result(live, mode, skew), _result(run, mode, skew)
            info = (seed, case, mode, skew, [(e.where, e.time, e.stamp) for e in live],
                    [(v.verdict, v.update, v.reason) for v in got[3]])
            assert got[:3] == want[:3], info  # counts, undecided, time margins
            assert _final(got[3]) == _final(want[3]), info


def _result(run: list[Event], sim: Any, skew_ms: int) -> tuple[dict[str, int], dict[str, int], list[Any],
                                                                list[DeadlineVerdict]]:
    """The counts, the unaccepted counts, the time margins and the verdicts of ``run``."""
    seen: list[DeadlineVerdict] = []
    mon = DeadlineMonitor(CHECKED, NODE, _rules(sim, skew_ms), seen.append)
    for ev in run:
        mon.feed(ev)
    res = mon.finish()
    return dict(res.counts), dict(res.unaccepted), [m.to_json() for m in res.time_margins.values()], seen


def test_every_offline_path_reads_the_same() -> None:
    run = _run(203, 207)
    for sim in (True, None):
        assert _judge(run, sim, monitor=deadline_monitor)[:2] == _judge(run, sim)[:2]


RELAY_RUN = RELAY.replace("guarantee(", "assume( TRUE )\n  guarantee(").replace("Float32", "Float64")
T0 = 1_700_000_000.0  # a date's seconds since the epoch: the float precision the engine really has


def _live_run(ws: Path, answer_s: float, clock_heard_s: float) -> dict[str, Any]:
    """The live run in-process (the engine with its lateness bound of 50 ms, writing the log, and the bag
    recorder told of late messages as runtime/dds/live.py wires it): /clock every 10 ms at factor 1 (a node
    under use_sim_time), a reading at 0.1 s, the relay's answer at ``answer_s``, the /clock message of
    0.203 s (showing 0.205 s, past the reading's deadline) heard at ``clock_heard_s`` and the /clock
    messages after it no earlier.  Returns the live record."""
    (ws / "contracts").mkdir()
    (ws / "contracts" / "c.rcl").write_text(RELAY_RUN)
    (ws / "contracts" / "plan.yaml").write_text("contracts: [contracts/c.rcl]\n")
    (ws / "mapping.yaml").write_text("topics:\n  s: {fields: [data]}\n  r: {fields: [data]}\nuse_sim_time: true\n")
    heard = [(t / 1000, "clock", t / 1000, t / 1000) for t in range(0, 201, 10)]
    heard += [(0.100, "s", 0.100, 1.0), (answer_s, "r", answer_s, 1.0), (clock_heard_s, "clock", 0.203, 0.205)]
    heard += [(max(t / 1000, clock_heard_s), "clock", t / 1000, t / 1000) for t in range(210, 401, 10)]
    heard.sort(key=lambda h: h[0])
    return _feed(ws, heard)


def _feed(ws: Path, heard: list[tuple[float, str, float, float]]) -> dict[str, Any]:
    """The relay of ``ws`` (its contract and mapping written) run live in-process on ``heard``: each message
    ``(heard at s, topic, stamped at s, value)`` pushed at its stamp (from :data:`T0`) once the run's clock,
    ticked every 10 ms, reaches the time it was heard, and written to the ``--record`` bag at its stamp; a
    ``clock`` message's value is ``/clock``'s (s).  Returns the live record (``ws/live.json``)."""
    from rclverify.backends.monitors.config import load_mapping
    from rclverify.lang.typecheck import load
    from rclverify.runtime.dds.bag import BagRecorder
    from rclverify.runtime.live import LiveRun
    from rclverify.traces.bag import typestore

    checked = load([ws / "contracts" / "c.rcl"])
    live = LiveRun(checked, [checked.nodes["Relay"]], load_mapping(ws, "mapping.yaml").rules, 0.5,
                   ws / "live.jsonl", reorder_window=0.05)
    store = typestore([])
    f64, clock, time = (store.types[t] for t in ("std_msgs/msg/Float64", "rosgraph_msgs/msg/Clock",
                                                  "builtin_interfaces/msg/Time"))
    rec = BagRecorder(ws / "bag", "sqlite3", {"s": "std_msgs/msg/Float64", "r": "std_msgs/msg/Float64",
                                              "clock": "rosgraph_msgs/msg/Clock"}, [])
    live.engine.on_late = rec.late
    now, period = T0, 0.01
    for arrival, topic, source, value in heard:
        while now + period <= T0 + arrival:
            now += period
            live.tick(now)
        ns = round((T0 + source) * 1e9)
        if topic == "clock":
            sec, nsec = divmod(round((T0 + value) * 1e9), 1_000_000_000)
            fields: dict[str, Any] = {"clock": {"sec": sec, "nanosec": nsec}}
            raw = store.serialize_cdr(clock(clock=time(sec=sec, nanosec=nsec)), "rosgraph_msgs/msg/Clock")
        else:
            fields, raw = {"data": value}, store.serialize_cdr(f64(data=value), "std_msgs/msg/Float64")
        rec.write(topic, ns, raw)
        live.push(topic, fields, ns / 1e9)
    for _ in range(100):
        now += period
        live.tick(now)
    record: dict[str, Any] = live.stop(ws / "live.json")
    rec.close()
    return record


def _offline_deadlines(ws: Path, trace: Path, capsys: pytest.CaptureFixture[str]) -> dict[str, int]:
    from rclverify.cli.commands import main

    main(["monitor", "-w", str(ws), "--mapping", "mapping.yaml", "--horizon", "0.5", "--json", str(trace)])
    (got,) = [x["deadlines"] for x in json.loads(capsys.readouterr().out) if "deadlines" in x]
    return {**got["counts"], "undecided": got["unaccepted"]["undecided"]}


@pytest.mark.parametrize("answer_s, want", [(0.207, "undecided"), (0.235, "false")])
def test_the_live_run_its_log_and_its_bag_give_the_same_counts(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                              answer_s: float, want: str) -> None:
    """The default transport skew (20 ms): an answer 4 ms after the late /clock message is ``undecided``,
    one 32 ms after it ``false``; live gave ``true`` first and replaced it.  Control: the /clock message
    heard in time (before the answer was released), nothing withdrawn, the same counts everywhere."""
    for heard_s, late in ((0.30, True), (answer_s - 0.001, False)):
        ws = tmp_path / f"{answer_s}-{late}"
        ws.mkdir()
        record = _live_run(ws, answer_s, heard_s)
        (dl,) = record["topic_deadlines"]
        live = {**dl["deadlines"]["counts"], "undecided": dl["deadlines"]["unaccepted"]["undecided"]}
        assert {k for k, n in live.items() if n} == {want}, (late, live)
        assert _offline_deadlines(ws, ws / "live.jsonl", capsys) == live
        assert _offline_deadlines(ws, ws / "bag", capsys) == live
        lines = [json.loads(x) for x in (ws / "live.jsonl").read_text().splitlines()]
        given = [x["verdict"]["verdict"] for x in lines if x.get("kind") == "deadline"]
        withdrawn = [x for x in lines if x.get("kind") == "deadline" and "withdrawn" in x["verdict"]["reason"]]
        assert [x["topic"] for x in lines if "late_s" in x][:1] == (["clock"] if late else [])
        if late:
            assert given == ["true", want] and withdrawn[0]["verdict"]["update"] is True
        else:
            assert not withdrawn


def test_the_clock_is_heard_after_an_answer_once_any_later_sample_comes() -> None:
    """An answer's margin reads /clock at it: final once a sample placed after it was heard, one repeating
    the value (a paused simulator) included; control: none after it, or a broken clock (nothing to read)."""
    from rclverify.traces.sim_clock import SimClock

    c = SimClock()
    assert not c.heard_after(0)
    c.see(100, 5)
    assert c.heard_after(99) and not c.heard_after(100)
    c.see(120, 5)  # the clock stands still: no new sample kept, but heard
    assert c.times == [100] and c.heard_after(110) and not c.heard_after(120)
    c.see(130, 4)  # went back: broken
    assert c.broken and c.heard_after(10**9)
