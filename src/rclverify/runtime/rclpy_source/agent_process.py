"""The rclpy agent (:mod:`.agent`) as a process of the monitor's: its
script (:data:`AGENT`), run in a ROS 2 Python; the one-shot answers it
gives when run with arguments (:func:`agent_answer`: ``--describe``,
``--graph``); the capacity asked for on the pipe it writes its frames to
(:func:`widen`); and the one error of a source that cannot run
(:class:`RclpyUnavailable`).  The long-running agent of a live run is
:class:`~.bus.RclpyBus`'s.
"""
from __future__ import annotations

import io
import json
import subprocess
from pathlib import Path
from typing import Any

from rclverify.runtime.rclpy_source.wire import read_frame

AGENT = Path(__file__).with_name("agent.py")
#: the agent's pipe's capacity asked for (Linux ``F_SETPIPE_SZ``; an unprivileged process may ask up to
#: ``/proc/sys/fs/pipe-max-size``, 1 MiB by default): about 4000 samples of a few hundred bytes, so the agent
#: goes on taking messages while the monitor's reading thread waits for the interpreter
PIPE_BYTES = 1 << 20


class RclpyUnavailable(Exception):
    """The rclpy source cannot run; ``str`` says why in one line."""


def agent_answer(python: Path, args: list[str], timeout_s: float, unreachable: str, failed: str) -> Any:
    """The JSON answer of one run of the agent (:data:`AGENT`) in the ROS 2 Python ``python`` with
    ``args`` (``--describe ...``, ``--graph S``): the body of its one ``J`` frame on stdout.  Raises
    :class:`RclpyUnavailable` with ``unreachable: <why>`` when the process cannot start or outlives
    ``timeout_s`` seconds, ``failed (exit N): <its last stderr line>`` when it fails or answers no
    ``J`` frame."""
    try:
        proc = subprocess.run([str(python), str(AGENT), *args], capture_output=True, timeout=timeout_s)
    except (OSError, subprocess.TimeoutExpired) as exc:
        raise RclpyUnavailable(f"{unreachable}: {exc}") from None
    frame = read_frame(io.BytesIO(proc.stdout))
    if proc.returncode != 0 or frame is None or frame[0] != b"J":
        last = proc.stderr.decode(errors="replace").strip().splitlines()[-1:]
        raise RclpyUnavailable(f"{failed} (exit {proc.returncode}): {' '.join(last)}")
    return json.loads(frame[1])


def widen(fd: int) -> None:
    """Ask for :data:`PIPE_BYTES` of capacity on the pipe ``fd`` (Linux); elsewhere, or where the system
    refuses, the pipe keeps its own (64 KiB on Linux) and the agent waits for the monitor sooner."""
    import fcntl  # deferred: POSIX only
    setsz = getattr(fcntl, "F_SETPIPE_SZ", None)
    if setsz is None:
        return
    try:
        fcntl.fcntl(fd, setsz, PIPE_BYTES)
    except OSError:
        pass


__all__ = ["AGENT", "PIPE_BYTES", "RclpyUnavailable", "agent_answer", "widen"]
