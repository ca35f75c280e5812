"""``rclverify nodl``: NoDL v2 node interface documents (docs/nodl.md).

``rclverify nodl check``          the workspace's documents against its contracts and each other
                                  (``--ros PATH...``: and against the code's endpoints;
                                  ``--ros2``: and against the running ROS 2 graph)
``rclverify nodl check --graph FILE``  (with ``-w``) against a graph recorded by ``--ros2 --record-graph FILE``
``rclverify nodl check DIR|FILE...`` (no ``-w``) a set of documents against each other, no contract
                                  (``--external NAME``, ``--namespace NODE=NS``, ``--sarif FILE``)
``rclverify nodl validate FILE...`` documents against the schema, their includes followed
``rclverify nodl write [-o DIR]`` one document per node from its contract

Exit codes: 0 nothing found (``check``: no error, or under ``--strict`` no
warning either); 1 a finding, a document that cannot be read (located
``file:line:col: error:`` lines, printed by ``rclverify``'s main), or
contracts that do not check; 2 usage errors.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any, cast

from rclverify.cli.common import seconds


def add_parsers(sub: Any) -> None:
    """Add the ``nodl`` command and its ``check``, ``validate`` and ``write`` subcommands."""
    g = sub.add_parser("nodl", help="NoDL node interface documents: check, validate, write (docs/nodl.md)",
                       description="NoDL v2 node interface documents beside the contracts (docs/nodl.md)")
    gs = g.add_subparsers(dest="nodl_command", required=True)

    def common(sp: argparse.ArgumentParser) -> None:
        sp.add_argument("--ament-prefix", action="append", default=[], metavar="DIR",
                        help="an install prefix whose ament index resolves nodl:// includes (repeatable)")

    c = gs.add_parser("check", help="the workspace's NoDL documents against its contracts and each other; "
                                    "without -w, the documents named against each other")
    c.add_argument("paths", nargs="*", metavar="DIR|FILE",
                   help="check these documents (a folder's *.nodl.yaml/.yml/.json) against each other, with no "
                        "workspace (docs/nodl.md, 'Document sets')")
    c.add_argument("-w", "--workspace", help="workspace root (default: .; not with DIR|FILE)")
    c.add_argument("--external", action="append", default=[], metavar="NAME",
                   help="DIR|FILE: a topic, service or action served from outside the set (repeatable)")
    c.add_argument("--namespace", action="append", default=[], metavar="NODE=NS",
                   help="DIR|FILE: the namespace node NODE runs in (repeatable; default /); with --ros/--ros2: "
                        "each namespace one instance of NODE's document is matched in (docs/nodl.md)")
    c.add_argument("--sarif", metavar="FILE", help="also write the findings as SARIF 2.1.0 (rule RCL-NODL)")
    c.add_argument("--plan", default="contracts/plan.yaml", help="plan file, relative to the workspace")
    c.add_argument("--nodl", metavar="DIR", help="folder of the documents (default: nodl/ in the workspace)")
    c.add_argument("--ros", nargs="+", default=[], metavar="PATH",
                   help="also check the documents against the endpoints the code of these ROS workspaces creates "
                        "(the ROS scan, docs/ros.md)")
    c.add_argument("--launch", action="append", default=[], metavar="FILE", help="entry launch file of the scan")
    c.add_argument("--ros2", action="store_true",
                   help="also check the documents against the running ROS 2 graph (DDS discovery: ROS_DOMAIN_ID, "
                        "CYCLONEDDS_URI)")
    c.add_argument("--wait", type=seconds, default=2.0, metavar="S",
                   help="with --ros2: seconds to listen to discovery before the graph settles (default: 2)")
    c.add_argument("--source", choices=("auto", "rclpy", "dds"), default="auto",
                   help="--ros2: read the graph through rclpy's graph API or a DDS participant of rclverify's own; "
                        "auto: rclpy where rclverify's Python imports it (as ros diff)")
    c.add_argument("--ros2-python", metavar="PYTHON",
                   help="--ros2 --source rclpy: the Python with rclpy (default: $RCLVERIFY_ROS2_PYTHON, else this one)")
    c.add_argument("--record-graph", metavar="FILE",
                   help="--ros2: also write the graph read (either source), to check against later with --graph")
    c.add_argument("--graph", metavar="FILE", help="check against a recorded graph (--record-graph) instead of the "
                                                  "running one (docs/nodl.md, 'A recorded graph')")
    c.add_argument("--json", metavar="FILE", help="also write the findings as JSON")
    c.add_argument("--strict", action="store_true", help="exit 1 on a warning too")
    common(c)
    c.set_defaults(fn=cmd_check)
    v = gs.add_parser("validate", help="NoDL documents against the schema, their includes followed")
    v.add_argument("files", nargs="+", metavar="FILE")
    common(v)
    v.set_defaults(fn=cmd_validate)
    w = gs.add_parser("write", help="one NoDL document per node from its contract")
    w.add_argument("-w", "--workspace", default=".", help="workspace root (default: .)")
    w.add_argument("--plan", default="contracts/plan.yaml", help="plan file, relative to the workspace")
    w.add_argument("-o", "--output", metavar="DIR", help="folder written (default: nodl/ in the workspace)")
    w.add_argument("--force", action="store_true", help="overwrite documents that exist (default: refuse)")
    w.add_argument("nodes", nargs="*", metavar="NODE", help="the nodes (default: every node)")
    w.set_defaults(fn=cmd_write)


def cmd_check(args: argparse.Namespace) -> int:
    """Print each finding once per place it involves; see the module docstring for the exit code."""
    from rclverify.model.nodl.check import check  # deferred: start-up (loads jsonschema, yaml and more only when called)
    from rclverify.stages.workspace import Workspace  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    if args.paths:
        return _check_set(args)
    if args.graph and (args.ros2 or args.record_graph) or args.record_graph and not args.ros2:
        print("nodl check: error: --record-graph writes the graph --ros2 reads; --graph FILE reads one instead of "
              "--ros2", file=sys.stderr)
        return 2
    if args.external or (args.namespace and not (args.ros or args.ros2 or args.graph)):
        print("nodl check: error: --external and --namespace apply to a set of documents named without -w "
              "(nodl check DIR|FILE...); --namespace also to a workspace's documents with --ros or --ros2", file=sys.stderr)
        return 2
    ws = Path(args.workspace or ".")
    work = Workspace(ws, args.plan)
    checked = work.checked  # raises RclError, printed located by main
    folder = Path(args.nodl) if args.nodl else None
    res = check(checked, ws, folder, [Path(p) for p in args.ament_prefix])
    from rclverify.model.nodl.match import parse_namespaces  # deferred: start-up (as above)
    try:
        from rclverify.model.instances import namespaces_of  # deferred: start-up (as above)
        args.namespaces = {**namespaces_of(work.plan.node_instances), **parse_namespaces(args.namespace, res.documents)}
    except ValueError as exc:
        print(f"nodl check: error: {exc}", file=sys.stderr)
        return 2
    if args.ros:
        from rclverify.ros.graph.scan import scan  # deferred: start-up (loads the ROS scan only when called)
        from rclverify.ros.ground.nodl_code import check_code  # deferred: start-up (loads the ROS scan only when called)
        graph = scan([Path(p) for p in args.ros], [Path(p) for p in args.launch]).graph
        matched, found = check_code(res.documents, graph.nodes, namespaces=args.namespaces)
        res.findings += found
        print(f"{len(matched)} document(s) matched to a node of the scanned code"
              + "".join(f"; {n} -> {g}" for n, g in sorted(matched.items())))
    if (args.ros2 or args.graph) and not _live(args, res):
        return 1
    for f in res.findings:
        for line in f.lines():
            print(line, file=sys.stderr)
    for side in res.sides:
        if side.status == "proved":
            print(f"node {side.node}: parameter {side.parameter}'s declared constraints ensure the assumption "
                  f"{side.conjunct} (Z3: proved)")
    warnings = len(res.findings) - res.errors
    print(f"{len(res.documents)} node document(s) and {len(res.parts)} part(s) read; "
          f"{res.errors} error(s), {warnings} warning(s)")
    if args.json:
        from rclverify.lang.output import write_atomic  # deferred: start-up (loads rclverify.lang.output only when called)
        data = {"documents": {n: d.files for n, d in sorted(res.documents.items())},
                "parts": [d.file for d in res.parts], "findings": [f.to_json() for f in res.findings],
                "side_conditions": [{"node": s.node, "parameter": s.parameter, "conjunct": s.conjunct,
                                     "status": s.status, "model": dict(s.model)} for s in res.sides]}
        write_atomic(Path(args.json), json.dumps(data, indent=2, sort_keys=True) + "\n")
    if args.sarif:
        _write_sarif(Path(args.sarif), res.findings, "the root of the rclverify workspace")
    return 1 if res.errors or (args.strict and warnings) else 0


def _check_set(args: argparse.Namespace) -> int:
    """``nodl check DIR|FILE...``: the documents named against each other (:mod:`rclverify.model.nodl.sets`),
    findings printed once per place; the exit code as for a workspace's check."""
    from rclverify.model.nodl.check import read_all, shown  # deferred: start-up (loads jsonschema, yaml and more only when called)
    from rclverify.model.nodl.sets import check_set, namespace_of, set_files, set_resolver  # deferred: start-up (as above)
    alone = [o for o, given in (("-w", args.workspace), ("--ros", args.ros), ("--ros2", args.ros2), ("--nodl", args.nodl),
                                ("--launch", args.launch), ("--graph", args.graph),
                                ("--record-graph", args.record_graph)) if given]
    if alone:
        print(f"nodl check: error: {', '.join(alone)} with DIR|FILE: a set of documents is checked against each "
              "other only (a workspace's documents: nodl check -w WS --nodl DIR)", file=sys.stderr)
        return 2
    namespaces: dict[str, list[str]] = {}
    try:
        for item in args.namespace:
            node, eq, ns = item.partition("=")
            if not eq or not node:
                raise ValueError(f"--namespace {item!r}: write NODE=NAMESPACE")
            there = namespaces.setdefault(node, [])
            if namespace_of(ns) not in there:
                there.append(namespace_of(ns))
        paths = [Path(p) for p in args.paths]
        files = set_files(paths)
    except ValueError as exc:
        print(f"nodl check: error: {exc}", file=sys.stderr)
        return 2
    docs = read_all(files, set_resolver(paths, [Path(p) for p in args.ament_prefix], shown(Path("."))))  # raises RclError
    unknown = sorted(set(namespaces) - {d.node for d in docs})
    if unknown:
        print(f"nodl check: error: --namespace {unknown[0]}=...: no document of the set is named after node "
              f"{unknown[0]!r}", file=sys.stderr)
        return 2
    res = check_set(docs, namespaces, args.external)
    for f in res.findings:
        for line in f.lines():
            print(line, file=sys.stderr)
    warnings = len(res.findings) - res.errors
    print(f"{len(res.members)} node document(s) and {len(res.parts)} part(s) checked as a set; "
          f"{res.errors} error(s), {warnings} warning(s)")
    if args.json:
        from rclverify.lang.output import write_atomic  # deferred: start-up (loads rclverify.lang.output only when called)
        data = {"nodes": [{"node": m.node, "namespace": m.namespace, "files": list(m.doc.files)} for m in res.members],
                "parts": [d.file for d in res.parts], "external": sorted(args.external),
                "findings": [f.to_json() for f in res.findings]}
        write_atomic(Path(args.json), json.dumps(data, indent=2, sort_keys=True) + "\n")
    if args.sarif:
        _write_sarif(Path(args.sarif), res.findings, "the directory nodl check ran in")
    return 1 if res.errors or (args.strict and warnings) else 0


