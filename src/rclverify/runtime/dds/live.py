"""``rclverify monitor --live --ros2``: the live monitor as a DDS participant.

Everything that decides a verdict, writes the log or the evidence is the
ROS 1 monitor's (:class:`~.live.LiveRun` around the one engine,
:class:`~.worker.EngineWorker` as its only thread); this module moves
messages in and verdicts out over DDS (:mod:`rclverify.ros.live.dds`):

* joins domain ``ROS_DOMAIN_ID`` with Cyclone's ``CYCLONEDDS_URI``;
* reads every topic the monitored contracts name (``rt/<topic>``, the
  struct made from the contract's type, :mod:`.dds_types`) with a reader
  that follows its publishers' QoS (:mod:`.dds_bus`), and every linked
  service and action (:mod:`.dds_services`, checked call by call by
  :mod:`.dds_calls`);
* reads the run's simulated clock, ``/clock`` (``rosgraph_msgs/msg/Clock``,
  :mod:`rclverify.traces.sim_clock`), whatever the contracts name: each
  sample is pushed to the engine as a contract sample is (its publisher's
  source timestamp, its writer's id), its matched writers handed to the
  engine's ``match`` under ``clock`` once it has one, and recorded in the
  ``--record`` bag; its reader is made only when a publisher of ``/clock`` is
  discovered, so a run without a simulator pays nothing for it; the call
  taps take each sample too, among the calls' samples
  (:meth:`~.services.CallTaps.clock`), for the calls' deadlines kept in
  simulated time.  A contract
  that names ``/clock`` itself makes it a contract topic like any other;
* publishes each verdict as ``std_msgs/msg/String`` JSON on
  ``rt/rclverify/verdict`` (``ros2 topic echo /rclverify/verdict``) and each
  node's latest on ``rt/rclverify/<Node>/last_verdict``, reliable and
  transient-local, depth 1 (ROS 2's latching);
* with ``enforce``, republishes the guarded topics (:mod:`.dds_enforce`);
  with ``record``, writes the run to a ROS 2 bag (:mod:`.dds_bag`), its
  calls as ROS 2 records them (:mod:`.bag_calls`).

Threads: Cyclone's own (C, no GIL), the bus thread (takes raw samples,
queues them), the engine thread (decodes, checks, logs, publishes, runs
the timer; with a lateness bound it lets messages gather for
:data:`~rclverify.runtime.worker.LINGER_S` rather than waking for each, and
the source lets samples gather for :func:`source_linger`),
and the caller's (status lines, the stop).  While the run lasts the
interpreter's switch interval is :data:`SWITCH_INTERVAL_S` (Python's
default is 5 ms): the engine thread, woken for a release, waits at most
that long for the bus thread to hand the interpreter over.  The wait for the
stop and the evidence record are :mod:`.live_end`'s: the ROS 1 record
(``live.stop_and_record``) with ``calls`` (per node the call-by-call
verdicts' status), ``deadlines``, ``qos`` (per topic the reader's QoS and
what it heard), ``warnings``, ``enforce`` and ``bag``.
"""
from __future__ import annotations

import math
import sys
import time as _time
from pathlib import Path
from typing import Any, Callable, Mapping

from rclverify.lang.types import Checked, CheckedNode
from rclverify.backends.monitors.run_origin import origin_line
from rclverify.ros.live.dds import DdsUnavailable, domain_id, make_participant, topic_name, type_hash_user_data, write_raw
from rclverify.ros.live.dds_qos import writer_profile
from rclverify.runtime.dds.bag import BagRecorder
from rclverify.runtime.dds.bag_calls import CallRecorder
from rclverify.backends.monitors.dds_calls import CallBook
from rclverify.runtime.dds.services import CallTaps
from rclverify.runtime.dds.cdr_fields import read_fields
from rclverify.runtime.dds.types import DdsTypeError, TypeBook
from rclverify.runtime.dds.wire import WriterIds
from rclverify.runtime.live import VERDICT_LOG_TOPIC, LiveRun, dumps
from rclverify.runtime.live_status import warm_bounds
from rclverify.runtime.ros1 import contract_topics
from rclverify.runtime.worker import LINGER_S, EngineWorker
from rclverify.runtime.dds.bag import BagError
from rclverify.traces.event_time import event_ns
from rclverify.traces.sim_clock import CLOCK_TOPIC
from rclverify.runtime.dds.bus import Bus
from rclverify.runtime.dds.trust import VERDICT_KEY
from rclverify.runtime.dds.live_end import DdsRunEnd


