"""One verdict engine: the online path (message by message, timer, reorder
window) gives the offline verdicts on every bundled run, event for event."""
from __future__ import annotations

import math
import random
import time
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.check import check_trace
from rclverify.backends.monitors.config import load_mapping
from rclverify.backends.monitors.online import OnlineEngine, header_stamp
from rclverify.lang.typecheck import load
from rclverify.traces import read_trace

REPO = Path(__file__).resolve().parents[2]
TRACES = REPO / "backends" / "monitors" / "traces"
MSG = [REPO / "backends" / "monitors" / "msg"]
RUNS = sorted(p.name for p in TRACES.iterdir())


@pytest.fixture(scope="module")
def case_study() -> tuple[Any, Any]:
    return load([REPO / "contracts" / "remote_inspection.rcl"]), load_mapping(REPO, "backends/monitors/mapping.yaml", 2.0)


def offline(checked: Any, cfg: Any, run: str) -> tuple[list[Any], list[Any]]:
    seen: list[Any] = []
    _, results = check_trace(checked, list(checked.nodes.values()), read_trace(TRACES / run, MSG), cfg.rules,
                             cfg.horizon, seen.append)
    return seen, results


def key(v: Any) -> tuple[Any, ...]:
    return (v.node, v.where, v.verdict, v.guarantee, tuple(sorted(v.values.items())), v.reason)


@pytest.mark.parametrize("run", RUNS)
def test_online_replay_gives_the_offline_verdicts_event_for_event(case_study: tuple[Any, Any], run: str) -> None:
    checked, cfg = case_study
    expected, results = offline(checked, cfg, run)
    got: list[Any] = []
    eng = OnlineEngine(checked, list(checked.nodes.values()), cfg.rules, cfg.horizon, on_verdict=got.append)
    for ev in read_trace(TRACES / run, MSG):
        eng.tick(ev.time)  # the timer fires before each message arrives
        eng.push(ev.topic, ev.fields, ev.time, ev.where)
    live = eng.finish()
    assert [key(v) for v in got] == [key(v) for v in expected]
    assert [r.to_json() for r in live] == [r.to_json() for r in results]
    assert any(v.verdict == "satisfied" for v in got)


def test_reordered_arrivals_within_the_window_give_the_same_verdicts(case_study: tuple[Any, Any]) -> None:
    checked, cfg = case_study
    expected, _ = offline(checked, cfg, "sensor_fault.jsonl")
    events = list(read_trace(TRACES / "sensor_fault.jsonl", MSG))
    rng = random.Random(7)
    delay = {t: rng.uniform(0, 0.04) for t in {e.time for e in events}}
    arrivals = sorted(events, key=lambda e: (e.time + delay[e.time], e.index))
    assert [e.index for e in arrivals] != [e.index for e in events]  # the network did reorder them
    got: list[Any] = []
    eng = OnlineEngine(checked, list(checked.nodes.values()), cfg.rules, cfg.horizon, reorder_window=0.05,
                       on_verdict=got.append)
    for e in arrivals:
        eng.tick(e.time + delay[e.time])
        stamp = {"secs": int(e.time), "nsecs": round((e.time - int(e.time)) * 1e9)}
        eng.push(e.topic, {**e.fields, "header": {"stamp": stamp}}, e.time + delay[e.time], e.where)
    eng.finish()
    assert eng.late == 0
    assert sorted(key(v) for v in got) == sorted(key(v) for v in expected)


def test_the_timer_resolves_an_unanswered_input_without_a_new_message(case_study: tuple[Any, Any]) -> None:
    checked, cfg = case_study
    got: list[Any] = []
    eng = OnlineEngine(checked, [checked.nodes["RadiationSensor"]], cfg.rules, horizon=0.5, on_verdict=got.append)
    eng.push("r", {"value": 300.0}, 1.0)
    eng.push("command", {"command": "inspect", "posx": 0.0, "posy": 0.0, "id": 4}, 1.1)
    eng.push("radiationStatus", {"level": "orange"}, 1.2)  # misclassified: 300 is red
    eng.tick(1.5)
    assert [v.verdict for v in got] == ["incomplete input"]  # the reading before any command; the command waits
    got.clear()
    eng.tick(1.7)
    [v] = [v for v in got if v.verdict == "violated"]
    assert v.guarantee == 1 and v.decided_at == pytest.approx(1.7) and v.values["out.radiationStatus"] == "orange"


