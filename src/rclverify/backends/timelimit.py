"""A wall-clock limit on work a backend runs in its own process (a user's
Python implementation under the ``property_tests`` backend).

External tools get their limit from ``subprocess`` (Dafny's ``timeout``,
AJPF's ``timeout_s``); code that runs in the process -- an implementation
that loops forever -- can only be stopped by a signal.  :func:`wall_clock_limit`
arms ``SIGALRM`` (``setitimer``) for ``seconds`` and raises
:class:`TimeLimitExceeded` in the running code when it fires.  The exception
derives from ``BaseException`` so that neither the implementation's own
``except Exception`` nor Hypothesis (which treats an ``Exception`` as a
failing example and would shrink it) swallows it.

Where a signal cannot be used (not the main thread: a Dask worker thread;
a platform without ``setitimer``) the limit is not enforced and
:func:`wall_clock_limit` says so by yielding ``False``; docs/plan.md records
it.  Python runs a signal handler between bytecodes, so a limit hit inside a
long call into C (a Z3 query, which has its own budget) takes effect when
that call returns.
"""
from __future__ import annotations

import contextlib
import signal
import threading
from typing import Any, Iterator


class TimeLimitExceeded(BaseException):
    """The limit of :func:`wall_clock_limit` was reached (``seconds``: the limit)."""

    def __init__(self, seconds: float) -> None:
        self.seconds = seconds
        super().__init__(f"did not finish within {seconds:g} s")


@contextlib.contextmanager
def wall_clock_limit(seconds: float | None) -> Iterator[bool]:
    """Run the body for at most ``seconds`` of wall-clock time (``None``: no
    limit).  Yields whether the limit is enforced; raises
    :class:`TimeLimitExceeded` from inside the body when it is reached.  The
    previous ``SIGALRM`` handler and timer are restored afterwards."""
    usable = (seconds is not None and hasattr(signal, "setitimer")
              and threading.current_thread() is threading.main_thread())
    if not usable:
        yield False
        return
    assert seconds is not None

    def fire(signum: int, frame: Any) -> None:
        raise TimeLimitExceeded(seconds)

    previous = signal.signal(signal.SIGALRM, fire)
    old_timer = signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield True
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
        if old_timer[0] > 0:  # an outer timer keeps running (less the time spent here, not tracked)
            signal.setitimer(signal.ITIMER_REAL, *old_timer)