#: the most a source (the DDS bus thread, the rclpy agent) lets samples gather after a round that took some
#: (s; :func:`source_linger`)
SOURCE_LINGER_S = 0.004


def source_linger(reorder_window: float) -> float:
    """How long the source lets samples gather (s) under the lateness bound ``reorder_window`` (s): a
    tenth of the bound, at most :data:`SOURCE_LINGER_S`; none without a bound.  A sample held there is
    not yet in the engine's queue, so the wait is kept well inside the bound that makes a message late."""
    return min(SOURCE_LINGER_S, reorder_window / 10) if reorder_window > 0 else 0.0
#: the interpreter's switch interval during a run (s; module docstring)
SWITCH_INTERVAL_S = 0.001
#: the encapsulation header of plain little-endian CDR (XCDR1), as rmw writes ROS 2 messages
_CDR_LE = b"\x00\x01\x00\x00"
#: the type of the run's simulated clock, ``/clock`` (REP 2008)
CLOCK_TYPE = "rosgraph_msgs/msg/Clock"
#: where warnings about the ``/clock`` reader say they come from (no contract names it)
CLOCK_WHERE = "rclverify monitor --live"


def string_cdr(text: str) -> bytes:
    """``std_msgs/String(data=text)`` as plain little-endian CDR, its encapsulation
    header included: the bytes the struct's serializer gives (a ``uint32``
    length counting the closing NUL, the UTF-8 text, the NUL), made without
    it, since a verdict is sent for every message."""
    data = text.encode()
    return _CDR_LE + (len(data) + 1).to_bytes(4, "little") + data + b"\0"


class _Sink:
    """What the engine thread feeds: the run's engine, and the call book's clock."""

    def __init__(self, live: LiveRun, book: CallBook | None, taps: CallTaps | None, window: float,
                 flush_writes: Callable[[], None] | None = None) -> None:
        self.live, self.book, self.taps, self.window = live, book, taps, window
        self.flush_writes = flush_writes

    def push(self, topic: str, fields: Mapping[str, object], received: float,
             writer: bytes | str | None = None) -> None:
        self.live.push(topic, fields, received, writer)

    def due(self) -> float:
        return self.live.due()

    def tick(self, now: float) -> None:
        self.live.tick(now)
        if self.book is not None and self.taps is not None:
            self.taps.tick(now, self.window)  # the book's clock as far behind as the topic engine's, or more

    def flush(self) -> None:
        """Hand on the verdicts the bus holds (the rclpy source's writes to its agent; the DDS bus writes each)."""
        if self.flush_writes is not None:
            self.flush_writes()


