"""The CPUs this process may run on, and how many of them are idle now.

A stage that can split its work over two processes (the second solver's,
:mod:`rclverify.stages.crosscheck.stage`) should do so only when another CPU
would run the second half: on a busy machine the second process only waits
for a core and costs its fork and its own solver.  The one-minute load
average answers that late: at the end of a ``doit -n 2`` run's evidence
phase it still reads about 2 while the other doit process already waits
idle, and the 1000-node system's second solver then ran on one core for
13 s.  :func:`idle_cpus` reads the kernel's per-CPU time
counters (``/proc/stat``, proc(5)) twice, a short window apart, and says
how many of this process's CPUs were idle in between.
"""
from __future__ import annotations

import os
import time

#: How long :func:`idle_cpus` watches the counters, in seconds.
WINDOW_S = 0.05


def allowed_cpus() -> set[int]:
    """The numbers of the CPUs this process may run on (its affinity mask;
    every CPU the machine has where the mask cannot be read)."""
    getter = getattr(os, "sched_getaffinity", None)
    return set(getter(0)) if getter is not None else set(range(os.cpu_count() or 1))


def _ticks(cpus: set[int]) -> tuple[int, int] | None:
    """(idle ticks, all ticks) summed over ``cpus`` from ``/proc/stat``
    (proc(5): a ``cpuN`` line's fields are user, nice, system, idle, iowait,
    irq, softirq, steal, ...; idle and iowait count as idle), or ``None``
    where the file cannot be read or names none of them."""
    try:
        with open("/proc/stat", "rb") as f:
            lines = f.read().split(b"\n")
    except OSError:
        return None
    idle = total = 0
    seen = False
    for line in lines:
        if not line.startswith(b"cpu") or line.startswith(b"cpu "):
            continue
        name, *fields = line.split()
        try:
            n, values = int(name[3:]), [int(x) for x in fields[:8]]
        except ValueError:
            continue
        if n in cpus and len(values) >= 5:
            seen = True
            idle += values[3] + values[4]
            total += sum(values)
    return (idle, total) if seen else None


def idle_cpus(window_s: float = WINDOW_S) -> float | None:
    """How many of this process's CPUs (:func:`allowed_cpus`) were idle
    during the next ``window_s`` seconds, while this thread sleeps (so its
    own CPU counts as idle unless something else ran there): a float from 0
    to their number.  ``None`` where the counters cannot be read (not
    Linux) or did not move (a window shorter than a clock tick)."""
    cpus = allowed_cpus()
    before = _ticks(cpus)
    if before is None:
        return None
    time.sleep(window_s)
    after = _ticks(cpus)
    if after is None:
        return None
    d_idle, d_total = after[0] - before[0], after[1] - before[1]
    if d_total <= 0:
        return None
    return len(cpus) * max(0, d_idle) / d_total
