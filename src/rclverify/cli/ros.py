"""``rclverify ros scan``, ``rclverify ros diff`` and ``rclverify ros check`` (docs/ros.md).

Exit codes: 0 the graph (or the findings) was written; 1 an input file could
not be read (``ROS-PARSE`` error, the graph is still written from the rest),
or for ``check`` any grounding error, and with ``--strict`` (``check``, ``init
--from-ros``) a declared program that is no node of the graph or an absent
interface package (:func:`strict_failures`); 2 usage errors.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from collections.abc import Mapping, Sequence
from typing import Any

#: Seconds each call to a master may take by default (ros/live/master_rpc.py MASTER_TIMEOUT_S; not imported
#: here, so that building the command line does not load the XML-RPC client)
MASTER_TIMEOUT_S = 10.0
#: the code of the scan's note on an absent interface package (ros/graph/absent.py CODE; not imported here,
#: so that building the command line does not load the scan)
ABSENT = "ROS-INTERFACE-ABSENT"
#: the lines of the scan's first screen (ros/graph/summary.py SCREEN, not imported here for the same reason)
_SCREEN = 20


def add_parsers(sub: Any) -> None:
    """Add the ``ros`` command and its subcommands to ``rclverify``'s parser."""
    r = sub.add_parser("ros", help="read the ROS computation graph from workspaces; check contracts against it",
                       description="read the ROS computation graph from workspaces; check contracts against it")
    rs = r.add_subparsers(dest="ros_command", required=True)
    s = rs.add_parser("scan", help="recover the computation graph from ROS 1/ROS 2 workspaces, launch files, bags, a master")
    _code_args(s)
    s.add_argument("--bag", action="append", default=[], metavar="BAG", help="recorded run: .bag, ROS 2 bag dir, .mcap")
    s.add_argument("--master", metavar="URI", help="also read the running ROS 1 master at URI (http://127.0.0.1:11311)")
    s.add_argument("--timeout", type=_seconds, default=MASTER_TIMEOUT_S, metavar="S",
                   help=f"seconds each call to the master may take (default {MASTER_TIMEOUT_S:g})")
    s.add_argument("--json", metavar="FILE", help="write the graph as JSON (docs/ros-graph.schema.json)")
    s.add_argument("--cache", metavar="DIR", help="per-file parse cache directory (e.g. artifacts/cache)")
    s.add_argument("--verbose", "-v", action="store_true",
                   help=f"list every warning, one a line (default: when there are more than {_SCREEN}, one line per "
                        f"cause with its count, first places and packages; errors always in full)")
    s.set_defaults(fn=cmd_scan)
    d = rs.add_parser("diff", help="the graph the code promises against a running ROS 1 master, a running ROS 2 "
                                   "system or a recorded run",
                      description="compare the static graph (PATH..., --launch, --arg) with a running ROS 1 "
                                  "master (--master), the running ROS 2 system on its DDS domain (--ros2) or a bag "
                                  "(--bag): exit 0 equal, 1 they differ, 2 usage")
    _code_args(d)
    d.add_argument("--master", metavar="URI", help="the running ROS 1 master (http://127.0.0.1:11311)")
    d.add_argument("--timeout", type=_seconds, default=MASTER_TIMEOUT_S, metavar="S",
                   help=f"seconds each call to the master may take (default {MASTER_TIMEOUT_S:g})")
    d.add_argument("--ros2", action="store_true", help="the running ROS 2 system: its DDS domain (ROS_DOMAIN_ID, "
                   "CYCLONEDDS_URI), nodes from ros_discovery_info, endpoints and QoS from DDS discovery")
    d.add_argument("--source", choices=("auto", "rclpy", "dds"), default="auto",
                   help="--ros2: read the graph through rclpy's graph API (any middleware) or a DDS participant of "
                        "rclverify's own; auto: rclpy where rclverify's Python imports it")
    d.add_argument("--ros2-python", metavar="PYTHON",
                   help="--ros2 --source rclpy: the Python with rclpy (default: $RCLVERIFY_ROS2_PYTHON, else this one)")
    d.add_argument("--wait", type=float, default=2.0, metavar="S",
                   help="--ros2: seconds to listen to discovery before comparing (default 2), then up to 6 s "
                        "more while a ROS 2 participant's node list or endpoints are still on their way")
    d.add_argument("--bag", metavar="BAG", help="a recorded run: .bag, ROS 2 bag dir, .mcap (topics and types only)")
    d.add_argument("--graph", metavar="FILE", help="a recorded ROS 2 graph (--ros2 --record-graph, nodl check "
                   "--record-graph; docs/nodl.md, 'A recorded graph'), compared as the live reading it was made from")
    d.add_argument("--record-graph", metavar="FILE",
                   help="--ros2: also write the graph read (either source), to compare against later with --graph")
    d.add_argument("--json", metavar="FILE", help="write both lists as JSON (docs/ros.md)")
    d.add_argument("--nodl", metavar="DIR", help="the expected graph is the one the NoDL documents of DIR declare "
                   "(*.nodl.yaml|yml|json, QoS included; docs/nodl.md) instead of the code's")
    d.add_argument("--ament-prefix", action="append", default=[], metavar="DIR",
                   help="--nodl: an install prefix whose ament index resolves nodl:// includes (repeatable)")
    d.add_argument("--namespace", action="append", default=[], metavar="NODE=NS",
                   help="--nodl: a namespace one instance of node NODE's document runs in (repeatable; docs/nodl.md)")
    d.set_defaults(fn=cmd_diff)
    c = rs.add_parser("check", help="check the plan's contracts against the graph of its ros: section")
    c.add_argument("-w", "--workspace", default=".", help="workspace root (default: .)")
    c.add_argument("--plan", default="contracts/plan.yaml", help="plan file, relative to the workspace")
    c.add_argument("--strict", action="store_true", help="also exit 1 when a program the packages declare is no node "
                   "of the graph or an interface package is neither scanned nor installed (each is listed either "
                   "way); any grounding error always exits 1")
    c.add_argument("--json", metavar="FILE", help="write the findings as JSON")
    c.set_defaults(fn=cmd_check)


