"""External tools run with a wall-clock bound, and never outliving rclverify.

Every external tool a backend starts (SPIN's ``spin -a``, ``gcc`` and
``pan``, AJPF's JVM, Dafny) goes through :func:`run_bounded`:

* it runs in a **session of its own** (its own process group), so that the
  whole group -- ``gcc`` with its ``cc1`` and ``as``, a JVM with its
  children -- is killed at once (``killpg``) when the bound is reached, when
  rclverify is interrupted, and after it exits (leftover grandchildren);
* its direct child gets ``SIGKILL`` when rclverify dies
  (``prctl(PR_SET_PDEATHSIG)``, Linux);
* the group and every temporary directory a backend registers
  (:func:`temporary_directory`) are known to the **reaper**
  (:mod:`._reaper`), one small process per rclverify process that kills the
  groups and removes the directories still registered when rclverify ends
  in any way, SIGKILL included;
* while a tool runs in the main thread, SIGTERM and SIGHUP raise
  :class:`SystemExit` (exit status 128 + the signal) instead of ending the
  process on the spot, so the ``finally`` clauses on the way out kill the
  group and remove the build directories; SIGINT already raises
  ``KeyboardInterrupt``.

A tool that ends by a signal rclverify did not send (``kill``, the OOM
killer, a user stopping a run) was **interrupted**: that is not a result.
:func:`run_bounded` raises :class:`ToolInterrupted` (a located
:class:`~rclverify.lang.errors.RclError`), so the evidence task fails
without writing a record and the next run checks the obligation again.  A
tool that crashes (SIGSEGV, SIGABRT) returns its negative exit code: the
caller reports it as an error.
"""
from __future__ import annotations

import contextlib
import ctypes
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterator, Mapping

from rclverify.lang.ast import Loc
from rclverify.lang.errors import RclError, error

#: Signals by which something outside rclverify stops a tool (not a crash of the tool).
INTERRUPTS = frozenset(int(s) for s in (signal.SIGKILL, signal.SIGTERM, signal.SIGINT, signal.SIGHUP,
                                         signal.SIGQUIT))
_PR_SET_PDEATHSIG = 1


class ToolInterrupted(RclError):
    """A tool was stopped by a signal from outside rclverify (``signal``: its
    number): the run is not a result and nothing is recorded for it."""

    def __init__(self, where: Loc, tool: str, signum: int) -> None:
        self.signal = signum
        try:
            name = signal.Signals(signum).name
        except ValueError:
            name = f"signal {signum}"
        super().__init__([error(where, f"{tool} was stopped by {name} from outside rclverify: the run was "
                                       "interrupted, nothing is recorded for it; run the verification again",
                                "E-interrupted")])


# -- the reaper ----------------------------------------------------------------

_LOCK = threading.Lock()


@dataclass
class _Reaper:
    """The reaper process of the process ``pid`` that started it (``proc``: ``None`` when it is gone)."""

    pid: int | None = None
    proc: subprocess.Popen[bytes] | None = None


_REAPER = _Reaper()


def _reaper() -> subprocess.Popen[bytes] | None:
    """This process's reaper, started at the first call (again after a ``fork``);
    ``None`` when it cannot be started (then only the other safeguards hold)."""
    if _REAPER.pid == os.getpid() and _REAPER.proc is not None and _REAPER.proc.poll() is None:
        return _REAPER.proc
    try:
        proc = subprocess.Popen([sys.executable, "-I", "-S", str(Path(__file__).with_name("_reaper.py"))],
                                stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                start_new_session=True, close_fds=True)
    except OSError:
        proc = None
    _REAPER.pid, _REAPER.proc = os.getpid(), proc
    return proc


def _tell(op: str, arg: int | str) -> None:
    with _LOCK:
        proc = _reaper()
        if proc is None or proc.stdin is None:
            return
        try:
            proc.stdin.write((json.dumps([op, arg]) + "\n").encode())
            proc.stdin.flush()
        except OSError:  # the reaper is gone: the other safeguards remain
            _REAPER.proc = None


@contextlib.contextmanager
def temporary_directory(parent: Path, prefix: str) -> Iterator[Path]:
    """A fresh directory under ``parent`` (created), removed on leaving the
    block and, should rclverify be killed meanwhile, by the reaper.  Raises
    ``OSError`` when it cannot be made."""
    path = Path(tempfile.mkdtemp(prefix=prefix, dir=parent))
    _tell("+d", str(path))
    try:
        yield path
    finally:
        shutil.rmtree(path, ignore_errors=True)
        _tell("-d", str(path))


