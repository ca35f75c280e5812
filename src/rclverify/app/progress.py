"""Progress of a doit run on a terminal: the stage, ``k/n`` obligations, the
running backend.

:class:`ProgressReporter` is a doit reporter (``DOIT_CONFIG["reporter"]``).
When standard output is a terminal it replaces doit's one line per task by
one live status line (``rich``), e.g.::

    evidence  12/50 obligations  running: dafny (Agent.g0.dafny.contract)  0:07

and leaves what the actions print above it; the line disappears when the run
ends.  When standard output is not a terminal (CI logs, pipes, tests) it is
exactly doit's console reporter (``.  task`` / ``-- task`` lines), with no
progress lines.  ``n`` is the number of evidence tasks known so far: they are
created after the export stage ran (docs/decisions.md, "doit tasks").
"""
from __future__ import annotations

import io
import os
import sys
import time
from pathlib import Path
from typing import Any, Mapping

from typing import TYPE_CHECKING

from doit.exceptions import TaskFailed
from doit.reporter import ConsoleReporter

from rclverify.app.doit_checker import forget_stats, keep_stats
from rclverify.app.doitstate import save_finished
from rclverify.report.summary import is_terminal

if TYPE_CHECKING:  # rich is imported when the live line starts (a terminal): doit imports this on every run
    from rich.live import Live
    from rich.text import Text


class _ChildLineWriter(io.TextIOBase):
    """Standard output of a ``doit -n N`` worker process forked while the live
    line is shown.  It writes whole lines only, each batch starting by
    clearing the terminal line (``\\r`` + erase line), in one ``os.write``:
    the parent's one-line live display is then redrawn below it at its next
    refresh instead of being overwritten mid-line."""

    def __init__(self, fd: int) -> None:
        super().__init__()
        self._fd = fd
        self._buf = ""

    def writable(self) -> bool:
        return True

    def isatty(self) -> bool:
        return True

    def fileno(self) -> int:
        return self._fd

    def write(self, text: str) -> int:
        self._buf += text
        if "\n" in self._buf:
            lines, _, self._buf = self._buf.rpartition("\n")
            os.write(self._fd, ("\r\x1b[2K" + lines + "\n").encode("utf-8", "replace"))
        return len(text)

    def flush(self) -> None:
        if self._buf:
            text, self._buf = self._buf, ""
            os.write(self._fd, ("\r\x1b[2K" + text + "\n").encode("utf-8", "replace"))


_LIVE_ACTIVE = False


def _after_fork_in_child() -> None:
    if _LIVE_ACTIVE and sys.__stdout__ is not None and sys.__stderr__ is not None:
        sys.stdout = _ChildLineWriter(sys.__stdout__.fileno())
        sys.stderr = _ChildLineWriter(sys.__stderr__.fileno())


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_after_fork_in_child)


def whole_lines() -> None:
    """Make standard output and error line-buffered and not write-through
    (when they are text streams that can be), so that each line goes out in
    one ``write`` as soon as it ends.  Under ``doit -n N`` (the default on a
    machine of two CPUs or more, :mod:`rclverify.app.jobs`) the main
    process's ``.  task`` lines and the workers' prints share one pipe or
    file.  Block-buffered (no terminal), each process wrote its buffer when
    8 KiB were full, cutting a line there; unbuffered (``PYTHONUNBUFFERED``,
    set in many CI images), ``print`` wrote a line's text and its newline in
    two ``write`` calls.  Either way another process's line landed inside
    one, e.g. a problem line of the summary followed by ``.  verify`` on the
    same line (tests/app/test_jobs.py).  Called before doit forks its workers,
    which inherit the setting; a line of up to ``PIPE_BUF`` (4096) bytes is
    written to a pipe whole (pipe(7))."""
    for stream in (sys.stdout, sys.stderr):
        reconfigure = getattr(stream, "reconfigure", None)
        if reconfigure is not None:
            try:
                reconfigure(line_buffering=True, write_through=False)
            except (ValueError, OSError):  # a closed or detached stream: left as it is
                pass


class PlainFailure(TaskFailed):  # type: ignore[misc]
    """A task failure the user caused or asked for (``verify --strict`` on
    open evidence, a last-run file of another shape): :class:`ProgressReporter`
    prints its message alone, one plain line, instead of doit's
    ``TaskFailed - taskid:NAME`` header; the run still exits 1."""


def backend_of(obligation_id: str) -> str:
    """The backend named in an obligation id ``Node.gK.backend.instance``
    (``''`` when the id has fewer parts)."""
    parts = obligation_id.split(".")
    return parts[2] if len(parts) > 2 else ""


