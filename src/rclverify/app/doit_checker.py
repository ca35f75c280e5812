"""doit's file checker for rclverify: a file dependency is changed when its content is.

A task's file dependencies are compared by their sha256, the digest the
evidence records keep of their inputs (``input_hashes``,
:func:`rclverify.records.records.sha256_file`) and the report reads when it
calls a record ``stale``.  doit's own checker (``MD5Checker``) believes a
file unchanged while its modification time is the one saved; a run edited
in place with its size and modification time kept (``os.utime``, a copy
tool that keeps times, a clock set back) was then ``stale`` in every
report and never judged again, so an incremental run differed from a clean
one.  :class:`ContentChecker` never trusts a time: every run reads each
file dependency's bytes once (docs/integrity.md, "Content digests").

The state saved per file is doit's shape, ``(modification time, size,
digest)``, the digest a hex sha256; a different size is a change without
reading.  Within one process each file is hashed once per file state
(modification time in nanoseconds, size, inode, device, change time):
every task of a run depends on the system model
(``artifacts/system/model.json``, 1.15 MB at 5000 nodes), and hashing it
per task was quadratic in the system's size.  Every write of rclverify's is
a rename of a new file (a new inode), and any write or ``utime`` sets a
file's change time, so a file changed meanwhile is hashed again.

The ``stat`` of each file dependency is also taken once between two task
events of a run, not once per task that names it: doit asks for it in
every task's status (34,000 times in a no-op run of a 1000-node system,
for about 8,000 distinct files).  A file can only change between two
events when a task writes it, so the kept results are forgotten
(:func:`forget_stats`) whenever a task starts, succeeds or fails, which
rclverify's reporter (:class:`rclverify.app.progress.ProgressReporter`)
says; they are kept only while that reporter runs the run
(:func:`keep_stats`), so doit with another reporter stats every time, as
doit does.

doit saves the checker's class name with each task's state and runs a task
again when the name differs: a workspace whose states were saved by doit's
``MD5Checker`` runs every task once, and its states are then this
checker's.  :func:`rclverify.app.tasks.doit_config` hands it to doit as
``check_file_uptodate`` (doit accepts a checker class there).
"""
from __future__ import annotations

import hashlib
import os
from typing import Any

from doit.dependency import FileChangedChecker

#: ``os.stat`` of file dependencies since the last task event, or ``None`` when none are kept (module docstring).
_STATS: dict[str, os.stat_result] | None = None
#: Bytes read at a time when a file is hashed.
_BLOCK = 1 << 20


def keep_stats(keep: bool) -> None:
    """Keep (``True``) or stop keeping the ``stat`` results of file
    dependencies between two task events; either way forget those kept."""
    global _STATS
    _STATS = {} if keep else None


def forget_stats() -> None:
    """Forget the kept ``stat`` results: a task starts, succeeded or failed, and may have written a file."""
    if _STATS is not None:
        _STATS.clear()


def file_sha256(path: str) -> str:
    """The hex sha256 of the bytes of the file at ``path`` (as
    :func:`rclverify.records.records.sha256_file` gives it for a file that
    exists).  Raises ``OSError`` when it cannot be read."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(_BLOCK), b""):
            h.update(block)
    return h.hexdigest()


class ContentChecker(FileChangedChecker):  # type: ignore[misc]
    """doit's file checker comparing contents (module docstring): a file
    dependency is changed when its size or its sha256 differs from the
    saved state, whatever its modification time."""

    def __init__(self) -> None:
        super().__init__()
        self._digests: dict[tuple[str, int, int, int, int, int], str] = {}
        keep_stats(False)  # a new run: nothing kept until its reporter says so

    def info(self, file_path: str) -> os.stat_result:
        """doit's: the file's ``os.stat`` (raises ``OSError`` when it is missing),
        taken once between two task events while :func:`keep_stats` is on."""
        stats = _STATS
        if stats is None:
            return os.stat(file_path)
        st = stats.get(file_path)
        if st is None:
            st = stats[file_path] = os.stat(file_path)
        return st

    def digest_of(self, path: str, st: os.stat_result) -> str:
        """The hex sha256 of the file at ``path`` whose ``stat`` is ``st``,
        computed once while that file state is the same.  Raises ``OSError``
        when it cannot be read."""
        key = (path, st.st_mtime_ns, st.st_size, st.st_ino, st.st_dev, st.st_ctime_ns)
        digest = self._digests.get(key)
        if digest is None:
            digest = self._digests[key] = file_sha256(path)
        return digest

    def check_modified(self, file_path: str, file_stat: os.stat_result, state: Any) -> bool:
        """doit's question: is the file changed since ``state`` (``(modification
        time, size, digest)``)?  Changed when its size differs, else when its
        sha256 does; its modification time is never trusted."""
        _, size, digest = state
        if file_stat.st_size != size:
            return True
        return bool(digest != self.digest_of(file_path, file_stat))

    def get_state(self, dep: str, current_state: Any) -> Any:
        """doit's: the state to save after the task ran, ``(modification time,
        size, sha256)``, or ``None`` when ``current_state`` already holds this
        size and content."""
        st = os.stat(dep)
        digest = self.digest_of(dep, st)
        if current_state and tuple(current_state[1:]) == (st.st_size, digest):
            return None
        return st.st_mtime, st.st_size, digest
