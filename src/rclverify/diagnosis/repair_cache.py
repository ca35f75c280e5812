"""The diagnosis' repairs kept between runs, and the lock that makes one
process at a time diagnose a workspace.

Repairs cost Z3 queries (a minute for the case study's Agent), so each
problem's repairs are kept in :data:`CACHE` (:class:`RepairCache`) keyed by
everything they are computed from: the problem record, the contract files
and the plan (or, for a search that names them, the files it reads), the
program, and the rclverify and Z3 versions.  Deleting the cache is always safe.
"""
from __future__ import annotations

import json
import os
from contextlib import contextmanager
from typing import Any, Callable, Iterator, Mapping

import z3

from rclverify.core.cache import Shelf, file_digest
from rclverify.lang.errors import RclError

CACHE = "artifacts/cache/diagnosis.pickle"
#: Taken while diagnosing (:func:`one_at_a_time`); beside the run lock, not a kept result.
LOCK = "artifacts/diagnosis.lock"
#: Most entries the cache keeps.
KEEP = 200

class RepairCache:
    """The repairs of this workspace's problems, kept between runs: a
    :class:`~rclverify.core.cache.store.Shelf` of kind ``diagnosis`` (salted with
    Z3's version besides the rclverify code), keyed by the contract and plan
    files' sha256 and the problem's own key.  Keeps what this report used
    and earlier entries up to :data:`KEEP` in all (an edit undone finds them
    again: a repair search costs Z3 seconds)."""

    def __init__(self, ws: Any) -> None:
        self.ws = ws
        self.shelf = Shelf(ws.path(CACHE), "diagnosis", (f"z3 {z3.get_version_string()}",), keep=KEEP)
        files = sorted({*ws.plan.contracts, ws.plan.file})
        self.base = [f"{rel}\0{file_digest(ws.path(rel))}" for rel in files]

    def get(self, key: Any, make: Callable[[], Any], extra_file: str | None = None,
            inputs: Mapping[str, str] | None = None) -> Any:
        """The kept value of ``key`` (any JSON-able value; ``extra_file``, a
        workspace path whose digest joins the key), else ``make()``'s, kept
        as JSON gives it back; ``None`` when ``make`` raises a Z3, RCL, OS,
        value or key error (then nothing is kept).

        ``inputs`` (workspace path -> sha256 of its current text): every file
        the search reads, when the caller knows them (a property test's code
        repair: its evidence's inputs, the node's snapshot among them); they
        take the place of the contract and plan files in the key, so an edit
        of another node's contract keeps the entry.  ``None``: keyed by every
        contract file and the plan."""
        base = [f"{rel}\0{digest}" for rel, digest in sorted(inputs.items())] if inputs is not None else self.base
        k = self.shelf.key("repairs", *base, json.dumps(key, sort_keys=True, default=str),
                           file_digest(self.ws.path(extra_file)) if extra_file else "")
        got = self.shelf.get(k)
        if got is None:
            try:
                # as JSON gives it back (sorted keys), so a fresh result and a kept one are the same
                # data, key order included (the report's kept pieces are keyed by it: report/fragments.py)
                got = [json.loads(json.dumps(make(), sort_keys=True))]
            except (z3.Z3Exception, RclError, OSError, ValueError, KeyError):
                # a checker that misbehaves gives no repair (and nothing is kept)
                return None
            self.shelf.put(k, got)
        return got[0]

    def save(self) -> None:
        """Write the cache (an ``OSError`` is ignored: the cache only saves work)."""
        try:
            self.shelf.save()
        except OSError:
            pass  # a pure speed-up


@contextmanager
def one_at_a_time(ws: Any) -> Iterator[None]:
    """Hold an exclusive lock on ``artifacts/diagnosis.lock`` (POSIX
    ``flock``; released when the block ends or the process dies).

    Two processes may diagnose the same workspace at once (the diagnosis
    task of ``doit -n 2`` and an ``rclverify report``, or two report parts
    that both found the stage's record stale, :func:`rclverify.app.pipeline.diagnosed`);
    without the lock both computed every repair of a cold run (the case
    study: about 4 CPU seconds each).  With it the second waits, then finds
    the first's repairs in the cache.  Where the
    lock cannot be taken (no ``fcntl``, a read-only workspace) the block
    runs unlocked: the lock only saves work."""
    try:
        import fcntl  # deferred: optional or conditional (inside a block)
        path = ws.path(LOCK)
        path.parent.mkdir(parents=True, exist_ok=True)
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    except (ImportError, OSError):
        yield
        return
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX)
        except OSError:
            pass
        yield
    finally:
        os.close(fd)  # releases the lock