def _seconds(text: str) -> float:
    """A time limit in seconds: a finite number > 0 (argparse type; a usage error otherwise)."""
    import math  # deferred: start-up (imported where it is used)
    try:
        x = float(text)
    except ValueError:
        x = math.nan
    if not (math.isfinite(x) and x > 0):
        raise argparse.ArgumentTypeError(f"expected a finite number of seconds > 0, not {text!r}")
    return x


def _launch_args(items: list[str]) -> dict[str, str]:
    out = {}
    for it in items:
        k, sep, v = it.partition(":=")
        if not sep or not k:
            raise SystemExit(f"error: --arg {it!r}: expected NAME:=VALUE")
        out[k] = v
    return out


def _code_args(p: argparse.ArgumentParser) -> None:
    """The code side of ``ros scan`` and ``ros diff``: ``PATH...``, ``--launch``, ``--arg``."""
    p.add_argument("paths", nargs="*", metavar="PATH", help="workspace (or package) directories")
    p.add_argument("--launch", action="append", default=[], metavar="FILE", help="entry launch file (repeatable)")
    p.add_argument("--arg", action="append", default=[], metavar="NAME:=VALUE", help="launch argument (repeatable)")


def _scan_args(args: argparse.Namespace, bags: list[str], cache: Path | None,
               also_exist: list[str] | None = None) -> Any:
    """The scan of ``args.paths``/``args.launch``/``args.arg`` (and ``bags``) shared by
    ``ros scan`` and ``ros diff``: ``graph.scan``'s result, or ``None`` after one
    usage message on standard error (a path that does not exist, a bad ``--arg``)."""
    from rclverify.ros.graph.scan import scan  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    for p in list(args.paths) + list(args.launch) + bags + list(also_exist or ()):
        if not Path(p).exists():
            print(f"{p}: error: no such file or directory", file=sys.stderr)
            return None
    try:
        largs = _launch_args(args.arg)
    except SystemExit as exc:
        print(exc, file=sys.stderr)
        return None
    return scan([Path(p) for p in args.paths], [Path(p) for p in args.launch], largs, [Path(b) for b in bags], cache)


