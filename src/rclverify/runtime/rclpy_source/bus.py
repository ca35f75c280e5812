"""The live monitor's bus with rclpy as the source: what the robot carries,
heard through the ROS client library on whatever middleware it runs.

:class:`RclpyBus` has the face of the DDS bus (:class:`~rclverify.runtime.dds.bus.Bus`:
``tap``, ``writer``, ``watch_writers``, ``discovery``, ``taps``,
``bypass``, ``start``, ``stop``, ``close``), so the run, the engine, the
call book, the log and the bag are the DDS path's, unchanged; only where
the bytes come from differs.  Its data come from an agent process
(:mod:`.agent`) run in a ROS 2 Python (:func:`.python.ros2_python`), over a
pipe (:mod:`.wire`; asked to hold :data:`.agent_process.PIPE_BYTES`, read :data:`READ_CHUNK`
bytes at a time, so one read hands over every frame waiting):

* each tap becomes a raw subscription of the topic's ROS name and type
  (``rt/scan`` -> ``/scan``, ``sensor_msgs::msg::dds_::LaserScan_`` ->
  ``sensor_msgs/msg/LaserScan``), its samples the serialized bytes rmw
  received, decoded by the monitor as the DDS path decodes them (every field
  at its width);
* discovery is rclpy's graph API (:mod:`.discovery`): each publisher's GID, node, type, ROS 2
  type hash (REP-2011) and QoS; a publisher of another type than the
  contract's is named in a located warning and never heard;
* a publisher of the contract's type with **another type hash** than the
  monitor's definition (the robot's distribution changed the type: Kilted's
  ``sensor_msgs/Range`` has ``variance``) is read in its own definition (:mod:`.declared`):
  the agent is asked for the type description it declares (``describe``:
  the ROS 2 Python's own when its hash is that one, else the publisher's
  node's type description service), each description found is checked to
  hash to the publisher's hash (:func:`~rclverify.runtime.dds.types.declare`),
  and the publisher's samples are handed on as
  :class:`~rclverify.runtime.dds.types.Declared` bytes, which the contract's
  struct reads in that definition; the run says so in a located note.
  Its samples that arrive before the answer are held (at most
  :data:`HOLD_MAX` per publisher) and handed on, in order and with their
  own stamps, once it comes (after what other publishers' samples were
  handed on meanwhile).  When no description checks out, one located
  warning says what was heard, what the monitor knows, why the publisher's
  own definition could not be had, and what to do (the robot's ``.msg``
  with ``--interfaces``); the publisher is never heard;
* the monitor's writes (its verdicts) are command lines to the agent,
  held in the pipe's buffer and handed over in one write per batch of the
  engine thread (:meth:`RclpyBus.flush_writes`), in the order written;
* a sample carries its writer's GID and sequence number: the messages a
  publisher wrote before the monitor heard it are counted
  (``published_before_heard``);
* **what rclpy cannot hear** is said, never silent: a service's requests
  and replies travel on the middleware's own request and reply topics,
  which only the middleware's client and server see; rclpy hears a call
  through the service's introspection events (``<service>/_service_event``)
  and a goal through its action's own services' events, and nowhere else.
  Each request or reply tap is deaf here (``deaf``), and the run warns once
  per link (docs/ros2.md);
* the nodes that serve and call each service or action
  (:meth:`RclpyBus.service_nodes`) come from the graph API: they tell whose
  events pair a call (the server's, else every client's).

Errors: :class:`~.agent_process.RclpyUnavailable` (no ROS 2 Python, the agent could not
start): one message.  The agent's process (its script, its one-shot answers, its pipe's capacity) is
:mod:`.agent_process`.
"""
from __future__ import annotations

import base64
import json
import subprocess
import threading
from pathlib import Path
from types import SimpleNamespace
from typing import Any, Callable, IO, Mapping

from rclverify.ros.live.dds_qos import QosProfile
from rclverify.runtime.dds.bus import Tap
from rclverify.runtime.rclpy_source.discovery import AgentDiscovery, ros_name, ros_type
from rclverify.runtime.rclpy_source.declared import DeclaredTypes
from rclverify.runtime.dds.types import Declaration, Declared
from rclverify.runtime.rclpy_source.agent_process import AGENT, RclpyUnavailable, agent_answer, widen
from rclverify.runtime.rclpy_source.wire import FrameBuffer, parse_sample, read_frame

