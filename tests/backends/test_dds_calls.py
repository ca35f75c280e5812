"""Calls and goals checked one by one, the ``--enforce`` gate and the bag
recorder, without a bus (docs/monitors.md, "ROS 2 over DDS").

The call book pairs answers with requests by identity, never by order:
two clients whose calls interleave get each its own verdict; the same
calls replayed from the log give the same summary; the gate lets through
exactly what is shown to satisfy the guarantee; a recorded SQLite 3 bag is
read back by the offline monitor with the live times.
"""
from __future__ import annotations

import random
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.check import check_trace
from rclverify.backends.monitors.dds_calls import CallBook, link_view, replay
from rclverify.runtime.enforce import EnforceUsage, judge, parse_enforce
from rclverify.backends.monitors.online import OnlineEngine
from rclverify.lang.typecheck import load
from rclverify.traces import read_trace
from rclverify.traces.events import Event

WS = Path(__file__).parent.parent / "data" / "dds_ws"
CHECKED = load([WS / "contracts" / "dds.rcl"])
LINKS = [(n, lk) for n in CHECKED.nodes.values() for lk in n.node.links]


def _book(lines: list[dict[str, Any]], horizon: float = 1.0) -> CallBook:
    book = CallBook(CHECKED, LINKS, {}, horizon)
    book.on_verdict = lambda v: lines.append({"topic": "rclverify/verdict", "time": v.decided_at,
                                              "verdict": v.to_json()})
    book.on_deadline = lambda v: lines.append({"topic": "rclverify/verdict", "time": book.now if book.now > 0 else
                                               v.trigger_stamp, "kind": "deadline", "verdict": v.to_json()})
    book.on_event = lines.append
    return book


def test_interleaved_calls_are_paired_by_identity_not_by_order() -> None:
    lines: list[dict[str, Any]] = []
    book = _book(lines)
    # client A asks, client B asks, B is answered wrong first, then A right
    book.open("/estop", (0xA, 1), "estop call a:1", {"data": True}, 10.00)
    book.open("/estop", (0xB, 1), "estop call b:1", {"data": True}, 10.01)
    book.answer((0xB, 1), "response", {"success": False, "message": ""}, 10.05)
    book.answer((0xA, 1), "response", {"success": True, "message": ""}, 10.06)
    book.tick(11.5)
    summary = book.finish()
    base = {x["verdict"]["where"]: x["verdict"]["verdict"] for x in lines
            if "verdict" in x and x["verdict"].get("node") == "Base" and "kind" not in x}
    assert base == {"estop call a:1 response": "satisfied", "estop call b:1 response": "violated"}
    # by order, B's wrong answer would have been A's, and A's right one B's: both judged wrongly
    deadlines = [x["verdict"] for x in lines if x.get("kind") == "deadline"]
    assert sorted((d["trigger_where"], d["verdict"]) for d in deadlines) == [
        ("estop call a:1 request", "true"), ("estop call b:1 request", "false")]
    assert summary["counts"]["calls"] == 2 and summary["counts"]["answered"] == 2
    assert replay(_book([]), lines) == summary  # the offline replay of the log's lines


def test_a_call_without_answer_is_unanswered_and_false_and_an_answer_without_call_counted() -> None:
    lines: list[dict[str, Any]] = []
    book = _book(lines)
    book.open("/estop", (1, 1), "estop call 1:1", {"data": True}, 5.0)
    book.tick(5.3)  # past the 200 ms deadline: false at once
    assert [x["verdict"]["verdict"] for x in lines if x.get("kind") == "deadline"] == ["false"]
    book.tick(6.5)  # past the horizon: unanswered, inconclusive (the deadline above is what fails it)
    assert [x["verdict"]["verdict"] for x in lines if x.get("verdict", {}).get("node") == "Base"
            and "kind" not in x] == ["inconclusive"]
    assert not book.answer((9, 9), "response", {"success": True, "message": ""}, 6.6, name="/estop")
    assert book.finish()["counts"]["orphan_answers"] == 1


