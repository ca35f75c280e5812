"""``rclverify init``, ``cache`` and ``review``: a new workspace written, what a workspace keeps
between runs listed or cleared, a review record to fill in."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from rclverify.cli.common import AddCommand, io_error
from rclverify.lang.errors import RclError


def cmd_init(args: argparse.Namespace) -> int:
    """Write a new workspace in ``args.dir`` that verifies at once (``--from-ros``: one contract skeleton per node of a ROS workspace, docs/ros.md); print the files written."""
    if getattr(args, "from_ros", None):
        from rclverify.cli.ros import init_from_ros  # deferred: optional or conditional (inside a block)
        return init_from_ros(args)
    from rclverify.tools.scaffold import InitError, init_workspace  # deferred: start-up (loads jinja2, rclverify.core and more only when called)
    names = [n.strip() for n in args.nodes.split(",")] if args.nodes is not None else None
    try:
        written = init_workspace(Path(args.dir), names)
    except InitError as exc:
        print(f"{args.dir}: error: {exc}", file=sys.stderr)
        return exc.exit_code
    except OSError as exc:
        print(f"{args.dir}: error: cannot write the workspace: {exc.strerror or exc}", file=sys.stderr)
        return 1
    for p in written:
        print(p)
    print(f"workspace written; run `doit verify` in {args.dir}")
    return 0


def cmd_cache(args: argparse.Namespace) -> int:
    """List what the workspace keeps between runs under ``artifacts/cache``
    (:func:`rclverify.core.cache.kept_files`: file, kind, entries, size, whether
    this rclverify code wrote it), or delete it all with ``--clear`` (always
    safe: every entry is a pure speed-up).  Exit 0; 1 (located) for a
    missing workspace."""
    import shutil  # deferred: start-up (loads shutil only when called)

    from rclverify.core.cache import CACHE_DIR, kept_files  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    root = Path(args.workspace)
    if not root.is_dir():
        raise RclError([io_error(root, "no such workspace directory")])
    if args.clear:
        shutil.rmtree(root / CACHE_DIR, ignore_errors=True)
        print(f"{CACHE_DIR}: cleared")
        return 0
    rows = kept_files(root)
    if not rows:
        print(f"{CACHE_DIR}: empty")
    for r in rows:
        entries = "" if r["entries"] is None else f"{r['entries']} files"
        current = {True: "current", False: "other code: not used", None: ""}[r["current"]]
        print(f"{r['file']:<48} {r['kind'] or '?':<18} {r['bytes'] / 1024:>9.1f} KiB  {entries:<10} {current}")
    print("Why a task ran again, or did not: `doit info TASK` in the workspace (docs/scale.md).")
    return 0


def cmd_review(args: argparse.Namespace) -> int:
    """Write (``-o FILE``) or print the review record to fill in for ``args.node`` (a checklist from its guarantees, the reviewed files with their sha256); exit 2 for an unknown node."""
    from rclverify.backends.review.blank import blank_record  # deferred: start-up (loads jinja2, yaml and more only when called)
    from rclverify.lang.output import write_atomic  # deferred: start-up (loads rclverify.lang.ast, rclverify.lang.output and more only when called)
    from rclverify.stages.workspace import Workspace  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    root = Path(args.workspace)
    out_rel = ""
    if args.output:  # the record this command writes may be the one the plan names and misses
        try:
            out_rel = Path(args.output).resolve().relative_to(root.resolve()).as_posix()
        except ValueError:
            out_rel = ""
    ws = Workspace(root, args.plan, missing_ok=(out_rel,) if out_rel else ())
    if args.node not in ws.checked.nodes:
        print(f"error: no node named {args.node!r}; nodes: {', '.join(ws.node_names())}", file=sys.stderr)
        return 2
    try:
        text = blank_record(ws.checked.nodes[args.node], ws.root, args.files)
    except FileNotFoundError as exc:
        print(f"error: cannot read reviewed file {exc}", file=sys.stderr)
        return 1
    if args.output:
        Path(args.output).parent.mkdir(parents=True, exist_ok=True)  # reviews/ of a new workspace, as before
        write_atomic(Path(args.output), text)
        print(f"review record to fill in: {args.output}")
    else:
        print(text, end="")
    return 0


def add_cache(add: AddCommand) -> None:
    """The ``cache`` parser."""
    add("cache", cmd_cache, "list what the workspace keeps between runs (artifacts/cache), or clear it",
        True).add_argument("--clear", action="store_true", help="delete artifacts/cache (always safe)")


def add_init(add: AddCommand) -> None:
    """The ``init`` parser."""
    i = add("init", cmd_init, "write a new workspace (dodo.py, example contracts, plan) that verifies at once")
    i.add_argument("dir", help="directory to create (must be new or empty)")
    i.add_argument("--nodes", help="comma-separated node names, in chain order (default: Sensor,Controller,Actuator)")
    i.add_argument("--from-ros", metavar="PATH", action="append",
                   help="one contract skeleton per node of the ROS workspace PATH (repeatable; docs/ros.md)")
    i.add_argument("--launch", action="append", default=[], metavar="FILE",
                   help="with --from-ros: entry launch file (repeatable)")
    i.add_argument("--library-endpoints", action="store_true",
                   help="with --from-ros: also make the libraries' endpoints (tf, bond, diagnostics, interactive "
                        "markers) contract inputs and outputs; by default they are listed apart")
    i.add_argument("--strict", action="store_true",
                   help="with --from-ros: exit 1, writing nothing, when a program the packages declare is no node "
                        "of the graph or an interface package is neither scanned nor installed (each listed; "
                        "docs/ros.md, \"Every program accounted for\", \"Absent interface packages\")")


def add_review(add: AddCommand) -> None:
    """The ``review`` parser."""
    rv = add("review", cmd_review, "write a review record to fill in for NODE (checklist from its guarantees)", True)
    rv.add_argument("node")
    rv.add_argument("-o", "--output", help="write the record to this file instead of standard output")
    rv.add_argument("-f", "--files", nargs="*", default=[], help="reviewed files (workspace-relative), listed with their sha256")