def test_a_silent_topic_is_reported_once_and_its_return_too(case_study: tuple[Any, Any]) -> None:
    checked, cfg = case_study
    notes: list[tuple[str, bool]] = []
    eng = OnlineEngine(checked, [checked.nodes["RadiationSensor"]], cfg.rules, 2.0, silence_s=1.0,
                       on_silence=lambda t, s, silent: notes.append((t, silent)))
    eng.push("r", {"value": 3.0}, 0.0)
    eng.tick(0.5)
    eng.tick(1.6)
    eng.tick(2.0)
    eng.push("/r", {"value": 3.0}, 2.1)
    assert notes == [("r", True), ("r", False)]
    assert eng.topics["r"].received == 2 and eng.topics["command"].received == 0


@pytest.mark.parametrize("fields, stamp", [
    ({"header": {"stamp": {"secs": 3, "nsecs": 500_000_000}}}, 3.5),
    ({"header": {"stamp": {"sec": 3, "nanosec": 250_000_000}}}, 3.25),
    ({"header.stamp.secs": 2, "header.stamp.nsecs": 0}, 2.0),
    ({"header": {"stamp": {"secs": 0, "nsecs": 0}}}, None),
    ({"header": {"stamp": {"secs": "x"}}}, None),
    ({"header": 3}, None),
    ({"value": 1.0}, None),
])
def test_header_stamp(fields: dict[str, Any], stamp: float | None) -> None:
    assert header_stamp(fields) == stamp


def test_live_run_logs_publishes_and_writes_evidence_the_offline_check_agrees_with(
        case_study: tuple[Any, Any], tmp_path: Path) -> None:
    """The part of the live monitor below the middleware (what the ROS 2 layer uses too)."""
    import hashlib
    import json

    from rclverify.runtime.live import VERDICT_LOG_TOPIC, LiveRun
    checked, cfg = case_study
    published: list[str] = []
    last: dict[str, str] = {}
    log = tmp_path / "live.jsonl"
    live = LiveRun(checked, list(checked.nodes.values()), cfg.rules, cfg.horizon, log, reorder_window=0.05,
                          silence_s=5.0, publish=published.append, publish_last=lambda n, m: last.__setitem__(n, m))
    for ev in read_trace(TRACES / "sensor_fault.jsonl", MSG):
        live.tick(ev.time)
        live.push("/" + ev.topic, {**ev.fields, "nan": float("nan")}, ev.time)
    live.tick(40.0)
    assert "RadiationSensor:" in live.status_line() and "silent:" in live.status_line()
    record = live.stop(tmp_path / "evidence.json")
    assert json.loads((tmp_path / "evidence.json").read_text()) == record
    assert record["sha256"] == hashlib.sha256(log.read_bytes()).hexdigest()
    assert record["silent_topics"] and all(s["silent"] for s in record["silent_topics"])
    verdicts = [m for m in map(json.loads, published) if m["node"]]
    assert len(verdicts) == record["verdicts"]
    assert json.loads(last["RadiationSensor"]) == [m for m in verdicts if m["node"] == "RadiationSensor"][-1]
    sensor = {n["node"]: n for n in record["nodes"]}["RadiationSensor"]
    assert sensor["status"] == "failed" and sensor["first_violation"]["guarantee"] == 1
    # the log re-checks offline to the same counts; its verdict lines are skipped
    _, results = check_trace(checked, list(checked.nodes.values()), read_trace(log), cfg.rules, cfg.horizon)
    assert {r.node: r.counts for r in results} == {n["node"]: n["counts"] for n in record["nodes"]}
    assert sum(1 for line in log.read_text().splitlines() if VERDICT_LOG_TOPIC in line) == record["verdicts"]


def _worker_run(checked: Any, cfg: Any, tmp_path: Path, run: str, *, before_start: bool) -> tuple[list[Any], Any]:
    """Offer a bundled run's messages to an EngineWorker (all queued before the
    thread starts, or while it runs) with a clock already at each offered
    message; returns (verdict keys, evidence record)."""
    import json

    from rclverify.runtime.live import LiveRun
    from rclverify.runtime.worker import EngineWorker
    published: list[str] = []
    live = LiveRun(checked, list(checked.nodes.values()), cfg.rules, cfg.horizon, tmp_path / f"{run}.jsonl",
                   reorder_window=0.0, publish=published.append)
    clock = {"t": 0.0}
    worker = EngineWorker(live, lambda topic, fields: None if topic == "undecodable" else fields,
                          lambda: clock["t"], tick_s=0.0005, batch=3)
    if not before_start:
        worker.start()
    events = list(read_trace(TRACES / run, MSG))
    for ev in events:
        clock["t"] = ev.time  # the middleware's clock runs ahead of what the engine has checked
        worker.offer(ev.topic, ev.fields, ev.time)
        worker.offer("undecodable", b"", ev.time)  # a message the decoder refuses: skipped
    if before_start:
        worker.start()
    worker.stop()
    record = live.stop()
    assert worker.handled == 2 * len(events) and worker.backlog_max >= 1 and worker.cpu_s > 0
    verdicts = [m for m in map(json.loads, published) if m["node"]]
    return [(m["node"], m["event"], m["verdict"], m["guarantee"], sorted(m["values"].items())) for m in verdicts], record