def test_a_random_call_sequence_replays_to_the_same_verdicts() -> None:
    """Random interleavings of calls, right, wrong, late and missing answers,
    a goal with feedback: the live book's lines replayed give the same summary."""
    rng = random.Random(3)
    for _ in range(20):
        lines: list[dict[str, Any]] = []
        book = _book(lines)
        t, open_ = 100.0, []
        for k in range(rng.randint(2, 8)):
            t += rng.uniform(0.0, 0.3)
            if open_ and rng.random() < 0.5:
                key = open_.pop(rng.randrange(len(open_)))
                book.answer(key, "response", {"success": rng.random() < 0.7, "message": ""}, t)
            else:
                key = (rng.randrange(3), k)
                book.open("/estop", key, f"estop call {key[0]}:{key[1]}", {"data": rng.random() < 0.8}, t)
                open_.append(key)
            if rng.random() < 0.4:
                book.tick(t)
        gid = ("g",)
        book.open("/move", gid, "move goal g", {"target": rng.choice([-1.0, 2.0])}, t, "goal")
        book.answer(gid, "feedback", {"progress": rng.choice([-0.5, 0.5])}, t + 0.1, final=False)
        book.answer(gid, "result", {"arrived": True}, t + 0.2)
        book.tick(t + 3.0)
        assert replay(_book([]), lines) == book.finish()


def test_a_link_view_is_the_node_through_its_link() -> None:
    base = CHECKED.nodes["Base"]
    view = link_view(base, base.node.links[0])
    assert [(t.field, t.match.qualified) for t in view.node.topics] == [("estop/request", "in.stop_req"),
                                                                         ("estop/response", "out.stopped")]
    teleop = CHECKED.nodes["Teleop"]
    assert link_view(teleop, teleop.node.links[0]).node.guarantees == ()  # a client is held to its assumption


def _engine() -> OnlineEngine:
    return OnlineEngine(CHECKED, [CHECKED.nodes["Limiter"], CHECKED.nodes["Ranger"]], {}, 1.0)


def test_the_gate_releases_only_what_is_shown_to_hold() -> None:
    eng = _engine()
    ev = lambda k, topic, v: Event(k, float(k), topic, {"data": v}, f"m{k}")  # noqa: E731
    ok, why = judge(eng.monitors, CHECKED, ev(0, "speed", 0.5), {})
    assert not ok and why["verdict"] == "incomplete input"  # no limit received yet: nothing shows it holds
    eng.push("limit", {"data": 1.0}, 1.0)
    for k, (v, want) in enumerate([(0.5, True), (1.0, True), (1.5, False), (float("nan"), False)], 2):
        ok, why = judge(eng.monitors, CHECKED, ev(k, "speed", v), {})
        assert ok is want, (v, why)
        if not ok and v == 1.5:
            assert why["verdict"] == "violated" and why["values"] == {"in.limit": "1.0", "out.speed": "1.5"}
    assert judge(eng.monitors, CHECKED, ev(9, "range", -1.0), {})[0] is False
    assert judge(eng.monitors, CHECKED, ev(9, "range", 0.0), {})[0] is True
    assert parse_enforce(["/speed", "/cmd:=/cmd_raw"]) == {"speed": "/speed_unchecked", "cmd": "/cmd_raw"}
    for bad in ("/speed:=/speed", ":=/x"):
        with pytest.raises(EnforceUsage):
            parse_enforce([bad])


