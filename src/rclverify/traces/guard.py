"""Which files of a recorded run may be opened: regular files only.

Opening a FIFO for reading blocks until someone writes to it, and a device
may never end; a recorded run is user input and may hold either (a FIFO
named ``metadata.yaml`` in a ROS 2 bag directory held ``ground``, ``ros
check`` and ``monitor`` for ever).  So every reader of a trace or a bag
asks :func:`check_trace_path` first (the rule of ``ros/extract/safefs.py``, which
guards the ROS scan's source files, applied to recorded runs; it lives here
because the trace readers sit below the ROS layer):

* the trace itself must be a regular file or a directory (a bag
  directory); a ROSMonitoring log may also be a stream (a FIFO) when the
  caller says so (``streams=True``: a log named on the command line);
* in a bag directory, an entry that is not a regular file (``os.stat``
  follows links) and that the bag reader would open (``metadata.yaml``, a
  storage file ``*.db3``/``*.mcap`` or SQLite's ``*.db3-*`` companions)
  makes the bag unreadable: :class:`~.events.TraceError`, located at that
  entry; any other such entry is never opened, and is skipped with a
  warning (returned, for the caller to show).

Standard library only; no file is opened here.
"""
from __future__ import annotations

import os
import stat
from pathlib import Path

from rclverify.traces.events import TraceError

#: Suffixes of the files a ROS bag reader opens in a bag directory.
BAG_FILE_SUFFIXES = (".yaml", ".db3", ".mcap")
#: Suffixes of ROSMonitoring logs (traces/__init__.py picks the reader by them).
LOG_SUFFIXES = (".jsonl", ".log", ".txt", ".json")


def kind_of(mode: int) -> str:
    """A word for a file type that is not a regular file or a directory."""
    if stat.S_ISFIFO(mode):
        return "a FIFO"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def _opened_by_reader(name: str) -> bool:
    return name == "metadata.yaml" or name.endswith(BAG_FILE_SUFFIXES) or ".db3-" in name


def check_trace_path(path: Path, streams: bool = False) -> list[str]:
    """Check that reading the trace at ``path`` opens regular files only.

    Returns warnings (``path: warning: ...``), one per entry of a bag
    directory that is not a regular file and is skipped.  Raises
    :class:`TraceError` (``path: error: ...``) when the trace, or an entry a
    bag reader would open, is a FIFO, device or socket (``streams``: a log
    by its suffix may be a FIFO, read as a stream), or cannot be looked at.
    """
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise TraceError(f"{path}: error: no such trace") from None
    except OSError as exc:
        raise TraceError(f"{path}: error: cannot read the trace: {exc.strerror or exc}") from None
    if stat.S_ISREG(st.st_mode):
        return []
    if stat.S_ISFIFO(st.st_mode) and streams and path.suffix in LOG_SUFFIXES:
        return []
    if not stat.S_ISDIR(st.st_mode):
        raise TraceError(f"{path}: error: {kind_of(st.st_mode)}, not a recorded run (a log file or a bag): "
                         "not read, since reading it could block for ever")
    warnings: list[str] = []
    try:
        names = sorted(os.listdir(path))
    except OSError as exc:
        raise TraceError(f"{path}: error: cannot list the bag directory: {exc.strerror or exc}") from None
    for name in names:
        entry = path / name
        try:
            mode = os.stat(entry).st_mode
        except OSError:
            try:
                mode = os.lstat(entry).st_mode  # a dangling link (or one in a loop): no reader can open it
            except OSError as exc:
                raise TraceError(f"{entry}: error: cannot look at it: {exc.strerror or exc}") from None
        if stat.S_ISREG(mode) or stat.S_ISDIR(mode):
            continue
        if _opened_by_reader(name):
            raise TraceError(f"{entry}: error: {kind_of(mode)}, not a regular file: the bag reader would open it, "
                             "so the bag is not read (reading it could block for ever)")
        warnings.append(f"{entry}: warning: {kind_of(mode)}, not a regular file: skipped")
    return warnings


__all__ = ["BAG_FILE_SUFFIXES", "LOG_SUFFIXES", "check_trace_path", "kind_of"]