def _write_sarif(path: Path, findings: Any, root: str) -> None:
    """Write ``findings`` as a SARIF 2.1.0 log at ``path`` (atomically): one run of tool ``rclverify``,
    rule ``RCL-NODL``, one result per finding laid out by the report's writer
    (:func:`rclverify.report.nodl.sarif_results`: its first place, the others related); file names are
    relative to ``%SRCROOT%``, described as ``root``."""
    from rclverify import __version__  # deferred: start-up (the package is loaded already)
    from rclverify.lang.output import write_atomic  # deferred: start-up (loads rclverify.lang.output only when called)
    import msgspec  # deferred: start-up (loads msgspec only when called)
    from types import SimpleNamespace  # deferred: start-up (as above)
    from rclverify.records.nodl_rows import NodlRow  # deferred: start-up (loads the report's records only when called)
    from rclverify.records.report_record import AssuranceReport  # deferred: start-up (as above)
    from rclverify.records.sarif import SRCROOT, SarifDescriptor, SarifLog, sarif_locations, sarif_result  # deferred: start-up (as above)
    from rclverify.records.store import dumps  # deferred: start-up (as above)
    from rclverify.report import nodl as report_nodl  # deferred: start-up (loads the report layer only when called)
    from rclverify.report.sarif import SARIF_SCHEMA, SARIF_VERSION  # deferred: start-up (as above)
    row = msgspec.convert({"documents": {}, "parts": [], "findings": [f.to_json() for f in findings], "counts": {},
                           "side_conditions": [], "inputs": {}}, NodlRow)
    # the writer reads the report's nodl part only: a report holding that part alone
    results = report_nodl.sarif_results(cast(AssuranceReport, SimpleNamespace(nodl=row)), sarif_result, sarif_locations)
    for res in results:
        res["ruleIndex"] = 0
    rules: list[SarifDescriptor] = [{"id": i, "name": n, "shortDescription": {"text": t}, "defaultConfiguration": {"level": lv}}
             for i, n, lv, t in report_nodl.SARIF_RULES]
    errors = sum(f.severity == "error" for f in findings)
    log: SarifLog = {"$schema": SARIF_SCHEMA, "version": SARIF_VERSION, "runs": [{
        "tool": {"driver": {"name": "rclverify", "version": __version__, "rules": rules}},
        "originalUriBaseIds": {SRCROOT: {"description": {"text": root}}},
        "columnKind": "unicodeCodePoints", "results": results,
        "properties": {"command": "nodl check", "errors": errors, "warnings": len(findings) - errors}}]}
    write_atomic(path, dumps(log))


