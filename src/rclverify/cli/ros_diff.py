"""``rclverify ros diff``'s running side and its printing (docs/ros.md, "Expected against observed";
docs/nodl.md, "A recorded graph"): the running ROS 2 graph through either source (``--ros2``), or a recording
of one (``--graph FILE``), compared with the code's graph or, with ``--nodl DIR``, the documents'
(:func:`diff_ros2`, :func:`diff_nodl`); the result printed and written as JSON (:func:`print_diff`).
``cli/ros.py``'s :func:`~rclverify.cli.ros.cmd_diff` calls them.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any


def diff_nodl(args: argparse.Namespace) -> int:
    """``ros diff --nodl DIR``: the graph the documents declare against the running side
    (:mod:`rclverify.ros.ground.diff_nodl`); exit 0 equal, 1 they differ or a side cannot be read, 2 usage."""
    from rclverify.model.nodl.check import document_files, read_all, shown  # deferred: start-up (loads jsonschema and yaml only when called)
    from rclverify.model.nodl.document import Resolver  # deferred: start-up (loads jsonschema and yaml only when called)
    from rclverify.ros.ground.diff_nodl import nodes_of  # deferred: start-up (loads the ROS layers only when called)
    if args.paths or args.launch:
        print("error: ros diff --nodl compares the documents, not the code: give no PATH or --launch", file=sys.stderr)
        return 2
    folder = Path(args.nodl)
    files = document_files(folder)
    if not files:
        print(f"{args.nodl}: error: no NoDL document (*.nodl.yaml, *.nodl.yml, *.nodl.json) in this folder",
              file=sys.stderr)
        return 2
    docs = nodes_of(read_all(files, Resolver([Path(p) for p in args.ament_prefix], shown(Path(".")))))  # raises RclError, printed located by main
    from rclverify.model.nodl.match import parse_namespaces  # deferred: start-up (as above)
    try:
        args.namespaces = parse_namespaces(args.namespace, docs)
    except ValueError as exc:
        print(f"ros diff: error: {exc}", file=sys.stderr)
        return 2
    if not args.ros2 and getattr(args, "graph", None) is None:
        print("error: ros diff --nodl compares with the running ROS 2 system: give --ros2 (or a recording of it: "
              "--graph FILE)", file=sys.stderr)
        return 2
    result = diff_ros2(args, None, docs)
    if result is None:
        return 1
    if not print_diff(result, args.json):
        return 1
    return 0 if result.equal else 1


def print_diff(result: Any, json_path: str | None) -> bool:
    """Print the diff ``result`` and write its JSON to ``json_path`` (``--json``) when given; ``False``
    after saying on stderr why the JSON could not be written."""
    from rclverify.ros.live.diff import render_text  # deferred: start-up (loads the ROS layers only when called)
    from rclverify.records.store import atomic_write_text  # deferred: start-up (loads rclverify.records only when called)
    for line in render_text(result):
        print(line)
    if json_path:
        try:
            atomic_write_text(Path(json_path), json.dumps(result.to_json(), indent=2) + "\n", named=True)
        except OSError as exc:
            print(f"{json_path}: error: cannot write: {exc.strerror or exc}", file=sys.stderr)
            return False
    return True


def diff_ros2(args: argparse.Namespace, static: Any, documents: Any = None) -> Any:
    """``ros diff --ros2``: the running graph through the source ``--source`` picks (docs/ros2.md, "Two
    sources": rclpy's graph API in the ROS 2 Python, or a DDS participant of rclverify's own), or ``--graph``'s
    recording of one (:mod:`rclverify.model.nodl.graph_record`, named as the reading it was made from),
    compared with ``static`` (the code's graph) or, given ``documents`` (NoDL documents by node), with the
    graph they declare; ``--record-graph`` writes the graph read.  ``None`` after printing why it cannot be
    read; a recording that is not one, or cannot be written, raises :class:`~rclverify.lang.errors.RclError`
    (located, printed by main)."""
    from rclverify.model.nodl.graph_record import source_of  # deferred: start-up (loads the recording's reader only when called)
    from rclverify.ros.graph.graph_bag import read_graph, write_graph  # deferred: start-up (a recording is JSON or a bag)
    from rclverify.ros.live.dds import DdsUnavailable  # deferred: optional or conditional (inside a block)
    from rclverify.ros.live.diff_dds import diff_dds, graph_of, qos_conflicts, read_dds_graph  # deferred: optional or conditional (inside a block)
    from rclverify.runtime.rclpy_source.bus import RclpyUnavailable  # deferred: optional or conditional (inside a block)
    from rclverify.runtime.rclpy_source.graph import RclpyDiscovery, read_rclpy_graph  # deferred: optional or conditional (inside a block)
    from rclverify.runtime.rclpy_source.python import pick_source  # deferred: optional or conditional (inside a block)
    from rclverify.ros.ground.diff_nodl import diff_nodl  # deferred: optional or conditional (inside a block)
    recorded = getattr(args, "graph", None)
    record = getattr(args, "record_graph", None)
    if recorded is not None:
        source_kind, py, why = "recorded", None, f"the graph recorded in {recorded}"
    else:
        try:
            source_kind, py, why = pick_source(getattr(args, "source", "auto"), getattr(args, "ros2_python", None))
        except ValueError as exc:
            print(f"ros diff --ros2: error: {exc}", file=sys.stderr)
            return None
    print(f"source: {source_kind} ({why})", file=sys.stderr)
    if recorded is not None or source_kind == "rclpy" and py is not None:
        try:
            rdisc = RclpyDiscovery(read_graph(Path(recorded))) if recorded is not None else \
                read_rclpy_graph(py, max(0.0, args.wait))  # type: ignore[arg-type]  # py is not None here
        except RclpyUnavailable as exc:
            print(f"ros diff --ros2: error: {exc}", file=sys.stderr)
            return None
        if record:
            write_graph(Path(record), rdisc.dump)
        source = source_of(rdisc.dump)
        if documents is not None:
            return diff_nodl(documents, graph_of(rdisc, source), source, qos_conflicts(rdisc), rdisc,  # type: ignore[arg-type]
                             args.namespaces)
        return diff_dds(static, graph_of(rdisc, source), source, qos_conflicts(rdisc), rdisc)  # type: ignore[arg-type]
    try:
        running, disc, source, dp = read_dds_graph(max(0.0, args.wait))
    except DdsUnavailable as exc:
        print(f"ros diff --ros2: error: {exc}", file=sys.stderr)
        return None
    try:
        for n in running.notes:
            print(f"{source}: {n.severity}: {n.message}", file=sys.stderr)
        if record:
            from rclverify.ros.live.dds_record import dds_dump  # deferred: optional or conditional (inside a block)
            write_graph(Path(record), dds_dump(disc, source))
        if documents is not None:
            return diff_nodl(documents, running, source, qos_conflicts(disc), disc, args.namespaces)
        return diff_dds(static, running, source, qos_conflicts(disc), disc)
    finally:
        disc.close()
        dp.__del__()


__all__ = ["diff_nodl", "diff_ros2", "print_diff"]
