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

:func:`end_bounded` is what the live command's own process does once its run
is over and everything it writes (log, bag, evidence, verdict lines, its
summary on stdout) is written and flushed: the process then ends within
:data:`EXIT_BOUND_S`, whatever a library left behind.  A thread that would
hold the interpreter's exit (one not a daemon, which the interpreter joins
without a limit) is a library thread that refuses to end: the process says
which on stderr and ends at once with ``os._exit`` and the run's exit code,
since nothing is left to write.  Otherwise it exits as usual, its end
watched by :mod:`faulthandler`'s own thread (C, not held by the interpreter's
lock): should the interpreter's finalization (the daemon threads left, the
exit handlers, the libraries' objects deleted with their modules: a DDS
domain, a bag writer) take longer than the bound, the stacks of every thread
are written on stderr, naming what held it, and the process exits with
status 1.
"""
from __future__ import annotations

import faulthandler
import os
import select
import signal
import sys
import threading
from typing import Any, Iterable

#: the most the live command's process may take to end once everything it writes is written (s,
#: :func:`end_bounded`): its exit measured under load at 0.05-0.5 s after the summary, once 2.9 s
EXIT_BOUND_S = 5.0


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


def holding_threads() -> list[str]:
    """The names of the live threads, the calling one aside, that are not daemons: the interpreter joins
    each of them, without a limit, before it exits."""
    me = threading.current_thread()
    return sorted(t.name for t in threading.enumerate() if t is not me and not t.daemon and t.is_alive())


def end_bounded(code: int, bound_s: float = EXIT_BOUND_S) -> None:
    """End the calling process promptly with exit status ``code`` once everything it writes is written
    (module docstring): ``os._exit(code)`` at once when a thread that is not a daemon is alive (said on
    stderr, by name); else return, the rest of the exit watched for ``bound_s`` seconds by
    :func:`faulthandler.dump_traceback_later` (past it: every thread's stack on stderr, exit status 1).
    Only for a process that ends after this call (the command line's, never an in-process caller's):
    the watch is never cancelled."""
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # closed, or a reader gone: nothing more can be said there
            pass
    holding = holding_threads()
    if holding:
        try:
            print(f"rclverify: warning: thread(s) {', '.join(holding)} did not end with the run; the process "
                  "exits without waiting for them (everything it writes is written)", file=sys.stderr, flush=True)
        except (OSError, ValueError):
            pass
        os._exit(code)
    try:
        faulthandler.dump_traceback_later(bound_s, exit=True, file=sys.__stderr__ or sys.stderr)
    except (OSError, ValueError, RuntimeError, AttributeError):  # no file descriptor behind stderr: no watch
        pass


__all__ = ["EXIT_BOUND_S", "StopFlag", "end_bounded", "holding_threads", "on_signals"]
