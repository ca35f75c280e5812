"""A recorded ROS 2 graph kept as a ``rosgraph_msgs/msg/Graph`` message in a ROS 2 bag, and the one reader of a
recorded graph whichever form it has (docs/nodl.md, "The graph message in a bag").

``--record-graph FILE`` (``nodl check --ros2``, ``ros diff --ros2``) writes, by ``FILE``'s suffix
(:func:`write_graph`):

* ``.mcap`` or ``.db3``: a new ROS 2 bag directory (``FILE`` without the suffix, as ``--record`` names a bag),
  MCAP or SQLite 3 storage, rosbag2 format version 8, holding one message on ``/rosgraph`` (the topic the ROS
  graph monitor publishes on) of type ``rosgraph_msgs/msg/Graph`` (:mod:`.graph_msg`), at the time it was
  recorded; the connection carries the message's definition and its type hash (``RIHS01_...``, computed
  from the definition); the bag's metadata (``custom_data``) keeps the reading's rmw and label
  (``rclverify.graph.rmw``, ``rclverify.graph.source``), which the message has no field for.  The bag is
  made beside ``FILE`` and moved into place at once (:func:`rclverify.core.atomic.move_into_place`); an
  existing bag is never replaced;
* anything else: the JSON recording of :mod:`rclverify.model.nodl.graph_record`.

``--graph PATH`` reads (:func:`read_graph`) a bag (a directory, a ``.mcap`` or ``.db3`` file) holding
messages of type ``rosgraph_msgs/msg/Graph`` on any topic, whoever wrote it: the last such message (by
its recorded time) is the graph; else the JSON recording.  A connection that names a type hash other
than :func:`.graph_msg.graph_type_hash` was recorded in another definition of the message and is refused,
as is a bag with no graph message, one that cannot be read, or a message that does not decode: one located
error (``E-graph-record``) at the bag.
"""
from __future__ import annotations

import os
import shutil
import time
from pathlib import Path
from typing import Any

from rclverify.lang import ast
from rclverify.lang.errors import RclError, error
from rclverify.ros.graph.graph_msg import GRAPH_TYPE, from_message, graph_store, graph_type_hash, to_message

#: The topic a recorded graph is written on.
TOPIC = "/rosgraph"
#: Bag suffixes: the storage each names.
STORAGES = {".mcap": "mcap", ".db3": "sqlite3"}
_RMW, _SOURCE = "rclverify.graph.rmw", "rclverify.graph.source"


def _fail(shown: str, message: str) -> RclError:
    return RclError([error(ast.Loc(shown, 1, 1), message, "E-graph-record")])


def is_bag(path: Path) -> bool:
    """Whether ``path`` names a ROS 2 bag rather than a JSON recording: a directory, or a file whose suffix is
    ``.mcap`` or ``.db3``."""
    return path.is_dir() or path.suffix in STORAGES


def bag_dir(path: Path) -> Path:
    """The bag directory ``--record-graph`` makes for ``path`` (``graph.mcap`` -> ``graph``)."""
    return path.with_suffix("") if path.suffix in STORAGES else path


def _resolve(path: Path) -> Path:
    """The bag to open for ``path``: the directory ``--record-graph`` made for it when ``path`` itself does not
    exist (``graph.mcap`` -> ``graph``), the bag directory of a storage file that lies in one (its
    ``metadata.yaml`` beside it, the directory named as the file: the metadata is read too), else ``path``."""
    if not os.path.lexists(path) and path.suffix in STORAGES and bag_dir(path).is_dir():
        return bag_dir(path)
    if path.is_file() and path.parent.name == path.stem and (path.parent / "metadata.yaml").is_file():
        return path.parent
    return path


def write_bag(path: Path, dump: dict[str, Any], stamp_ns: int | None = None) -> Path:
    """Write graph dump ``dump`` as one ``rosgraph_msgs/msg/Graph`` message to a new bag for ``path`` (module
    docstring) at ``stamp_ns`` (ns since the epoch; default: now); return the bag directory.  Raises
    :class:`RclError` (``E-graph-record``, at ``path``) when the bag exists or cannot be written."""
    from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime  # deferred: start-up (loads rosbags only when called)
    from rosbags.rosbag2 import StoragePlugin, Writer  # deferred: start-up (loads rosbags only when called)
    from rclverify.core.atomic import move_into_place  # deferred: start-up (loads the writer only when called)
    final = bag_dir(path)
    shown = str(path)
    if os.path.lexists(final):
        raise _fail(shown, f"cannot record the graph: {final} exists; a recording goes to a new bag")
    store = graph_store()
    work = final.with_name(f".{final.name}.{os.getpid()}.tmp")  # the bag is built inside, under its own name
    built = work / final.name
    never = QosTime(sec=0, nsec=0)
    latched = Qos(history=QosHistory.KEEP_LAST, depth=1, reliability=QosReliability.RELIABLE,
                  durability=QosDurability.TRANSIENT_LOCAL, deadline=never, lifespan=never,
                  liveliness=QosLiveliness.AUTOMATIC, liveliness_lease_duration=never,
                  avoid_ros_namespace_conventions=False)
    try:
        work.mkdir()
        writer = Writer(built, version=8, storage_plugin=StoragePlugin.MCAP if STORAGES.get(path.suffix) == "mcap"
                        else StoragePlugin.SQLITE3)
        writer.set_custom_data(_RMW, str(dump.get("rmw", "")))
        if dump.get("source"):
            writer.set_custom_data(_SOURCE, str(dump["source"]))
        writer.open()
        try:
            conn = writer.add_connection(TOPIC, GRAPH_TYPE, msgdef=store.generate_msgdef(GRAPH_TYPE, ros_version=2)[0],
                                         rihs01=graph_type_hash(),
                                         offered_qos_profiles=[latched])
            writer.write(conn, time.time_ns() if stamp_ns is None else stamp_ns,
                         bytes(store.serialize_cdr(to_message(dump), GRAPH_TYPE)))
        finally:
            writer.close()
        move_into_place(built, final)
        work.rmdir()
    except Exception as exc:  # rosbags raises its own writer errors; OSError from the file system
        shutil.rmtree(work, ignore_errors=True)
        raise _fail(shown, f"cannot record the graph: {' '.join(str(exc).split())[:300]}") from None
    return final


