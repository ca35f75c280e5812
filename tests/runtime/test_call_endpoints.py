"""Every endpoint of a call accounted for, without a bus (docs/ros2.md,
"Every endpoint of a call accounted for"; tests/runtime/test_ros2_call_endpoints.py
runs the same rules against real rclpy nodes).

Which introspection side pairs a service's calls, which endpoints are not
heard with contents, how the call book keeps their nodes from
``discharged`` and names the answers whose request it did not hear, and
that the log's replay and the not-judged list say the same as the live
book.  Each rule has its control: the configuration that is judged, green.
"""
from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from rclverify.backends.monitors.dds_calls import CallBook, replay
from rclverify.backends.monitors.judged import Heard, count_call_line, not_judged
from rclverify.backends.monitors.summary import verdict_status
from rclverify.lang.typecheck import load
from rclverify.runtime.dds.introspection import side_of, uncovered

WS = Path(__file__).parent.parent / "data" / "dds_ws"
CHECKED = load([WS / "contracts" / "dds.rcl"])
LINKS = [(n, lk) for n in CHECKED.nodes.values() for lk in n.node.links]
NODES = list(CHECKED.nodes.values())


def _book(lines: list[dict[str, Any]]) -> CallBook:
    book = CallBook(CHECKED, LINKS, {}, 1.0)
    book.on_event = lines.append
    return book


def test_a_side_is_taken_only_when_it_hears_every_call() -> None:
    # the control: the one server publishes contents: its events cover every client
    assert side_of({"/s"}, {"/s"}, {"/a", "/b"}) == "server"
    assert uncovered({"/s"}, {"/a", "/b"}, {"/s": "contents"}) == {}
    # every client publishes contents: they cover every server
    assert side_of({"/a", "/b"}, {"/s", "/t"}, {"/a", "/b"}) == "client"
    assert uncovered({"/s", "/t"}, {"/a", "/b"}, {"/a": "contents", "/b": "contents"}) == {}
    # two servers, one publishing: the DDS source takes no side (it pairs the request and reply topics), the
    # rclpy source hears the one and names the other and the clients that publish nothing
    assert side_of({"/s"}, {"/s", "/t"}, {"/a"}) is None
    assert side_of({"/s"}, {"/s", "/t"}, {"/a"}, partial=True) == "server"
    assert set(uncovered({"/s", "/t"}, {"/a"}, {"/s": "contents"})) == {"server /t", "client /a"}
    # a client publishing metadata only covers nothing: its calls, and its server's with it, are not all heard
    why = uncovered({"/s"}, {"/a", "/b"}, {"/a": "contents", "/b": "metadata"})
    assert set(why) == {"server /s", "client /b"} and "without contents (METADATA)" in why["client /b"], why
    assert uncovered({"/s"}, {"/a", "/b"}, {"/s": "contents", "/b": "metadata"}) == {}  # the server covers it


def _taps(lines: list[dict[str, Any]], servers: set[str], clients: set[str]) -> Any:
    """The call taps of the rclpy source (events only), the graph's endpoints given."""
    pytest.importorskip("cyclonedds", reason="the cyclonedds binding is not installed")
    from rclverify.runtime.dds.services import CallTaps
    from rclverify.runtime.dds.types import TypeBook
    types = TypeBook([WS / "interfaces"])
    taps = CallTaps(_book(lines), types, LINKS, framed=False, events=True)
    owners = {b"\x0a" * 16: "/a", b"\x0b" * 16: "/b", b"\x05" * 16: "/s"}
    taps._node_of = owners.get
    taps._ends = lambda name: (servers, clients) if name == "/estop" else (set(), set())
    taps.taps = {"call:/estop:event": SimpleNamespace(heard={g for g, n in owners.items() if n != "/s"})}
    return taps, types


