"""What the live monitor benches share (bench/monitor_live.py for ROS 1, bench/monitor_live_dds.py
for DDS): the recorded run they publish, waiting for a process to say it is ready, stopping the
processes they start, their CPU, the latencies' p99 and CPU burners beside a run."""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator

ROOT = Path(__file__).resolve().parents[1]
RUN = ROOT / "backends" / "monitors" / "traces" / "nominal.jsonl"


def messages() -> list[dict[str, Any]]:
    """The recorded nominal run's lines (topic, time and fields), the messages the benches publish."""
    return [json.loads(line) for line in RUN.read_text().splitlines() if line.strip()]


def wait_text(path: Path, text: str, timeout: float) -> None:
    """Wait until the file ``path`` holds ``text`` (s); ``SystemExit`` after ``timeout`` seconds."""
    deadline = time.monotonic() + timeout
    while not (path.exists() and text in path.read_text(errors="replace")):
        if time.monotonic() > deadline:
            raise SystemExit(f"{path.name} never said {text!r}")
        time.sleep(0.05)


def stop(p: subprocess.Popen[bytes], sig: int = signal.SIGTERM, grace: float = 20.0) -> None:
    """Send ``sig`` to the process group of ``p`` (started in a session of its own), SIGKILL after ``grace`` s."""
    if p.poll() is None:
        os.killpg(p.pid, sig)
        try:
            p.wait(grace)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait(5)


def cpu_seconds(pid: int) -> float | None:
    """User + system CPU seconds of a process (Linux ``/proc``), or None."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except (OSError, IndexError, ValueError):
        return None


def thread_cpu_seconds(pid: int) -> dict[str, float]:
    """User + system CPU seconds of each thread of process ``pid`` by its name (``/proc/<pid>/task``; the
    threads of one name summed, but Python's own, which carry the interpreter's name and are keyed
    ``python/<tid>``; empty elsewhere): the monitor's engine, bus and middleware threads."""
    out: dict[str, float] = {}
    for stat in Path(f"/proc/{pid}/task").glob("*/stat"):
        try:
            head, rest = stat.read_text().rsplit(")", 1)
        except OSError:
            continue
        fields = rest.split()
        name = head.split("(", 1)[1]
        if name.startswith("python"):
            name = f"python/{stat.parent.name}"
        out[name] = out.get(name, 0.0) + (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    return out


def _children(pid: int) -> Iterator[tuple[int, list[str]]]:
    """Each live child process of ``pid`` (Linux ``/proc``; none elsewhere): its pid and the fields of its
    ``stat`` after the command name (field 1 the parent's pid, 11 and 12 user and system clock ticks)."""
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if len(fields) > 12 and fields[1] == str(pid):
            yield int(stat.parent.name), fields


def children_cpu_seconds(pid: int) -> float:
    """User + system CPU seconds of the live child processes of ``pid`` (Linux ``/proc``; 0 elsewhere): the
    rclpy source's agent, which the monitor starts in a session of its own."""
    return sum((int(f[11]) + int(f[12])) / os.sysconf("SC_CLK_TCK") for _, f in _children(pid))


def children_thread_cpu_seconds(pid: int) -> dict[str, float]:
    """:func:`thread_cpu_seconds` of each live child process of ``pid`` (the rclpy agent's threads), merged."""
    out: dict[str, float] = {}
    for child, _ in _children(pid):
        for k, v in thread_cpu_seconds(child).items():
            out[k] = out.get(k, 0.0) + v
    return out


def p99(xs: list[float]) -> float:
    """The 99th percentile of ``xs`` (nearest rank)."""
    ys = sorted(xs)
    return ys[min(len(ys) - 1, int(0.99 * len(ys)))]


def exit_on_sigterm() -> None:
    """SIGTERM (``timeout``, a CI job's end) raises ``SystemExit`` in the
    bench's own process, so the ``finally`` blocks stop the processes it
    started (each in a session of its own): killed by the default handler,
    the bench left a 10-minute publisher running."""
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(128 + signal.SIGTERM))


@contextmanager
def burners(n: int) -> Iterator[list[subprocess.Popen[bytes]]]:
    """``n`` processes spinning ``while True: pass`` (each in a session of its own) while the block
    runs, every one stopped (SIGKILL) and reaped when it ends, however it ends: the load of other
    work on the machine, beside a run."""
    procs: list[subprocess.Popen[bytes]] = []
    try:
        for _ in range(n):
            procs.append(subprocess.Popen([sys.executable, "-c", "while True: pass"], start_new_session=True,
                                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        yield procs
    finally:
        for p in procs:
            stop(p, signal.SIGKILL)