def run_dds(run_factory: Callable[..., LiveRun], checked: Checked, nodes: list[CheckedNode],
            type_dirs: list[Path], *, verdict_topic: str, last_prefix: str, duration: float | None, tick_s: float,
            status_s: float, evidence: Path | None, stop: Any, out: Callable[[str], None],
            enforce: Mapping[str, str] | None = None, record: tuple[Path, str] | None = None,
            msg_dirs: list[Path] | None = None, reorder_window: float = 0.0,
            bus_factory: Callable[..., Any] | None = None,
            describe: Callable[[list[str]], Mapping[str, Any]] | None = None, **_ignored: Any) -> dict[str, Any]:
    """Monitor the ROS 2 system on the DDS domain until ``stop`` is set or
    ``duration`` s passed; returns the evidence record (written to
    ``evidence`` too).  ``type_dirs``: directories of ``<pkg>/msg|srv|action``
    (the mapping's message directories and ``--interfaces``); ``enforce``:
    guarded contract topic -> private ROS name (``run_factory`` makes an
    :class:`~.dds_enforce.EnforcingRun` then); ``record``: ``(bag path,
    storage)``; ``bus_factory(on_sample, warn, on_reader=, type_hash=)``: the
    bus of another source with the DDS bus's face (the rclpy source,
    :mod:`rclverify.runtime.rclpy_source.bus`), else a Cyclone DDS participant
    of the monitor's own; ``describe(["pkg/msg/T"])``: the declarations the
    rclpy source's ROS 2 Python has of types the workspace does not define
    (:func:`~rclverify.runtime.rclpy_source.describe.installed_declarations`).  Raises
    :class:`~rclverify.ros.live.dds.DdsUnavailable` (the binding, the domain,
    a type that cannot be made, a bag that cannot be created, the rclpy agent
    that cannot start: one message)."""
    run = _DdsRun(checked, nodes, type_dirs, dict(enforce or {}), out, describe)
    run.by_receipt = reorder_window <= 0
    run.open_recorder(record, msg_dirs)
    dp = make_participant() if bus_factory is None else None
    run.join(dp, run_factory, verdict_topic, last_prefix, bus_factory)
    run.live.note(origin_line(_time.time(), *run.origin()))  # the log says which source heard it (run_origin.py)
    worker = EngineWorker(_Sink(run.live, run.book, run.calls, reorder_window, getattr(run.bus, "flush_writes", None)),
                          run.decode, _time.time,
                          tick_s=tick_s, linger_s=LINGER_S if reorder_window > 0 else 0.0)
    run.worker_box.append(worker.start())
    run.bus.linger_s = source_linger(reorder_window)
    run.bus.start()
    via = f"through rclpy on {run.source_rmw()}" if dp is None else f"on DDS domain {domain_id()}"
    out(f"monitoring {len(run.structs)} topic(s) and {len(run.calls.specs) if run.calls else 0} service/action "
        f"topic(s) for {len(nodes)} node(s) {via}; verdicts on {verdict_topic}")
    warm_bounds()  # the status line a stop prints need not wait for scipy (live_status.py)
    switch = sys.getswitchinterval()
    sys.setswitchinterval(SWITCH_INTERVAL_S)
    try:
        run.wait(worker, stop, duration, tick_s, status_s)
    finally:
        record_ = run.finish(worker, evidence)
        run.bus.close()
        if dp is not None:
            dp.__del__()
        sys.setswitchinterval(switch)
    return record_


