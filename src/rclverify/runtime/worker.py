"""The verdict engine in its own thread: middleware callbacks only enqueue.

A ROS 1 subscriber callback runs in the receiving thread of its connection
(rospy starts one per publisher and topic).  When every callback took the
engine's lock and evaluated the contracts itself, the receiving threads
queued on that lock behind each other's evaluations and the verdict
publisher's writer thread, and each hand-over waited for Python's GIL
switch interval: at 2,000 messages/s the verdict latency grew to tens of
milliseconds with spikes of hundreds (docs/monitors.md, "Live monitoring",
"Threads").  :class:`EngineWorker` decouples them:

* :meth:`offer` (called from any callback) stamps nothing and evaluates
  nothing: it appends ``(topic, payload, received)`` to a
  :class:`queue.SimpleQueue` (a C queue, no Python-level lock) and returns;
* one worker thread takes the messages in arrival order, decodes each
  (``decode(topic, payload) -> fields | None``; ``None`` drops the message,
  the decoder counts why) and pushes it into the :class:`~.live.LiveRun`,
  so each event's verdicts are published as soon as its own evaluation
  ends (latency stays per event);
* when the worker falls behind it drains the queue in batches of at most
  ``batch`` messages between timer ticks (one lock acquisition, one log
  flush and one latched-verdict publication per batch, not per message);
* the timer (:meth:`~.live.LiveRun.tick`) runs in the same thread every
  ``tick_s`` seconds, and as soon as the watermark reaches the earliest
  buffered message (the sink's ``due()``, at most every :data:`MIN_TICK_S`),
  so a horizon is closed without a new message, a verdict waits the
  lateness bound and not a timer period more, and the engine is never
  entered by two threads.  While messages still wait in the
  queue the timer's time is that of the last message checked, not the
  clock's: the clock never passes a message received earlier, so a backlog
  cannot close an obligation before the answer waiting behind it is read.

:meth:`stop` processes what is still queued, then ends the thread.
"""
from __future__ import annotations

import math
import queue
import threading
import time as _time
from collections.abc import Callable, Mapping
from typing import Any, Protocol
from rclverify.core.cache.heap import freeze_for_live


class Sink(Protocol):
    """What the worker feeds: :class:`~.live.LiveRun` (push a message, run the timer)."""

    def push(self, topic: str, fields: Mapping[str, object], received: float) -> None: ...

    def tick(self, now: float) -> None: ...


_STOP = object()
#: the shortest time between two timer runs (s) when the sink asks for one sooner than ``tick_s``
MIN_TICK_S = 0.002


class EngineWorker:
    """One thread feeding ``live`` from a queue.

    ``decode(topic, payload)`` turns a queued payload into the message's
    fields (``None``: skip it); ``now()`` is the clock of the timer (s, the
    same clock as the receipt times given to :meth:`offer`); ``tick_s`` the
    timer period (s); ``batch`` the most messages processed between two
    timer checks; ``max_queue`` the most messages waiting (more are dropped,
    counted in :attr:`dropped`).  :attr:`backlog_max` is the longest queue seen (messages),
    :attr:`handled` the messages taken, :attr:`cpu_s` the worker thread's CPU
    seconds (set when it ends).
    """

    def __init__(self, live: Sink, decode: Callable[[str, Any], Mapping[str, object] | None],
                 now: Callable[[], float], tick_s: float = 0.02, batch: int = 256,
                 max_queue: int = 100_000) -> None:
        self.live, self.decode, self.now = live, decode, now
        self.tick_s, self.batch, self.max_queue = tick_s, batch, max_queue
        self.dropped = 0  # messages refused because max_queue were already waiting
        self._drop_lock = threading.Lock()
        self._q: queue.SimpleQueue[Any] = queue.SimpleQueue()
        self._thread = threading.Thread(target=self._run, name="rclverify-engine", daemon=True)
        self.backlog_max = 0
        self.cpu_s = 0.0  # CPU seconds the worker thread spent (decode, check, publish, timer)
        self.handled = 0  # messages taken from the queue
        self.error: BaseException | None = None

    def start(self) -> EngineWorker:
        """Start the worker thread, the loaded heap frozen first (:func:`~rclverify.core.cache.heap.freeze_for_live`)."""
        freeze_for_live()
        self._thread.start()
        return self

    def offer(self, topic: str, payload: Any, received: float) -> None:
        """Queue one message (thread safe, never blocks, never evaluates).  When
        ``max_queue`` messages already wait (the engine is that far behind) the
        message is dropped and counted in :attr:`dropped`: memory stays bounded
        and the loss is reported, never silent."""
        if self._q.qsize() >= self.max_queue:
            with self._drop_lock:  # callbacks of several topics may drop at once: count each
                self.dropped += 1
            return
        self._q.put((topic, payload, received))

    def stop(self, timeout: float = 30.0) -> None:
        """Process every message queued so far, then end the thread (waits at
        most ``timeout`` seconds).  Re-raises an error the worker died of."""
        self._q.put(_STOP)
        self._thread.join(timeout)
        if self.error is not None:
            raise self.error

    def _run(self) -> None:
        try:
            self._loop()
        except BaseException as exc:  # noqa: BLE001 - kept for stop(): a dead engine must not look like a quiet one
            self.error = exc
        finally:
            self.cpu_s = _time.thread_time()  # this thread's own CPU time, whatever the machine's load

    def _loop(self) -> None:
        q, live = self._q, self.live
        due = getattr(live, "due", None)  # the sink's next release (s, the now() clock), where it tells
        next_tick = _time.monotonic() + self.tick_s
        last = -math.inf  # receipt time of the last message pushed
        while True:
            if due is not None:
                soon = _time.monotonic() + max(due() - self.now(), MIN_TICK_S)
                if soon < next_tick:
                    next_tick = soon
            wait = next_tick - _time.monotonic()
            try:
                item = q.get(timeout=wait) if wait > 0 else q.get_nowait()
            except queue.Empty:
                item = None
            done = False
            n = 0
            while item is not None:
                if item is _STOP:
                    done = True
                    break
                topic, payload, received = item
                last = received
                fields = self.decode(topic, payload)
                if fields is not None:
                    live.push(topic, fields, received)
                n += 1
                self.handled += 1
                if n >= self.batch:
                    break
                try:
                    item = q.get_nowait()
                except queue.Empty:
                    item = None
            if n:
                size = q.qsize() + n
                self.backlog_max = max(self.backlog_max, size)
            if done or _time.monotonic() >= next_tick:
                now = self.now()
                if not q.empty():
                    # messages received before `now` still wait in the queue: the
                    # clock must not pass them (an obligation they answer would be
                    # closed as violated before its answer is checked)
                    now = min(now, last)
                if now > -math.inf:
                    live.tick(now)
                    next_tick = _time.monotonic() + self.tick_s
                # else a message arrived as the clock was read and none was pushed before it: no clock
                # passes nothing queued, so the tick waits until that message is pushed (the next round)
            if done:
                return


__all__ = ["EngineWorker"]
