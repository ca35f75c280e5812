"""When the garbage collector looks at a doit run's heap.

A ``doit verify`` run of a large system holds a large heap that stays live
until the process ends: the loaded workspace (parsed contracts, plan,
model) and doit's thousands of task objects.  Python's cyclic collector
traverses all of it at every full collection, and the run's own
allocations (task definitions, report dicts, JSON artifacts) trigger many.
At 1000 nodes that was 0.3-0.6 s of the main process before the first task
and about 0.4 s of each report task after a one-contract edit, and
0.6-0.9 s at exit (docs/scale.md).  Reference counting frees what is not
cyclic either way; these functions only keep the collector from walking
objects that cannot be garbage yet:

* :func:`no_collection` -- no collection while :func:`rclverify.app.tasks.build_tasks`
  loads the workspace and defines the tasks (also while the parser builds
  syntax trees and the workspace cache is unpickled: everything made there
  is live);
* :func:`freeze_for_run` -- then the main process's heap goes to the
  collector's permanent generation (``gc.freeze``) for the run, and
  :func:`release_after_run` gives it back when doit completes the run (a
  test session that runs doit in-process gets its objects back);
* :func:`no_full_collections` -- a run's reporter turns the process's full
  collections off until a task executes in it (:func:`executing`, called by
  every task action) or the run ends: a process that only dispatches (the main one of ``doit -n 2``,
  and any no-op run) makes doit's task objects, checks their state and
  keeps both to the end, so a full collection there walks only what is
  live.  A no-op run of a 1000-node system made two, 60 and 87 ms, and
  spent 196 ms in the collector in all, 49-66 ms after; its main
  process's peak memory in a cold run stayed 134-135 MB.  Young
  collections run as before;
* :func:`freeze_inherited` -- a worker forked by ``doit -n`` freezes the
  heap it inherited, once;
* :func:`loading` -- no collection while a command loads what it keeps,
  then that heap frozen while it runs (``rclverify monitor``: the first
  young collection after re-enabling the collector would walk all that
  its start-up made);
* :func:`freeze_at_exit` -- nothing is collected while the process exits;
* :func:`freeze_for_live` -- a live monitor, once loaded, collects and
  freezes its heap before the first message, so a full collection later
  walks only what the run made (a full collection of the loaded heap,
  contracts, Z3, the middleware's types, took 30-50 ms of the engine
  thread at once: the verdicts' latency tail; docs/monitors.md).

Objects made after a freeze are collected as usual.

One thing here is about C's heap, not Python's: :func:`keep_freed_memory`
(called with :func:`freeze_for_run` and :func:`freeze_inherited`).  Every
node stage starts a fresh Z3 context (semantics/world.py), and a context's
tables are blocks large enough for glibc's ``malloc`` to map them with
``mmap`` and hand them back with ``munmap`` (measured in a doit run of a
200-node chain, not in a small process), so each context paid page faults
for the memory it touched: 8 ms instead of 0.7 ms, and a quarter of
``rclverify verify``'s CPU seconds there (docs/scale.md).
"""
from __future__ import annotations

import gc
import os
from contextlib import contextmanager
from typing import Callable, Iterator
import atexit

_WORKER: list[int] = []
_RUN: list[bool] = []
_EXIT: list[bool] = []