class _DdsRun(DdsRunEnd):
    """One live run on DDS, step by step (:func:`run_dds`): the types made
    before joining, the bus and its writers, the call book, the engine
    thread's decoding; the wait and the evidence record at the end are
    :class:`~.live_end.DdsRunEnd`'s."""

    def __init__(self, checked: Checked, nodes: list[CheckedNode], type_dirs: list[Path],
                 enforce: dict[str, str], out: Callable[[str], None],
                 describe: Callable[[list[str]], Mapping[str, Any]] | None = None) -> None:
        self.checked, self.nodes, self.type_dirs, self.enforce, self.out = checked, nodes, type_dirs, enforce, out
        try:
            self.types = TypeBook(type_dirs)
            self.string = self.types.message("std_msgs/String")
        except DdsTypeError as exc:
            raise DdsUnavailable(str(exc)) from None
        self.topics = contract_topics(checked, nodes)  # "/topic" -> "pkg/Type"
        #: "pkg/msg/T" -> the ROS 2 Python's declaration of a contract type the workspace does not define
        self.described: dict[str, Any] = {}
        self.where = {t.field.strip("/"): f"{t.loc.file}:{t.loc.line}:{t.loc.col}" for n in reversed(nodes)
                      for t in reversed(n.node.topics)}  # the first mention of each topic
        self.structs: dict[str, Any] = {}
        for t, typ in self.topics.items():
            try:
                self.structs[t.strip("/")] = self._message(typ, describe)
            except DdsTypeError as exc:
                raise DdsUnavailable(f"{self.where.get(t.strip('/'), t)}: error: topic {t} ({typ}): {exc}") from None
        #: the struct of ``/clock`` heard beside the contract topics (``None``: a contract names it, so it is
        #: one of :attr:`structs`); the struct each tapped topic's samples are read with (:meth:`decode`)
        self.clock_struct: Any = None
        if CLOCK_TOPIC not in self.structs:
            try:
                self.clock_struct = self.types.message(CLOCK_TYPE)
            except DdsTypeError as exc:
                raise DdsUnavailable(f"{CLOCK_WHERE}: error: /clock ({CLOCK_TYPE}): {exc}") from None
        self.readers: dict[str, Any] = {**self.structs, **({CLOCK_TOPIC: self.clock_struct}
                                                          if self.clock_struct is not None else {})}
        #: the tap of ``/clock`` beside the contract topics (:meth:`join`), kept out of the record's ``qos``
        self.clock_tap: Any = None
        self.links = [(n, lk) for n in nodes for lk in n.node.links]
        for _n, lk in self.links:  # every linked type made now: a missing one is one located message, before joining
            try:
                self.types.service(lk.ros_type) if lk.kind == "service" else self.types.action(lk.ros_type)
            except DdsTypeError as exc:
                raise DdsUnavailable(f"{lk.loc.file}:{lk.loc.line}:{lk.loc.col}: error: {lk.kind} {lk.name} "
                                     f"({lk.ros_type}): {exc}") from None
        self.recorder: BagRecorder | None = None
        self.call_recorder: CallRecorder | None = None
        self.warnings: list[str] = []
        self.decode_errors: dict[str, int] = {}
        self.worker_box: list[EngineWorker] = []
        self.republish: dict[str, Any] = {}
        self.book: CallBook | None = None
        self.calls: CallTaps | None = None
        self.call_counts: dict[tuple[str, str], int] = {}
        self.bus: Any = None  # the DDS bus, or the rclpy source's (join)
        self.receipt_timed = 0  # samples placed at their receipt: no source time, or one ahead of the clock
        #: --reorder-window 0: no watermark, so messages are judged in the order heard, at their receipt
        #: (a source time would make every message heard after a later-published one late, judged apart
        #: from how its log line, at the clock, reads offline)
        self.by_receipt = False
        self.t0 = _time.monotonic()  # when the run began to listen (wait)

    def _message(self, typ: str, describe: Callable[[list[str]], Mapping[str, Any]] | None) -> Any:
        """The struct of contract type ``typ``: the workspace's definition, else (the rclpy source,
        ``describe``) the ROS 2 Python's own description of it, checked against its hash
        (:func:`~rclverify.runtime.rclpy_source.describe.installed_declarations`).  Raises
        :class:`DdsTypeError` when neither defines it."""
        try:
            return self.types.message(typ)
        except DdsTypeError:
            if describe is None:
                raise
            full = _full(typ)
            try:
                decls = describe([full])
            except Exception:  # noqa: BLE001 - the ROS 2 Python could not say: the workspace's error stands
                decls = {}
            if full not in decls:
                raise
            self.types.add_declaration(decls[full])
            self.described[full] = decls[full]  # recorded in this definition too (open_recorder)
            self.out(f"{full}: no definition in the workspace: read as the ROS 2 Python's rosidl describes it")
            return self.types.message(typ)

    def open_recorder(self, record: tuple[Path, str] | None, msg_dirs: list[Path] | None) -> None:
        """The bag the run is written to, when ``record`` names one: the contract topics'
        messages, and the linked services' and actions' calls as ROS 2 records them (:mod:`.bag_calls`)."""
        if record is None:
            return
        try:
            self.call_recorder = CallRecorder(self.types, self.links) if self.links else None
            described = {t.strip("/"): self.described[_full(ty)] for t, ty in self.topics.items()
                         if _full(ty) in self.described}  # a type known only from its description: recorded in it
            self.recorder = BagRecorder(record[0], record[1], {t.strip("/"): ty for t, ty in self.topics.items()},
                                        msg_dirs if msg_dirs is not None else self.type_dirs,
                                        calls=self.call_recorder.plan if self.call_recorder else None,
                                        described=described,
                                        heard={CLOCK_TOPIC: CLOCK_TYPE} if self.clock_struct is not None else None)
        except (BagError, DdsTypeError) as exc:
            raise DdsUnavailable(str(exc)) from None
        if self.call_recorder is not None:
            self.call_recorder.write = self.recorder.write

    def on_reader(self, tap: Any, publishers: list[Any]) -> None:
        """A guarded topic's real name is published as soon as its private one is
        heard, with the QoS the node's publisher offers (so subscribers match it
        before the first message is released)."""
        if tap.key in self.enforce and tap.key not in self.republish:
            self.republish[tap.key] = self.bus.writer(topic_name(tap.key), self.structs[tap.key], publishers[0].qos)

    def join(self, dp: Any, run_factory: Callable[..., LiveRun], verdict_topic: str, last_prefix: str,
             bus_factory: Callable[..., Any] | None = None) -> None:
        """The bus on participant ``dp`` (or the one ``bus_factory`` makes:
        :func:`run_dds`), the verdict writers, the run, the call book, and a
        tap on every contract topic and linked call."""
        string, enforce = self.string, self.enforce
        writers = WriterIds()  # a service sample's writer tells its wire form (dds_wire.py)
        bus: Any  # the DDS bus, or the rclpy source's with its face

        def writer_of(tap: Any, info: Any) -> bytes | None:
            guid = getattr(info, "writer_guid", None)  # the rclpy source hands the publisher's GID over
            return (bytes(guid) or None) if guid is not None else writers.of(tap.reader, info)

        def on_sample(tap: Any, raw: bytes, info: Any, rns: int) -> None:
            # the robot's time: the publisher's source timestamp (event_time.py), the receipt only without one
            source_ns = int(getattr(info, "source_timestamp", 0) or 0)
            ens, from_source = (rns, True) if self.by_receipt else event_ns(source_ns, rns)
            if not from_source:
                self.receipt_timed += 1
            writer = writer_of(tap, info)  # a topic's: the engine's early release (OnlineEngine.watermark)
            self.worker_box[0].offer(tap.key, (raw, source_ns, rns, writer, ens), ens / 1e9, writer)
        if bus_factory is not None:
            self.bus = bus = bus_factory(on_sample, self.warn, on_reader=self.on_reader,
                                         type_hash=self.types.type_hash)
        else:
            self.bus = bus = Bus(dp, on_sample, self.warn, on_reader=self.on_reader, type_hash=self.types.type_hash)
        user = type_hash_user_data("std_msgs/msg/String")
        self.pub = bus.writer(topic_name(verdict_topic), string, writer_profile(depth=1000), user)
        latched = writer_profile(transient_local=True, depth=1)
        lasts = {n.name: bus.writer(topic_name(f"{last_prefix}/{n.name}/last_verdict"), string, latched, user)
                 for n in self.nodes}

        def release(topic: str, raw: bytes) -> None:
            w = self.republish[topic]  # made when the private topic's reader was (on_reader)
            own = getattr(w, "write_raw", None)  # the rclpy source's publisher writes bytes itself
            own(raw) if own is not None else write_raw(w, raw)
        extra = {"release": release} if enforce else {}

        def send_last(node: str, text: str) -> None:
            self.write_text(lasts[node], text)
        self.live = run_factory(publish=self.send, publish_last=send_last, **extra)
        bus.on_matched = self.on_matched  # each topic's matched writers, from the bus thread
        if self.recorder is not None:  # the bag keeps what was heard late, as the log does (traces/bag_late.py)
            self.live.engine.on_late = self.recorder.late
        if self.links:
            rec, note = self.call_recorder, self.live.note

            def on_line(obj: dict[str, Any]) -> None:  # the log's call line, and the bag's events (bag_calls.py)
                note(obj)
                if rec is not None:
                    rec.line(obj)
            self.book = CallBook(self.checked, self.links, self.live.engine.rules, self.live.engine.horizon,
                                 self.on_call_verdict, self.on_deadline, on_line)
            self.calls = CallTaps(self.book, self.types, self.links, events=getattr(bus, "events_only", False))
            if rec is not None:
                rec.specs = self.calls.specs
        for t, struct in self.structs.items():
            bus.tap(t, topic_name(enforce.get(t, t)), struct, self.where.get(t, t))
        if self.clock_struct is not None:  # the run's simulated clock, whatever the contracts name (docstring)
            self.clock_tap = bus.tap(CLOCK_TOPIC, topic_name(CLOCK_TOPIC), self.clock_struct, CLOCK_WHERE)
        for t in enforce:  # only the gate may write a guarded topic, only the monitor the verdict topic (dds_trust.py)
            bus.watch_writers(topic_name(t), t, self.where.get(t, t), "guarded topic")
        bus.watch_writers(topic_name(verdict_topic), VERDICT_KEY, "--verdict-topic", "verdict topic")
        if self.calls is not None:
            self.calls.attach(bus, self.warn)
        if self.calls is not None and self.calls.events:
            self.out(f"the rclpy source hears the calls of {', '.join(sorted(self.calls.kinds))} through their "
                     "introspection events only, never their request and reply topics (docs/ros2.md)")

    def on_matched(self, sets: Mapping[str, frozenset[bytes]]) -> None:
        """Hand the engine each tapped topic's matched writers (tap key -> writer ids, from the bus's
        thread): ``/clock`` beside the contract topics only once a writer of it is matched."""
        if self.clock_tap is not None and not sets.get(CLOCK_TOPIC, True):
            sets = {k: v for k, v in sets.items() if k != CLOCK_TOPIC}
        self.live.match(sets)

    def send(self, text: str) -> None:
        self.write_text(self.pub, text)

    def write_text(self, w: Any, text: str) -> None:
        """Write ``std_msgs/String(data=text)`` with writer ``w``: its plain CDR made by :func:`string_cdr`
        where the writer writes plain CDR (the rclpy source's writers; a Cyclone writer whose data
        representation is XCDR1, as ``writer_profile``'s are), else the struct serialized by the writer."""
        own = getattr(w, "write_raw", None)  # the rclpy source's writer: plain CDR, as rmw writes
        if own is not None:
            own(string_cdr(text))
        elif getattr(w, "_use_version_2", None) is False:  # cyclonedds' DataWriter of XCDR1
            write_raw(w, string_cdr(text))
        else:
            w.write(self.string(data=text))

    def on_call_verdict(self, v: Any) -> None:
        key = (v.node, v.verdict)
        self.call_counts[key] = self.call_counts.get(key, 0) + 1
        d = {**v.to_json(), "call": True}
        self.live.note({"topic": VERDICT_LOG_TOPIC, "time": v.decided_at, "verdict": d})
        self.send(dumps(d))

    def on_deadline(self, v: Any) -> None:
        book = self.book
        t = book.now if book is not None and math.isfinite(book.now) else v.trigger_stamp
        self.live.note({"topic": VERDICT_LOG_TOPIC, "time": t, "kind": "deadline", "verdict": v.to_json()})
        self.send(dumps({"kind": "deadline", **v.to_json()}))

    def decode(self, key: str, payload: Any) -> Mapping[str, object] | None:
        """One sample's fields (engine thread), a contract topic's or ``/clock``'s; a call sample goes to the
        call taps, bytes that are not the topic's type are counted."""
        raw, source_ns, received_ns = payload[:3]
        calls = self.calls
        try:
            if calls is not None and key.startswith("call:"):
                if self.call_recorder is not None:
                    self.call_recorder.sample(key, raw, source_ns, payload[3])
                calls.handle(key, raw, source_ns / 1e9, received_ns / 1e9, payload[3])
                return None
            fields: Mapping[str, object] = read_fields(self.readers[key], raw)  # to_fields(deserialize(raw))
        except Exception:  # bytes that are not the contract's type: counted, never a crash
            self.decode_errors[key] = self.decode_errors.get(key, 0) + 1
            return None
        if self.recorder is not None:
            self.recorder.write(key, payload[4], raw)  # at its event time, as the log and the engine place it
        if key == CLOCK_TOPIC and calls is not None:  # the call book's /clock: among the calls' samples
            calls.clock(fields, source_ns / 1e9, received_ns / 1e9)
        if key in self.enforce:
            self.live.stash(fields, raw)  # type: ignore[attr-defined]
        return fields


def _full(typ: str) -> str:
    """``pkg/msg/T`` of a contract's ``pkg/T`` or ``pkg/msg/T``."""
    pkg, _, name = typ.replace("/msg/", "/").partition("/")
    return f"{pkg}/msg/{name}"


__all__ = ["SOURCE_LINGER_S", "run_dds", "source_linger"]
