"""The live monitor's stop request, safe to set from a signal handler.

A Python signal handler runs on the main thread, between two bytecodes of
whatever the main thread was running.  ``threading.Event.set`` takes the lock
of the event's condition, a plain (not re-entrant) lock, and
``Event.wait`` holds that very lock for a few bytecodes on the way into and
out of its condition's wait: a SIGINT or SIGTERM whose handler calls ``set``
in that window blocks the main thread forever on a lock it holds itself, and
every later signal's handler queues behind it: the stop is never heard, and
the ``--record`` bag is never finished.

:class:`StopFlag` is what ``rclverify monitor --live`` and the ROS 1 service
proxy wait on instead.  Its :meth:`~StopFlag.set` takes no lock: it sets a
flag and writes one byte to a non-blocking pipe of its own (a self-pipe), and
:meth:`~StopFlag.wait` waits on that pipe with ``select``, which the byte
wakes at once, in whichever thread waits.  The byte is never read, so every
later wait returns at once too.  It keeps ``threading.Event``'s face
(``set``, ``is_set``, ``wait``), so the code that polls a stop takes either.
:func:`on_signals` installs the handler that only calls :meth:`StopFlag.set`; it
stays installed once the run is over (a second Ctrl-C while the process ends
is then only one more request, never a ``KeyboardInterrupt``).
"""
from __future__ import annotations

import os
import select
import signal
import threading
from typing import Any, Iterable


class StopFlag(threading.Event):
    """A stop request that a signal handler may set (module docstring).

    ``set()`` may be called from a signal handler, any thread, any number of
    times; ``wait(timeout)`` (seconds, ``None``: no limit) returns whether the
    flag is set, as soon as it is; ``clear()`` is refused (a stop is for
    good: :class:`RuntimeError`).  The pipe's two descriptors live as long as
    the object; :meth:`close` gives them back."""

    def __init__(self) -> None:
        super().__init__()
        self._stopped = False
        self._r, self._w = os.pipe()
        os.set_blocking(self._r, False)
        os.set_blocking(self._w, False)

    def set(self) -> None:
        """Request the stop: no lock, no allocation beyond the call (a full pipe is already awake)."""
        self._stopped = True
        try:
            os.write(self._w, b"!")
        except OSError:  # full (a byte is there already) or closed: either way the flag is set
            pass

    def is_set(self) -> bool:
        """Whether the stop was requested."""
        return self._stopped

    def wait(self, timeout: float | None = None) -> bool:
        """Wait until the stop is requested or ``timeout`` seconds passed; returns :meth:`is_set`.  A
        signal arriving meanwhile runs its handler and the wait goes on (PEP 475), woken by its byte."""
        if self._stopped:
            return True
        try:
            select.select([self._r], [], [], timeout)
        except (OSError, ValueError):  # closed: no pipe left to wait on
            pass
        return self._stopped

    def clear(self) -> None:
        raise RuntimeError("a stop request is not taken back")

    def close(self) -> None:
        """Give the pipe's descriptors back (idempotent); :meth:`set` and :meth:`wait` stay callable."""
        for fd in (self._r, self._w):
            try:
                os.close(fd)
            except OSError:
                pass
        self._r = self._w = -1


def on_signals(stop: StopFlag, signals: Iterable[int] = (signal.SIGINT, signal.SIGTERM)) -> dict[int, Any]:
    """Make each of ``signals`` (default SIGINT and SIGTERM) request ``stop`` and do nothing else;
    returns the handlers they had.  Only from the main thread (``signal.signal``'s rule,
    :class:`ValueError` otherwise)."""
    def handler(_signum: int, _frame: Any) -> None:
        stop.set()
    return {sig: signal.signal(sig, handler) for sig in signals}


__all__ = ["StopFlag", "on_signals"]