def test_the_gate_fails_closed_on_an_input_it_cannot_judge_against() -> None:
    """Issue 47: 0.9 was released after ``limit = NaN`` (judged against the stale
    1.0), 5.0 after ``limit = +inf`` blocked as violated with ``in.limit: 1.0``.
    Both are held back as inconclusive now, naming the input; a valid limit
    after it is judged again; ``@open`` releases what cannot be decided."""
    from rclverify.runtime.enforce import fail_open
    eng = _engine()
    ev = lambda k, topic, v: Event(k, float(k), topic, {"data": v}, f"m{k}")  # noqa: E731
    eng.push("limit", {"data": 1.0}, 1.0)
    for k, bad in ((2, float("nan")), (4, float("inf"))):
        eng.push("limit", {"data": bad}, float(k))
        for v in (0.9, 5.0):
            ok, why = judge(eng.monitors, CHECKED, ev(k + 1, "speed", v), {})
            assert not ok and why["verdict"] == "inconclusive", (bad, v, why)
            assert "in.limit" in why["reason"] and "stale" in why["reason"]
    eng.push("limit", {"data": 2.0}, 6.0)
    assert judge(eng.monitors, CHECKED, ev(7, "speed", 0.9), {})[0] is True
    assert judge(eng.monitors, CHECKED, ev(7, "speed", 5.0), {})[1]["verdict"] == "violated"
    assert fail_open(["/speed@open", "/cmd:=/cmd_raw"]) == {"speed"}
    assert parse_enforce(["/speed@open"]) == {"speed": "/speed_unchecked"}


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_a_recorded_bag_reads_back_with_the_live_times(storage: str, tmp_path: Path) -> None:
    pytest.importorskip("cyclonedds", reason="the cyclonedds binding is not installed")
    from rclverify.runtime.dds.bag import BagError, BagRecorder
    from rclverify.runtime.dds.types import TypeBook
    book = TypeBook([])
    F64 = book.message("std_msgs/Float64")
    rec = BagRecorder(tmp_path / "run", storage, {"limit": "std_msgs/Float64", "speed": "std_msgs/Float64"}, [])
    sent = [("limit", 1.0), ("speed", 0.5), ("limit", 2.0), ("speed", 2.5)]
    times = [1_795_000_000_123_456_789 + k * 50_000_000 for k in range(len(sent))]
    for (topic, v), t in zip(sent, times):
        rec.write(topic, t, F64(data=v).serialize(use_version_2=False))
    assert rec.close()["messages"] == 4
    events = list(read_trace(tmp_path / "run"))
    assert [(e.topic, e.time, e.fields) for e in events] == [(tp, t / 1e9, {"data": v}) for (tp, v), t in
                                                              zip(sent, times)]
    direct = [Event(k, t / 1e9, tp, {"data": v}, f"m{k}") for k, ((tp, v), t) in enumerate(zip(sent, times))]
    _, from_bag = check_trace(CHECKED, [CHECKED.nodes["Limiter"]], events, {}, 1.0)
    _, from_live = check_trace(CHECKED, [CHECKED.nodes["Limiter"]], direct, {}, 1.0)
    # every answer judged against the question it answers: 0.5 meets the first limit, 2.5 fails the second
    # (issue 47: a wrong answer is violated whatever comes later), the same read from the bag as from the
    # messages themselves
    assert from_bag[0].counts == from_live[0].counts
    assert from_bag[0].counts["satisfied"] == 1 and from_bag[0].counts["violated"] == 1
    with pytest.raises(BagError, match="exists"):
        BagRecorder(tmp_path / "run", storage, {}, [])


# -- calls without identity (rmw_fastrtps: docs/monitors.md, "Services and actions over DDS") --------------

def test_the_order_pairs_only_what_it_makes_certain() -> None:
    from rclverify.runtime.dds.order import OrderPairer, Pending
    p = OrderPairer("/estop")
    a, b, c, d = (Pending(("w", "a", k), t, f"call {k}") for k, t in ((1, 1.0), (2, 2.0), (3, 2.1), (4, 5.0)))
    p.request(a)
    assert p.reply(1.5, b"S").answers == a  # one outstanding: certain
    assert p.reply(1.6, b"S").orphan  # nothing outstanding: an answer without a call
    p.request(b)
    p.request(c)
    two = p.reply(2.5, b"S")  # two outstanding: which one it answers cannot be known
    assert two.answers is None and two.undecided == (b, c) and "2 requests of /estop" in two.reason
    p.request(d)
    # one of b, c is still unanswered: this reply may be its, so d is undecided too, never paired by a guess
    three = p.reply(5.5, b"S")
    assert three.answers is None and three.undecided == (d,) and "could not be paired" in three.reason
    assert p.reply(5.6, b"S") == type(three)()  # the last of the pool: nothing left to decide
    p.request(Pending(("w", "a", 5), 6.0, "call 5"))
    assert p.reply(6.5, b"S").answers is not None  # certain again once the pool is spent
    p.request(Pending(("w", "a", 6), 7.0, "call 6"))
    # a second server's reply before discovery told it: it was not sent the calls heard before: an orphan,
    # counted and named, never dropped and never taken from the first server's call
    assert p.reply(7.5, b"T").orphan
    assert p.reply(7.6, b"S").answers == Pending(("w", "a", 6), 7.0, "call 6")


