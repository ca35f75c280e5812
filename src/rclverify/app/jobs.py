"""How many doit processes a run uses when the command line does not say.

``doit verify`` and ``rclverify verify`` without ``-n`` run the pipeline in
as many processes as this process has CPUs (:func:`rclverify.core.cpus.allowed_cpus`),
at most :data:`MAX_DEFAULT`: on the 2-core machines of the benches the case
study's cold run took 23.9 s serially and 14.2 s in two processes, for the
same CPU seconds (21.5 and 21.3; docs/scale.md, "Standing decisions").  The
verdicts and reports do not depend on the number of processes (each stage
starts from a fresh Z3 context and writes its own records;
``tests/report/test_pipeline_e2e.py`` holds a parallel run against the serial one).

``RCLVERIFY_JOBS=N`` (a whole number, at least 1) sets the default instead,
for a CI job that shares its machine or a test suite that counts CPU
seconds; ``-n N`` on the command line wins over both.  Serial (1) where
processes are not forked (``multiprocessing``'s start method is not
``fork``: doit's process pool then pickles the tasks, which a workspace's
task functions are not made for).  Decision and figures: docs/decisions.md,
"Processes".
"""
from __future__ import annotations

import multiprocessing
import os
import sys

from rclverify.core.cpus import allowed_cpus

#: The environment variable that sets the default number of processes.
ENV = "RCLVERIFY_JOBS"
#: The most processes a run uses by default: each holds its own copy of
#: what it computes (the 5000-node system: 1.3 GB in two processes), so a
#: machine with many CPUs is not filled without being asked (``-n``).
MAX_DEFAULT = 4


class JobsError(ValueError):
    """``RCLVERIFY_JOBS`` is not a whole number of at least 1 (the message says so)."""


def default_jobs(env: dict[str, str] | None = None) -> int:
    """The number of doit processes a run uses without ``-n``: ``RCLVERIFY_JOBS``
    when set in ``env`` (default ``os.environ``), else the CPUs this process
    may run on, at most :data:`MAX_DEFAULT`; 1 where processes are not forked.

    Raises :class:`JobsError` (one line naming the variable and its value)
    when ``RCLVERIFY_JOBS`` is set but not a whole number of at least 1."""
    raw = (os.environ if env is None else env).get(ENV, "").strip()
    if raw:
        try:
            n = int(raw)
        except ValueError:
            n = 0
        if n < 1:
            raise JobsError(f"{ENV}={raw!r}: not a whole number of processes of at least 1")
        return n
    if _start_method() != "fork":
        return 1
    return max(1, min(MAX_DEFAULT, len(allowed_cpus())))


def doit_num_process(jobs: int) -> int:
    """doit's ``num_process`` for ``jobs`` processes: doit's serial runner
    (``0``, the actions in the calling process) for one or fewer, else
    ``jobs`` (doit's ``-n 1`` is one worker process beside the main one)."""
    return jobs if jobs > 1 else 0


def _start_method() -> str:
    """How ``multiprocessing`` (doit's process pool) starts processes here:
    the method set in this process, else the platform's default without
    fixing it (``fork`` on Linux before Python 3.14; ``spawn`` on macOS and
    Windows; ``forkserver`` on Linux from 3.14)."""
    method = multiprocessing.get_start_method(allow_none=True)
    if method is not None:
        return method
    return "fork" if sys.platform.startswith("linux") and sys.version_info < (3, 14) else "other"


__all__ = ["ENV", "MAX_DEFAULT", "JobsError", "default_jobs", "doit_num_process"]
