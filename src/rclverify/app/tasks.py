"""doit task generators for a workspace (``dodo.py`` only calls :func:`build_tasks`).

Stages and their real file dependencies, per node ``N``:

``check``          contracts + plan -> artifacts/contracts/N.json (one snapshot per
                   node, rewritten only when that node's text changes), artifacts/cones/N.sha256
                   (a digest of N's upstream cone's snapshots), model, lint
``graph``          model -> model.dot, model.svg (when graphviz is installed); not part of
                   ``verify`` (the report lays out its own diagram, with statuses):
                   ``doit graph`` runs it
``node:N``         two stages, each run only when one of its own inputs changed:
                   compose  snapshot of N and of N's producers + model -> calculus/N.json;
                            run again too when the part of N's cone digest it read changed
                            (app/conetask.py: the whole cone when a side condition was decided in
                            context, the cone's environment assumptions otherwise)
                   export   snapshot of N + the backend input files -> obligations/N.json
``health:N``       snapshot of N (+ replacement contract) -> health/N.json (a task of its own,
                   so that long health checks run beside the evidence: docs/decisions.md)
``evidence:ID``     one obligation's record + the files it reads -> its evidence record
                   (created after ``node`` ran, when the obligations are known)
``requirements``   plan + model + contract snapshots (+ Doorstop files, recorded runs) ->
                   artifacts/requirements/<ID>.json; inside, only requirements whose
                   cone's snapshots or statements changed are checked again
``deadlines``      plan + model + snapshots of the nodes between a deadline's ends ->
                   artifacts/deadlines/index.json (rule D3, every end-to-end deadline;
                   only when the plan has one)
``nodl``           plan + contract snapshots + the NoDL documents under nodl/ ->
                   artifacts/nodl/index.json (the documents against the contracts and
                   each other, docs/nodl.md; only when nodl/ holds a document)
``diagnosis``      every artifact the report reads -> artifacts/diagnosis/index.json (each
                   problem of the report explained, repairs checked by Z3; sealed with the
                   digest of the report dict it explains: stages/diagnoses.py)
``report:html``    every artifact above -> reports/assurance.{html,json}, the CI formats
                   reports/assurance.sarif, assurance.junit.xml, argument.svg
``report:text``    every artifact above -> reports/assurance.md, argument.{json,gsn.yaml,dot}
                   (two tasks rendered at once by ``doit -n 2``: report/parts.py)
``verify``         the whole pipeline; ``doit verify --strict`` fails unless every
                   obligation is discharged

doit compares file contents (sha256), so editing one node's contract changes
only that node's snapshot: its node and health tasks and run tasks,
its consumers' node tasks (the compose stage only: their side conditions), the
node tasks downstream whose side conditions were decided in context against
the cone (app/conetask.py)
and the report re-run.  Compose and export share one doit task per node
because doit's own cost per task (defining it, checking its dependencies)
was most of a no-op run of a large system (docs/scale.md); the task's
action gets doit's list of changed dependencies and runs the stages that
read one of them (:func:`stages_to_run`).

The tasks are defined by :class:`rclverify.app.task_table.TaskTable` (one
method per task family), run the actions of :mod:`rclverify.app.task_actions`
(module-level functions with plain arguments, so ``doit -n 2``, parallel
processes, behaves like a serial run) and are kept up to date by the checks of
:mod:`rclverify.app.task_checks`; :mod:`rclverify.app.doit_patches` holds the
three changes made to doit's internals.

With the environment variable ``RCLVERIFY_CLUSTER=ADDRESS`` the ``evidence``
tasks send their backend jobs to that Dask scheduler (:mod:`rclverify.app.cluster`);
the records are stored locally as in a local run.
"""
from __future__ import annotations

import sys
from pathlib import Path
from typing import Any, Callable

from rclverify.core.cache import heap
from rclverify.core.cache import workspace as wscache
from rclverify.stages.workspace import TaskIndex, Workspace
from rclverify.app.doit_patches import guard_dep_writes, release_in_order, use_linear_implicit_task_dep
from rclverify.app.task_actions import (NODE_STAGES, WORKSPACES, act_check, act_report, act_verify,
                                        stages_to_run)
from rclverify.app.task_checks import entry_inputs
from rclverify.app.task_table import CROSSCHECK_INDEX, DEADLINES_INDEX, REPORTS, TaskTable
from rclverify.lang.errors import RclError

__all__ = ["build_tasks", "doit_config", "DEP_FILE", "REPORTS", "DEADLINES_INDEX", "CROSSCHECK_INDEX", "NODE_STAGES",
           "stages_to_run", "act_check", "act_report", "act_verify"]

#: The name older callers import (tests, ``from rclverify.app.tasks import _inputs``): :func:`entry_inputs`.
_inputs = entry_inputs


#: Where doit keeps the state of each task (its file_dep signatures), relative to the workspace.
DEP_FILE = ".doit.sqlite"