def test_each_discovered_server_answers_each_call() -> None:
    """Two servers of one service: each request is one call per server, each server's reply paired with its
    own; a server that leaves leaves its calls undecided, with the reason."""
    from rclverify.runtime.dds.order import OrderPairer, Pending
    p = OrderPairer("/dual", who=lambda g: g.decode())
    assert p.discovered([b"A", b"B"], 0.5) == []
    calls = p.request(Pending(("w", "c", 1), 1.0, "dual call c#1", b"c"))
    assert [c.key for c in calls] == [("w", "c", 1, b"A".hex()), ("w", "c", 1, b"B".hex())]
    assert calls[1].label == "dual call c#1 answered by B"
    assert p.reply(1.1, b"B").answers == calls[1]  # the slower server's reply first: still its own call
    assert p.reply(1.2, b"A").answers == calls[0]
    later = p.request(Pending(("w", "c", 2), 2.0, "dual call c#2", b"c"))
    (left,) = p.discovered([b"A"], 2.5)  # B left before answering
    assert left[0] == later[1] and "B, a server of /dual, left" in left[1]
    assert p.reply(2.6, b"A").answers == later[0]


def test_a_reply_in_a_clients_start_up_window_is_undecided() -> None:
    """A request written before the monitor heard its writer is not heard; its reply, within the window
    (the horizon) after the writer began to be heard, could look like the answer of a request heard."""
    from rclverify.runtime.dds.order import OrderPairer, Pending
    p = OrderPairer("/estop", window=1.0, who=lambda g: g.decode())
    p.discovered([b"S"], 0.0)
    p.hearing(b"c", 10.0)
    q = p.request(Pending(("w", "c", 1), 10.2, "call 1", b"c"))[0]
    young = p.reply(10.3, b"S")
    assert young.answers is None and young.undecided == (q,) and "began hearing the requests of c" in young.reason
    q2 = p.request(Pending(("w", "c", 2), 11.5, "call 2", b"c"))[0]
    assert p.reply(11.6, b"S").answers == q2  # past the window: certain
    # requests heard before any server was: undecided when the server appears (their replies may be unheard)
    r = OrderPairer("/late", who=lambda g: g.decode())
    early = r.request(Pending(("w", "c", 1), 1.0, "call 1", b"c"))[0]
    ((undecided, why),) = r.discovered([b"S"], 2.0)
    assert undecided == early and "before the monitor heard S" in why


@pytest.mark.parametrize("seed", range(40))
def test_the_order_pairs_only_what_every_history_agrees_on(seed: int) -> None:
    """Oracle: on small random histories of one server (requests and replies in stamp order, each reply the
    answer of a distinct earlier request), every reply the pairer pairs is paired so in EVERY complete
    matching of replies to earlier requests (brute force), and it calls a reply an orphan only where no
    request can be its."""
    import itertools
    import random
    from rclverify.runtime.dds.order import OrderPairer, Pending
    rnd = random.Random(seed)
    seq: list[str] = []
    opened = answered = 0
    for _ in range(rnd.randint(2, 7)):
        if opened > answered and rnd.random() < 0.5:
            seq.append("rep")
            answered += 1
        else:
            seq.append("req")
            opened += 1
    reqs = [i for i, x in enumerate(seq) if x == "req"]
    reps = [i for i, x in enumerate(seq) if x == "rep"]
    matchings = [m for m in itertools.permutations(reqs, len(reps)) if all(q < r for q, r in zip(m, reps))]
    assert matchings  # every prefix has no more replies than requests
    p = OrderPairer("/s")
    p.discovered([b"S"], -1.0)
    for i, x in enumerate(seq):
        if x == "req":
            p.request(Pending((i,), float(i), f"call {i}"))
            continue
        out = p.reply(float(i), b"S")
        k = reps.index(i)
        if out.answers is not None:
            assert {m[k] for m in matchings} == {out.answers.key[0]}, (seq, i)
        assert not out.orphan  # a request is always left for it in these histories


