"""A live ROS 2 run recorded as a ROS 2 bag (``--record BAG``), in either of
rosbag2's storage formats: SQLite 3 (``.db3``, the default before Iron) or
MCAP (the default since Iron), written by rosbags (``rosbag2`` format
version 8, which ``ros2 bag`` reads from Iron on and rosbags reads in any
version).

Each message of a contract topic is stored as it came off the wire (its CDR
bytes, encapsulation header included: what rosbag2 stores), under its ROS
name, at its event time (its publisher's source timestamp:
:mod:`rclverify.traces.event_time`), the same time the live engine gives a
message without a header stamp; the message definition comes from
the workspace's ``.msg`` files and rosbags' store (the types the monitor
decoded with), or, for samples the monitor decoded in the definition their
publisher declared (:class:`~.types.Declared`), that definition
(:func:`~.bag_types.declared_store`); a contract type the workspace does not
define and the rclpy source's ROS 2 Python describes (``described``:
docs/ros2.md, "The publisher's own definition") is recorded in that
description, as it was read.  A topic's connection is made at its first
message, in the definition that message is written in (one topic,
one definition: a later message in another is not written, and counted in
``failed``), and at the end for a topic that had none.  So ``rclverify
monitor BAG`` checks exactly the messages the live run checked, at the same
times, and gives the same verdicts (tests/backends/test_monitor_live_dds.py,
tests/runtime/test_ros2_declared_types.py).

The run's simulated clock goes to the bag too (``heard``: ``/clock``,
:mod:`rclverify.traces.sim_clock`): each ``/clock`` message the live run heard,
as it came off the wire, at the same event time, so the bag's offline check
places the simulated clock where the live run did.  Such a topic's connection
is made at its first message only: a run that heard no ``/clock`` records none.

The linked services' and actions' calls go to the bag too, as ROS 2 records
them (``<service>/_service_event`` ...), with the live call book's pairing
(:mod:`.bag_calls`): their connections carry the definitions and type
hashes :mod:`.bag_types` makes, so ``rclverify monitor BAG`` judges the calls
as the live run did (tests/runtime/test_ros2_bag_calls.py).

The bag carries the run's end (:meth:`BagRecorder.end`): one message, written last, on
``/rclverify/run_end`` (``builtin_interfaces/msg/Time``) at the time the
live run's monitors' clock reached, so a question whose horizon the live
clock passed is closed, and a deadline it passed is ``false``, on the bag
as on the log (:mod:`rclverify.traces.bag_end`).
"""
from __future__ import annotations

import math
import queue
import shutil
import threading
from pathlib import Path
from typing import Any, Mapping, Sequence
from rclverify.traces.bag import typestore
from rclverify.traces.bag_late import KEY as LATE_KEY, encode as encode_late
from rclverify.traces import bag_end
from rclverify.runtime.dds.bag_types import declared_store
from rclverify.runtime.dds.types import Declaration
from rclverify.traces.events import TraceError
from rclverify.runtime.shapes import BagSummary

STORAGES = ("sqlite3", "mcap")


class BagError(Exception):
    """The bag cannot be written (it exists, a type is unknown); ``str`` says why."""


def storage_of(path: Path, storage: str | None) -> str:
    """The storage format: ``storage`` when given, else ``mcap`` for a path
    ending in ``.mcap``, else ``sqlite3``."""
    if storage:
        return storage
    return "mcap" if Path(path).suffix == ".mcap" else "sqlite3"


