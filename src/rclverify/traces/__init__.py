"""Recorded runs of a ROS system as streams of events.

:mod:`.events` is the event record and the located error; :mod:`.jsonl`
reads ROSMonitoring's JSON-lines logs (:mod:`.jsonl_blocks`: a block of
lines at a time, as columns, for the offline batch path), :mod:`.bag` ROS 1 and ROS 2 bags
(through ``rosbags``; :mod:`.bag_blocks`: a ROS 2 bag's messages a block
at a time, as columns, for the offline batch path); :mod:`.table` a run
already held in columns; :mod:`.mapping` turns messages into RCL values with
the paper's mapping rules (lines 535-548).  :func:`read_trace` picks the
reader by the file's form.
"""
from __future__ import annotations

from pathlib import Path
from typing import Callable, Iterator, Sequence

from rclverify.traces.events import Event, TraceError
from rclverify.traces.guard import LOG_SUFFIXES, check_trace_path


def read_trace(path: Path, msg_dirs: Sequence[Path] = (), *, streams: bool = False,
               on_warning: Callable[[str], None] | None = None) -> Iterator[Event]:
    """Events of the trace at ``path`` in order (a generator: memory is flat).

    ``.jsonl``/``.log``/``.txt``/``.json`` files are ROSMonitoring logs;
    ``.bag``, ``.mcap``, ``.db3`` or a ROS 2 bag directory are bags, whose
    non-standard message types are read from the ``.msg`` files found under
    ``msg_dirs``.  Only regular files are opened (:mod:`.guard`): a log may
    also be a FIFO when ``streams`` (a log named on the command line); an
    entry of a bag directory that is not a regular file and that the reader
    never opens is skipped, each with a warning line passed to
    ``on_warning``.  Raises :class:`TraceError` (located) for a trace it
    cannot read, or one that could block the reader (a FIFO, a device).
    """
    for w in check_trace_path(path, streams):
        if on_warning is not None:
            on_warning(w)
    if not path.is_dir() and path.suffix in LOG_SUFFIXES:
        from rclverify.core.extras import installed  # deferred: optional or conditional (inside a block)
        if not installed("numpy"):  # no batch path without the fast extra: the events one by one
            from rclverify.traces.jsonl import read_jsonl  # deferred: optional or conditional (inside a block)
            return read_jsonl(path)
        from rclverify.traces.jsonl_blocks import JsonlLog  # deferred: optional or conditional (inside a block)
        return JsonlLog(path)  # its events, as read_jsonl reads them, or its blocks for the batch path
    from rclverify.core.extras import installed, missing_message  # deferred: start-up (only for a bag)
    if not installed("rosbags"):
        raise TraceError(f"{path}: error: {missing_message('rosbags', 'reading a bag')}")
    from rclverify.traces.bag_blocks import BagTrace  # deferred: start-up (loads numpy, rclverify.traces.bag and more only when called)
    return BagTrace(path, msg_dirs)  # read_bag's events, or its blocks for the batch path (a ROS 2 bag)


__all__ = ["Event", "TraceError", "read_trace"]
