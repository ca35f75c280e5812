"""Services and actions heard on the DDS bus, paired and fed to the
:class:`~.dds_calls.CallBook`.

For every link a monitored contract declares (``services(...)``,
``actions(...)``), :class:`CallTaps` asks the bus (:mod:`.dds_bus`) for the
topics :mod:`.call_plan` names: a service's request and reply topics and
its introspection events; an action's send-goal, get-result and
cancel-goal request and reply topics, its feedback and status.

The request and reply readers are of the wire form ``RMW_IMPLEMENTATION``
names (:mod:`.dds_wire`); a sample whose writer is of the other vendor is
counted, not decoded:

* **with the request header** (rmw_cyclonedds): a request opens its call
  under its identity (the client's writer handle and the sequence number),
  the reply with the same identity answers it;
* **without it** (rmw_fastrtps): the service's introspection events pair
  request and reply exactly when every server (or every client) publishes
  them with contents; else the order pairs them where it is certain
  (:mod:`.dds_order`), and says which calls it cannot pair;
* **an action**: a goal opens its call under its ``goal_id``, the feedback
  messages and the get-result reply carrying that goal id answer it (the
  get-result request tells which goal its reply is about: by the header's
  identity, or by the order), a refused goal (``accepted`` false) closes it
  unjudged; status changes, cancel requests and the goals a cancel reply
  names (goal ids in both: no pairing needed) are logged.

**Events only** (``events``: the rclpy source, which cannot read a
service's request and reply topics): a service's calls come from its
introspection events alone, and an action's goals, results, refusals and
cancels from the introspection events of its own three services
(``<a>/_action/send_goal/_service_event``, ``get_result``'s, ``cancel_goal``'s;
the goal id in each request names the goal, the event's client gid and
sequence number name the reply), its feedback and status from their
topics.  Whose events are read (the servers', else the clients') is
decided from the serving and calling nodes the graph API reports and the
nodes that publish the events (:func:`~.introspection.side_of`).  A link
none of whose nodes publish events is not heard, and is said so; an
endpoint not heard with contents (its introspection off, or metadata as its
events show) is told to the call book as not judged
(:meth:`CallTaps._coverage`, docs/ros2.md "Every endpoint of a call
accounted for").

An answer whose request was not heard, and an event of a request stamped
more than :data:`LATE_S` before the monitor began, leave an answer the book
names undecided (:meth:`~.dds_calls.CallBook.orphan`).

Samples are taken in the order of their event times (the DDS source
timestamp, else the receipt: :func:`~rclverify.traces.event_time.event_s`),
held in the one reorder buffer (:mod:`rclverify.traces.reorder`): each waits
:data:`SETTLE_S` seconds after its time (so that a request taken after its
reply, the two travelling on different topics, still comes first), and the
call book's clock runs that far behind.  An answer whose request has not been
heard waits up to :data:`EARLY_S` seconds for it before it counts as an
answer without a call.

The run's ``/clock`` samples (:meth:`CallTaps.clock`) wait in the same
buffer and are taken in the same order, each given to the book
(:meth:`~.dds_calls.CallBook.clock`) where its time falls among the calls'
samples: a call's deadline kept in simulated time reads the ``/clock`` of
its request's stamp and of its answer's.

An action's parts are read by :mod:`.action_taps`, whose introspection
side pairs a link's calls and which endpoints go unheard by
:mod:`.event_sides`, the seconds waited are :mod:`.call_times`'; both
mixins share this class's state.
"""
from __future__ import annotations

import os
from typing import Any, Iterable, Mapping

from rclverify.lang import ast
from rclverify.lang.types import CheckedNode
from rclverify.runtime.dds.bus import NAME_GRACE_S, Tap
from rclverify.backends.monitors.dds_calls import CallBook
from rclverify.runtime.dds.action_taps import GOAL_STATUS, ActionTaps
from rclverify.runtime.dds.call_plan import CallPlan
from rclverify.runtime.dds.call_times import EARLY_S, LATE_S, SETTLE_S
from rclverify.runtime.dds.event_sides import EventSides
from rclverify.runtime.dds.introspection import SIDES, event_key
from rclverify.runtime.dds.order import OrderPairer, Pending
from rclverify.runtime.dds.shadow import REPLY_OF, SHADOW, Shadows
from rclverify.runtime.dds.types import TypeBook, request_id, to_fields
from rclverify.runtime.dds.wire import framed_rmw, has_header, vendor
from rclverify.traces.event_time import event_s
from rclverify.traces.reorder import ReorderBuffer
from rclverify.traces.sim_clock import CLOCK_TOPIC


