"""Calls' and goals' deadlines kept in simulated time (backends/monitors/dds_calls.py, CallBook.clock;
docs/semantics.md, "Deadlines in simulated time").

A server said to keep ``/clock`` time (the mapping's ``use_sim_time``) has the ``within d`` of a guarantee
its request (its goal) triggers judged in simulated time, by the rule of its topics: Base serves ``estop``
within 200 ms; at a real-time factor of 0.5 a reply 300 ms after its request on the wall clock is 150 ms of
simulated time, in time; at a factor of 2 a reply 150 ms after is 300 ms, late.  Controls: the same calls
with the node said to keep the run's clock give the other verdicts; a node whose clock is not said is
decided only where both clocks agree.  The ``/clock`` lines the book writes replay to the same verdicts
(live = log), through the call taps' reorder buffer too (samples handed out of order are taken in their
stamps' order, among the calls'), and through a ``--record`` bag's decisions (live = bag).  An oracle: on
random small runs (random ``/clock`` samples, pauses and a reset included, one to three calls, each
answered or not) the counts equal the rule enumerated over every delivery delay of ``/clock`` to the
node within the transport skew."""
from __future__ import annotations

import json
import random
from collections import Counter
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.dds_calls import CallBook, replay
from rclverify.lang.typecheck import load
from rclverify.traces.mapping import load_rules

WS = Path(__file__).parent.parent / "data" / "dds_ws"
CHECKED = load([WS / "contracts" / "dds.rcl"])
LINKS = [(n, lk) for n in CHECKED.nodes.values() for lk in n.node.links]
D_MS = 200  # Base serves estop within 200 ms; Mover's goal: within 2 s


def _rules(sim: Any, skew: float = 0.0) -> Any:
    rules = load_rules({})
    rules.skew = skew
    rules.sim_time = sim
    return rules


def _clock(value_ms: float) -> dict[str, Any]:
    ns = round(value_ms * 1_000_000)
    return {"clock": {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}}


def _book(sim: Any, lines: list[dict[str, Any]], skew: float = 0.0) -> CallBook:
    seen = lines

    def deadline(v: Any) -> None:
        seen.append({"topic": "rclverify/verdict", "kind": "deadline", "time": 0.0, "verdict": v.to_json()})
    return CallBook(CHECKED, LINKS, _rules(sim, skew), 1.0, on_deadline=deadline, on_event=lines.append)


def _verdicts(lines: list[dict[str, Any]]) -> list[dict[str, Any]]:
    return [x["verdict"] for x in lines if x.get("kind") == "deadline"]