def cmd_scan(args: argparse.Namespace) -> int:
    from rclverify.records.store import atomic_write_text  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    from rclverify.ros.live.master import MasterError, read_master  # deferred: start-up (loads rclverify.ros, rclverify.ros.extract and more only when called)
    res = _scan_args(args, list(args.bag), Path(args.cache) / "ros-scan.pickle" if args.cache else None)
    if res is None:
        return 2
    g = res.graph
    data: dict[str, Any] = g.to_json()
    if args.master:
        try:
            mg = read_master(args.master, timeout=args.timeout)
        except MasterError as exc:
            print(f"{args.master}: error: {exc}", file=sys.stderr)
            return 1
        data["master"] = {"uri": args.master, "nodes": [n.to_json() for _, n in sorted(mg.nodes.items())]}
        for n in mg.notes:  # a service whose type the probe could not read
            print(f"{args.master}: {n.severity}: {n.message}", file=sys.stderr)
    from rclverify.ros.graph.summary import report  # deferred: start-up (the scan's own module, loaded with it)
    packages = {p["manifest"]: p["name"] for p in data.get("packages", []) if p.get("manifest")}
    for text in report(g.notes, packages, bool(getattr(args, "verbose", False))):
        print(text, file=sys.stderr)
    if args.json:
        atomic_write_text(Path(args.json), json.dumps(data, indent=2, sort_keys=False) + "\n", named=True)
    else:
        print(json.dumps(data, indent=2))
    errors = sum(1 for n in g.notes if n.severity == "error")
    print(f"{len(g.packages)} package(s), {len(g.nodes)} node(s), {len(data['topics'])} topic(s), "
          f"{len(g.types)} message type(s); {errors} error(s), {len(g.notes) - errors} warning(s)",
          file=sys.stderr)
    return 1 if errors else 0


def cmd_diff(args: argparse.Namespace) -> int:
    """``rclverify ros diff``: print the missing and extra lists (docs/ros.md,
    "Expected against observed"); exit 0 equal, 1 they differ (or the master or
    the DDS domain cannot be read, or a scanned file cannot be), 2 usage."""
    from rclverify.ros.graph.bag import bag_topics  # deferred: start-up (imported where it is used)
    from rclverify.ros.live.diff import diff_bag, diff_master  # deferred: start-up (loads rclverify.ros, rclverify.ros.extract and more only when called)
    from rclverify.ros.live.master import MasterError, read_master  # deferred: start-up (loads rclverify.ros, rclverify.ros.extract and more only when called)
    graph = getattr(args, "graph", None)
    if sum((args.master is not None, args.bag is not None, bool(getattr(args, "ros2", False)), graph is not None)) != 1:
        print("error: ros diff needs exactly one running side: --master URI, --ros2, --bag BAG or --graph FILE",
              file=sys.stderr)
        return 2
    if getattr(args, "record_graph", None) and not getattr(args, "ros2", False):
        print("error: ros diff --record-graph FILE writes the graph --ros2 reads: give --ros2", file=sys.stderr)
        return 2
    if getattr(args, "namespace", None) and not getattr(args, "nodl", None):
        print("error: ros diff --namespace NODE=NS places a NoDL document's instances: give --nodl DIR", file=sys.stderr)
        return 2
    from rclverify.cli.ros_diff import diff_nodl, diff_ros2, print_diff  # deferred: start-up (the running side's readers, only for ros diff)
    if getattr(args, "nodl", None):
        return diff_nodl(args)
    if not args.paths and not args.launch:
        print("error: ros diff needs the code: PATH... and/or --launch FILE (or the documents: --nodl DIR)",
              file=sys.stderr)
        return 2
    res = _scan_args(args, [], None, [args.bag] if args.bag else [])
    if res is None:
        return 2
    for n in res.graph.notes:
        print(n, file=sys.stderr)
    if args.master:
        try:
            running = read_master(args.master, timeout=args.timeout)
        except MasterError as exc:
            print(f"{args.master}: error: {exc}", file=sys.stderr)
            return 1
        for n in running.notes:
            print(f"{args.master}: {n.severity}: {n.message}", file=sys.stderr)
        result = diff_master(res.graph, running, args.master)
    elif getattr(args, "ros2", False) or graph is not None:
        got = diff_ros2(args, res.graph)
        if got is None:
            return 1
        result = got
    else:
        bag, notes = bag_topics(Path(args.bag), args.bag)
        if bag is None:
            for n in notes:
                print(n, file=sys.stderr)
            return 1
        result = diff_bag(res.graph, bag)
    if not print_diff(result, args.json):
        return 1
    errors = any(n.severity == "error" for n in res.graph.notes)
    return 0 if result.equal and not errors else 1