@pytest.mark.parametrize("metadata", [False, True])
def test_an_endpoint_seen_publishing_metadata_is_not_judged(metadata: bool) -> None:
    from rclverify.runtime.dds.introspection import event_struct
    lines: list[dict[str, Any]] = []
    taps, types = _taps(lines, {"/s"}, {"/a", "/b"})
    ev = event_struct(types, "std_srvs/SetBool")

    def event(writer: bytes, kind: int, seq: int, stamp: float, **parts: Any) -> None:
        s = types.build(ev, {"info": {"event_type": kind, "client_gid": list(writer), "sequence_number": seq},
                             **{k: [v] for k, v in parts.items()}})
        taps.handle("call:/estop:event", s.serialize(), stamp, stamp, writer)
    a, b = b"\x0a" * 16, b"\x0b" * 16
    event(a, 0, 1, 20.0, request={"data": True})
    event(a, 3, 1, 20.1, response={"success": True, "message": ""})
    if metadata:  # /b's events carry no request or response
        event(b, 0, 1, 20.2)
        event(b, 3, 1, 20.3)
    else:
        event(b, 0, 1, 20.2, request={"data": True})
        event(b, 3, 1, 20.3, response={"success": True, "message": ""})
    for now in (21.0, 22.0, 23.0):  # the grace passes
        taps.tick(now)
    summary = taps.finish()
    base = next(r for r in summary["nodes"] if r["node"] == "Base")
    if metadata:
        assert set(summary["unjudged"]["estop"]) == {"server /s", "client /b"}, summary["unjudged"]
        assert "client /b publishes introspection events without contents" in taps.unheard()["/estop"]
        assert base["counts"]["inconclusive"] == 2 and base["counts"]["satisfied"] >= 1
    else:  # the control: both clients publish contents, every call judged, nothing unjudged
        assert summary["unjudged"] == {} and "/estop" not in taps.unheard()
        assert base["counts"]["inconclusive"] == 0 and summary["counts"]["calls"] == 2
    # the log's replay gives the same summary (the unjudged line among the book's lines)
    assert replay(_book([]), lines) == summary


@pytest.mark.parametrize("heard", [False, True])
def test_a_link_heard_only_at_metadata_level_says_what_was_heard(heard: bool) -> None:
    from rclverify.runtime.dds.introspection import event_struct
    taps, types = _taps([], {"/s"}, {"/a", "/b"})
    ev = event_struct(types, "std_srvs/SetBool")
    if heard:  # every endpoint publishes its events without contents: three of them heard
        for k, (writer, kind) in enumerate([(b"\x0a" * 16, 0), (b"\x0b" * 16, 0), (b"\x05" * 16, 1)]):
            s = types.build(ev, {"info": {"event_type": kind, "client_gid": list(b"\x0a" * 16), "sequence_number": 1}})
            taps.handle("call:/estop:event", s.serialize(), 20.0 + k / 10, 20.0 + k / 10, writer)
    taps.tick(22.0)  # the samples are taken
    said = taps.unheard()["/estop"]
    if heard:
        assert said.startswith("3 introspection event(s) of it were heard (/estop/_service_event), all at metadata "
                               "level: their request and response contents are not introspected"), said
        assert "CONTENTS" in said and "none of its calls was heard" not in said
    else:  # the control: nothing heard at all is said as such
        assert said.startswith("no introspection event of its server or of every client was heard"), said


@pytest.mark.parametrize("both", [False, True])
def test_the_dds_source_takes_a_side_only_when_every_server_publishes(both: bool) -> None:
    """Two servers of /estop on the DDS source: with one publishing events, the request and reply topics
    pair the calls (both servers' replies heard); with both publishing, their events do."""
    lines: list[dict[str, Any]] = []
    pytest.importorskip("cyclonedds", reason="the cyclonedds binding is not installed")
    from rclverify.runtime.dds.services import CallTaps
    from rclverify.runtime.dds.types import TypeBook
    taps = CallTaps(_book(lines), TypeBook([WS / "interfaces"]), LINKS, framed=False)
    one, two, client = (bytes([1, 15, k]) + bytes(9) + b"\x00\x00\x13\x03" for k in (1, 2, 3))
    event = {one[:12] + b"\x00\x00\x15\x03"} | ({two[:12] + b"\x00\x00\x15\x03"} if both else set())
    taps.taps = {"call:/estop:event": SimpleNamespace(heard=event),
                 "call:/estop:reply": SimpleNamespace(heard={one, two}, dds_topic="rr/estopReply"),
                 "call:/estop:request": SimpleNamespace(heard={client})}
    assert taps._side("/estop", 1.0) == ("server" if both else None)