def test_an_unpaired_call_is_inconclusive_and_replays() -> None:
    lines: list[dict[str, Any]] = []
    book = _book(lines)
    book.open("/estop", ("w", "a", 1), "estop call a#1", {"data": True}, 10.0)
    book.open("/estop", ("w", "b", 1), "estop call b#1", {"data": False}, 10.01)
    book.tick(10.1)
    book.unpaired(("w", "a", 1), 10.15, "two outstanding")
    book.unpaired(("w", "b", 1), 10.15, "two outstanding")
    book.tick(12.0)
    summary = book.finish()
    base = [x["verdict"] for x in lines if x.get("verdict", {}).get("node") == "Base" and "kind" not in x]
    # the data: false call holds whatever its answer (decided on its request); the other waits: inconclusive
    assert sorted(v["verdict"] for v in base) == ["inconclusive", "satisfied"]
    assert [v["reason"] for v in base if v["verdict"] == "inconclusive"] == ["two outstanding"]
    assert summary["counts"]["unpaired"] == 2 and summary["false"] == 0  # its deadline was not yet due: undecided
    (dl,) = summary["deadlines"]
    assert dl["unaccepted"]["undecided"] == 2 and dl["first_unaccepted"]["reason"] == "two outstanding"
    assert replay(_book([]), lines) == summary


def _taps(lines: list[dict[str, Any]]) -> tuple[Any, Any]:
    pytest.importorskip("cyclonedds", reason="the cyclonedds binding is not installed")
    from rclverify.runtime.dds.services import CallTaps
    from rclverify.runtime.dds.types import TypeBook
    types = TypeBook([WS / "interfaces"])
    return CallTaps(_book(lines), types, LINKS, framed=False), types


FAST = bytes.fromhex("010f78fd00000001000000000000") + b"\x14\x03"  # an eProsima writer GUID (vendor 0x010f)


def test_plain_samples_are_taken_in_stamp_order_and_checked_by_vendor() -> None:
    lines: list[dict[str, Any]] = []
    taps, types = _taps(lines)
    req = types.struct("std_srvs/srv/SetBool_Request")
    rep = types.struct("std_srvs/srv/SetBool_Response")
    assert taps.specs["call:/estop:request"][1] is req  # the plain layout: Fast DDS's
    server, client = FAST[:-2] + b"\x13\x03", FAST
    # the monitor has heard the client's request writer since long before (its reader matched at 10 s: the
    # bus tells it, :meth:`CallTaps._discover`): no earlier request of it can be unheard
    taps._pairer("/estop").hearing(client, 10.0)
    # the reply is handed on before its request (two topics, two readers): the stamps put them in order
    taps.handle("call:/estop:reply", rep(success=False, message="").serialize(), 20.05, 20.06, server)
    taps.handle("call:/estop:request", req(data=True).serialize(), 20.0, 20.07, client)
    # a Cyclone writer's sample is of the other wire form: counted, never decoded as this one
    taps.handle("call:/estop:request", req(data=True).serialize(), 20.1, 20.1, b"\x01\x10" + FAST[2:])
    taps.tick(20.2)
    assert not [x for x in lines if x.get("part") == "request"]  # still settling
    taps.tick(22.0)
    summary = taps.finish()
    base = [x["verdict"]["verdict"] for x in lines if x.get("verdict", {}).get("node") == "Base"
            and "kind" not in x]
    assert base == ["violated"] and summary["counts"]["calls"] == 1 and taps.counts["other_form"] == 1
    assert replay(_book([]), lines) == summary


