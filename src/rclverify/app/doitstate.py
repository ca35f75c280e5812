"""doit's dependency state saved after every task, so a killed run resumes.

doit keeps what it knows of each task (the signatures of its file
dependencies, its ``uptodate`` values) in memory and writes them to its
store (``.doit.sqlite``, :data:`rclverify.app.tasks.DEP_FILE`) only when the run
ends.  A run killed with SIGKILL (or a machine that loses power) therefore
left no trace of the tasks it had finished, and the next run executed every
task again: 67 tasks and about a minute on the case study, even after a kill
during the last task.

:func:`save_finished` writes the state of the tasks that finished since its
last call, in one SQLite transaction, and is called by the progress reporter
(:class:`rclverify.app.progress.ProgressReporter`) after each task: a run killed
at any point then re-executes only the task(s) that were running and those
that had not run yet.  Every output a task writes is written atomically
(:func:`rclverify.records.store.atomic_write_bytes`), and doit saves a
task's state only after its action returned, so a task whose state was
saved has all its outputs on disk.

The store is opened with ``PRAGMA synchronous=OFF``: a commit is then in the
operating system's hands at once (a killed process loses nothing) without an
``fsync`` per task; a power loss may lose the last commits, and their tasks
run again.

This reads doit's SQLite backend (``doit.dependency.SqliteDB``: its
connection, cache and set of changed task ids); ``pyproject.toml`` pins the
doit versions it was written against, and any other backend is left to
doit's own saving at the end of the run.
"""
from __future__ import annotations

from typing import Any


def save_finished() -> int:
    """Write the state of every task whose state changed since the last call
    to doit's SQLite store and commit.  Returns the number of tasks written
    (0 when doit's dependency manager is not the SQLite backend, e.g. with
    another ``backend`` in ``DOIT_CONFIG``, or outside a doit run).
    Never raises: a state that cannot be written now is written by doit at
    the end of the run, as before."""
    try:
        from doit.dependency import SqliteDB  # deferred: optional or conditional (inside a block)
        from doit.globals import Globals  # deferred: optional or conditional (inside a block)
    except ImportError:  # pragma: no cover - doit is a dependency
        return 0
    manager = getattr(Globals, "dep_manager", None)
    backend = getattr(manager, "backend", None)
    if not isinstance(backend, SqliteDB):
        return 0
    dirty = getattr(backend, "_dirty", None)
    cache = getattr(backend, "_cache", None)
    conn = getattr(backend, "_conn", None)
    if not dirty or cache is None or conn is None:
        return 0
    try:
        if not getattr(backend, "_rclverify_fast", False):
            conn.execute("PRAGMA synchronous=OFF")
            backend._rclverify_fast = True
        ids = [t for t in dirty if t in cache]
        conn.executemany("insert or replace into doit values (?,?)",
                         [(t, backend.codec.encode(cache[t])) for t in ids])
        conn.commit()
    except Exception:  # noqa: BLE001 - doit writes the state at the end of the run anyway
        return 0
    dirty.difference_update(ids)
    return len(ids)