class ProgressReporter(ConsoleReporter):  # type: ignore[misc]
    """doit reporter showing live progress on a terminal (see the module docstring)."""

    desc = "console output, with a live progress line on a terminal"

    def __init__(self, outstream: Any, options: Mapping[str, Any]) -> None:
        super().__init__(outstream, options)
        self.live_mode = is_terminal()
        self.tasks: Mapping[str, Any] = {}
        self.stage = "starting"
        self.running: dict[str, str] = {}
        self.done: set[str] = set()
        self.started = time.monotonic()
        self.live: Live | None = None
        #: The workspace root of a ``verify`` task doit found up to date: its
        #: action (the status and summary) did not run, so :meth:`complete_run` prints them.
        self.verify_root: str | None = None
        keep_stats(True)  # the task events below forget them (app/doit_checker.py)

    # -- doit reporter interface -------------------------------------------------
    def write(self, text: str) -> None:
        """doit's own messages (failures, errors): above the live line when there is one."""
        if self.live is not None:
            self.live.console.print(text, end="", markup=False, highlight=False)
        else:
            super().write(text)

    def initialize(self, tasks: Mapping[str, Any], selected_tasks: Any) -> None:
        """Remember doit's task table (it grows when delayed tasks are created),
        and freeze doit's task objects for the run with the workspace
        (:func:`rclverify.core.cache.heap.freeze_for_run`), with no full
        collection until a task executes here (:func:`~rclverify.core.cache.heap.no_full_collections`)."""
        from rclverify.core.cache.heap import freeze_for_run, no_full_collections  # deferred: start-up (loads rclverify.core, rclverify.core.cache and more only when called)
        freeze_for_run()
        no_full_collections()  # until a task executes in this process, or the run ends (complete_run)
        self.tasks = tasks
        if self.live_mode:
            from rich.console import Console  # deferred: optional or conditional (inside a block)
            from rich.live import Live  # deferred: optional or conditional (inside a block)
            console = Console(file=sys.stdout, force_terminal=True)
            self.live = Live(self._line(), console=console, transient=True, refresh_per_second=4,
                             redirect_stdout=True, redirect_stderr=True, get_renderable=self._line)
            self.live.start()
            global _LIVE_ACTIVE
            _LIVE_ACTIVE = True
        else:
            whole_lines()

    def execute_task(self, task: Any) -> None:
        forget_stats()
        if not self.live_mode:
            super().execute_task(task)
            return
        if task.actions and not task.name.startswith("_"):
            self.stage = task.name.split(":", 1)[0]
            if self.stage == "evidence":
                self.running[task.name] = backend_of(task.name.split(":", 1)[1])

    def _finish(self, task: Any) -> None:
        self.running.pop(task.name, None)
        if task.name.startswith("evidence:"):
            self.done.add(task.name)

    def add_success(self, task: Any) -> None:
        forget_stats()
        save_finished()  # doit saved the task's state in memory just before: on disk now (doitstate)
        self._finish(task)
        super().add_success(task)

    def add_failure(self, task: Any, fail: Any) -> None:
        forget_stats()
        save_finished()
        self._finish(task)
        if isinstance(fail, PlainFailure):  # one plain sentence, not doit's header
            self.write(fail.message.rstrip("\n") + "\n")
            return
        super().add_failure(task, fail)

    def skip_uptodate(self, task: Any) -> None:
        if task.name == "verify" and task.actions and getattr(task.actions[0], "args", None):
            self.verify_root = str(task.actions[0].args[0])
        if not self.live_mode:
            super().skip_uptodate(task)
            return
        self._finish(task)

    def complete_run(self) -> None:
        """Stop the live line, then let doit report failures as usual; and
        have the process skip the cyclic garbage collection of its whole
        heap when it exits (:mod:`rclverify.core.cache.heap`: the heap frozen for the
        run is given back to the collector, then frozen again at exit)."""
        keep_stats(False)
        if self.live is not None:
            global _LIVE_ACTIVE
            _LIVE_ACTIVE = False
            self.live.stop()
            self.live = None
        super().complete_run()
        if self.verify_root is not None:  # nothing had to run: the last run's status all the same
            from rclverify.lang.errors import RclError  # deferred: optional or conditional (inside a block)
            from rclverify.report.summary import print_last_run  # deferred: optional or conditional (inside a block)
            try:
                print_last_run(Path(self.verify_root))
            except RclError as exc:  # no report to show, or one of another shape: its one located line
                self.write("".join(f"{d}\n" for d in exc.diagnostics))
        from rclverify.core.cache.heap import freeze_at_exit, release_after_run  # deferred: start-up (loads rclverify.core, rclverify.core.cache and more only when called)
        from rclverify.core.runlock import release  # deferred: start-up (loads rclverify.core, rclverify.core.runlock only when called)
        release()  # the workspace's run lock (rclverify.core.runlock): the next run may start
        release_after_run()
        freeze_at_exit()

    # -- the status line -----------------------------------------------------------
    def _line(self) -> Text:
        # called from rich's refresh thread while doit may add delayed tasks: copy first
        try:
            names, running = list(self.tasks), list(self.running.items())
        except RuntimeError:  # changed during the copy; the next refresh redraws
            names, running = [], []
        total = sum(1 for name in names if name.startswith("evidence:"))
        obligations = f"{len(self.done)}/{total}" if total else "0/?"
        from rich.text import Text  # deferred: start-up (loads rich and more only when called)
        line = Text()
        line.append(f"{self.stage:<9}", style="bold cyan")
        line.append(f" {obligations} obligations")
        if running:
            name, backend = running[0]
            line.append("  running: ")
            line.append(backend or "?", style="bold")
            line.append(f" ({name.split(':', 1)[1]})")
            if len(running) > 1:
                line.append(f" +{len(running) - 1}")
        secs = int(time.monotonic() - self.started)
        line.append(f"  {secs // 60}:{secs % 60:02d}", style="dim")
        # one terminal line at most: worker processes rely on it (see _ChildLineWriter)
        line.no_wrap, line.overflow = True, "ellipsis"
        return line
