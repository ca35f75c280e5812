"""The rclpy agent's output (:mod:`agent`): the frames it queues for the
monitor, written to stdout in one write per batch.

Imported by the agent and its sibling modules as a top-level module (their
folder is the script's), so it imports the standard library only.
"""
from __future__ import annotations

import os

_out: list[bytes] = []


def emit(frame: bytes) -> None:
    """Queue one frame for the monitor; :func:`_flush` writes the queued frames, in order."""
    _out.append(frame)


def flush() -> None:
    """Write every queued frame to stdout in one write (one system call for a batch of samples)."""
    if not _out:
        return
    data = b"".join(_out)
    _out.clear()
    view = memoryview(data)
    while view:
        view = view[os.write(1, view):]