def test_introspection_events_pair_concurrent_calls_exactly() -> None:
    from types import SimpleNamespace

    from rclverify.runtime.dds.introspection import event_side, event_struct
    lines: list[dict[str, Any]] = []
    taps, types = _taps(lines)
    ev = event_struct(types, "std_srvs/SetBool")
    server, client = FAST[:-2] + b"\x13\x03", b"\x01\x0f" + bytes(range(10)) + b"\x00\x00\x14\x03"
    taps.taps = {"call:/estop:event": SimpleNamespace(heard={server[:-2] + b"\x15\x03"}),
                 "call:/estop:reply": SimpleNamespace(heard={server}, reader_changes=0, dds_topic="rr/estopReply"),
                 "call:/estop:request": SimpleNamespace(heard={client}, reader_changes=0)}

    def event(kind: int, seq: int, stamp: float, **parts: Any) -> None:
        s = types.build(ev, {"info": {"event_type": kind, "client_gid": list(client), "sequence_number": seq},
                             **{k: [v] for k, v in parts.items()}})
        taps.handle("call:/estop:event", s.serialize(), stamp, stamp, server)
    # two calls outstanding at once, answered in the other order: the events name each call
    event(1, 1, 30.00, request={"data": True})
    event(1, 2, 30.01, request={"data": True})
    event(2, 2, 30.05, response={"success": True, "message": ""})
    event(2, 1, 30.10, response={"success": False, "message": ""})
    event(3, 1, 30.11, response={"success": False, "message": ""})  # the client's own event: not read twice
    # the request/reply samples of the same calls are left to the events
    req = types.struct("std_srvs/srv/SetBool_Request")
    taps.handle("call:/estop:request", req(data=True).serialize(), 30.0, 30.0, client)
    taps.tick(32.0)
    summary = taps.finish()
    base = {x["verdict"]["where"]: x["verdict"]["verdict"] for x in lines
            if x.get("verdict", {}).get("node") == "Base" and "kind" not in x}
    gid = client.hex()
    assert base == {f"estop call {gid}:1 response": "violated", f"estop call {gid}:2 response": "satisfied"}
    assert summary["counts"]["calls"] == 2 and taps.counts["introspected"] == 1
    assert event_side([client], [server], [client]) == "client" and event_side([], [server], [client]) is None


def test_introspection_that_begins_mid_call_leaves_that_call_unpaired() -> None:
    from types import SimpleNamespace
    lines: list[dict[str, Any]] = []
    taps, types = _taps(lines)
    server = FAST[:-2] + b"\x13\x03"
    event = SimpleNamespace(heard=set())
    taps.taps = {"call:/estop:event": event, "call:/estop:reply": SimpleNamespace(heard={server}, reader_changes=0, dds_topic="rr/estopReply"),
                 "call:/estop:request": SimpleNamespace(heard={FAST}, reader_changes=0)}
    req = types.struct("std_srvs/srv/SetBool_Request")
    taps.handle("call:/estop:request", req(data=True).serialize(), 40.0, 40.0, FAST)
    taps.tick(41.0)
    assert list(taps.book.calls) == [("w", FAST.hex(), 1)]  # opened by the order's source
    event.heard = {server[:-2] + b"\x15\x03"}  # the server's event writer is discovered now
    rep = types.struct("std_srvs/srv/SetBool_Response")
    taps.handle("call:/estop:reply", rep(success=False, message="").serialize(), 41.1, 41.1, server)
    taps.tick(42.0)
    (line,) = [x for x in lines if x.get("unpaired")]
    assert "introspection events began while this call was open" in line["reason"]
    assert not taps.book.calls and taps.counts["introspected"] == 1  # the reply is left to the events


