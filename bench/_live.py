"""What the live monitor benches share (bench/monitor_live.py for ROS 1, bench/monitor_live_dds.py
for DDS): the recorded run they publish, waiting for a process to say it is ready, stopping the
processes they start, their CPU and the latencies' p99."""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

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


def stop(p: subprocess.Popen[bytes], sig: int = signal.SIGTERM) -> None:
    """Send ``sig`` to the process group of ``p`` (started in a session of its own), SIGKILL after 20 s."""
    if p.poll() is None:
        os.killpg(p.pid, sig)
        try:
            p.wait(20)
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