def register_directory(path: Path) -> None:
    """Have the reaper remove ``path`` when rclverify ends (a directory that
    lives as long as the process)."""
    _tell("+d", str(path))


def forget_directory(path: Path) -> None:
    """Tell the reaper that ``path`` (made by :func:`temporary_directory`) was
    renamed into place and must be kept."""
    _tell("-d", str(path))


# -- running one tool ------------------------------------------------------------

def _die_with_parent() -> None:  # pragma: no cover - runs in the child, between fork and exec
    try:
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
    except (OSError, AttributeError):
        pass


_PREEXEC = _die_with_parent if sys.platform.startswith("linux") else None


def _kill_group(pgid: int) -> None:
    try:
        os.killpg(pgid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass


@contextlib.contextmanager
def _exit_on_termination() -> Iterator[list[int]]:
    """In the main thread: SIGTERM and SIGHUP raise ``SystemExit(128 + signal)``
    while the block runs (previous handlers restored after it).  Yields the
    signals received: a handler's ``SystemExit`` raised inside a callback whose
    exceptions Python ignores is lost (``os.fork``'s ``after_in_parent``
    callbacks, such as ``logging``'s lock release, while ``subprocess.Popen``
    starts the tool: the whole suite caught a SIGTERM there, and rclverify went
    on waiting for the tool), so the block checks the list at its own points
    (:func:`_raise_received`), and a block that ends normally after a signal
    raises its ``SystemExit`` on leaving."""
    received: list[int] = []
    if threading.current_thread() is not threading.main_thread():
        yield received
        return

    def stop(signum: int, frame: Any) -> None:
        received.append(signum)
        raise SystemExit(128 + signum)

    previous = {s: signal.signal(s, stop) for s in (signal.SIGTERM, signal.SIGHUP)}
    try:
        yield received
    finally:
        for s, h in previous.items():
            signal.signal(s, h)
    _raise_received(received)


def _raise_received(received: list[int]) -> None:
    """``SystemExit(128 + signal)`` for the first signal in ``received``, if any."""
    if received:
        raise SystemExit(128 + received[0])


def run_bounded(cmd: list[str], cwd: Path, timeout_s: float,
                env: Mapping[str, str] | None = None, *, where: Loc | None = None,
                tool: str | None = None) -> tuple[str, int | None, float]:
    """Run ``cmd`` in ``cwd`` for at most ``timeout_s`` seconds (see the module docstring).

    Returns ``(stdout and stderr together, decoded with replacement; the exit
    code -- negative for a crash by a signal -- or None when the bound was
    reached and the process group was killed; the wall-clock duration in
    seconds, rounded to ms)``.  Raises ``OSError`` when the process cannot be
    started, :class:`ToolInterrupted` (located at ``where``; ``tool`` names
    it, default ``cmd[0]``'s file name) when it was stopped by a signal
    rclverify did not send, and lets ``KeyboardInterrupt``/``SystemExit``
    through after killing the group.
    """
    t0 = time.perf_counter()
    with _exit_on_termination() as received:
        proc = subprocess.Popen(cmd, cwd=cwd, env=None if env is None else dict(env), stdin=subprocess.DEVNULL,
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, start_new_session=True,
                                preexec_fn=_PREEXEC)
        _tell("+g", proc.pid)
        code: int | None
        try:
            _raise_received(received)  # a signal while the tool started (its SystemExit may have been lost)
            out, _ = proc.communicate(timeout=max(timeout_s, 0.1))
            code = proc.returncode
        except subprocess.TimeoutExpired:
            _kill_group(proc.pid)
            out, _ = proc.communicate()
            code = None
        finally:  # also on KeyboardInterrupt/SystemExit: nothing of the tool survives
            _kill_group(proc.pid)
            if proc.returncode is None:
                proc.wait()
            _tell("-g", proc.pid)
    if code is not None and code < 0 and -code in INTERRUPTS:
        raise ToolInterrupted(where or Loc(Path(cmd[0]).name, 1, 1), tool or Path(cmd[0]).name, -code)
    return out.decode("utf-8", errors="replace"), code, round(time.perf_counter() - t0, 3)
