"""The engine thread's timer (runtime/worker.py): a release already due when the thread comes round (it was
held off the CPU, or busy with a batch) is timed at once, and two timer runs stay at least ``MIN_TICK_S``
apart.  Before, the floor was counted from the moment the thread looked, so an overdue release waited
``MIN_TICK_S`` more after every stall."""
from __future__ import annotations

import threading
import time
from typing import Mapping

import pytest

import rclverify.runtime.worker as worker_module
from rclverify.runtime.worker import EngineWorker

#: a floor long enough to tell "at once" from "after the floor" on a loaded machine
FLOOR_S = 1.0


class _Overdue:
    """A sink whose next release is always already due (``due()`` long past ``now``): the timer runs as
    often as the floor lets it.  ``ticks`` are the monotonic times of its timer runs."""

    def __init__(self) -> None:
        self.ticks: list[float] = []
        self.ran = threading.Event()

    def push(self, topic: str, fields: Mapping[str, object], received: float) -> None:
        pass

    def tick(self, now: float) -> None:
        self.ticks.append(time.monotonic())
        self.ran.set()

    def due(self) -> float:
        return 0.0  # the clock reads 100.0: overdue


def test_an_overdue_release_is_timed_at_once_and_the_floor_counts_from_the_last_timer_run(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(worker_module, "MIN_TICK_S", FLOOR_S)
    sink = _Overdue()
    worker = EngineWorker(sink, lambda topic, payload: None, lambda: 100.0, tick_s=100.0)
    t0 = time.monotonic()
    worker.start()
    try:
        assert sink.ran.wait(30.0)
        first = sink.ticks[0] - t0
        deadline = time.monotonic() + 30.0
        while len(sink.ticks) < 2 and time.monotonic() < deadline:
            time.sleep(0.05)
    finally:
        worker.stop()
    assert first < FLOOR_S / 2, first  # at once, not a floor after the thread looked
    assert len(sink.ticks) >= 2 and sink.ticks[1] - sink.ticks[0] >= FLOOR_S * 0.99, sink.ticks  # the control