def test_a_shadow_reply_writer_exists_only_while_a_real_server_does() -> None:
    """dds_shadow.py: the monitor's request reader must not hide a service from rmw_fastrtps clients (one
    more reader than reply writers), nor may its shadow fake a server when none is there."""
    from types import SimpleNamespace

    from rclverify.runtime.dds.shadow import SHADOW, Shadows
    made: list[str] = []
    dropped: list[str] = []
    servers: list[Any] = []

    class Writer:
        def __init__(self, topic: str) -> None:
            self.topic = topic

        def __del__(self) -> None:
            dropped.append(self.topic)
    bus = SimpleNamespace(discovery=SimpleNamespace(publishers=lambda topic: list(servers)),
                          writer=lambda topic, struct, qos, user: made.append(topic) or Writer(topic))
    rq, rr = SimpleNamespace(reader=None, dds_topic="rq/sRequest"), SimpleNamespace(dds_topic="rr/sReply", struct=int)
    sh = Shadows(bus, [(rq, rr)])
    servers.append(SimpleNamespace(qos=SimpleNamespace(user_data=b"")))
    sh.update()
    assert made == []  # the monitor reads no request yet: nothing to balance
    rq.reader = object()
    sh.update()
    sh.update()
    assert made == ["rr/sReply"] and list(sh.writers) == ["rr/sReply"]
    servers[:] = [SimpleNamespace(qos=SimpleNamespace(user_data=SHADOW))]  # only another monitor's shadow left
    sh.update()
    assert sh.writers == {} and "rr/sReply" in dropped  # no server: no shadow to fake one


def test_results_of_concurrent_goals_without_identity_are_undecided_feedback_still_judged() -> None:
    """rmw_fastrtps: a get-result reply names no goal; with two get-result requests outstanding, neither
    goal's result can be told apart (their feedback, which carries the goal id, is still judged)."""
    lines: list[dict[str, Any]] = []
    taps, types = _taps(lines)
    base = "rclverify_examples/action/Move"
    goal_rq, goal_rr = types.struct(f"{base}_SendGoal_Request"), types.struct(f"{base}_SendGoal_Response")
    res_rq, res_rr = types.struct(f"{base}_GetResult_Request"), types.struct(f"{base}_GetResult_Response")
    fb = types.struct(f"{base}_FeedbackMessage")
    server, client = FAST[:-2] + b"\x13\x03", FAST
    uuid = lambda k: {"uuid": [k] * 16}  # noqa: E731
    feed = [("goal_request", types.build(goal_rq, {"goal_id": uuid(1), "goal": {"target": 1.0}}), 50.0, client),
            ("goal_request", types.build(goal_rq, {"goal_id": uuid(2), "goal": {"target": 2.0}}), 50.01, client),
            ("goal_reply", types.build(goal_rr, {"accepted": True}), 50.02, server),
            ("goal_reply", types.build(goal_rr, {"accepted": True}), 50.03, server),
            ("result_request", types.build(res_rq, {"goal_id": uuid(1)}), 50.04, client),
            ("result_request", types.build(res_rq, {"goal_id": uuid(2)}), 50.05, client),
            ("feedback", types.build(fb, {"goal_id": uuid(2), "feedback": {"progress": -0.5}}), 50.1, server),
            ("result_reply", types.build(res_rr, {"status": 4, "result": {"arrived": True}}), 50.3, server),
            ("result_reply", types.build(res_rr, {"status": 4, "result": {"arrived": True}}), 50.4, server)]
    for part, s, stamp, writer in feed:
        taps.handle(f"call:/move:{part}", s.serialize(), stamp, stamp, writer)
    taps.tick(53.0)
    summary = taps.finish()
    mover = [x["verdict"] for x in lines if x.get("verdict", {}).get("node") == "Mover" and "kind" not in x]
    assert [v["verdict"] for v in mover if v["topic"] == "move/feedback"] == ["violated"]  # by its goal id
    # goal 1 waits for its result: inconclusive, with the reason; goal 2 was already decided by its feedback
    (undecided,) = [v for v in mover if v["verdict"] == "inconclusive"]
    assert "its result cannot be told apart" in undecided["reason"] and undecided["where"].startswith("move goal 01")
    assert summary["counts"]["goals"] == 2 and summary["counts"]["unpaired"] == 2
    assert replay(_book([]), lines) == summary