def _live(args: argparse.Namespace, res: Any) -> bool:
    """Add the findings of ``res.documents`` against the running graph to ``res``, read through the
    source ``--source`` picks (as ``ros diff --ros2`` does), or against the graph recorded in ``--graph``
    (:mod:`rclverify.model.nodl.graph_record`; ``--record-graph`` writes the one read, from either source);
    ``False`` after printing why it cannot be read (a recording that cannot be written raises
    :class:`~rclverify.lang.errors.RclError`, located at its path)."""
    from rclverify.ros.ground.nodl_code import check_code, live_qos_of  # deferred: start-up (loads the ROS layers only when called)
    from rclverify.ros.live.dds import DdsUnavailable  # deferred: optional or conditional (inside a block)
    from rclverify.ros.live.diff_dds import graph_of, read_dds_graph  # deferred: optional or conditional (inside a block)
    from rclverify.runtime.rclpy_source.bus import RclpyUnavailable  # deferred: optional or conditional (inside a block)
    from rclverify.runtime.rclpy_source.graph import RclpyDiscovery, read_rclpy_graph  # deferred: optional or conditional (inside a block)
    from rclverify.runtime.rclpy_source.python import pick_source  # deferred: optional or conditional (inside a block)
    from rclverify.model.nodl.graph_record import source_of  # deferred: start-up (loads the recording's reader only when called)
    from rclverify.ros.graph.graph_bag import read_graph, write_graph  # deferred: start-up (a recording is JSON or a bag)
    try:
        if args.graph:
            kind, py, why = "recorded", None, f"the graph recorded in {args.graph}"
        else:
            kind, py, why = pick_source(args.source, args.ros2_python)
        print(f"source: {kind} ({why})", file=sys.stderr)
        rdisc = RclpyDiscovery(read_graph(Path(args.graph))) if args.graph else \
            read_rclpy_graph(py, args.wait) if kind == "rclpy" and py is not None else None
        if rdisc is not None:
            if args.record_graph:
                write_graph(Path(args.record_graph), rdisc.dump)
            source = source_of(rdisc.dump)
            running = graph_of(rdisc, source)  # type: ignore[arg-type]  # the same shape as Discovery
            matched, found = check_code(res.documents, running.nodes, side="live", qos_of=live_qos_of(rdisc),
                                        namespaces=args.namespaces)
        else:
            from rclverify.ros.live.dds_record import dds_dump  # deferred: start-up (loads the DDS layer only when called)
            running, disc, source, dp = read_dds_graph(args.wait)
            try:
                if args.record_graph:
                    write_graph(Path(args.record_graph), dds_dump(disc, source))
                matched, found = check_code(res.documents, running.nodes, side="live", qos_of=live_qos_of(disc),
                                            namespaces=args.namespaces)
            finally:
                disc.close()
                dp.__del__()
    except (ValueError, DdsUnavailable, RclpyUnavailable) as exc:
        print(f"nodl check --ros2: error: {exc}", file=sys.stderr)
        return False
    for n in running.notes:
        print(f"{source}: {n.severity}: {n.message}", file=sys.stderr)
    res.findings += found
    print(f"{len(matched)} document(s) matched to a running node ({source})"
          + "".join(f"; {n} -> {g}" for n, g in sorted(matched.items())))
    return True


