"""Recorded runs of a ROS system as streams of events.

:mod:`.events` is the event record and the located error; :mod:`.jsonl`
reads ROSMonitoring's JSON-lines logs, :mod:`.bag` ROS 1 and ROS 2 bags
(through ``rosbags``); :mod:`.mapping` turns messages into RCL values with
the paper's mapping rules (lines 535-548).  :func:`read_trace` picks the
reader by the file's form.
"""
from __future__ import annotations

from pathlib import Path
from typing import Iterator, Sequence

from .events import Event, TraceError


def read_trace(path: Path, msg_dirs: Sequence[Path] = ()) -> Iterator[Event]:
    """Events of the trace at ``path`` in order (a generator: memory is flat).

    ``.jsonl``/``.log``/``.txt``/``.json`` files are ROSMonitoring logs;
    ``.bag``, ``.mcap``, ``.db3`` or a ROS 2 bag directory are bags, whose
    non-standard message types are read from the ``.msg`` files found under
    ``msg_dirs``.  Raises :class:`TraceError` (located) for a file it cannot read.
    """
    if path.is_file() and path.suffix in (".jsonl", ".log", ".txt", ".json"):
        from .jsonl import read_jsonl
        return read_jsonl(path)
    if path.exists():
        from .bag import read_bag
        return read_bag(path, msg_dirs)
    raise TraceError(f"{path}: error: no such trace")


__all__ = ["Event", "TraceError", "read_trace"]
