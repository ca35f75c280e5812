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

* :func:`no_collection` -- no collection while :func:`rclverify.tasks.build_tasks`
  loads the workspace and defines the tasks (also while the parser builds
  syntax trees and the workspace cache is unpickled: everything made there
  is live);
* :func:`freeze_for_run` -- then the main process's heap goes to the
  collector's permanent generation (``gc.freeze``) for the run, and
  :func:`release_after_run` gives it back when doit completes the run (a
  test session that runs doit in-process gets its objects back);
* :func:`freeze_inherited` -- a worker forked by ``doit -n`` freezes the
  heap it inherited, once;
* :func:`freeze_at_exit` -- nothing is collected while the process exits.

Objects made after a freeze are collected as usual.
"""
from __future__ import annotations

import gc
import os
from contextlib import contextmanager
from typing import Iterator

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


def freeze_for_run() -> None:
    """Freeze the heap of a process about to run doit's tasks (the loaded
    workspace and the task definitions), until :func:`release_after_run`."""
    gc.freeze()
    _RUN[:] = [True]


def release_after_run() -> None:
    """Give the heap frozen by :func:`freeze_for_run` back to the collector
    (nothing when none was frozen)."""
    if _RUN:
        _RUN.clear()
        gc.unfreeze()


def freeze_inherited() -> None:
    """In a process forked by ``doit -n`` (a ``multiprocessing`` child),
    freeze the heap it inherited, once per process; nothing elsewhere."""
    import multiprocessing
    pid = os.getpid()
    if _WORKER == [pid] or multiprocessing.parent_process() is None:
        return
    gc.freeze()
    _WORKER[:] = [pid]


def freeze_at_exit() -> None:
    """At interpreter exit, freeze every object before Python finalises its
    modules, so the final collection does not traverse the heap of a large
    run.  Registered once per process with ``atexit`` (handlers run
    last-registered first, so this runs before the earlier ones; nothing is
    frozen while the process still works).  Memory goes back to the
    operating system at exit either way."""
    if _EXIT:
        return
    import atexit
    atexit.register(gc.freeze)
    _EXIT.append(True)
