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
  nothing: it appends ``(topic, payload, received, writer)`` to a
  :class:`queue.SimpleQueue` (a C queue, no Python-level lock) and returns;
* one worker thread takes the messages in arrival order, decodes each
  (``decode(topic, payload) -> fields | None``; ``None`` drops the message,
  the decoder counts why) and pushes it into the :class:`~.live.LiveRun`
  (with its writer's id where the source names it),
  so each event's verdicts are published as soon as its own evaluation
  ends (latency stays per event);
* with ``linger_s`` (a lateness bound, where a verdict waits for the
  watermark anyway), after taking what waits it lets what arrives next
  gather in the queue for at most ``linger_s`` seconds (never past its next
  timer run) before it takes it, instead of waking for every message: at
  1000 messages/s a wake-up a message, each on cold caches, was about half
  its CPU.  A message then reaches the engine at most ``linger_s`` after it
  was offered; its verdict waits for its release, ``reorder_window``
  after its time, which a linger shorter than the bound does not delay;
* when the worker falls behind it drains the queue in batches of at most
  ``batch`` messages between timer ticks (one lock acquisition, one log
  flush and one latched-verdict publication per batch, not per message);
* after each batch and each timer run it calls the sink's ``flush()``,
  where it has one: what the batch published leaves in one write (the
  rclpy source's verdicts to its agent);
* the timer (:meth:`~.live.LiveRun.tick`) runs in the same thread every
  ``tick_s`` seconds, and as soon as the watermark reaches the earliest
  buffered message (the sink's ``due()``, at most every :data:`MIN_TICK_S`),
  so a horizon is closed without a new message, a verdict waits the
  lateness bound and not a timer period more, and the engine is never
  entered by two threads; and right after a batch whose messages let the
  watermark reach it (``due()`` at or before the clock: every writer heard
  past it, the early release of :meth:`~rclverify.backends.monitors.online.OnlineEngine.watermark`),
  at most every :data:`MIN_TICK_S` too.  While messages still wait in the
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

    def push(self, topic: str, fields: Mapping[str, object], received: float,
             writer: bytes | str | None = None) -> None: ...

    def tick(self, now: float) -> None: ...


_STOP = object()
#: the shortest time between two timer runs (s) when the sink asks for one sooner than ``tick_s``
MIN_TICK_S = 0.002
#: how long messages gather in the queue before the worker takes them (s) when the run has a lateness bound
#: (``linger_s``, module docstring): a tenth of the CLI's 50 ms bound, within the 5 ms a verdict may take past it
LINGER_S = 0.004


class EngineWorker:
    """One thread feeding ``live`` from a queue.

    ``decode(topic, payload)`` turns a queued payload into the message's
    fields (``None``: skip it); ``now()`` is the clock of the timer (s, the
    same clock as the receipt times given to :meth:`offer`); ``tick_s`` the
    timer period (s); ``batch`` the most messages processed between two
    timer checks; ``max_queue`` the most messages waiting (more are dropped,
    counted in :attr:`dropped`).  :attr:`backlog_max` is the longest queue seen (messages),
    :attr:`handled` the messages taken, :attr:`cpu_s` the worker thread's CPU
    seconds (set when it ends), :attr:`wakeups` how many times it woke.  ``linger_s`` (s, 0: none) is
    how long messages may gather in the queue before it takes them (module docstring).
    """

    def __init__(self, live: Sink, decode: Callable[[str, Any], Mapping[str, object] | None],
                 now: Callable[[], float], tick_s: float = 0.02, batch: int = 256,
                 max_queue: int = 100_000, linger_s: float = 0.0) -> None:
        self.live, self.decode, self.now = live, decode, now
        self.tick_s, self.batch, self.max_queue, self.linger_s = tick_s, batch, max_queue, linger_s
        self.wakeups = 0  # times the thread woke (a message came, the timer or a release was due)
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

    def offer(self, topic: str, payload: Any, received: float, writer: bytes | str | None = None) -> None:
        """Queue one message (thread safe, never blocks, never evaluates), with
        its ``writer``'s id where the source names it (a DDS writer's GUID, an
        rclpy publisher's GID; ``None``: the topic is its writer).  When
        ``max_queue`` messages already wait (the engine is that far behind) the
        message is dropped and counted in :attr:`dropped`: memory stays bounded
        and the loss is reported, never silent."""
        if self._q.qsize() >= self.max_queue:
            with self._drop_lock:  # callbacks of several topics may drop at once: count each
                self.dropped += 1
            return
        self._q.put((topic, payload, received, writer))

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
        flush = getattr(live, "flush", None)  # hands on what a batch published, where it holds it
        next_tick = _time.monotonic() + self.tick_s
        ticked = -math.inf  # when (monotonic s) the timer last ran
        last = -math.inf  # receipt time of the last message pushed
        linger, took = self.linger_s, False
        while True:
            if due is not None:
                soon = _time.monotonic() + max(due() - self.now(), MIN_TICK_S)
                if soon < next_tick:
                    next_tick = soon
            if took and linger > 0:  # let the next messages gather, up to the timer's next run
                nap = min(linger, next_tick - _time.monotonic())
                if nap > 0:
                    _time.sleep(nap)
            wait = next_tick - _time.monotonic()
            try:
                item = q.get(timeout=wait) if wait > 0 else q.get_nowait()
            except queue.Empty:
                item = None
            self.wakeups += 1
            done = False
            n = 0
            while item is not None:
                if item is _STOP:
                    done = True
                    break
                topic, payload, received, writer = item
                last = received
                fields = self.decode(topic, payload)
                if fields is not None:
                    live.push(topic, fields, received, writer)
                n += 1
                self.handled += 1
                if n >= self.batch:
                    break
                try:
                    item = q.get_nowait()
                except queue.Empty:
                    item = None
            took = 0 < n < self.batch  # a full batch: more wait, taken at once
            if n and flush is not None:
                flush()
            if n:
                size = q.qsize() + n
                self.backlog_max = max(self.backlog_max, size)
            ripe = done or _time.monotonic() >= next_tick
            if not ripe and n and due is not None and _time.monotonic() - ticked >= MIN_TICK_S:
                ripe = due() <= self.now()  # the batch let the watermark reach the head: release it now
            if ripe:
                now = self.now()
                if not q.empty():
                    # messages received before `now` still wait in the queue: the
                    # clock must not pass them (an obligation they answer would be
                    # closed as violated before its answer is checked)
                    now = min(now, last)
                if now > -math.inf:
                    live.tick(now)
                    if flush is not None:
                        flush()
                    ticked = _time.monotonic()
                    next_tick = ticked + self.tick_s
                # else a message arrived as the clock was read and none was pushed before it: no clock
                # passes nothing queued, so the tick waits until that message is pushed (the next round)
            if done:
                return


__all__ = ["EngineWorker", "LINGER_S", "MIN_TICK_S"]