class CallTaps(EventSides, ActionTaps):
    """The taps of every monitored link and the decoding of their samples
    (module docstring).  Raises :class:`~.dds_types.DdsTypeError` (with the
    link's location) for a link type the interface files do not define."""

    def __init__(self, book: CallBook, types: TypeBook, links: Iterable[tuple[CheckedNode, ast.Link]],
                 framed: bool | None = None, events: bool = False) -> None:
        self.book, self.types = book, types
        #: the services' samples carry rmw_cyclonedds' request header (default: by RMW_IMPLEMENTATION)
        self.framed = framed_rmw() if framed is None else framed
        #: calls heard through introspection events only (module docstring: the rclpy source)
        self.events = events
        plan = CallPlan(types, links, self.framed, events)  # which topics, read as which structs (call_plan.py)
        self.kinds, self.where, self.specs, self.plan = plan.kinds, plan.where, plan.specs, plan.plan
        self._pair_taps = plan.pair_taps
        self.taps: dict[str, Tap] = {}  # tap key -> the bus's Tap (attach)
        self._node_of: Any = lambda guid: None  # a writer's ROS node (the bus's discovery, attach)
        self._ends: Any = None  # name -> (serving nodes, calling nodes): the graph API's (the rclpy bus, attach)
        self._disc: Any = None
        self._warn: Any = None
        self._warned: set[bytes] = set()
        self._seen: dict[bytes, float] = {}  # when a writer of the other form was first seen
        self._said: set[str] = set()
        self._checked = float("-inf")
        self.shadows: Shadows | None = None  # reply writers that keep services visible to clients (attach)
        self._goal_of: dict[tuple[Any, ...], str] = {}  # send-goal/get-result request id (or event key) -> goal id
        self._status: dict[str, int] = {}
        self._early: dict[tuple[Any, ...], list[tuple[str, Mapping[str, object], float, bool, float, str]]] = {}
        #: samples waiting to be taken (traces/reorder.py, the one reorder buffer): (received, key, raw, writer);
        #: a ``/clock`` sample's key is :data:`~rclverify.traces.sim_clock.CLOCK_TOPIC`, its fields in place of raw
        self._queue: ReorderBuffer[tuple[float, str, bytes | Mapping[str, object], bytes | None]] = ReorderBuffer()
        self._n = 0
        self._pairers: dict[str, OrderPairer] = {}
        self._paired_before: dict[str, OrderPairer] = {}  # service -> its last pairer, kept when set aside
        #: service -> request writer -> the stamp (s) of its last request the introspection events took
        self._unheard: dict[str, dict[bytes, float]] = {}
        self._sides: dict[str, str | None] = {}  # per service, the introspection side last used
        self.sided: set[str] = set()  # the links some of whose calls an introspection side paired
        #: (link, endpoint owner) -> "metadata": an endpoint seen publishing events without contents
        self._levels: dict[tuple[str, str], str] = {}
        #: link -> introspection events heard of it without a request or response (metadata level)
        self.metadata_events: dict[str, int] = {}
        #: link -> introspection events heard of it with their request or response (contents level)
        self.content_events: dict[str, int] = {}
        #: (link, endpoint, why) -> since when (s) the endpoint has been unheard with contents
        self._uncovered: dict[tuple[str, str, str], float] = {}
        #: link -> endpoint -> why, the endpoints said not judged (events only; the book has them too)
        self.unjudged: dict[str, dict[str, str]] = {}
        self._ev_opened: dict[tuple[str, str, int], int] = {}  # (link, client gid, seq) -> servers that took it
        #: when the monitor began (s, the first sample's or tick's receipt time): an event of a request stamped
        #: more than :data:`LATE_S` before it opens no call, and its answer is named undecided (docs/ros2.md)
        self.started: float | None = None
        #: (link, "servers" | "clients" | an event part) -> endpoint -> when last read (s)
        self._ends_seen: dict[tuple[str, str], dict[str, float]] = {}
        self._shadow_guids: dict[str, set[bytes]] = {}  # reply topic -> monitors' shadow writers (read each 0.5 s)
        self._asked: dict[bytes, int] = {}  # requests heard per writer without identity
        self._changes: dict[str, tuple[int, int]] = {}  # pairer name -> its readers' reader_changes seen
        #: pairer name -> (the reply reader's writers, the pairer's servers) when discovery was last read
        self._servers_seen: dict[str, tuple[frozenset[bytes], frozenset[bytes]]] = {}
        self.last = float("-inf")  # the stamp of the last sample taken
        #: samples taken after a later-stamped one (``late``), of a writer no longer known or of the other
        #: wire form (:mod:`.dds_wire`), events without contents, request/reply samples left to the
        #: introspection events, samples that did not decode, request events stamped before the monitor began
        self.counts = {"late": 0, "unknown_writer": 0, "other_form": 0, "no_contents": 0, "introspected": 0,
                       "undecodable": 0, "before_start": 0}

    def attach(self, bus: Any, warn: Any = None) -> None:
        """Ask ``bus`` (a :class:`~.dds_bus.Bus`, before it starts) for every topic of the plan;
        ``warn(line)`` is told of each writer of the other wire form (:meth:`check_forms`); the
        request readers get their shadow reply writers (:mod:`.dds_shadow`)."""
        for key, dds_topic, struct, where in self.plan:
            self.taps[key] = bus.tap(key, dds_topic, struct, where)
        self._node_of = bus.discovery.node_of
        self._ends = getattr(bus, "service_nodes", None)
        if self._ends is not None:
            for name, kind in self.kinds.items():
                bus.watch_service(name, kind == "action")
        self._disc, self._warn = bus.discovery, warn
        self.shadows = Shadows(bus, [(self.taps[k], self.taps[k.rsplit(":", 1)[0] + ":" + REPLY_OF[part]])
                                     for k, (_n, _s, _h, part) in self.specs.items() if part in REPLY_OF])

    def check_forms(self, now: float) -> None:
        """Warn once about each writer discovery shows on a request or reply
        topic whose vendor writes the other wire form (:mod:`.dds_wire`): the
        monitor's reader cannot take its samples (they do not have its
        layout), so its calls would otherwise go unheard in silence.  A writer
        is named by its node once ``ros_discovery_info`` tells it, or after
        :data:`~.dds_bus.NAME_GRACE_S` seconds by its participant."""
        if self._disc is None or self._warn is None:
            return
        for key, (name, _struct, header, _part) in self.specs.items():
            if header is None:
                continue
            try:
                pubs = self._disc.publishers(self.taps[key].dds_topic)
            except RuntimeError:  # discovery changed under us (the DDS thread): next time
                return
            for e in pubs:
                if has_header(e.guid) == self.framed or e.guid in self._warned:
                    continue
                first = self._seen.setdefault(e.guid, now)
                if self._node_of(e.guid) is None and now - first < NAME_GRACE_S:
                    continue
                self._warned.add(e.guid)
                mine, theirs = ("with", "without") if self.framed else ("without", "with")
                line = (f"{self.taps[key].where}: warning: {name}: {self._disc.who(e)} is {vendor(e.guid)}, whose "
                        f"service samples come {theirs} rmw_cyclonedds' request header; the monitor reads them {mine} "
                        f"it (RMW_IMPLEMENTATION={os.environ.get('RMW_IMPLEMENTATION', '')!r}): its calls are not "
                        "heard (set RMW_IMPLEMENTATION to the robot's middleware)")
                if line not in self._said:  # a participant's request and reply writers, before its nodes are known
                    self._said.add(line)
                    self._warn(line)

    # -- samples (engine thread) -------------------------------------------------------------
    def handle(self, key: str, raw: bytes, stamp: float, now: float, writer: bytes | None = None) -> None:
        """One sample of tap ``key`` (serialized, source stamp ``stamp``, received
        ``now``, written by ``writer``: its GUID), taken at a later :meth:`tick`
        at its event time (:func:`~rclverify.traces.event_time.event_s`: the
        source stamp, or the receipt when the source stamp is missing or
        more than a second ahead of it), as the topics' engine places its samples."""
        self._n += 1
        if self.started is None:
            self.started = now
        t = event_s(stamp, now)
        self._queue.push(t, t, (now, key, raw, writer))

    def clock(self, fields: Mapping[str, object], stamp: float, now: float) -> None:
        """One ``/clock`` sample (its ``fields``, source stamp ``stamp``,
        received ``now``, s), taken as a call sample is (:meth:`handle`), given
        to the book then (:meth:`~.dds_calls.CallBook.clock`); nothing when
        no node with a call deadline may keep simulated time."""
        if not self.book.reads_clock:
            return
        t = event_s(stamp, now)
        self._queue.push(t, t, (now, CLOCK_TOPIC, fields, None))

    def tick(self, now: float, window: float = 0.0) -> None:
        """Take the samples whose time has come, in their stamps' order; answers
        that waited :data:`EARLY_S` s for their call count as answers without
        one; the book's clock moves to ``now - max(window, SETTLE_S)``."""
        if self.started is None:
            self.started = now
        self._discover(now)
        self._take(lambda stamp, _src, item: stamp <= now - SETTLE_S or item[0] <= now - LATE_S)
        if now - self._checked >= 0.5:
            self._checked = now
            self._coverage(now)
            self.check_forms(now)
            if self.shadows is not None:
                self.shadows.update()
            self._read_shadows()
        for key in [k for k, xs in self._early.items() if now - xs[0][4] > EARLY_S]:
            for part, fields, stamp, final, _t, name in self._early.pop(key):
                self.book.answer(key, part, fields, stamp, final, name)
        self.book.tick(now - max(window, SETTLE_S))

    def finish(self) -> dict[str, Any]:
        """Take every sample still waiting, then finish the book (its summary)."""
        self._take(lambda _stamp, _src, _item: True)
        return self.book.finish()

    def _take(self, due: Any) -> None:
        for stamp, _, (got, key, raw, writer), late in self._queue.release_while(due):
            if late > 1e-9:
                self.counts["late"] += 1
            if key == CLOCK_TOPIC:
                assert not isinstance(raw, bytes)  # clock() queues the fields
                self.book.clock(stamp, raw)
                continue
            self.last = max(self.last, stamp)
            try:
                assert isinstance(raw, bytes)  # handle() queues the serialized sample
                self._decode(key, raw, stamp, got, writer)
            except Exception:  # noqa: BLE001 - bytes that are not the link's type: counted, never a crash
                self.counts["undecodable"] += 1

    def _decode(self, key: str, raw: bytes, stamp: float, now: float, writer: bytes | None) -> None:
        name, struct, header, part = self.specs[key]
        framed = header is not None and self.framed
        if header is not None:
            if writer is None:
                self.counts["unknown_writer"] += 1
                return
            if has_header(writer) != framed:
                self.counts["other_form"] += 1
                return  # a writer of the other middleware: its bytes are not this reader's layout
        s = struct.deserialize(raw)
        if part == "event":
            self._event(name, s, stamp, now, writer)
        elif part.endswith("_event"):
            self._action_event(name, part, s, stamp, now, writer)
        elif part in ("request", "reply"):
            if self._side(name, stamp) is not None:
                self.counts["introspected"] += 1
                if part == "request" and writer is not None:  # a request the order pairer does not hear
                    self._unheard.setdefault(name, {})[writer] = stamp
                return  # the introspection events pair this service's calls (and would count them again)
            if part == "request":
                self._request(name, s, stamp, framed, writer)
            elif framed:
                self._answer(request_id(s), "response", to_fields(s), stamp, True, name, now)
            else:
                self._ordered_reply(name, s, stamp, writer)
        else:
            self._action(name, part, s, stamp, now, framed, writer)

    # -- services ------------------------------------------------------------------------------
    def _request(self, name: str, s: Any, stamp: float, framed: bool, writer: bytes | None) -> None:
        if framed:
            guid, seq = request_id(s)
            self._open(name, (guid, seq), f"{name.strip('/')} call {guid:016x}:{seq}", to_fields(s), stamp)
            return
        assert writer is not None
        k = self._asked[writer] = self._asked.get(writer, 0) + 1
        key, label = ("w", writer.hex(), k), f"{name.strip('/')} call {writer.hex()}#{k}"
        fields = to_fields(s)
        for i, p in enumerate(self._pairer(name).request(Pending(key, stamp, label, writer))):
            self._open(name, p.key, p.label, fields, stamp, count=i == 0)

    def _ordered_reply(self, name: str, s: Any, stamp: float, writer: bytes | None) -> None:
        out = self._pairer(name).reply(stamp, writer)
        if out.answers is not None:
            self.book.answer(out.answers.key, "response", to_fields(s), stamp, True, name)
        elif out.orphan:  # counted and logged with its server: an answer no heard request can be its
            self.book.answer(("w", "", 0, writer.hex() if writer else ""), "response", to_fields(s), stamp, True,
                             name)
        for p in out.undecided:
            self.book.unpaired(p.key, stamp, out.reason)

    def _pairer(self, name: str) -> OrderPairer:
        """The order pairer of service ``name``; made again, from the one set aside, after its calls
        changed hands between its introspection events and its request and reply topics (``_side``)."""
        p = self._pairers.get(name)
        if p is None:
            before = self._paired_before.get(name)
            p = before.again(self._unheard.get(name, {})) if before is not None else \
                OrderPairer(name, self.book.horizon, self._who)
            self._pairers[name] = self._paired_before[name] = p
        return p

    def _who(self, guid: bytes) -> str:
        node = self._node_of(guid) if guid else None
        return f"node {node} (writer {guid.hex()})" if node else f"writer {guid.hex() or 'unknown'}"

    def _discover(self, now: float) -> None:
        """Tell each pairer the request writers its reader hears and the servers (reply writers, never a
        monitor's shadow) it matches; the calls a change leaves undecided are unpaired with the reason."""
        for pname, (rq_key, rr_key) in self._pair_taps.items():
            rq, rr = self.taps.get(rq_key), self.taps.get(rr_key)
            if rq is None or rr is None:
                continue
            pairer = self._pairer(pname)
            changes = (rq.reader_changes, rr.reader_changes)
            if self._changes.get(pname) != changes:  # a reader made (again): from now on, everything heard
                self._changes[pname] = changes
                for w in rq.heard:
                    pairer.hearing(w, now)
            for w in rq.heard:
                if w not in pairer.heard_since:
                    pairer.hearing(w, now)
            if not rr.heard and not pairer.servers:
                continue
            seen = (frozenset(rr.heard), frozenset(pairer.servers))
            if self._servers_seen.get(pname) == seen:
                continue  # nothing changed since the last look: discovery is not read again at every tick
            try:
                shadows = {p.guid for p in self._disc.publishers(rr.dds_topic) if SHADOW in p.qos.user_data} \
                    if self._disc is not None else set()
            except RuntimeError:  # discovery changed under us (the DDS thread): next time
                continue
            servers = (set(rr.heard) - shadows) | {g for g in pairer.servers if g not in rr.heard and not g}
            if servers != set(pairer.servers):
                for p, why in pairer.discovered(servers, now):
                    self.book.unpaired(p.key, now, why)
            self._servers_seen[pname] = (frozenset(rr.heard), frozenset(pairer.servers))

    def _event(self, name: str, s: Any, stamp: float, now: float, writer: bytes | None = None) -> None:
        self._level(name, writer, s)
        side = self._side(name, stamp, writer=writer)
        if side is None:
            return
        asked, told = SIDES[side]
        gid, seq = event_key(s)
        # a server's events: each server that took the request has a call of its own (two servers of one
        # service both answer it), named by its event writer; a client's: the client gid names it
        key: tuple[Any, ...] = ("ev", gid, seq, bytes(writer).hex()) if side == "server" and writer else \
            ("ev", gid, seq)
        kind = int(s.info.event_type)
        if kind == asked:
            if not s.request:
                self.counts["no_contents"] += 1
                return  # introspection without CONTENTS: nothing to judge (docs/ros2.md)
            if self.started is not None and stamp < self.started - LATE_S:
                self.counts["before_start"] += 1
                return  # made before the monitor began: its answer is an orphan, named undecided (CallBook.orphan)
            memo = (name, gid, seq)
            taken = self._ev_opened[memo] = self._ev_opened.get(memo, 0) + 1
            while len(self._ev_opened) > 10_000:
                self._ev_opened.pop(next(iter(self._ev_opened)))
            where = "" if len(key) == 3 else f" at {self._owner(writer or b'')}"
            self._open(name, key, f"{name.strip('/')} call {gid}:{seq}{where if taken > 1 else ''}",
                       to_fields(s.request[0]), stamp, count=taken == 1)
        elif kind == told and s.response:
            self._answer(key, "response", to_fields(s.response[0]), stamp, True, name, now)

    # -- the book --------------------------------------------------------------------------------
    def _open(self, name: str, key: tuple[Any, ...], label: str, fields: Mapping[str, object], stamp: float,
              part: str = "request", count: bool = True) -> None:
        self.book.open(name, key, label, fields, stamp, part, count)
        for apart, afields, astamp, final, _t, aname in self._early.pop(key, ()):
            self.book.answer(key, apart, afields, astamp, final, aname)

    def _answer(self, key: tuple[Any, ...], part: str, fields: Mapping[str, object], stamp: float, final: bool,
                name: str, now: float) -> None:
        if key in self.book.calls:
            self.book.answer(key, part, fields, stamp, final, name)
        else:
            self._early.setdefault(key, []).append((part, fields, stamp, final, now, name))

__all__ = ["CallTaps", "EARLY_S", "GOAL_STATUS", "LATE_S", "SETTLE_S"]
