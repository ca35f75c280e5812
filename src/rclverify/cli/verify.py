"""``rclverify verify`` and ``report``: the whole pipeline through doit, and the assurance report
rebuilt from the artifacts (one run at a time per workspace: core/runlock.py)."""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from rclverify.cli.common import AddCommand, no_wait_option, run_lock, workspace_of


def cmd_report(args: argparse.Namespace) -> int:
    """Rebuild reports/ from the artifacts (waiting for a run in progress unless ``--no-wait``); print the files and the headline."""
    from rclverify.app.pipeline import stage_report  # deferred: start-up (loads rclverify.app, rclverify.app.pipeline and more only when called)
    with run_lock(args):
        report, paths = stage_report(workspace_of(args))
    for p in paths:
        print(p)
    print(report.summary.headline)
    return 0


def cmd_verify(args: argparse.Namespace) -> int:
    """Run the whole pipeline through doit in ``args.workspace`` (``--strict``: exit 1 unless everything holds; ``-n``: doit processes, else :func:`rclverify.app.jobs.default_jobs`; ``--cluster``: backend jobs on Dask); doit's exit code."""
    from rclverify.app.tasks import DEP_FILE, build_tasks, doit_config  # deferred: start-up (loads doit, rclverify.app and more only when called)
    if not Path(args.workspace).is_dir():  # before doit opens its state file there (a sqlite3 traceback)
        print(f"{args.workspace}: error: no such workspace directory", file=sys.stderr)
        return 1
    if not (Path(args.workspace) / args.plan).is_file():
        # a missing plan: the located error `compose` gives, not doit's DependencyError
        workspace_of(args).plan
    try:  # a bad RCLVERIFY_JOBS: doit_config printed the one-line reason (before the lock is taken)
        config = doit_config(str(Path(args.workspace) / DEP_FILE))
    except SystemExit as exc:
        return int(exc.code) if isinstance(exc.code, int) else 1
    try:  # takes the workspace's run lock: waits for a run in progress unless --no-wait
        tasks = build_tasks(Path(args.workspace), args.plan, wait=False if args.no_wait else None)
    except SystemExit as exc:  # build_tasks printed the one-line reason
        return int(exc.code) if isinstance(exc.code, int) else 1
    module = type(sys)("rclverify_dodo")
    module.__dict__.update(tasks)
    module.DOIT_CONFIG = config  # type: ignore[attr-defined]
    argv = ["verify"] + (["--strict"] if args.strict else [])
    if args.jobs is not None:  # else DOIT_CONFIG's num_process (app/jobs.py)
        from rclverify.app.jobs import doit_num_process  # deferred: start-up (loads multiprocessing only when called)
        argv = ["-n", str(doit_num_process(args.jobs))] + argv
    try:  # SystemExit: a fault while doit saves its state, already reported in one line (doit_patches.guard_dep_writes)
        return run_doit(module, argv, args.cluster)
    except SystemExit as exc:
        return int(exc.code) if isinstance(exc.code, int) else 1
    finally:  # the run lock, also when doit ended before completing the run (in-process callers go on)
        from rclverify.core.runlock import release  # deferred: optional or conditional (inside a block)
        release(Path(args.workspace))


def run_doit(module: object, argv: list[str], cluster: str | None) -> int:
    """Run doit's ``argv`` on the tasks of ``module``, with the Dask scheduler ``cluster`` named to the evidence tasks when given; doit's exit code."""
    from doit.cmd_base import ModuleTaskLoader  # deferred: start-up (loads doit and more only when called)
    from doit.doit_cmd import DoitMain  # deferred: start-up (loads doit and more only when called)
    # doit's default output is the sys.stdout of the moment doit was imported; an in-process caller's
    # stream may have been another since (and closed): doit writes to today's
    config = getattr(module, "DOIT_CONFIG", None)
    if isinstance(config, dict):
        config["outfile"] = sys.stdout
    if not cluster:
        return int(DoitMain(ModuleTaskLoader(module)).run(argv))
    from rclverify.app.cluster import CLUSTER_ENV  # read by the evidence tasks, also in doit's worker processes; deferred: start-up (loads rclverify.app, rclverify.app.cluster and more only when called)
    before = os.environ.get(CLUSTER_ENV)
    os.environ[CLUSTER_ENV] = cluster
    try:
        return int(DoitMain(ModuleTaskLoader(module)).run(argv))
    finally:
        if before is None:
            del os.environ[CLUSTER_ENV]
        else:
            os.environ[CLUSTER_ENV] = before


def add_report(add: AddCommand) -> None:
    """The ``report`` parser."""
    no_wait_option(add("report", cmd_report, "rebuild the assurance report from the artifacts", True))


def add_verify(add: AddCommand) -> None:
    """The ``verify`` parser."""
    v = add("verify", cmd_verify, "run the whole pipeline with doit", True)
    v.add_argument("--strict", action="store_true",
                   help="exit 1 unless every obligation, side condition and health check holds")
    v.add_argument("-n", "--jobs", type=int, default=None,
                   help="doit processes (default: this machine's CPUs, at most 4, or RCLVERIFY_JOBS)")
    v.add_argument("--no-wait", action="store_true",
                   help="exit 1 instead of waiting when another run is in progress in the workspace "
                        "(also: RCLVERIFY_NO_WAIT=1)")
    v.add_argument("--cluster", metavar="ADDRESS",
                   help="send backend jobs to the Dask scheduler at ADDRESS (e.g. tcp://127.0.0.1:8786); "
                        "default: run them locally")