def init_from_ros(args: argparse.Namespace) -> int:
    """``rclverify init DIR --from-ros PATH [--launch FILE]``."""
    from rclverify.ros.graph.scan import scan  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    from rclverify.tools.scaffold.skeleton import write_from_ros  # deferred: start-up (loads jinja2, rclverify.core and more only when called)
    root = Path(args.dir)
    if root.exists() and (not root.is_dir() or any(root.iterdir())):
        print(f"{args.dir}: error: exists and is not an empty directory; rclverify init writes only into a new "
              f"or empty one", file=sys.stderr)
        return 1
    for p in list(args.from_ros) + list(args.launch):
        if not Path(p).exists():
            print(f"{p}: error: no such file or directory", file=sys.stderr)
            return 2
    res = scan([Path(p) for p in args.from_ros], [Path(p) for p in args.launch], base=_shown_base(
        [Path(p) for p in list(args.from_ros) + [str(Path(lf).parent) for lf in args.launch]]))
    from rclverify.ros.graph.summary import report  # deferred: start-up (the scan's own module, loaded with it)
    packages = {str(p["manifest"]): str(p["name"]) for p in res.graph.to_json().get("packages", [])
                if p.get("manifest")}
    again = " ".join(list(args.from_ros) + [f"--launch {lf}" for lf in args.launch])
    full = (f"`rclverify ros scan {again} --verbose` lists each one; `rclverify ros check` in the new workspace "
            f"writes them, located, to artifacts/ros/graph.json")
    for text in report(res.graph.notes, packages, full=full):
        print(text, file=sys.stderr)
    missing = unaccounted_lines(res.graph.programs)
    for line in missing:
        print(line, file=sys.stderr)
    refused = strict_failures(missing, [n.to_json() for n in res.graph.notes]) if getattr(args, "strict", False) else []
    if refused:
        print(f"{args.from_ros[0]}: error: {' and '.join(refused)} (--strict); nothing written", file=sys.stderr)
        return 1
    if not res.graph.nodes:
        print(f"{args.from_ros[0]}: error: no ROS node found (no launch file node, no source naming its node)",
              file=sys.stderr)
        return 1
    try:
        written = write_from_ros(root, res, [Path(p) for p in args.from_ros], [Path(p) for p in args.launch],
                                 bool(getattr(args, "library_endpoints", False)))
    except OSError as exc:
        print(f"{args.dir}: error: cannot write the workspace: {exc.strerror or exc}", file=sys.stderr)
        return 1
    for p in written:
        print(p)
    print(f"{len(res.graph.nodes)} contract skeleton(s) written; run `doit verify` in {args.dir}")
    return 0