@pytest.mark.parametrize("violated", [False, True])
def test_an_answer_whose_request_was_not_heard_is_named_whatever_else_was_judged(violated: bool) -> None:
    lines: list[dict[str, Any]] = []
    book = _book(lines)
    book.open("/estop", ("ev", "aa", 2), "estop call aa:2", {"data": True}, 10.0)
    book.answer(("ev", "aa", 2), "response", {"success": not violated, "message": ""}, 10.1)
    book.tick(12.0)
    control = book.finish()
    assert control["undecided"] == {}
    base = next(r for r in book.results.values() if r.node == "Base")
    status, _ = verdict_status(base, "the calls")
    assert status == ("failed" if violated else "discharged")  # the control: judged, green when right
    book = _book(lines := [])
    book.answer(("ev", "aa", 1), "response", {"success": False, "message": ""}, 9.5, name="/estop")  # before
    book.open("/estop", ("ev", "aa", 2), "estop call aa:2", {"data": True}, 10.0)
    book.answer(("ev", "aa", 2), "response", {"success": not violated, "message": ""}, 10.1)
    book.tick(12.0)
    summary = book.finish()
    assert summary["undecided"] == {"estop": {"count": 1, "first": [["ev", "aa", 1]]}}
    base = next(r for r in book.results.values() if r.node == "Base")
    status, explanation = verdict_status(base, "the calls")
    assert status == ("failed" if violated else "inconclusive")
    said = book.with_notes("Base", explanation)
    assert "1 answer(s) of /estop whose request the monitor did not hear" in said and "client gid aa seq 1" in said
    assert replay(_book([]), lines) == summary
    # the not-judged list names the link, whatever else of it was judged; the control's has nothing
    messages: dict[str, int] = {}
    orphans: dict[str, int] = {}
    for x in lines:
        count_call_line(x, messages, orphans)
    statuses = {"Base": [(status, explanation)]}
    items = not_judged(NODES, Heard(messages, orphans), statuses, {}, "in the run")
    assert [(i["name"], i["reason"]) for i in items if i["name"] == "/estop"] == [("/estop", "not paired")]
    del orphans["estop/undecided"]
    assert [i for i in not_judged(NODES, Heard(messages, orphans), statuses, {}, "in the run")
            if i["name"] == "/estop"] == []


def test_an_endpoint_not_judged_is_an_item_whatever_else_was_judged() -> None:
    lines: list[dict[str, Any]] = []
    book = _book(lines)
    book.open("/estop", ("ev", "aa", 1), "estop call aa:1", {"data": True}, 10.0)
    book.answer(("ev", "aa", 1), "response", {"success": True, "message": ""}, 10.1)
    book.unjudged("/estop", "server /t", "server /t publishes no introspection events (off), and ...", 10.5)
    book.unjudged("/estop", "server /t", "server /t publishes no introspection events (off), and ...", 11.0)  # once
    book.tick(12.0)
    summary = book.finish()
    assert summary["unjudged"] == {"estop": {"server /t": "server /t publishes no introspection events (off), and ..."}}
    assert [x["part"] for x in lines if x.get("part") == "unjudged"] == ["unjudged"]
    base = next(r for r in book.results.values() if r.node == "Base")
    assert verdict_status(base, "the calls")[0] == "inconclusive"  # never discharged
    messages: dict[str, int] = {}
    orphans: dict[str, int] = {}
    for x in lines:
        count_call_line(x, messages, orphans)
    items = not_judged(NODES, Heard(messages, orphans), {}, {}, "in the run")
    assert [(i["name"], i["reason"]) for i in items if i["name"] == "/estop"] == [("/estop", "endpoint not heard")]
    assert replay(_book([]), lines) == summary


@pytest.mark.parametrize("before", [False, True])
def test_a_request_event_stamped_before_the_monitor_began_is_named_undecided(before: bool) -> None:
    """An event of a request stamped well before the monitor began (a durable event, a late delivery): the
    monitor may have missed the exchange's start, so it opens no call; its answer is named undecided by its
    client gid and sequence number.  The control: the same request stamped after the start is judged."""
    from rclverify.runtime.dds.introspection import event_struct
    lines: list[dict[str, Any]] = []
    taps, types = _taps(lines, {"/s"}, {"/a"})
    taps.taps = {"call:/estop:event": SimpleNamespace(heard={b"\x05" * 16})}  # the server publishes contents
    ev = event_struct(types, "std_srvs/SetBool")
    server, gid = b"\x05" * 16, b"\x0a" * 16
    taps.tick(20.0)  # the monitor begins

    def event(kind: int, stamp: float, now: float, **parts: Any) -> None:
        s = types.build(ev, {"info": {"event_type": kind, "client_gid": list(gid), "sequence_number": 1},
                             **{k: [v] for k, v in parts.items()}})
        taps.handle("call:/estop:event", s.serialize(), stamp, now, server)
    asked = 12.0 if before else 20.5
    event(1, asked, 20.6, request={"data": True})
    event(2, 20.7, 20.7, response={"success": False, "message": ""})
    for now in (21.0, 23.0, 25.0):
        taps.tick(now)
    summary = taps.finish()
    if before:
        assert taps.counts["before_start"] == 1 and summary["counts"]["calls"] == 0
        assert summary["undecided"]["estop"] == {"count": 1, "first": [["ev", gid.hex(), 1, server.hex()]]}
        base = next(r for r in summary["nodes"] if r["node"] == "Base")
        assert base["counts"]["violated"] == 0 and base["counts"]["inconclusive"] == 1
        assert f"client gid {gid.hex()} seq 1" in base["first_inconclusive"]["reason"]
    else:
        assert summary["counts"]["calls"] == 1 and summary["undecided"] == {}
        base = next(r for r in summary["nodes"] if r["node"] == "Base")
        assert base["counts"]["violated"] == 1


