"""doit's md5 file checker, each file's md5 computed once per process and file state.

doit keeps ``(modification time, size, md5)`` for every file dependency of
every task, and computes the md5 again for each task that names the file
(doit's ``MD5Checker.get_state``, when the task's state is saved after it
ran).  Every node task of a run depends on the system model
(``artifacts/system/model.json``, 1.15 MB at 5000 nodes): doit's process
hashed it 5000 times, about 10 CPU s of a cold run, quadratic in the
system's size (issue 67).  :class:`MD5Checker` gives doit's states and
answers, with the md5 of a file kept while the file's ``stat`` (modification
time in nanoseconds, size, inode, device) is unchanged; every write of
rclverify's is a rename of a new file, so a rewritten file has a new inode
and is hashed again, which is stricter than doit's own shortcut (an equal
modification time alone means unchanged).

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


class MD5Checker(DoitMD5Checker):  # type: ignore[misc]
    """doit's ``MD5Checker`` (module docstring) with one md5 per file state
    and process; the same states and the same answers."""

    def __init__(self) -> None:
        super().__init__()
        self._md5: dict[tuple[str, int, int, int, int], str] = {}

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