def _shown_base(paths: list[Path]) -> Path | None:
    """Where the scan's locations are shown from: the current directory when it
    holds every path (as ``ros scan`` does), else the directory above the paths'
    common one, so that no absolute path of this machine goes into the skeletons'
    comments (``robot_driver/src/driver.cpp:12``); ``None`` for the current one."""
    import os  # deferred: start-up (imported where it is used)
    real = [os.path.realpath(p) for p in paths]
    here = os.path.realpath(os.getcwd())
    if all(r == here or r.startswith(here.rstrip(os.sep) + os.sep) for r in real):
        return None
    common = os.path.commonpath(real)
    parent = os.path.dirname(common)
    return Path(parent) if parent and parent != os.sep else Path(common)


def unaccounted_lines(programs: Sequence[Mapping[str, object]]) -> list[str]:
    """One ``file:line:col: unaccounted: ...`` line per declared program that is no
    node of the graph (the scan's ``programs``, ros/graph/accounting.py ``Account.to_json``:
    ``package``, ``kind``, ``name``, ``declared`` ``{"file", "line", "col"}``, ``unaccounted``
    why), then a count.  Raises ``TypeError`` for a ``declared`` that is no JSON object."""
    out = []
    for p in programs:
        if p.get("unaccounted"):
            d = p["declared"]
            if not isinstance(d, Mapping):
                raise TypeError(f"a program's declared place is no JSON object: {d!r}")
            out.append(f"{d['file']}:{d['line']}:{d['col']}: unaccounted: {p['kind']} {p['name']} of package "
                       f"{p['package']}: {p['unaccounted']}")
    if out:
        out.append(f"programs: {len(out)} of {len(programs)} declared are no node of the graph")
    return out


def strict_failures(unaccounted: list[str], notes: list[Any]) -> list[str]:
    """What ``--strict`` fails on, one phrase each: declared programs that are no
    node of the graph (``unaccounted``: :func:`unaccounted_lines`, its last line the
    count) and absent interface packages (``notes``: the scan's notes as JSON, each
    a ``ROS-INTERFACE-ABSENT`` one per package); ``[]`` when neither."""
    out = []
    if unaccounted:
        out.append(f"{len(unaccounted) - 1} declared program(s) are no node of the graph")
    absent = sum(1 for n in notes if isinstance(n, dict) and n.get("code") == ABSENT)
    if absent:
        out.append(f"{absent} interface package(s) are in neither the scanned tree nor an installed ROS")
    return out


def cmd_check(args: argparse.Namespace) -> int:
    """``rclverify ros check``: the grounding (exit 1 on any grounding error), then the
    declared programs that are no node of the graph, listed; with ``--strict`` any
    such program, or an absent interface package (a located ``ROS-SCAN`` warning of
    the grounding), is exit 1 too."""
    from rclverify.app.ros_stage import GRAPH, run_check  # deferred: start-up (loads rclverify.app, rclverify.app.ros_stage and more only when called)
    import time  # deferred: start-up (imported where it is used)
    start = time.time()
    rc = run_check(Path(args.workspace), args.plan, args.strict, args.json)
    path = Path(args.workspace) / GRAPH
    try:
        # exit 0 comes only after the grounding ran; a graph the run found unchanged keeps its time
        if rc != 0 and path.stat().st_mtime < start - 1:
            return rc  # no graph written by this run: the plan has no ros: section (already said)
        graph = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return rc
    if not isinstance(graph, dict):
        return rc
    missing = unaccounted_lines(graph.get("programs", []))
    for line in missing:
        print(line)
    refused = strict_failures(missing, graph.get("unresolved", [])) if args.strict else []
    for why in refused:
        print(f"ros check --strict: {why}", file=sys.stderr)
    return 1 if refused else rc