@pytest.mark.parametrize("result_events", [True, False])
def test_an_action_server_is_covered_only_with_its_goal_and_result_events(result_events: bool) -> None:
    """An action's goals are heard through its send-goal events and their results through its get-result
    events: a server publishing both covers its clients (the control); one publishing only the send-goal
    events leaves the action not judged for it and for its clients."""
    lines: list[dict[str, Any]] = []
    taps, _types = _taps(lines, set(), set())
    server, client = b"\x05" * 16, b"\x0a" * 16
    taps._node_of = {server: "/s", client: "/a"}.get
    taps._ends = lambda name: ({"/s"}, {"/a"}) if name == "/move" else (set(), set())
    taps.taps = {"call:/move:goal_event": SimpleNamespace(heard={server}),
                 "call:/move:result_event": SimpleNamespace(heard={server} if result_events else set())}
    for now in (20.0, 21.0, 22.0):
        taps.tick(now)
    summary = taps.finish()
    if result_events:
        assert "move" not in summary["unjudged"], summary["unjudged"]
    else:
        assert set(summary["unjudged"]["move"]) == {"server /s", "client /a"}, summary["unjudged"]
        mover = next(r for r in summary["nodes"] if r["node"] == "Mover")
        assert mover["counts"]["inconclusive"] == 2


@pytest.mark.parametrize("gap", [5.0, 0.5], ids=["past the window: judged", "control: within the window: undecided"])
def test_calls_paired_by_the_order_once_introspection_stopped_are_judged_past_the_last_request_it_took(
        gap: float) -> None:
    """The DDS source, one /estop server on Fast DDS (no request identity on the wire): its first call paired by
    the server's introspection events, then the events stop (a server made again without them) and the order of
    the request and reply topics pairs the next call, ``gap`` s later.  The client's request writer was matched
    at 0 s; the order pairer did not hear the request the events took, whose reply could look like the next
    call's within the window (the horizon, 1 s) after it.  Past that window the next call is judged (its wrong
    answer ``violated``); within it (the control), ``inconclusive`` with the reason."""
    pytest.importorskip("cyclonedds", reason="the cyclonedds binding is not installed")
    from rclverify.runtime.dds.services import CallTaps
    from rclverify.runtime.dds.types import TypeBook
    lines: list[dict[str, Any]] = []
    book = _book(lines)
    taps = CallTaps(book, TypeBook([WS / "interfaces"]), LINKS, framed=False)
    server, client = (bytes([1, 15, k]) + bytes(9) for k in (1, 3))  # Fast DDS participants (vendor 01 0f)
    reply_w, event_w, request_w = (server + b"\x00\x00\x13\x03", server + b"\x00\x00\x15\x03",
                                   client + b"\x00\x00\x14\x03")
    read: dict[str, Any] = {  # the bus's taps as the pairing reads them
        "call:/estop:event": SimpleNamespace(heard={event_w}),
        "call:/estop:reply": SimpleNamespace(heard={reply_w}, dds_topic="rr/estopReply", reader_changes=0),
        "call:/estop:request": SimpleNamespace(heard={request_w}, reader_changes=0)}
    taps.taps = read
    request, reply = (taps.specs[f"call:/estop:{p}"][1] for p in ("request", "reply"))

    def call(t: float, right: bool) -> None:
        taps._decode("call:/estop:request", request(data=True).serialize(), t, t, request_w)
        taps._decode("call:/estop:reply", reply(success=right, message="").serialize(), t + 0.001, t + 0.001, reply_w)
    taps._discover(0.0)  # the readers match the client's request writer and the server's reply writer
    call(1.0, True)
    assert taps.counts["introspected"] == 2  # the events pair it: the order pairer hears neither sample
    taps.taps["call:/estop:event"].heard = set()  # the server's event writer gone
    taps._discover(1.0 + gap - 0.1)
    call(1.0 + gap, False)
    book.tick(1.0 + gap + 5.0)
    book.finish()
    base = next(r for r in book.results.values() if r.node == "Base")
    if gap > 1.0:
        assert (base.counts["violated"], base.counts["inconclusive"]) == (1, 0), base.counts
    else:
        assert (base.counts["violated"], base.counts["inconclusive"]) == (0, 1), base.counts
        (why,) = [x["reason"] for x in lines if x.get("unpaired")]
        assert "less than 1 s before this reply of /estop" in why, why