def read_bag(path: Path, shown: str | None = None) -> dict[str, Any]:
    """The graph dump (``what``, ``rmw``, ``nodes``, ``endpoints``, and ``source`` where the bag's metadata keeps
    one) of the last ``rosgraph_msgs/msg/Graph`` message of the bag at ``path`` (module docstring).  Raises
    :class:`RclError` (``E-graph-record``) located at the bag."""
    from rosbags.rosbag2 import Reader  # deferred: start-up (loads rosbags only when called)
    from rclverify.traces.events import TraceError  # deferred: start-up
    from rclverify.traces.guard import check_trace_path  # deferred: start-up
    file = shown or str(path)
    path = _resolve(path)
    try:
        check_trace_path(path)
    except TraceError as exc:
        raise _fail(file, f"cannot read the recorded graph: {str(exc).split(': error: ', 1)[-1]}") from None
    want = graph_type_hash()
    try:
        with Reader(path) as reader:
            conns = [c for c in reader.connections if c.msgtype == GRAPH_TYPE]
            if not conns:
                held = sorted({f"{c.topic} ({c.msgtype})" for c in reader.connections})
                raise _fail(file, f"the bag holds no {GRAPH_TYPE} message"
                            + (f" (its topics: {', '.join(held[:8])}{' ...' if len(held) > 8 else ''})" if held else ""))
            other = [c for c in conns if c.digest and c.digest != want]
            if other:
                raise _fail(file, f"{other[0].topic}: {GRAPH_TYPE} recorded with type hash {other[0].digest}, "
                            f"not the definition this reader knows ({want})")
            last: tuple[int, bytes] | None = None
            for _conn, stamp, raw in reader.messages(connections=conns):
                if last is None or stamp >= last[0]:
                    last = (stamp, bytes(raw))
            custom = dict(getattr(getattr(reader.storage, "metadata", None), "custom", None) or {})
    except RclError:
        raise
    except Exception as exc:  # rosbags raises its own reader errors on bad files
        raise _fail(file, f"cannot read the recorded graph: {' '.join(str(exc).split())[:300]}") from None
    if last is None:
        raise _fail(file, f"the bag's {GRAPH_TYPE} connection holds no message")
    try:
        msg = graph_store().deserialize_cdr(last[1], GRAPH_TYPE)
    except Exception as exc:  # rosbags raises its own decoding errors
        raise _fail(file, f"the {GRAPH_TYPE} message does not decode: {' '.join(str(exc).split())[:200]}") from None
    dump = from_message(msg)
    dump["rmw"] = str(custom.get(_RMW, ""))
    if custom.get(_SOURCE):
        dump["source"] = str(custom[_SOURCE])
    elif not dump["rmw"]:
        dump["source"] = f"{GRAPH_TYPE} in {file}"
    return dump


def read_graph(path: Path) -> dict[str, Any]:
    """The graph dump a recording at ``path`` holds: a bag (:func:`is_bag`: :func:`read_bag`), else the JSON
    recording (:func:`rclverify.model.nodl.graph_record.read_record`).  Raises :class:`RclError` located at
    the recording."""
    from rclverify.model.nodl.graph_record import read_record  # deferred: start-up
    return read_bag(path) if is_bag(path) else read_record(path)


def write_graph(path: Path, dump: dict[str, Any]) -> None:
    """Record graph dump ``dump`` at ``path``: a new bag for a ``.mcap`` or ``.db3`` path (:func:`write_bag`),
    else the JSON recording through the atomic writer.  Raises :class:`RclError` located at ``path``."""
    from rclverify.lang.output import write_atomic  # deferred: start-up
    from rclverify.model.nodl.graph_record import record_text  # deferred: start-up
    if path.suffix in STORAGES:
        write_bag(path, dump)
    else:
        write_atomic(path, record_text(dump))


__all__ = ["STORAGES", "TOPIC", "bag_dir", "is_bag", "read_bag", "read_graph", "write_bag", "write_graph"]