@contextmanager
def no_collection() -> Iterator[None]:
    """No cyclic collection inside the block (the collector's state is
    restored after it, also on an exception).  For blocks that make many
    objects that all stay live: collecting there only walks them again."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()


@contextmanager
def loading() -> Iterator[Callable[[], None]]:
    """No cyclic collection inside the block until the function it gives is called (the start-up's objects
    loaded by then); from that call on, the heap made so far frozen (``gc.freeze``: no collection walks it,
    objects made later are collected as usual) until the block ends, when it is given back to the
    collector (``gc.unfreeze``), also on an exception.  For a command whose loaded modules and inputs stay
    live while it works (``rclverify monitor`` on a recorded run: the first young collection after
    re-enabling the collector would walk all the start-up made); a process that runs it again, a test's,
    gets its objects back."""
    was_enabled = gc.isenabled()
    done: list[bool] = []

    def loaded() -> None:
        if not done:
            gc.freeze()
            done.append(True)
            if was_enabled:
                gc.enable()
    gc.disable()
    try:
        yield loaded
    finally:
        if done:
            gc.unfreeze()
        elif was_enabled:
            gc.enable()


def freeze_for_live() -> None:
    """Collect once, then freeze the heap of a live monitor about to take
    its first message (module docstring); objects made after it are
    collected as usual.  Never undone: the process monitors until it ends."""
    gc.collect()
    gc.freeze()


def freeze_for_run() -> None:
    """Freeze the heap of a process about to run doit's tasks (the loaded
    workspace and the task definitions), until :func:`release_after_run`;
    and :func:`keep_freed_memory`."""
    gc.freeze()
    _RUN[:] = [True]
    keep_freed_memory()


#: The collector's third threshold while a run's process only dispatches (:func:`no_full_collections`): the
#: number of middle-generation collections before a full one, larger than any run makes.
NO_FULL = 1 << 30
#: The thresholds :func:`no_full_collections` replaced, until :func:`executing` or :func:`release_after_run`.
_THRESHOLD: list[tuple[int, int, int]] = []


def no_full_collections() -> None:
    """A doit run starts in this process (its reporter's ``initialize``): no
    full collection here until a task executes in it (:func:`executing`) or
    the run ends (:func:`release_after_run`, the reporter's ``complete_run``).
    Only a run that will end calls it: a process that defines the tasks
    without running them (``doit list``, a test) keeps its collector as it was."""
    if not _THRESHOLD:
        _THRESHOLD[:] = [gc.get_threshold()]
        young, middle, _old = _THRESHOLD[0]
        gc.set_threshold(young, middle, NO_FULL)


def executing() -> None:
    """A task of the run is about to execute in this process (the main one of
    a serial run, or a ``doit -n`` worker forked from it): full collections
    as before :func:`no_full_collections`, since a task's work may leave cycles
    behind.  Nothing when they were never turned off."""
    if _THRESHOLD:
        gc.set_threshold(*_THRESHOLD[0])
        _THRESHOLD.clear()


#: glibc's ``mallopt`` parameters (malloc.h) and the values set: blocks up to
#: 32 MiB (glibc's largest mmap threshold on 64 bits) come from the heap, and
#: up to 256 MiB freed at its top stay there for the next allocation.
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
_TRIM, _MMAP = 256 << 20, 32 << 20
_MALLOPT: list[bool] = []


def keep_freed_memory() -> bool:
    """Tell glibc's ``malloc`` to keep memory freed by this process for
    its next allocations instead of returning it to the system at once
    (module docstring), once per process.  Returns whether it was set;
    ``False`` (nothing done) on a C library without ``mallopt`` (macOS,
    musl) or when it refuses the values: only the speed differs."""
    if _MALLOPT:
        return _MALLOPT[0]
    ok = False
    try:
        if "glibc" in (os.confstr("CS_GNU_LIBC_VERSION") or "").lower():
            import ctypes  # deferred: optional or conditional (inside a block)
            # the process's own symbols, glibc's among them: `ctypes.util.find_library("c")` runs
            # `ldconfig -p` in a child process (10 ms of every doit run)
            mallopt = getattr(ctypes.CDLL(None), "mallopt", None)
            if mallopt is not None:
                ok = bool(mallopt(_M_MMAP_THRESHOLD, _MMAP)) and bool(mallopt(_M_TRIM_THRESHOLD, _TRIM))
    except (OSError, ValueError, AttributeError):
        ok = False
    _MALLOPT[:] = [ok]
    return ok


def release_after_run() -> None:
    """Give the heap frozen by :func:`freeze_for_run` back to the collector
    (nothing when none was frozen), and full collections as they were
    (:func:`no_full_collections`)."""
    executing()
    if _RUN:
        _RUN.clear()
        gc.unfreeze()


def freeze_inherited() -> None:
    """In a process forked by ``doit -n`` (a ``multiprocessing`` child),
    freeze the heap it inherited, once per process; nothing elsewhere."""
    import multiprocessing  # deferred: start-up (this module loads at every `rclverify`/doit start; the import does not)
    pid = os.getpid()
    if _WORKER == [pid] or multiprocessing.parent_process() is None:
        return
    gc.freeze()
    _WORKER[:] = [pid]
    keep_freed_memory()  # inherited from the parent with fork; set again where it was not


def freeze_at_exit() -> None:
    """At interpreter exit, freeze every object before Python finalises its
    modules, so the final collection does not traverse the heap of a large
    run.  Registered once per process with ``atexit`` (handlers run
    last-registered first, so this runs before the earlier ones; nothing is
    frozen while the process still works).  Memory goes back to the
    operating system at exit either way."""
    if _EXIT:
        return
    atexit.register(gc.freeze)
    _EXIT.append(True)
