"""A live ROS 2 run recorded as a ROS 2 bag (``--record BAG``), in either of
rosbag2's storage formats: SQLite 3 (``.db3``, the default before Iron) or
MCAP (the default since Iron), written by rosbags (``rosbag2`` format
version 8, which ``ros2 bag`` reads from Iron on and rosbags reads in any
version).

Each message of a contract topic is stored as it came off the wire (its CDR
bytes, encapsulation header included: what rosbag2 stores), under its ROS
name, with the time the monitor received it, the same time the live engine
gives a message without a header stamp; the message definition comes from
the workspace's ``.msg`` files and rosbags' store (the types the monitor
decoded with).  So ``rclverify monitor BAG`` checks exactly the messages the
live run checked, at the same times, and gives the same verdicts
(tests/test_monitor_live_dds.py).
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping, Sequence

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
    ``pkg/msg/T``) to a new ROS 2 bag directory ``path``.  Raises
    :class:`BagError` when the bag cannot be created."""

    def __init__(self, path: Path, storage: str, topics: Mapping[str, str], msg_dirs: Sequence[Path]) -> None:
        from rosbags.rosbag2 import StoragePlugin, Writer

        from ...traces.bag import typestore
        from ...traces.events import TraceError
        self.path = Path(path)
        if self.path.suffix == ".mcap":  # a bag is a directory: name it without the suffix
            self.path = self.path.with_suffix("")
        if self.path.exists():
            raise BagError(f"{self.path}: error: exists; a recording goes to a new bag directory")
        try:
            store = typestore(list(msg_dirs))
        except TraceError as exc:
            raise BagError(str(exc)) from None
        self.writer = Writer(self.path, version=8,
                             storage_plugin=StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3)
        self.writer.open()
        self.connections: dict[str, Any] = {}
        self.count = 0
        try:
            for topic, msg_type in topics.items():
                pkg, _, name = msg_type.replace("/msg/", "/").partition("/")
                self.connections[topic.strip("/")] = self.writer.add_connection(
                    "/" + topic.strip("/"), f"{pkg}/msg/{name}", typestore=store)
        except Exception as exc:  # rosbags: a type its store cannot describe
            self.writer.close()
            raise BagError(f"{self.path}: error: cannot record: {exc}") from None

    def write(self, topic: str, time_ns: int, raw: bytes) -> None:
        """One message of ``topic`` received at ``time_ns`` (ns since the epoch)."""
        conn = self.connections.get(topic)
        if conn is not None:
            self.writer.write(conn, time_ns, raw)
            self.count += 1

    def close(self) -> dict[str, Any]:
        """Finish the bag; returns what the evidence says of it."""
        self.writer.close()
        return {"path": str(self.path), "messages": self.count, "topics": sorted("/" + t for t in self.connections)}


__all__ = ["BagError", "BagRecorder", "STORAGES", "storage_of"]
