"""One external tool run with a wall-clock bound (AJPF's Java, SPIN's verifier).

The tool runs in a session of its own so that everything it starts (``pan``
forks nothing, but MCAPL's JVM may) dies with it when the bound is reached.
"""
from __future__ import annotations

import os
import signal
import subprocess
import time
from pathlib import Path
from typing import Mapping


def run_bounded(cmd: list[str], cwd: Path, timeout_s: float,
                env: Mapping[str, str] | None = None) -> tuple[str, int | None, float]:
    """Run ``cmd`` in ``cwd`` for at most ``timeout_s`` seconds.

    Returns ``(stdout and stderr together, decoded with replacement; the exit
    code, or None when the bound was reached and the process group was
    killed; the wall-clock duration in seconds, rounded to ms)``.  Raises
    ``OSError`` when the process cannot be started at all.
    """
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, cwd=cwd, env=None if env is None else dict(env), stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, start_new_session=True)
    try:
        out, _ = proc.communicate(timeout=max(timeout_s, 0.1))
        code: int | None = proc.returncode
    except subprocess.TimeoutExpired:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        out, _ = proc.communicate()
        code = None
    return out.decode("utf-8", errors="replace"), code, round(time.perf_counter() - t0, 3)