@pytest.mark.parametrize("before_start", [True, False])
@pytest.mark.parametrize("run", ["sensor_fault.jsonl", "nominal.jsonl"])
def test_the_engine_thread_gives_the_offline_verdicts_even_with_a_backlog(
        case_study: tuple[Any, Any], tmp_path: Path, run: str, before_start: bool) -> None:
    """Callbacks only queue; the worker thread checks.  With the whole run queued
    before the thread starts, the timer's clock is already at the run's end:
    it must not pass the queued messages (or the sensor's answers would come
    after their obligations were closed as violated)."""
    checked, cfg = case_study
    expected, results = offline(checked, cfg, run)
    got, record = _worker_run(checked, cfg, tmp_path, run, before_start=before_start)
    assert got == [(v.node, v.event, v.verdict, v.guarantee, sorted(v.values.items())) for v in expected]
    assert {n["node"]: n["counts"] for n in record["nodes"]} == {r.node: r.counts for r in results}


def test_an_error_in_the_engine_thread_is_raised_by_stop(case_study: tuple[Any, Any], tmp_path: Path) -> None:
    from rclverify.runtime.live import LiveRun
    from rclverify.runtime.worker import EngineWorker
    checked, cfg = case_study
    live = LiveRun(checked, list(checked.nodes.values()), cfg.rules, cfg.horizon, tmp_path / "x.jsonl")

    def decode(topic: str, payload: Any) -> Any:
        raise RuntimeError("decoder bug")
    worker = EngineWorker(live, decode, lambda: 0.0).start()
    worker.offer("r", {}, 0.0)
    with pytest.raises(RuntimeError, match="decoder bug"):
        worker.stop()
    live.stop()


def test_a_full_queue_drops_and_counts_instead_of_growing(case_study: tuple[Any, Any], tmp_path: Path) -> None:
    from rclverify.runtime.live import LiveRun
    from rclverify.runtime.worker import EngineWorker
    checked, cfg = case_study
    live = LiveRun(checked, list(checked.nodes.values()), cfg.rules, cfg.horizon, tmp_path / "x.jsonl")
    worker = EngineWorker(live, lambda topic, fields: fields, lambda: 1.0, max_queue=5)
    for k in range(8):  # the thread is not running yet: nothing is taken from the queue
        worker.offer("r", {"value": 1.0}, k * 0.1)
    assert worker.dropped == 3
    worker.start().stop()
    assert worker.handled == 5 and live.stop()["events"] == 5


def test_the_evidence_of_a_run_that_dropped_messages_or_lost_its_engine_is_not_discharged(
        case_study: tuple[Any, Any], tmp_path: Path) -> None:
    """stop_and_record (both ROS layers): verdicts that miss dropped messages prove nothing, so no node
    reads discharged or pending; an engine that died makes every node error, with the reason."""
    from rclverify.runtime.live import LiveRun, stop_and_record
    from rclverify.runtime.worker import EngineWorker
    checked, cfg = case_study
    lines: list[str] = []

    def run(decode: Any) -> dict[str, Any]:
        live = LiveRun(checked, list(checked.nodes.values()), cfg.rules, cfg.horizon, tmp_path / "x.jsonl")
        worker = EngineWorker(live, decode, lambda: 1.0, max_queue=2)
        for k in range(4):
            worker.offer("r", {"value": 1.0}, k * 0.1)
        worker.start()
        return stop_and_record(worker, live, None, lines.append)
    dropped = run(lambda topic, fields: fields)
    assert dropped["dropped_messages"] == 2 and dropped["backlog_max"] >= 2
    assert {n["status"] for n in dropped["nodes"]} <= {"inconclusive", "failed"}
    assert any("dropped" in n.get("explanation", "") for n in dropped["nodes"])

    def broken(topic: str, payload: Any) -> Any:
        raise RuntimeError("decoder bug")
    died = run(broken)
    assert died["engine_error"] == "RuntimeError: decoder bug"
    assert {n["status"] for n in died["nodes"]} == {"error"}
    assert any("verdict engine stopped" in line for line in lines)


