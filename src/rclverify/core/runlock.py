"""One run at a time per workspace: an advisory lock on ``artifacts/run.lock``.

A doit run (``doit verify``, ``rclverify verify``, any doit command of the
workspace's ``dodo.py``) takes the lock when it defines its tasks
(:func:`rclverify.app.tasks.build_tasks`) and gives it back when doit completes
the run (the progress reporter) or, at the latest, when the process ends.
The lock is ``flock(2)`` on the open file: the kernel releases it when the
process dies, however it dies (``SIGKILL`` included), so a killed run never
leaves a stale lock behind; the file itself stays and is harmless.  It holds
the pid of the run that has it, for the message of the one that waits.

A second run in the same workspace prints one line to standard error,
``waiting for the run in progress (pid N)``, and proceeds when the first
ends.  With ``rclverify verify --no-wait`` or the environment variable
``RCLVERIFY_NO_WAIT=1`` it does not wait: :class:`RunInProgress` (the
command exits 1 with the message).  Within one process the lock is
re-entrant (tests and ``rclverify verify`` define the tasks of a workspace
more than once).  Decisions: docs/decisions.md, "One run at a time".
"""
from __future__ import annotations

import fcntl
import os
import sys
from pathlib import Path

#: The lock file, relative to the workspace root.
LOCK_FILE = "artifacts/run.lock"
#: Environment variable: ``1`` makes a second run exit instead of waiting.
NO_WAIT_ENV = "RCLVERIFY_NO_WAIT"

#: Workspace root (resolved, as text) -> the open lock file this process holds.
_HELD: dict[str, int] = {}


class RunInProgress(Exception):
    """Another process holds the workspace's lock and the caller would not wait.
    ``pid`` is that process's id (``None`` when the lock file does not say)."""

    def __init__(self, root: Path, pid: int | None) -> None:
        self.root, self.pid = root, pid
        super().__init__(f"not {waiting_message(pid)} (--no-wait or {NO_WAIT_ENV}=1); run again when it has ended")


def waiting_message(pid: int | None) -> str:
    """``waiting for the run in progress (pid N)``."""
    return f"waiting for the run in progress (pid {pid if pid is not None else 'unknown'})"


def no_wait_from_env() -> bool:
    """Whether ``RCLVERIFY_NO_WAIT`` asks a second run to exit instead of waiting."""
    return os.environ.get(NO_WAIT_ENV, "").strip().lower() in ("1", "true", "yes")


def _holder(fd: int) -> int | None:
    try:
        text = os.pread(fd, 32, 0).decode("ascii", "replace").strip()
        return int(text) if text.isdigit() else None
    except OSError:
        return None


def acquire(root: Path, *, wait: bool | None = None) -> bool:
    """Take the run lock of the workspace at ``root`` for this process.

    ``wait=None`` waits unless :func:`no_wait_from_env`.  Returns ``True``
    when this call took it, ``False`` when this process already held it.
    Raises :class:`RunInProgress` (not waiting) and ``OSError`` when the lock
    file cannot be created (e.g. ``artifacts/`` read-only).
    """
    key = str(root.resolve())
    if key in _HELD:
        return False
    if wait is None:
        wait = not no_wait_from_env()
    path = root / LOCK_FILE
    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    except FileNotFoundError:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            pid = _holder(fd)
            if not wait:
                raise RunInProgress(root, pid) from None
            print(waiting_message(pid), file=sys.stderr, flush=True)
            fcntl.flock(fd, fcntl.LOCK_EX)
        try:  # who holds it, for the message of a run that waits (best effort: a full disk is no reason to fail)
            os.ftruncate(fd, 0)
            os.pwrite(fd, f"{os.getpid()}\n".encode("ascii"), 0)
        except OSError:
            pass
    except BaseException:
        os.close(fd)
        raise
    _HELD[key] = fd
    return True


def release(root: Path | None = None) -> None:
    """Give back the lock of ``root`` (every lock this process holds when
    ``None``).  Idempotent; never raises."""
    keys = [str(root.resolve())] if root is not None else list(_HELD)
    for key in keys:
        fd = _HELD.pop(key, None)
        if fd is None:
            continue
        try:
            fcntl.flock(fd, fcntl.LOCK_UN)
        except OSError:
            pass
        os.close(fd)


def holds(root: Path) -> bool:
    """Whether this process holds the lock of ``root``."""
    return str(root.resolve()) in _HELD
