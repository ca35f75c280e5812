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

Long module: one state per link reads both wire forms (the request and
reply topics, the introspection events) and an action's five parts, and
decides per endpoint which it hears; its methods share that state, and a
split along the parts would hand the same tables between modules.
"""
from __future__ import annotations

import os
from typing import Any, Iterable, Mapping

from rclverify.lang import ast
from rclverify.lang.types import CheckedNode
from rclverify.ros.live.dds import ACTION_INFIX
from rclverify.runtime.dds.bus import NAME_GRACE_S, Tap
from rclverify.backends.monitors.dds_calls import CallBook
from rclverify.runtime.dds.call_plan import CallPlan
from rclverify.runtime.dds.introspection import EVENT_SUFFIX, SIDES, event_key, side_of, uncovered
from rclverify.runtime.dds.order import OrderPairer, Pending
from rclverify.runtime.dds.shadow import REPLY_OF, SHADOW, Shadows
from rclverify.runtime.dds.types import TypeBook, request_id, to_fields
from rclverify.runtime.dds.wire import framed_rmw, has_header, vendor
from rclverify.traces.event_time import event_s
from rclverify.traces.reorder import ReorderBuffer

#: seconds an answer waits for its request (or goal) to be heard
EARLY_S = 2.0
#: seconds a sample waits after its source stamp, so that samples are taken in the stamps' order
SETTLE_S = 0.3
#: seconds after its receipt a sample is taken whatever its stamp says (a writer whose clock runs ahead)
LATE_S = 1.0
#: seconds an endpoint goes unheard with contents before it is said not judged (the graph's reading of a node
#: that just appeared may list its service before its event publisher)
ENDPOINT_GRACE_S = 1.5
#: seconds before a sample's stamp the endpoints last read still count for it (the graph is read each 0.5 s and a
#: sample is taken 0.3 s after its stamp or later: an endpoint that left meanwhile was there when it was written)
RECENT_S = 1.0
#: the introspection event parts of an action that tell its goals and results (cancel's only tell cancels)
_GOAL_EVENTS = ("goal_event", "result_event")
#: action_msgs/msg/GoalStatus values (ROS 2 design "Actions")
GOAL_STATUS = {0: "unknown", 1: "accepted", 2: "executing", 3: "canceling", 4: "succeeded", 5: "canceled",
               6: "aborted"}


class CallTaps:
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
        #: samples waiting to be taken (traces/reorder.py, the one reorder buffer): (received, key, raw, writer)
        self._queue: ReorderBuffer[tuple[float, str, bytes, bytes | None]] = ReorderBuffer()
        self._n = 0
        self._pairers: dict[str, OrderPairer] = {}
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
            self.last = max(self.last, stamp)
            try:
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
                return  # the introspection events pair this service's calls (and would count them again)
            if part == "request":
                self._request(name, s, stamp, framed, writer)
            elif framed:
                self._answer(request_id(s), "response", to_fields(s), stamp, True, name, now)
            else:
                self._ordered_reply(name, s, stamp, writer)
        else:
            self._action(name, part, s, stamp, now, framed, writer)

    def unheard(self) -> dict[str, str]:
        """Events only (module docstring): each link (``/s``) with what the
        run could not hear of it: no introspection event of its server or of
        every client (none of its calls), or only events at metadata level
        (counted: heard, but without a request or response to judge), and each endpoint said not judged
        (:meth:`_coverage`: its calls not all heard with contents); ``{}`` on
        the DDS source."""
        if not self.events:
            return {}
        out = {}
        for name, kind in sorted(self.kinds.items()):
            metadata_only = self.metadata_events.get(name, 0) > 0 and not self.content_events.get(name)
            said = [] if name in self.sided and not metadata_only else [self._silence(name, kind)]
            said += list(self.unjudged.get(name, {}).values())
            if said:
                out[name] = "; ".join(said)
        return out

    def _silence(self, name: str, kind: str) -> str:
        """Why no call of link ``name`` (a ``service`` or an action) was paired: no introspection event
        was heard of it, or only events at metadata level (counted), which carry no request or response."""
        topics = (f"{name}{EVENT_SUFFIX}" if kind == "service" else
                  f"{name}{ACTION_INFIX}send_goal{EVENT_SUFFIX}, get_result's, cancel_goal's")
        calls = "calls" if kind == "service" else "goals or results"
        n = self.metadata_events.get(name, 0)
        if n:
            return (f"{n} introspection event(s) of it were heard ({topics}), all at metadata level: their "
                    f"request and response contents are not introspected, so none of its {calls} could be "
                    "judged; configure its server's (or every client's) introspection with CONTENTS "
                    "(ServiceIntrospectionState.CONTENTS; docs/ros2.md, \"Enabling service introspection\")")
        if kind == "service":
            return (f"no introspection event of its server or of every client was heard ({topics}): none of its "
                    "calls was heard")
        return (f"no introspection event of its own services was heard ({topics}): none of its goals or results "
                "was heard (its feedback and status topics are)")

    # -- endpoints -------------------------------------------------------------------------------
    def _owner(self, guid: bytes) -> str:
        """The endpoint a writer belongs to: its ROS node (``/ns/name``), else its participant."""
        return self._node_of(bytes(guid)) or bytes(guid[:12]).hex()

    def _level(self, name: str, writer: bytes | None, s: Any) -> None:
        """Note an event without the request or response it is about: its endpoint publishes metadata only."""
        kind = int(s.info.event_type)
        body = s.request if kind in (SIDES["server"][0], SIDES["client"][0]) else s.response
        counts = self.content_events if body else self.metadata_events
        counts[name] = counts.get(name, 0) + 1
        if writer is not None and not body:
            self._levels[(name, self._owner(writer))] = "metadata"

    def _publishing(self, name: str, part: str) -> set[str]:
        """The endpoints that publish the introspection events of tap ``part`` of ``name`` (an action's
        goal and result events both, for ``goal_event``/``result_event``): the graph API's report of the
        event publishers (the rclpy source) and the writers the tap hears, by owner."""
        parts = _GOAL_EVENTS if part in _GOAL_EVENTS else (part,)
        graph = (getattr(self._disc, "services", None) or {}) if self._ends is not None else {}
        reported = graph.get(name, {}).get("events") if part != "cancel_event" else None
        found: set[str] | None = None
        for p in parts:
            ev = self.taps.get(f"call:{name}:{p}")
            heard = {self._owner(g) for g in ev.heard} if ev is not None else set()
            found = heard if found is None else found & heard
        return (found or set()) | set(reported or ())

    def _contents(self, name: str, part: str) -> set[str]:
        """:meth:`_publishing` without the endpoints seen publishing metadata only."""
        return {o for o in self._publishing(name, part) if self._levels.get((name, o)) != "metadata"}

    def _read_shadows(self) -> None:
        """The DDS source: each reply topic's shadow writers (:mod:`.shadow`, this monitor's and any
        other's), which are no servers, as discovery shows them now."""
        if self.events or self._disc is None:
            return
        for key, (_name, _struct, _header, part) in self.specs.items():
            if part != "reply":
                continue
            try:
                topic = self.taps[key].dds_topic
                self._shadow_guids[topic] = {p.guid for p in self._disc.publishers(topic)
                                             if SHADOW in p.qos.user_data}
            except (RuntimeError, KeyError):  # discovery changed under us (the DDS thread): next time
                continue

    def _coverage(self, now: float) -> None:
        """Events only: every endpoint of each link not heard with contents for
        :data:`ENDPOINT_GRACE_S` s (:func:`~.introspection.uncovered`: its
        introspection off or metadata, from the graph API's endpoints and
        event publishers, read again at each look) is told to the book as not
        judged (:meth:`~.dds_calls.CallBook.unjudged`), once per reason."""
        if not self.events or self._ends is None:
            return
        now_uncovered: set[tuple[str, str, str]] = set()
        for name, kind in self.kinds.items():
            servers, clients = self._ends(name)
            part = "event" if kind == "service" else "goal_event"
            pubs = self._publishing(name, part)
            parts = ("event",) if kind == "service" else ("goal_event", "result_event", "cancel_event")
            for what, ends in (("servers", servers), ("clients", clients),
                               *((p, pubs if p == part else self._publishing(name, p)) for p in parts)):
                seen = self._ends_seen.setdefault((name, what), {})
                seen.update(dict.fromkeys(ends, now))
                for gone in [e for e, t in seen.items() if t < now - 10 * RECENT_S]:
                    del seen[gone]
            levels = {o: self._levels.get((name, o), "contents") for o in pubs}
            for end, why in uncovered(set(servers), set(clients), levels).items():
                k = (name, end, why)
                now_uncovered.add(k)
                since = self._uncovered.setdefault(k, now)
                said = self.unjudged.setdefault(name, {})
                if now - since >= ENDPOINT_GRACE_S and said.get(end) != why:
                    said[end] = why
                    self.book.unjudged(name, end, why, max(self.book.now, now - SETTLE_S))
        for k in [k for k in self._uncovered if k not in now_uncovered]:
            del self._uncovered[k]

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
        p = self._pairers.get(name)
        if p is None:
            p = self._pairers[name] = OrderPairer(name, self.book.horizon, self._who)
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

    def _side(self, name: str, stamp: float, part: str = "event", writer: bytes | None = None) -> str | None:
        """Which side's introspection events (tap ``part``) pair the calls of
        service or action ``name`` at the sample stamped ``stamp``
        (:func:`~.introspection.side_of` on the endpoints that publish them
        with contents).  The DDS source takes a side only when it hears every
        call (every server publishes, or every client), else it pairs the
        request and reply topics; the rclpy source, which hears nothing else,
        takes the side some endpoint publishes (the others are said not
        judged: :meth:`_coverage`), the endpoints read up to :data:`RECENT_S`
        s before the sample's stamp and the event's own ``writer`` counted
        (a node that left since was there).  When the side changes (an event writer
        discovered after calls began, gone, or seen to publish metadata only),
        the calls the other source opened can no longer be answered by it:
        they are unpaired."""
        ev = self.taps.get(f"call:{name}:{part}")
        if ev is None:
            side = None
        elif self._ends is not None:
            servers, clients = self._ends(name)
            recent = {what: {e for e, t in self._ends_seen.get((name, what), {}).items() if t >= stamp - RECENT_S}
                      for what in ("servers", "clients", part)}
            pubs = self._contents(name, part) | {o for o in recent[part] if self._levels.get((name, o)) != "metadata"}
            if writer is not None and self._levels.get((name, self._owner(writer))) != "metadata":
                pubs.add(self._owner(writer))
            side = side_of(pubs, set(servers) | recent["servers"], set(clients) | recent["clients"],
                           partial=self.events)
        else:
            rep, req = (self.taps.get(f"call:{name}:{p}") for p in ("reply", "request"))
            if rep is None or req is None:
                side = None
            else:
                shadows = self._shadow_guids.get(rep.dds_topic, set())
                side = side_of(self._contents(name, part), {self._owner(g) for g in rep.heard if g not in shadows},
                               {self._owner(g) for g in req.heard})
        memo = f"{name}:{part}"
        if side is not None:
            self.sided.add(name)
        if self._sides.setdefault(memo, side) == side:
            return side
        was, self._sides[memo] = self._sides[memo], side
        why = (f"{name}'s introspection events {'began' if was is None else 'changed or stopped'} while this call "
               "was open: its answer may come through the other source, and the two cannot be matched")
        link = name.strip("/")
        keys = [k for k, c in self.book.calls.items()
                if c.name == link and k and (part != "event" or k[0] in ("ev", "w"))]
        for k in keys:
            self.book.unpaired(k, stamp, why, "response" if part == "event" else "result")
        self._pairers.pop(name, None)
        return side

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

    # -- actions -------------------------------------------------------------------------------
    def _action_event(self, name: str, part: str, s: Any, stamp: float, now: float,
                      writer: bytes | None = None) -> None:
        """An introspection event of one of action ``name``'s own services (module docstring, events only)."""
        self._level(name, writer, s)
        side = self._side(name, stamp, part, writer)
        if side is None:
            return
        asked, told = SIDES[side]
        kind, key = int(s.info.event_type), ("ev", *event_key(s))
        body = s.request if kind == asked else s.response if kind == told else None
        if body is None:
            return
        if not body:
            self.counts["no_contents"] += 1
            return  # introspection without CONTENTS: nothing to judge (docs/ros2.md)
        r, link = body[0], name.strip("/")
        if part == "cancel_event":
            self.book.note({"link": link, "part": "cancel", "time": stamp,
                            "key": [bytes(r.goal_info.goal_id.uuid).hex()]} if kind == asked else
                           {"link": link, "part": "canceling", "time": stamp, "return_code": int(r.return_code),
                            "key": [bytes(g.goal_id.uuid).hex() for g in r.goals_canceling]})
        elif kind == asked:
            gid = self._goal_of[key] = bytes(r.goal_id.uuid).hex()
            while len(self._goal_of) > 10_000:
                self._goal_of.pop(next(iter(self._goal_of)))
            if part == "goal_event":
                self._open(name, (gid,), f"{link} goal {gid}", to_fields(r.goal), stamp, "goal")
        else:
            gid = self._goal_of.pop(key, "")
            if not gid:
                self.counts["unknown_writer"] += 1  # its request's event was not heard: which goal, unknown
            elif part == "goal_event" and not r.accepted:
                self.book.reject((gid,), stamp)
            elif part == "result_event":
                self._answer((gid,), "result", to_fields(r.result), stamp, True, name, now)
                self._note_status(name, gid, int(r.status), stamp)

    def _action(self, name: str, part: str, s: Any, stamp: float, now: float, framed: bool,
                writer: bytes | None) -> None:
        if part == "goal_request":
            gid = bytes(s.goal_id.uuid).hex()
            self._ask(name, "send_goal", s, gid, stamp, framed, writer)
            self._open(name, (gid,), f"{name.strip('/')} goal {gid}", to_fields(s.goal), stamp, "goal")
        elif part == "result_request":
            self._ask(name, "get_result", s, bytes(s.goal_id.uuid).hex(), stamp, framed, writer)
        elif part == "goal_reply":
            self._goal_reply(name, s, stamp, framed, writer)
        elif part == "result_reply":
            gid, undecided, why = self._told(name, "get_result", s, stamp, framed, writer)
            for g in undecided:
                self.book.unpaired((g,), stamp, f"its result cannot be told apart: {why}", "result")
            if gid:
                self._answer((gid,), "result", to_fields(s.result), stamp, True, name, now)
                self._note_status(name, gid, int(s.status), stamp)
        elif part == "feedback":
            self._answer((bytes(s.goal_id.uuid).hex(),), "feedback", to_fields(s.feedback), stamp, False, name, now)
        elif part == "status":
            for st in s.status_list:
                self._note_status(name, bytes(st.goal_info.goal_id.uuid).hex(), int(st.status), stamp)
        elif part == "cancel_request":  # a zero goal id (and stamp) asks to cancel every goal (before it)
            self.book.note({"link": name.strip("/"), "part": "cancel", "time": stamp,
                            "key": [bytes(s.goal_info.goal_id.uuid).hex()]})
        elif part == "cancel_reply":  # the goals the server accepted to cancel: their ids, no pairing needed
            self.book.note({"link": name.strip("/"), "part": "canceling", "time": stamp, "return_code":
                            int(s.return_code), "key": [bytes(g.goal_id.uuid).hex() for g in s.goals_canceling]})

    def _ask(self, name: str, svc: str, s: Any, gid: str, stamp: float, framed: bool,
             writer: bytes | None = None) -> None:
        """A send-goal or get-result request about goal ``gid``: remember which goal its reply is about."""
        if framed:
            self._goal_of[request_id(s)] = gid
            while len(self._goal_of) > 10_000:
                self._goal_of.pop(next(iter(self._goal_of)))
        else:
            self._pairer(f"{name}/_action/{svc}").request(Pending((gid,), stamp, f"goal {gid}", writer))

    def _told(self, name: str, svc: str, s: Any, stamp: float, framed: bool,
              writer: bytes | None) -> tuple[str, list[str], str]:
        """The goal a send-goal or get-result reply is about (``""``: unknown), the
        goals it leaves undecided and why."""
        if framed:
            return self._goal_of.pop(request_id(s), ""), [], ""
        pairer = self._pairer(f"{name}/_action/{svc}")
        out = pairer.reply(stamp, writer)
        return (str(out.answers.key[0]) if out.answers else "", [str(p.key[0]) for p in out.undecided],
                out.reason)

    def _goal_reply(self, name: str, s: Any, stamp: float, framed: bool, writer: bytes | None) -> None:
        pool = [str(p.key[0]) for p in self._pairers[f"{name}/_action/send_goal"].pool] \
            if f"{name}/_action/send_goal" in self._pairers else []
        gid, undecided, why = self._told(name, "send_goal", s, stamp, framed, writer)
        if s.accepted:
            return
        if gid:
            self.book.reject((gid,), stamp)
            return
        for g in dict.fromkeys(undecided + pool):  # one of them was refused: none can be judged
            self.book.unpaired((g,), stamp, f"a goal was refused and which one cannot be told: "
                               f"{why or 'its request is one of several unanswered'}", "result")

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

    def _note_status(self, name: str, gid: str, status: int, stamp: float) -> None:
        if self._status.get(gid) == status:
            return
        self._status[gid] = status
        while len(self._status) > 10_000:
            self._status.pop(next(iter(self._status)))
        self.book.note({"link": name.strip("/"), "part": "status", "time": stamp, "key": [gid],
                        "status": GOAL_STATUS.get(status, str(status))})


__all__ = ["CallTaps", "EARLY_S", "GOAL_STATUS", "LATE_S", "SETTLE_S"]
