"""doit's md5 file checker, each file's md5 computed once per process and file state.

doit keeps ``(modification time, size, md5)`` for every file dependency of
every task, and computes the md5 again for each task that names the file
(doit's ``MD5Checker.get_state``, when the task's state is saved after it
ran).  Every node task of a run depends on the system model
(``artifacts/system/model.json``, 1.15 MB at 5000 nodes): doit's process
hashed it 5000 times, about 10 CPU s of a cold run, quadratic in the
system's size.  :class:`MD5Checker` gives doit's states and
answers, with the md5 of a file kept while the file's ``stat`` (modification
time in nanoseconds, size, inode, device) is unchanged; every write of
rclverify's is a rename of a new file, so a rewritten file has a new inode
and is hashed again, which is stricter than doit's own shortcut (an equal
modification time alone means unchanged).

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

It is named ``MD5Checker``, as doit's: doit saves the checker's class name
with each task's state and runs a task again when the name differs, and the
states this one saves are doit's, so a workspace verified before keeps its
state.  :func:`rclverify.app.tasks.doit_config` hands it to doit as
``check_file_uptodate`` (doit accepts a checker class there).
"""
from __future__ import annotations

import os
from typing import Any

from doit.dependency import MD5Checker as DoitMD5Checker
from doit.dependency import get_file_md5


#: ``os.stat`` of file dependencies since the last task event, or ``None`` when none are kept (module docstring).
_STATS: dict[str, os.stat_result] | None = None


def keep_stats(keep: bool) -> None:
    """Keep (``True``) or stop keeping the ``stat`` results of file
    dependencies between two task events; either way forget those kept."""
    global _STATS
    _STATS = {} if keep else None


def forget_stats() -> None:
    """Forget the kept ``stat`` results: a task starts, succeeded or failed, and may have written a file."""
    if _STATS is not None:
        _STATS.clear()


class MD5Checker(DoitMD5Checker):  # type: ignore[misc]
    """doit's ``MD5Checker`` (module docstring) with one md5 per file state
    and process, and one ``stat`` per file between two task events; the same
    states and the same answers."""

    def __init__(self) -> None:
        super().__init__()
        self._md5: dict[tuple[str, int, int, int, int], str] = {}
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

    def md5_of(self, path: str, st: os.stat_result) -> str:
        """The md5 of the file at ``path`` whose ``stat`` is ``st``, computed
        once while the state is the same.  Raises ``OSError`` when it cannot
        be read."""
        key = (path, st.st_mtime_ns, st.st_size, st.st_ino, st.st_dev)
        md5 = self._md5.get(key)
        if md5 is None:
            md5 = self._md5[key] = get_file_md5(path)
        return md5

    def check_modified(self, file_path: str, file_stat: os.stat_result, state: Any) -> bool:
        """doit's: unchanged when the modification time is the saved one,
        changed when the size differs, else as the md5 says."""
        timestamp, size, file_md5 = state
        if file_stat.st_mtime == timestamp:
            return False
        if file_stat.st_size != size:
            return True
        return bool(file_md5 != self.md5_of(file_path, file_stat))

    def get_state(self, dep: str, current_state: Any) -> Any:
        """doit's: ``None`` when the saved modification time is the file's,
        else ``(modification time, size, md5)``."""
        st = os.stat(dep)
        if current_state and current_state[0] == st.st_mtime:
            return None
        return st.st_mtime, st.st_size, self.md5_of(dep, st)
