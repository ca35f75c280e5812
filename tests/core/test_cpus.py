"""core/cpus.py: the idle CPUs read from the kernel's counters (issue 67: the second solver's split)."""
from __future__ import annotations

import multiprocessing
import os
import sys
import time

import pytest

from rclverify.core import cpus

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="/proc/stat is Linux's")


def test_idle_cpus_is_between_none_and_all_of_them() -> None:
    idle = cpus.idle_cpus(0.05)
    assert idle is not None and 0.0 <= idle <= len(cpus.allowed_cpus())


def _spin(cpu: int, until: float) -> None:
    os.sched_setaffinity(0, {cpu})
    while time.monotonic() < until:
        pass


def test_cpus_kept_busy_are_not_idle() -> None:
    """A spinning process pinned to each CPU of this process: at most a small part of a CPU reads idle
    (the kernel's own ticks); the window is long enough for several clock ticks."""
    mine = sorted(cpus.allowed_cpus())
    until = time.monotonic() + 0.6
    ctx = multiprocessing.get_context("fork")
    spinners = [ctx.Process(target=_spin, args=(c, until)) for c in mine]
    for p in spinners:
        p.start()
    try:
        time.sleep(0.1)  # the spinners running
        idle = cpus.idle_cpus(0.3)
    finally:
        for p in spinners:
            p.join(5)
            if p.is_alive():
                p.kill()
    assert idle is not None and idle < 0.5, idle


def test_a_missing_counter_file_reads_unknown(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(cpus, "_ticks", lambda c: None)
    assert cpus.idle_cpus(0.0) is None


def test_the_counters_of_other_cpus_are_not_counted(tmp_path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Only the lines of this process's CPUs count; the aggregate ``cpu`` line never does (proc(5))."""
    text = ("cpu  100 0 100 800 0 0 0 0 0 0\n"
            "cpu0 10 0 10 80 0 0 0 0 0 0\n"
            "cpu1 90 0 90 720 0 0 0 0 0 0\n"
            "intr 5\n")
    real_open = open

    def fake_open(path, *a, **k):  # type: ignore[no-untyped-def]
        if path == "/proc/stat":
            f = tmp_path / "stat"
            f.write_text(text)
            return real_open(f, *a, **k)
        return real_open(path, *a, **k)
    monkeypatch.setattr("builtins.open", fake_open)
    assert cpus._ticks({0}) == (80, 100)
    assert cpus._ticks({1}) == (720, 900)
    assert cpus._ticks({0, 1}) == (800, 1000)
    assert cpus._ticks({5}) is None