def test_verdict_connections_get_tcp_nodelay() -> None:
    """The verdict publisher's subscriber sockets (rospy keeps them as
    ``impl.connections[*].socket``) get TCP_NODELAY; anything else is left alone."""
    import socket
    from types import SimpleNamespace

    from rclverify.runtime.live_ros1 import _no_delay
    server = socket.create_server(("127.0.0.1", 0))
    client = socket.create_connection(server.getsockname())
    peer, _ = server.accept()
    try:
        assert peer.getsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY) == 0
        pub = SimpleNamespace(impl=SimpleNamespace(connections=[SimpleNamespace(socket=peer), SimpleNamespace()]))
        _no_delay(pub)
        assert peer.getsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY) == 1
        _no_delay(SimpleNamespace())  # a publisher without rospy's internals: nothing to do, no error
    finally:
        for s in (client, peer, server):
            s.close()


def test_a_message_arriving_as_the_first_tick_reads_the_clock_does_not_stop_the_engine(
        case_study: tuple[Any, Any], tmp_path: Path) -> None:
    """The timer must not pass a message still queued, so its clock is held at the last message pushed.
    When the first message arrives just as the first tick reads the clock (nothing pushed yet), that
    clock was minus infinity, and the engine died of it (``OverflowError: cannot convert float infinity
    to integer``: every verdict of the live run lost; found by a whole-suite run, where the live DDS
    test's monitor heard nothing).  Here the clock itself offers that message when the timer reads it."""
    from rclverify.runtime.live import LiveRun
    from rclverify.runtime.worker import EngineWorker
    checked, cfg = case_study
    live = LiveRun(checked, list(checked.nodes.values()), cfg.rules, cfg.horizon, tmp_path / "x.jsonl",
                   reorder_window=0.0, publish=lambda _: None)
    ticks: list[float] = []
    tick = live.tick
    live.tick = lambda now: (ticks.append(now), tick(now))[1]  # type: ignore[method-assign]
    events = list(read_trace(TRACES / "nominal.jsonl", MSG))[:5]
    offered: list[int] = []

    def clock() -> float:
        if not offered:  # the first reading of the clock: a message arrives at that moment
            offered.append(1)
            worker.offer(events[0].topic, events[0].fields, events[0].time)
        return events[-1].time
    worker = EngineWorker(live, lambda topic, fields: fields, clock, tick_s=0.001)
    worker.start()
    deadline = time.monotonic() + 10
    while worker.handled < 1 and time.monotonic() < deadline:
        time.sleep(0.005)
    for ev in events[1:]:
        worker.offer(ev.topic, ev.fields, ev.time)
    worker.stop()
    record = live.stop()
    assert worker.error is None and record["events"] == len(events)
    assert ticks and all(math.isfinite(t) for t in ticks), ticks


@pytest.mark.parametrize("linger", [1.5, 0.0])
def test_a_lingering_engine_thread_lets_messages_gather_before_taking_them(
        case_study: tuple[Any, Any], tmp_path: Path, linger: float) -> None:
    """With ``linger_s`` the worker, having taken a message, takes the next one only once the linger is over
    (the timer and the release far away); without it (the control) at once."""
    from rclverify.runtime.live import LiveRun
    from rclverify.runtime.worker import EngineWorker
    checked, cfg = case_study
    live = LiveRun(checked, list(checked.nodes.values()), cfg.rules, cfg.horizon, tmp_path / "l.jsonl",
                   reorder_window=100.0, publish=lambda _: None)
    events = list(read_trace(TRACES / "nominal.jsonl", MSG))[:2]
    worker = EngineWorker(live, lambda topic, fields: fields, lambda: 0.0, tick_s=100.0, linger_s=linger).start()

    def handled(n: int, within: float) -> float:
        t0 = time.monotonic()
        while worker.handled < n and time.monotonic() - t0 < within:
            time.sleep(0.005)
        assert worker.handled >= n
        return time.monotonic() - t0
    try:
        worker.offer(events[0].topic, events[0].fields, 0.0)
        handled(1, 10.0)
        time.sleep(0.2)  # the worker is past its batch: napping (linger) or waiting on the queue
        worker.offer(events[1].topic, events[1].fields, 0.0)
        if linger:
            time.sleep(0.3)
            assert worker.handled == 1  # gathering
            handled(2, 10.0)
        else:
            assert handled(2, 10.0) < 1.0
    finally:
        worker.stop()
        live.stop()


@pytest.mark.parametrize("bound, linger", [(0.05, 0.004), (0.01, 0.001), (0.0, 0.0)])
def test_a_source_lingers_a_tenth_of_the_lateness_bound_at_most_4_ms(bound: float, linger: float) -> None:
    """The DDS bus thread and the rclpy agent hold samples not yet queued: their wait stays well inside the
    bound that makes a message late, and is none without a bound (messages judged as heard)."""
    from rclverify.runtime.dds.live import source_linger
    assert source_linger(bound) == pytest.approx(linger)