def _same(verdicts: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The verdicts as the replay must give them again: a ``currently_false``'s time left is read at the
    book's last clock, which the log moves only where it decided something, so its reason is left out."""
    return [{k: x for k, x in v.items() if not (k == "reason" and v["verdict"] == "currently_false")}
            for v in verdicts]


def _run(rate: float, answer_ms: int | None, end_ms: int = 1500, start_ms: int = 0,
         pause: tuple[int, int] | None = None) -> list[tuple[int, int, str, Any]]:
    """``/clock`` every 10 ms from ``start_ms`` (wall ms) at real-time factor ``rate`` (standing still over
    ``pause``), an estop request at 100 ms, its reply at ``answer_ms`` (or none), the run's end at
    ``end_ms``: ``(ms, order, kind, value)`` in the run's order."""
    out: list[tuple[int, int, str, Any]] = []
    value = 1000.0
    for t in range(start_ms, end_ms + 1, 10):
        if not (pause and pause[0] <= t < pause[1]) and t > start_ms:
            value += 10 * rate
        out.append((t, 0, "clock", value))
    out.append((100, 1, "request", 1))
    if answer_ms is not None:
        out.append((answer_ms, 2, "response", 1))
    out.append((end_ms, 3, "end", None))
    return sorted(out, key=lambda x: x[:2])


def _play(book: CallBook, run: list[tuple[int, int, str, Any]], t0: float = 50.0) -> dict[str, Any]:
    for ms, _, kind, v in run:
        t = t0 + ms / 1000
        if kind == "clock":
            book.clock(t, _clock(v))
        elif kind == "request":
            book.open("/estop", (7, v), f"estop call 7:{v}", {"data": True}, t)
        elif kind == "response":
            book.answer((7, v), "response", {"success": True, "message": ""}, t, name="/estop")
        elif kind == "goal":
            book.open("/move", (f"g{v}",), f"move goal g{v}", {"target": 1.0}, t, "goal")
        elif kind == "feedback":
            book.answer((f"g{v}",), "feedback", {"progress": 0.5}, t, False, "/move")
        else:
            book.tick(t)
    return book.finish()


def _judge(run: list[tuple[int, int, str, Any]], sim: Any, skew: float = 0.0,
           node: str = "Base") -> tuple[dict[str, int], dict[str, int], list[dict[str, Any]]]:
    lines: list[dict[str, Any]] = []
    summary = _play(_book(sim, lines, skew), run)
    again: list[dict[str, Any]] = []
    assert replay(_book(sim, again, skew), lines) == summary  # live = log, with its clock lines
    assert _same(_verdicts(again)) == _same(_verdicts(lines))
    res = next(d for d in summary["deadlines"] if d["node"] == node)
    return res["counts"], res["unaccepted"], _verdicts(lines)


def test_half_speed_a_reply_late_on_the_wall_clock_is_in_time_in_simulated_time() -> None:
    counts, _, seen = _judge(_run(0.5, 400), True)  # 300 ms wall = 150 ms simulated
    assert (counts["true"], counts["false"]) == (1, 0)
    assert "in simulated time (use_sim_time)" in seen[0]["reason"]
    counts, _, _ = _judge(_run(0.5, 400), False)  # control: said to keep the run's clock
    assert (counts["true"], counts["false"]) == (0, 1)


def test_double_speed_a_reply_in_time_on_the_wall_clock_is_late_in_simulated_time() -> None:
    counts, _, seen = _judge(_run(2.0, 250), True)  # 150 ms wall = 300 ms simulated
    assert (counts["true"], counts["false"]) == (0, 1)
    assert "/clock" in seen[0]["reason"]
    counts, _, _ = _judge(_run(2.0, 250), False)  # control
    assert (counts["true"], counts["false"]) == (1, 0)


def test_an_unanswered_call_is_false_only_once_clock_passes_its_deadline() -> None:
    counts, _, _ = _judge(_run(0.5, None, end_ms=480), True)  # /clock 190 ms simulated past the request
    assert counts["false"] == 0 and counts["currently_false"] == 1
    counts, _, _ = _judge(_run(0.5, None, end_ms=520), True)  # 210 ms simulated past: missed
    assert counts["false"] == 1
    counts, _, _ = _judge(_run(0.5, None, end_ms=480), False)  # control: 380 ms on the run's clock
    assert counts["false"] == 1


def test_a_paused_clock_keeps_the_call_open_past_the_books_linger() -> None:
    # paused from 150 ms to 12 s: no false, and the call is not closed as unanswered by the book's tick at
    # 12 s (past its linger on the run's clock), so its reply once the clock runs again is judged
    run = _run(1.0, None, end_ms=12_000, pause=(150, 20_000))
    counts, _, _ = _judge(run, True)
    assert (counts["false"], counts["currently_false"]) == (0, 1)
    resumed = sorted(_run(1.0, 12_150, end_ms=12_400, pause=(150, 12_100)) + [(12_000, 3, "end", None)],
                     key=lambda x: x[:2])  # 50 ms simulated before the pause, 50 after: in time
    counts, _, _ = _judge(resumed, True)
    assert (counts["true"], counts["false"]) == (1, 0)
    counts, _, _ = _judge(run, False)  # control: the run's clock
    assert counts["false"] == 1
    counts, _, _ = _judge(resumed, False)
    assert (counts["true"], counts["false"]) == (0, 1)


def test_not_said_is_decided_only_where_both_clocks_agree() -> None:
    counts, unaccepted, seen = _judge(_run(0.5, 400), None)  # in time simulated, late on the wall clock
    assert (counts["true"], counts["false"], unaccepted["undecided"]) == (0, 0, 1)
    assert "use_sim_time" in seen[0]["reason"]
    assert _judge(_run(0.5, 250), None)[0]["true"] == 1  # in time in both
    assert _judge(_run(0.5, 600), None)[0]["false"] == 1  # 500 ms wall, 250 ms simulated: late in both


def test_no_clock_before_the_request_of_a_node_said_to_keep_it_is_undecided_with_why() -> None:
    counts, unaccepted, seen = _judge(_run(1.0, 150, start_ms=150), True)
    assert (counts["true"], counts["false"], unaccepted["undecided"]) == (0, 0, 1)
    assert "no /clock message was heard before it" in seen[0]["reason"]
    assert _judge(_run(1.0, 150, start_ms=150), False)[0]["true"] == 1  # control: the run's clock


def test_a_reset_leaves_open_calls_undecided_and_later_calls_too() -> None:
    run = [(0, 0, "clock", 5000.0), (100, 1, "request", 1), (110, 0, "clock", 5010.0), (120, 0, "clock", 0.0),
           (200, 1, "request", 2), (210, 0, "clock", 90.0), (900, 0, "clock", 790.0), (1000, 3, "end", None)]
    counts, unaccepted, seen = _judge(run, True)
    assert counts["false"] == 0 and unaccepted["undecided"] == 2
    assert all("went back" in v["reason"] for v in seen)
    counts, _, _ = _judge(run, False)  # control: the run's clock
    assert counts["false"] == 2


def test_a_goal_of_an_action_server_keeps_simulated_time_too() -> None:
    # Mover: feedback within 2 s of the goal; factor 0.5: feedback 3 s after is 1.5 s simulated
    run = [x for x in _run(0.5, None, end_ms=4000) if x[2] != "request"]
    run = sorted(run + [(100, 1, "goal", 1), (3100, 2, "feedback", 1)], key=lambda x: x[:2])
    counts, _, _ = _judge(run, True, node="Mover")
    assert (counts["true"], counts["false"]) == (1, 0)
    counts, _, _ = _judge(run, False, node="Mover")  # control
    assert (counts["true"], counts["false"]) == (0, 1)


def test_a_book_of_wall_clock_nodes_takes_no_clock_line() -> None:
    lines: list[dict[str, Any]] = []
    _play(_book(False, lines), _run(0.5, 400))
    assert not [x for x in lines if x.get("part") == "clock"]
    lines = []  # control: said to keep simulated time, each change of /clock is a line (a repeated value is not)
    book = _book(True, lines)
    for t, v in ((1.0, 10.0), (1.01, 10.0), (1.02, 20.0)):
        book.clock(t, _clock(v))
    assert [x["clock"] for x in lines if x.get("part") == "clock"] == [
        {"sec": 0, "nanosec": 10_000_000}, {"sec": 0, "nanosec": 20_000_000}]


FAST = bytes.fromhex("010f78fd00000001000000000000") + b"\x14\x03"  # an eProsima writer GUID (vendor 0x010f)


@pytest.mark.parametrize("rate, answer_ms, sim_verdict", [(0.5, 400, "true"), (2.0, 250, "false")])
def test_the_call_taps_take_clock_among_the_calls_in_stamp_order(rate: float, answer_ms: int,
                                                                   sim_verdict: str) -> None:
    """Live, /clock and the calls' samples come off the bus on different readers; the taps take them in
    their stamps' order, so the book judges as the same run given in the run's order."""
    pytest.importorskip("cyclonedds", reason="the cyclonedds binding is not installed")
    from rclverify.runtime.dds.services import CallTaps
    from rclverify.runtime.dds.types import TypeBook
    types = TypeBook([WS / "interfaces"])
    req, rep = types.struct("std_srvs/srv/SetBool_Request"), types.struct("std_srvs/srv/SetBool_Response")
    server, client = FAST[:-2] + b"\x13\x03", FAST
    for sim, want in ((True, sim_verdict), (False, "false" if sim_verdict == "true" else "true")):
        lines: list[dict[str, Any]] = []
        taps = CallTaps(_book(sim, lines), types, LINKS, framed=False)
        taps._pairer("/estop").hearing(client, 10.0)
        run = _run(rate, answer_ms, end_ms=800)
        t0 = 20.0
        # every sample handed on 40 ms late, the reply and the request swapped, /clock in reverse pairs
        handed = []
        for ms, _, kind, v in run:
            t = t0 + ms / 1000
            if kind == "clock":
                handed.append((t + 0.04 + (0.005 if (ms // 10) % 2 == 0 else 0.0), "clock", t, v))
            elif kind == "request":
                handed.append((t0 + answer_ms / 1000 + 0.05, "request", t, v))
            elif kind == "response":
                handed.append((t + 0.04, "response", t, v))
        for got, kind, t, v in sorted(handed):
            if kind == "clock":
                taps.clock(_clock(v), t, got)
            elif kind == "request":
                taps.handle("call:/estop:request", req(data=True).serialize(), t, got, client)
            else:
                taps.handle("call:/estop:reply", rep(success=True, message="").serialize(), t, got, server)
            taps.tick(got)
        taps.tick(t0 + 2.0)
        summary = taps.finish()
        got_v = [v["verdict"] for v in _verdicts(lines) if not v["update"]]
        assert got_v == [want], (sim, got_v)
        assert replay(_book(sim, []), lines) == summary
        in_order: list[dict[str, Any]] = []  # the same run given to a book in the run's order
        _play(_book(sim, in_order), run, t0)
        assert [v["verdict"] for v in _verdicts(in_order) if not v["update"]] == got_v


@pytest.mark.parametrize("storage", ["sqlite3"])
def test_a_recorded_bag_replays_the_calls_clock(storage: str, tmp_path: Path) -> None:
    """live = bag: the book's clock lines go to the bag's decisions topic and come back in its order."""
    pytest.importorskip("cyclonedds", reason="the cyclonedds binding is not installed")
    from rclverify.backends.monitors.bag_calls import BagCalls, bag_connections
    from rclverify.backends.monitors.log_calls import LogCalls
    from rclverify.runtime.dds.bag import BagRecorder
    from rclverify.runtime.dds.bag_calls import CallRecorder
    from rclverify.runtime.dds.types import TypeBook
    from rclverify.traces import read_trace
    for sim, rate, answer in ((True, 0.5, 400), (True, 2.0, 250), (False, 0.5, 400)):
        types = TypeBook([WS / "interfaces"])
        calls = CallRecorder(types, LINKS)
        path = tmp_path / f"run_{sim}_{rate}"
        rec = BagRecorder(path, storage, {}, [WS / "interfaces"], calls=calls.plan)
        calls.write = rec.write
        lines: list[dict[str, Any]] = []

        def line(obj: dict[str, Any], lines: list[dict[str, Any]] = lines, calls: Any = calls) -> None:
            lines.append(obj)
            calls.line(obj)
        book = _book(sim, [])
        book.on_event = line
        live = _play(book, _run(rate, answer), t0=1_795_000_000.0)
        rec.close()
        assert calls.failed == 0
        rules = _rules(sim)
        log_calls = LogCalls(CHECKED, list(CHECKED.nodes.values()), rules, 1.0, str(path))
        bag = BagCalls(list(CHECKED.nodes.values()), log_calls, str(path),
                       bag_connections(path, [WS / "interfaces"]))
        for _ in bag.tap(read_trace(path, [WS / "interfaces"])):
            pass
        from_bag = log_calls.finish()
        assert from_bag is not None
        assert from_bag["deadlines"] == live["deadlines"], (sim, rate)
        base = next(d for d in live["deadlines"] if d["node"] == "Base")["counts"]
        want = (1, 0) if (rate == 0.5) == bool(sim) else (0, 1)
        assert (base["true"], base["false"]) == want


def _oracle(samples: list[tuple[int, int]], q: int, a: int | None, end: int, skew: int,
            mode: bool | None) -> str:
    """One call's verdict by enumeration (integer ms): the node's /clock read at wall time t with a delivery
    delay delta in [0, skew] is the value of the last sample at or before t - delta.  A sample whose value
    goes back (a reset, at ``r``) ends simulated time: a request from ``r`` on is undecided, and so is one
    before it still open at ``r`` whose simulated deadline no sample before ``r`` passed."""
    r = next((w for (w, v), (_, u) in zip(samples[1:], samples) if v < u), None)
    if mode is False:
        if a is not None:
            return "true" if a <= q + D_MS else "false"
        return "false" if end > q + D_MS else "currently_false"
    if r is not None and r <= q:
        return "undecided"
    pre = [s for s in samples if r is None or s[0] < r]

    def clock(t: int) -> int | None:
        got = [v for (w, v) in pre if w <= t]
        return got[-1] if got else None
    sq = clock(q)
    if sq is None and mode is True:
        return "undecided"
    if sq is None:  # not said, before /clock: the run's clock until /clock is first heard, then never false
        first = samples[0][0]
        if a is not None:
            return "true" if a <= q + D_MS else "false" if a < first else "undecided"
        return "undecided" if end > q + D_MS else "currently_false"
    if r is not None and (a is None or a >= r) and not any(v > sq + D_MS for _, v in pre):
        return "undecided"  # open at the reset, its simulated deadline not passed

    def late(t: int) -> set[bool]:  # late in simulated time at t, for each delivery delay
        assert sq is not None
        return {(v is not None and v > sq + D_MS) for v in (clock(t - delta) for delta in range(skew + 1))}
    if a is not None:
        wall_late = a > q + D_MS
        lt = late(a)
        if mode is True:
            return "false" if lt == {True} else "true" if lt == {False} else "undecided"
        if lt == {False} and not wall_late:
            return "true"
        if lt == {True} and wall_late:
            return "false"
        return "undecided"
    passed = late(end) == {True}
    return "false" if passed and (mode is True or end > q + D_MS) else "currently_false"


@pytest.mark.parametrize("seed", range(10))
def test_oracle_random_runs_match_the_rule_enumerated(seed: int) -> None:
    rnd = random.Random(seed)
    for case in range(50):
        samples, value = [], rnd.randrange(0, 100)
        for t in sorted(rnd.sample(range(0, 1200), rnd.randrange(1, 50))):
            value += rnd.choice((0, 0, 10, 20, 40, 80))
            samples.append((t, value))
        if rnd.random() < 0.1 and len(samples) > 2:  # a reset
            k = rnd.randrange(1, len(samples))
            samples = samples[:k] + [(w, v - samples[k][1]) for w, v in samples[k:]]
        skew = rnd.choice((0, 3, 8))
        mode = rnd.choice((True, False, None))
        calls = []
        for n in range(rnd.randrange(1, 4)):
            q = rnd.randrange(0, 700)
            a = rnd.choice((None, q + rnd.randrange(0, 500)))
            calls.append((q, a, n + 1))
        end = max([samples[-1][0]] + [max(q, a or 0) for q, a, _ in calls]) + rnd.randrange(0, 300)
        run: list[tuple[int, int, str, Any]] = [(w, 0, "clock", v) for w, v in samples]
        for q, a, n in calls:
            run.append((q, 1, "request", n))
            if a is not None:
                run.append((a, 2, "response", n))
        run.append((end, 3, "end", None))
        run.sort(key=lambda x: x[:2])
        counts, unaccepted, seen = _judge(run, mode, skew / 1000)
        got = Counter({"true": counts["true"], "false": counts["false"],
                       "currently_false": counts["currently_false"], "undecided": unaccepted["undecided"]})
        want = Counter(_oracle(samples, q, a, end, skew, mode) for q, a, _ in calls)
        assert +got == +want, (seed, case, samples, calls, end, skew, mode, [v["reason"] for v in seen])
        controls = [_oracle(samples, q, a, end, skew, False) for q, a, _ in calls]  # the run's clock
        assert +Counter(controls) == +Counter({k: v for k, v in _judge(run, False)[0].items()
                                               if k in ("true", "false", "currently_false")})


def test_a_bag_ros2_bag_record_made_reads_its_clock_among_the_calls(tmp_path: Path) -> None:
    """A bag without the book's decisions (``ros2 bag record --services`` of a server under use_sim_time):
    its /clock messages are read among its service events by their times, so the calls' deadlines are
    judged in simulated time as live; the control, said to keep the run's clock, gives the other verdict."""
    pytest.importorskip("cyclonedds", reason="the cyclonedds binding is not installed")
    pytest.importorskip("rosbags", reason="rosbags is not installed (the ros extra)")
    from rosbags.rosbag2 import StoragePlugin, Writer

    from rclverify.backends.monitors.bag_calls import BagCalls, bag_connections
    from rclverify.backends.monitors.log_calls import LogCalls
    from rclverify.runtime.dds.bag_types import definition
    from rclverify.runtime.dds.introspection import event_struct
    from rclverify.runtime.dds.types import TypeBook
    from rclverify.traces import read_trace
    from rclverify.traces.bag import typestore
    types = TypeBook([WS / "interfaces"])
    cls = event_struct(types, "std_srvs/SetBool")
    msgdef, digest = definition(types, "std_srvs/srv/SetBool_Event")
    store = typestore([])
    t0, ms = 1_700_000_000_000_000_000, 1_000_000
    for rate, answer, sim_verdict in ((0.5, 400, "true"), (2.0, 250, "false")):
        path = tmp_path / f"b{rate}"
        with Writer(path, version=8, storage_plugin=StoragePlugin.MCAP) as w:
            conn = w.add_connection("/estop/_service_event", "std_srvs/srv/SetBool_Event", msgdef=msgdef,
                                    rihs01=digest)
            cconn = w.add_connection("/clock", "rosgraph_msgs/msg/Clock", typestore=store)
            Clock = store.types["rosgraph_msgs/msg/Clock"]
            Time = store.types["builtin_interfaces/msg/Time"]
            for t_ms, _, kind, v in _run(rate, answer, end_ms=800):
                t = t0 + t_ms * ms
                if kind == "clock":
                    c = _clock(v)["clock"]
                    w.write(cconn, t, store.serialize_cdr(Clock(clock=Time(sec=c["sec"], nanosec=c["nanosec"])),
                                                          "rosgraph_msgs/msg/Clock"))
                elif kind in ("request", "response"):
                    data = {"info": {"event_type": 1 if kind == "request" else 2,
                                     "stamp": {"sec": t // 10**9, "nanosec": t % 10**9},
                                     "client_gid": list(range(1, 17)), "sequence_number": 1},
                            "request": [{"data": True}] if kind == "request" else [],
                            "response": [{"success": True, "message": ""}] if kind == "response" else []}
                    w.write(conn, t, bytes(types.build(cls, data).serialize()))
        for sim, want in ((True, sim_verdict), (False, "false" if sim_verdict == "true" else "true")):
            lines: list[dict[str, Any]] = []
            log_calls = LogCalls(CHECKED, list(CHECKED.nodes.values()), _rules(sim), 1.0, str(path))
            assert log_calls.book is not None
            log_calls.book.on_deadline = lambda v, lines=lines: lines.append(v.to_json())
            bag = BagCalls(list(CHECKED.nodes.values()), log_calls, str(path), bag_connections(path, []))
            for _ in bag.tap(read_trace(path, [])):
                pass
            assert log_calls.finish() is not None
            assert [v["verdict"] for v in lines if not v["update"]] == [want], (rate, sim, lines)