def cmd_validate(args: argparse.Namespace) -> int:
    """Read each file as a NoDL document; prints one line per valid file."""
    from rclverify.model.nodl.check import read_all, shown  # deferred: start-up (loads jsonschema, yaml and more only when called)
    from rclverify.model.nodl.document import Resolver  # deferred: start-up (loads jsonschema, yaml and more only when called)
    resolver = Resolver([Path(p) for p in args.ament_prefix], shown(Path(".")))
    for doc in read_all([Path(f) for f in args.files], resolver):  # raises RclError, printed located by main
        n = len(doc.endpoints)
        print(f"{doc.file}: valid NoDL v2: {n} endpoint(s), {len(doc.parameters)} parameter(s)"
              + (f", {len(doc.files) - 1} included document(s)" if len(doc.files) > 1 else ""))
    return 0


def cmd_write(args: argparse.Namespace) -> int:
    """Write ``<Node>.nodl.yaml`` per node (none when one exists, unless ``--force``); prints each file written."""
    from rclverify.model.nodl.contract import document_text  # deferred: start-up (loads yaml and more only when called)
    from rclverify.records.store import atomic_write_text  # deferred: start-up (loads rclverify.records only when called)
    from rclverify.stages.workspace import Workspace  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    ws = Path(args.workspace)
    checked = Workspace(ws, args.plan).checked  # raises RclError, printed located by main
    unknown = [n for n in args.nodes if n not in checked.nodes]
    if unknown:
        print(f"error: no node {unknown[0]!r} in the contracts (nodes: {', '.join(checked.nodes)})", file=sys.stderr)
        return 2
    out = Path(args.output) if args.output else ws / "nodl"
    texts = {n: document_text(cn, cn.node.loc.file, "written by rclverify nodl write from the RCL contract")
             for n, cn in checked.nodes.items() if not args.nodes or n in args.nodes}  # raises RclError (located)
    paths = {name: out / f"{name}.nodl.yaml" for name in texts}
    there = [p for p in paths.values() if p.exists()]
    if there and not args.force:
        for p in there:
            print(f"{p}: error: exists; nodl write overwrites no document unless --force", file=sys.stderr)
        return 1
    for name, text in texts.items():
        atomic_write_text(paths[name], text, within=None if args.output else ws)  # a special file there refused
        print(paths[name])
    return 0