class BagRecorder:
    """Write raw messages of ``topics`` (contract topic without ``/`` ->
    ``pkg/msg/T``) and of ``calls`` (call topic without ``/`` -> ``(type,
    ros2idl definition, type hash)``, :mod:`.bag_calls`) to a new ROS 2 bag
    directory ``path``; ``described``: contract topic -> the :class:`~.types.Declaration`
    its type is known from when no definition of the workspace or rosbags' store has it; ``heard``: topic
    without ``/`` -> ``pkg/msg/T`` of each topic recorded beside the contract topics only when messages of it
    come (``/clock``, module docstring).  Raises :class:`BagError` when the bag cannot be created.

    Threads: rosbags' writer is opened, written and closed in one thread of
    its own (``rclverify-bag``; SQLite allows a connection only in the thread
    that made it), fed through a queue: :meth:`write` may be called from any
    thread and never waits for the disk; :meth:`close` waits until every
    queued message is written and the bag is finished."""

    def __init__(self, path: Path, storage: str, topics: Mapping[str, str], msg_dirs: Sequence[Path],
                 open_timeout_s: float = 30.0,
                 calls: Mapping[str, tuple[str, str | None, str | None]] | None = None,
                 described: Mapping[str, Declaration] | None = None,
                 heard: Mapping[str, str] | None = None) -> None:
        self.path = Path(path)
        if self.path.suffix == ".mcap":  # a bag is a directory: name it without the suffix
            self.path = self.path.with_suffix("")
        if self.path.exists():
            raise BagError(f"{self.path}: error: exists; a recording goes to a new bag directory")
        try:
            self._store = typestore(list(msg_dirs))
        except TraceError as exc:
            raise BagError(str(exc)) from None
        self.storage, self.topics = storage, {t.strip("/"): ty for t, ty in topics.items()}
        #: the call topics (:mod:`.bag_calls`): topic -> (type, ros2idl definition, type hash), or
        #: (type, None, None) for a type rosbags' store describes
        self.calls = {t.strip("/"): d for t, d in (calls or {}).items()}
        #: contract topic -> the declaration its type is known from when the workspace does not define it
        #: (the rclpy source's ROS 2 Python describes it): its messages are recorded in that definition
        self.described = {t.strip("/"): d for t, d in (described or {}).items()}
        #: topics recorded beside the contract topics when messages of them come (topic -> ``pkg/msg/T``)
        self.heard = {t.strip("/"): ty for t, ty in (heard or {}).items() if t.strip("/") not in self.topics}
        #: messages written: the contract topics', the call topics', the :attr:`heard` topics' (per topic)
        self.count = self.call_count = self.failed = 0
        self.heard_count: dict[str, int] = {}
        #: per contract topic whose connection is made: the declaration it records (``None``: the workspace's)
        self._declared: dict[str, Any] = {}
        self._late: dict[str, list[tuple[float, float]]] = {}  # topic -> (time s, late s) of each late message
        self._end_ns: int | None = None  # the run's end (ns since the epoch), written last (:meth:`end`)
        self.error = ""
        self._queue: queue.SimpleQueue[tuple[str, int, bytes, Any] | None] = queue.SimpleQueue()
        self._opened = threading.Event()
        self._thread = threading.Thread(target=self._run, name="rclverify-bag", daemon=True)
        self._thread.start()
        if not self._opened.wait(open_timeout_s):
            raise BagError(f"{self.path}: error: cannot record: the bag was not opened within {open_timeout_s:g} s")
        if self.error:
            self._thread.join(open_timeout_s)
            shutil.rmtree(self.path, ignore_errors=True)  # new (checked above): no half-made bag is left behind
            raise BagError(f"{self.path}: error: cannot record: {self.error}")

    def _open(self) -> tuple[Any, dict[str, Any]]:
        from rosbags.rosbag2 import StoragePlugin, Writer  # deferred: start-up (loads rosbags and more only when called)
        writer = Writer(self.path, version=8,
                        storage_plugin=StoragePlugin.MCAP if self.storage == "mcap" else StoragePlugin.SQLITE3)
        writer.open()
        connections: dict[str, Any] = {}
        for topic, msg_type in {**self.topics, **self.heard}.items():  # each described now; connected at its first message
            try:
                if topic in self.described:
                    declared_store(self.described[topic])  # raises for a type rosbags cannot describe
                else:
                    self._store.generate_msgdef(_msg_name(msg_type), ros_version=2)
                    self._store.hash_rihs01(_msg_name(msg_type))
            except Exception as exc:  # rosbags: a type its store cannot describe
                writer.close()
                wide = " (rosbags has no wide string: a wstring cannot be stored)" if "wstring" in str(exc) else ""
                raise RuntimeError(f"topic /{topic} ({msg_type}): {exc}{wide}") from None
        for topic, (msg_type, msgdef, digest) in self.calls.items():
            try:
                connections[topic] = writer.add_connection("/" + topic, msg_type, msgdef=msgdef, rihs01=digest,
                                                           typestore=self._store)
            except Exception as exc:  # rosbags: a definition it refuses
                writer.close()
                raise RuntimeError(f"topic /{topic} ({msg_type}): {exc}") from None
        return writer, connections

    def _run(self) -> None:
        try:
            writer, connections = self._open()
        except Exception as exc:  # noqa: BLE001 - said by the constructor, in the caller's thread
            self.error = str(exc) or type(exc).__name__
            self._opened.set()
            return
        self._opened.set()
        try:
            while True:
                item = self._queue.get()
                if item is None:
                    break
                topic, time_ns, raw, decl = item
                try:
                    conn = connections.get(topic)
                    if conn is None:  # a contract topic's first message: its definition (module docstring)
                        conn = connections[topic] = self._connect(writer, topic, decl)
                    if topic in self.topics and decl is not self._declared.get(topic):
                        raise ValueError(f"/{topic}: a message in another definition than the topic's recorded one")
                    writer.write(conn, time_ns, raw)
                    if topic in self.topics:
                        self.count += 1
                    elif topic in self.heard:
                        self.heard_count[topic] = self.heard_count.get(topic, 0) + 1
                    else:
                        self.call_count += 1
                except Exception as exc:  # noqa: BLE001 - one message lost, said in close()'s record
                    self.failed += 1
                    self.error = f"{type(exc).__name__}: {exc}"
        finally:
            if self._end_ns is not None:  # the run's end, its last message (traces/bag_end.py)
                try:
                    self._write_end(writer, self._end_ns)
                except Exception as exc:  # noqa: BLE001 - said in close()'s record
                    self.failed += 1
                    self.error = f"{type(exc).__name__}: {exc}"
            if self._late:  # what the live monitor heard late, as its log says it (traces/bag_late.py)
                writer.set_custom_data(LATE_KEY, encode_late(self._late))
            for topic in self.topics:  # a topic without a message is in the bag too, in the workspace's definition
                if topic not in connections:
                    try:
                        connections[topic] = self._connect(writer, topic, None)
                    except Exception as exc:  # noqa: BLE001 - said in close()'s record
                        self.error = f"{type(exc).__name__}: {exc}"
            writer.close()

    def _connect(self, writer: Any, topic: str, decl: Any) -> Any:
        """The connection of ``topic``: a contract topic's in ``decl``'s definition (a
        :class:`~.types.Declaration`) or, ``None``, the workspace's; a call topic's from :attr:`calls`."""
        if topic in self.topics:
            self._declared[topic] = decl
            decl = decl if decl is not None else self.described.get(topic)
            if decl is not None:
                return writer.add_connection("/" + topic, decl.name, typestore=declared_store(decl))
            return writer.add_connection("/" + topic, _msg_name(self.topics[topic]), typestore=self._store)
        if topic in self.heard:
            return writer.add_connection("/" + topic, _msg_name(self.heard[topic]), typestore=self._store)
        msg_type, msgdef, digest = self.calls[topic]
        return writer.add_connection("/" + topic, msg_type, msgdef=msgdef, rihs01=digest, typestore=self._store)

    def _write_end(self, writer: Any, time_ns: int) -> None:
        """The end-of-run message at ``time_ns`` (:mod:`rclverify.traces.bag_end`), in the writer's thread."""
        conn = writer.add_connection("/" + bag_end.TOPIC, bag_end.TYPE, typestore=self._store)
        sec, nanosec = bag_end.split_ns(time_ns)
        writer.write(conn, time_ns, bytes(self._store.serialize_cdr(self._store.types[bag_end.TYPE](sec=sec, nanosec=nanosec),
                                                                bag_end.TYPE)))

    def end(self, time_s: float) -> None:
        """Note the run's end: ``time_s`` (s since the epoch, the time line of the run's log) is the time the
        live run's clock reached when it stopped; the bag's last message says it at its close
        (:mod:`rclverify.traces.bag_end`).  Called before :meth:`close`; a time that is not finite
        and >= 0 is ignored (no end is written)."""
        if isinstance(time_s, (int, float)) and math.isfinite(time_s) and time_s >= 0:
            self._end_ns = round(time_s * 1e9)

    def late(self, topic: str, time_s: float, late_s: float) -> None:
        """Note that the message of contract topic (or :attr:`heard` topic) ``topic`` (no leading ``/``)
        at ``time_s`` (s since the epoch: the time it is written at) was heard
        ``late_s`` (s) late by the live monitor: the bag says so at its close
        (:mod:`rclverify.traces.bag_late`).  Called from the engine's thread
        before :meth:`close`."""
        if topic in self.topics or topic in self.heard:
            self._late.setdefault(topic, []).append((time_s, late_s))

    def write(self, topic: str, time_ns: int, raw: bytes) -> None:
        """Queue one message of ``topic`` (a contract topic, a :attr:`heard` topic or a call topic, no
        leading ``/``) at ``time_ns`` (ns since the epoch: a contract or heard topic's
        event time, a call topic's time in the call book, :mod:`.bag_calls`); a
        topic not recorded, or data that are not bytes, is ignored (counted in
        ``failed`` for the latter: nothing malformed reaches the bag)."""
        if topic not in self.topics and topic not in self.calls and topic not in self.heard:
            return
        if not isinstance(raw, (bytes, bytearray, memoryview)) or not isinstance(time_ns, int) or time_ns < 0:
            self.failed += 1
            return
        self._queue.put((topic, time_ns, bytes(raw), getattr(raw, "declaration", None)))

    def close(self, timeout_s: float = 60.0) -> BagSummary:
        """Write what is queued, finish the bag (idempotent); returns what the evidence says of it
        (``messages``: contract topics' messages written, ``topics`` theirs and each :attr:`heard` topic
        a message of which was written, ``call_messages``: call topics' messages written, ``failed``:
        messages not written, ``error``: the last writer error)."""
        if self._thread.is_alive():
            self._queue.put(None)
            self._thread.join(timeout_s)
        out: BagSummary = {"path": str(self.path), "messages": self.count,
                           "topics": sorted("/" + t for t in [*self.topics, *self.heard_count])}
        if self.calls:
            out["call_messages"] = self.call_count
            out["call_topics"] = sorted("/" + t for t in self.calls)
        if self.failed or self._thread.is_alive():
            out["failed"] = self.failed
            out["error"] = self.error or f"the bag was not finished within {timeout_s:g} s"
        return out


def _msg_name(msg_type: str) -> str:
    """``pkg/msg/T`` of ``pkg/T`` or ``pkg/msg/T``."""
    pkg, _, name = msg_type.replace("/msg/", "/").partition("/")
    return f"{pkg}/msg/{name}"


__all__ = ["BagError", "BagRecorder", "STORAGES", "storage_of"]