def doit_config(dep_file: str = DEP_FILE) -> dict[str, Any]:
    """``DOIT_CONFIG`` of a workspace's ``dodo.py`` (and of ``rclverify verify``):
    ``verify`` by default, the progress reporter, and doit's SQLite
    dependency store in ``dep_file``.

    SQLite rather than doit's default ``dbm`` store: with Python's fallback
    ``dbm.dumb`` (no gdbm on many systems) opening the store parses one line
    per task with ``ast.literal_eval``, about 0.3 CPU s of a 1000-node no-op
    run when it had 5000 tasks (docs/scale.md).  A workspace that switches store runs
    every task once, as doit knows no earlier state in the new file.  The
    file checker compares contents by sha256, each file hashed once per file
    state and process, never trusting a modification time
    (:mod:`rclverify.app.doit_checker`); the store's codec writes
    doit's JSON and reads it with msgspec (:mod:`rclverify.app.doit_codec`).

    ``num_process``: the processes of a run without ``-n``
    (:func:`rclverify.app.jobs.default_jobs`: this machine's CPUs, at most
    4, or ``RCLVERIFY_JOBS``); one is doit's serial runner (``0``), the
    actions in this process.  A bad ``RCLVERIFY_JOBS`` prints one
    ``error:`` line and raises ``SystemExit(1)``, as :func:`build_tasks`
    does for its faults."""
    from rclverify.app.progress import ProgressReporter  # deferred: start-up (loads doit, rclverify.app.doitstate and more only when called)
    from rclverify.app.doit_checker import ContentChecker  # deferred: start-up (loads doit.dependency only when called)
    from rclverify.app.doit_codec import StateCodec  # deferred: start-up (loads msgspec only when called)
    from rclverify.app.jobs import JobsError, default_jobs, doit_num_process  # deferred: start-up (loads multiprocessing only when called)
    try:
        jobs = default_jobs()
    except JobsError as exc:
        print(f"error: {exc}", file=sys.stderr)
        raise SystemExit(1) from None
    return {"default_tasks": ["verify"], "verbosity": 2, "dep_file": dep_file, "backend": "sqlite3",
            "reporter": ProgressReporter, "check_file_uptodate": ContentChecker, "codec_cls": StateCodec,
            "num_process": doit_num_process(jobs)}


def build_tasks(root: str | Path, plan_file: str = "contracts/plan.yaml", *,
                wait: bool | None = None) -> dict[str, Callable[[], Any]]:
    """The ``task_*`` functions for a dodo.py of the workspace at ``root``.

    First takes the workspace's run lock (:mod:`rclverify.core.runlock`: one run
    at a time; a second run waits with the message ``waiting for the run in
    progress (pid N)``, or with ``wait=False`` / ``RCLVERIFY_NO_WAIT=1``
    does not wait).  The lock is given back when doit completes the run
    (the progress reporter) or the process ends.  When the lock cannot be
    had without waiting, or its file cannot be created, prints one
    ``error:`` line and raises ``SystemExit(1)`` (``dodo.py`` has no other
    way to end a doit command cleanly).

    The loaded workspace stays live for the run: it is loaded without
    cyclic garbage collection and then frozen for the run
    (:mod:`rclverify.core.cache.heap`; the progress reporter gives it back to the
    collector when doit completes the run)."""
    from rclverify.core import runlock  # deferred: start-up (loads rclverify.core.runlock only when called)
    from rclverify.core.faults import describe_os_error  # deferred: start-up (loads rclverify.core.faults only when called)
    rootp = Path(root)
    if not rootp.is_dir():
        print(f"{root}: error: no such workspace directory", file=sys.stderr)
        raise SystemExit(1)
    try:
        runlock.acquire(rootp, wait=wait)
    except runlock.RunInProgress as exc:
        print(f"error: {exc}", file=sys.stderr)
        raise SystemExit(1) from None
    except OSError as exc:
        print(describe_os_error(exc, rootp.resolve(), "cannot take the run lock in"), file=sys.stderr)
        raise SystemExit(1) from None
    from rclverify.core.extras import MissingExtra  # deferred: start-up (loads rclverify.core.extras only when called)
    with heap.no_collection():
        try:
            creators = _build_tasks(root, plan_file)
        except MissingExtra as exc:  # the workspace needs an optional part: one line naming the extra
            print(f"error: {exc}", file=sys.stderr)
            raise SystemExit(1) from None
        heap.freeze_for_run()  # before collecting again: what was made while loading is not looked at
    return creators


def _build_tasks(root: str | Path, plan_file: str) -> dict[str, Callable[[], Any]]:
    """Install the changes to doit, load the workspace (from the cache of an earlier run when no input
    changed) and seed the actions' workspace with it, then define the run's tasks (:class:`TaskTable`)."""
    use_linear_implicit_task_dep()
    guard_dep_writes()
    release_in_order()
    rootp = Path(root).resolve()
    r = str(rootp)
    ws = Workspace(rootp, plan_file)
    restored = wscache.restore(ws)  # the loaded workspace of an earlier run, when no input changed
    index: TaskIndex | None
    try:
        index = ws.index  # from the cache (no-op runs) or the loaded plan and model
    except RclError:
        index = None
    if index is not None:
        WORKSPACES[r] = ws
        if not restored:
            wscache.save_in_background(ws)
    else:
        WORKSPACES.pop(r, None)
    try:
        contract_deps = [f"{r}/{c}" for c in (index.contracts if index is not None else ws.plan.contracts)]
    except RclError:
        contract_deps = []
    return TaskTable(ws, index, plan_file, contract_deps).creators()