#: bytes read from the agent's pipe at once (what is there, up to this): one read hands over a batch of frames
READ_CHUNK = 1 << 20
#: seconds the agent has to say hello (rclpy's start-up)
HELLO_TIMEOUT_S = 30.0
#: samples held per publisher while its type description is asked for (the agent answers within its
#: DESCRIBE_TIMEOUT_S); past it, each further one is dropped and counted in the tap's ``dropped``
HOLD_MAX = 10_000


class _Writer:
    """A publisher of the monitor's, in the agent: ``write(sample)`` publishes it serialized."""

    def __init__(self, bus: RclpyBus, wid: int) -> None:
        self.bus, self.wid = bus, wid

    def write(self, sample: Any) -> None:
        self.write_raw(sample.serialize(use_version_2=False))  # plain CDR, as rmw writes ROS 2 messages

    def write_raw(self, raw: bytes) -> None:
        """Publish serialized bytes (encapsulation header included) as they are: the gate's release of a
        message it held back (``--enforce``), byte for byte."""
        self.bus._send({"op": "write", "id": self.wid, "raw": base64.b64encode(raw).decode()}, hold=True)


class RclpyBus(DeclaredTypes):
    """The taps, writers and discovery of one live run over rclpy (module
    docstring).  ``python``: the ROS 2 Python the agent runs in;
    ``on_sample(tap, raw, info, received_ns)`` is called in the bus thread
    for each sample (``info.source_timestamp`` ns, ``info.writer_guid``
    16 bytes, ``info.sequence``); ``type_hash(struct)`` the ROS 2 type hash of
    a contract struct."""

    #: calls are heard through introspection events only (module docstring; :mod:`~rclverify.runtime.dds.services`)
    events_only = True

    def __init__(self, python: Path, on_sample: Callable[[Tap, bytes, Any, int], None],
                 warn: Callable[[str], None], on_reader: Callable[[Tap, list[Any]], None] | None = None,
                 type_hash: Callable[[type], str | None] | None = None) -> None:
        self.python, self.on_sample, self.warn, self.on_reader = python, on_sample, warn, on_reader
        self.type_hash = type_hash or (lambda struct: None)
        self.discovery = AgentDiscovery()
        self.taps: list[Tap] = []
        self.deaf: list[Tap] = []
        self.watched: dict[str, tuple[str, str, str]] = {}
        self.bypass: dict[str, set[str]] = {}
        self.error: BaseException | None = None
        self.hello: dict[str, Any] = {}
        self.before: dict[str, int] = {}  # tap key -> messages its publishers wrote before the monitor heard them
        self._first: dict[tuple[int, bytes], int] = {}
        self._warned: set[tuple[str, bytes, str]] = set()
        self._admitted: dict[tuple[int, bytes], bool | Declaration] = {}
        #: (type, publisher's hash) -> the declaration its samples are read with, ``None`` when refused
        self._declared: dict[tuple[str, str], Declaration | None] = {}
        self._why: dict[tuple[str, str], str] = {}  # a refused declaration: why, as the warning says it
        self._asking: set[tuple[str, str]] = set()  # descriptions asked for, not yet answered
        self._held: dict[tuple[int, bytes], list[bytes]] = {}  # sample frames waiting for an answer
        self._writers = 0
        self._proc: subprocess.Popen[bytes] | None = None
        self._thread = threading.Thread(target=self._run, name="rclverify-rclpy", daemon=True)
        self._hello = threading.Event()
        #: seconds the agent lets samples gather after a round that took some (``None``: its own default),
        #: set before :meth:`start` (:func:`~rclverify.runtime.dds.live.source_linger`)
        self.linger_s: float | None = None
        #: the agent said ``stopped``: every sample it took was handed over (:meth:`stop`)
        self.stopped = False
        #: told, in the bus thread whenever the agent reports a tap's publishers, every reported tap's
        #: matched writers (tap key -> the publishers' 16-byte GIDs, as samples carry them; set before
        #: :meth:`start`): the face of :attr:`~rclverify.runtime.dds.bus.Bus.on_matched`
        self.on_matched: Callable[[dict[str, frozenset[bytes]]], None] | None = None
        self._lock = threading.Lock()
        self._gone = False  # the agent's stdin is closed: nothing more is sent (:meth:`_send`)
        self._start()

    # -- the face of the DDS bus ---------------------------------------------------------------
    def tap(self, key: str, dds_topic: str, struct: type, where: str) -> Tap:
        """Ask to hear ``dds_topic`` (before :meth:`start`); a request or reply topic stays deaf."""
        t = Tap(key, dds_topic, struct, where)
        self.taps.append(t)
        name = ros_name(dds_topic)
        if name is None:
            self.deaf.append(t)
        else:
            self._send({"op": "tap", "id": len(self.taps) - 1, "topic": name, "type": ros_type(struct)})
        return t

    def watch_writers(self, dds_topic: str, key: str, where: str, role: str) -> None:
        """Warn about every other publisher on ``dds_topic`` (the verdict topic, a guarded topic)."""
        self.watched[dds_topic] = (key, where, role)
        self.bypass.setdefault(key, set())
        name = ros_name(dds_topic)
        if name is not None:
            self._send({"op": "watch", "topic": name})

    def watch_service(self, name: str, action: bool) -> None:
        """Follow which nodes serve and call service (or action) ``name`` (``/s``): :meth:`service_nodes`."""
        self._send({"op": "service", "name": name, "action": action})

    def service_nodes(self, name: str) -> tuple[set[str], set[str]]:
        """``(servers, clients)`` of service or action ``name``: their nodes (``/ns/name``), as the graph
        API last reported them (empty sets before the first report)."""
        ends = self.discovery.services.get(name, {})
        return set(ends.get("servers", [])), set(ends.get("clients", []))

    def writer(self, dds_topic: str, struct: type, qos: QosProfile, user_data: bytes = b"") -> _Writer:
        """A publisher of the monitor on ``dds_topic``."""
        self._writers += 1
        self._send({"op": "writer", "id": self._writers, "topic": ros_name(dds_topic) or dds_topic,
                    "type": ros_type(struct), "reliable": qos.reliable,
                    "transient_local": qos.durability == "transient_local", "depth": qos.depth})
        return _Writer(self, self._writers)

    def writer_of(self, tap: Tap, info: Any) -> bytes | None:
        """The GID of the publisher of the sample ``info`` describes."""
        return bytes(info.writer_guid) or None

    def start(self) -> RclpyBus:
        self._send({"op": "start", **({"linger": self.linger_s} if self.linger_s is not None else {})})
        self._thread.start()
        return self

    def stop(self, timeout: float = 10.0) -> None:
        """Stop the agent (after it handed over what it had: its ``stopped``, or the end of its output);
        re-raise what the reading thread died of.  An agent that said ``stopped`` leaves the graph on
        its own, unwaited for; one that did not within ``timeout`` s is killed."""
        self._send({"op": "stop"})
        self._thread.join(timeout)
        proc = self._proc
        if proc is not None and not self.stopped:
            try:
                proc.wait(timeout)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait(5)
            self._thread.join(timeout)
        for (k, _gid), bodies in self._held.items():  # never answered: not heard, counted
            self.taps[k].dropped += len(bodies)
        self._held.clear()
        if self.error is not None:
            raise self.error

    def close(self) -> None:
        """Kill the agent unless it said ``stopped`` (then it is leaving the graph on its own)."""
        if self._proc is not None and not self.stopped and self._proc.poll() is None:
            self._proc.kill()
            self._proc.wait(5)

    # -- the agent -----------------------------------------------------------------------------
    def _start(self) -> None:
        try:
            self._proc = subprocess.Popen([str(self.python), str(AGENT)], stdin=subprocess.PIPE,
                                          stdout=subprocess.PIPE, start_new_session=True)
        except OSError as exc:
            raise RclpyUnavailable(f"the ROS 2 Python {self.python} cannot run: {exc}") from None
        assert self._proc.stdout is not None
        widen(self._proc.stdout.fileno())
        first = read_frame(self._proc.stdout)
        if first is None or first[0] != b"J":
            raise RclpyUnavailable(f"the rclpy agent in {self.python} stopped before it started")
        obj = json.loads(first[1])
        if obj.get("what") != "hello":
            self.close()
            raise RclpyUnavailable(f"{obj.get('text', 'the rclpy agent could not start')} (in {self.python})")
        self.hello = obj

    def _send(self, obj: Mapping[str, object], hold: bool = False) -> None:
        """One command line to the agent; with ``hold`` (a write) kept in the pipe's buffer until
        :meth:`flush_writes` or the next command not held, in the order sent."""
        proc = self._proc
        if proc is None or proc.stdin is None or self._gone:
            return
        line = (json.dumps(obj) + "\n").encode()
        with self._lock:
            try:
                proc.stdin.write(line)
                if not hold:
                    proc.stdin.flush()
            except (BrokenPipeError, ValueError):  # the agent ended (its exit is the reading thread's to say)
                self._gone = True

    def flush_writes(self) -> None:
        """Hand the agent the writes held since the last flush, in one write (the engine thread calls it
        after each batch of messages and each timer run: a verdict a message would otherwise cost a
        system call here and a wake-up of the agent's command thread there)."""
        proc = self._proc
        if proc is None or proc.stdin is None or self._gone:
            return
        with self._lock:
            try:
                proc.stdin.flush()
            except (BrokenPipeError, ValueError):
                self._gone = True

    def _run(self) -> None:
        proc = self._proc
        assert proc is not None and proc.stdout is not None
        stream: IO[bytes] = proc.stdout
        frames = FrameBuffer()
        try:
            while True:
                chunk = stream.read1(READ_CHUNK)  # type: ignore[attr-defined]  # a BufferedReader: what is there
                if not chunk:
                    break
                for kind, body in frames.feed(chunk):
                    if kind == b"S":
                        self._sample(body)
                        continue
                    obj = json.loads(body)
                    if obj.get("what") == "stopped":  # everything handed over (the agent's stop)
                        self.stopped = True
                        return
                    self._json(obj)
            if frames.left():
                raise ValueError("the agent's stream ended inside a frame")
            if proc.wait() not in (0, None):
                raise RclpyUnavailable(f"the rclpy agent exited with status {proc.returncode}")
        except BaseException as exc:  # noqa: BLE001 - kept for stop(): a dead reader must be said
            self.error = exc

    def _sample(self, body: bytes) -> None:
        k, source_ns, received_ns, seq, gid, raw = parse_sample(body)
        t = self.taps[k]
        ok = self._admitted.get((k, gid))
        if ok is None:
            now = self._admit(t, gid)
            if now is None:  # its definition asked for: held until the answer (module docstring)
                held = self._held.setdefault((k, gid), [])
                if len(held) < HOLD_MAX:
                    held.append(body)
                else:
                    t.dropped += 1
                return
            ok = self._admitted[(k, gid)] = now
        if ok is False:
            t.dropped += 1
            return
        if isinstance(ok, Declaration):
            raw = Declared.of(raw, ok)
        if seq and (k, gid) not in self._first:
            self._first[(k, gid)] = seq
            self.before[t.key] = self.before.get(t.key, 0) + seq - 1
        t.samples += 1
        self.on_sample(t, raw, SimpleNamespace(source_timestamp=source_ns, writer_guid=gid, sequence=seq),
                       received_ns)

    def _json(self, obj: dict[str, Any]) -> None:
        what = obj.get("what")
        if what == "graph":
            self.discovery.update(obj)
            self._check_graph()
        elif what == "tap":
            t = self.taps[int(obj["id"])]
            first = t.reader is None
            t.reader, t.reader_changes = True, int(obj["changes"])
            t.qos = QosProfile(reliable=bool(obj["reliable"]), durability=str(obj["durability"]),
                               depth=int(obj.get("depth", 1000)))
            t.heard = {bytes.fromhex(g) for g in obj["heard"]}
            if first and self.on_reader is not None:
                self.on_reader(t, self.discovery.publishers(t.dds_topic))
            if self.on_matched is not None:
                self.on_matched({u.key: frozenset(u.heard) for u in self.taps if u.reader is not None})
        elif what == "description":
            self._described(obj)
        elif what == "error":
            k = obj.get("id")
            where = f"{self.taps[int(k)].where}: warning: {self.taps[int(k)].key}: " if k is not None else "warning: "
            self.warn(f"{where}the rclpy source cannot subscribe ({obj.get('text')}): the ROS 2 Python "
                      f"{self.python} lacks the message package; its messages are not heard")

    def _check_graph(self) -> None:
        """Warn about publishers of another type on a tapped topic and other writers on a watched one;
        ask for the definition of each of the contract's type with another type hash (:meth:`_ask`)."""
        for t in self.taps:
            want = ros_type(t.struct)
            for p in self.discovery.publishers(t.dds_topic):
                if p.type_name != want:
                    self._warn_once(t.key, p.guid, "type", f"{t.where}: warning: {t.key}: "
                                    f"{self.discovery.who(p)} publishes {p.type_name}, the contract's type is "
                                    f"{want}; its messages are not heard")
                    continue
                theirs, ours = self.discovery.hash_of(t.dds_topic, p.guid), self.type_hash(t.struct)
                if theirs and ours and theirs != ours:
                    self._ask(t, p.guid, (want, theirs))
        for dds_topic, (key, where, role) in self.watched.items():
            for p in self.discovery.publishers(dds_topic):
                who = self.discovery.who(p)
                if who not in self.bypass[key]:
                    self.bypass[key].add(who)
                    self.warn(f"{where}: warning: /{key}: {who} writes on the {role} beside the monitor; what "
                              "it writes is not checked, and the evidence is not discharged while it does")


__all__ = ["AGENT", "RclpyBus", "RclpyUnavailable", "agent_answer"]
