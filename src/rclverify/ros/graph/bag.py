"""The topics and message types present in a recorded run: a ROS 1 ``.bag``
or a ROS 2 bag (directory or ``.mcap``), through ``rosbags``' AnyReader.

A ROS 2 bag holding ``rosgraph_msgs/msg/Graph`` messages (a recorded graph:
:mod:`rclverify.ros.graph.graph_bag`) gives, besides its own topics, each topic
the recorded graph's nodes publish, with its type, ``count`` 0 (no message of
it is in the bag) and ``graph``: the publishing nodes (docs/nodl.md, "The graph
message in a bag")."""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from rclverify.ros.extract.model import Note, Src, canon_type
from rclverify.traces.events import TraceError
from rclverify.traces.guard import check_trace_path

if TYPE_CHECKING:
    from rclverify.ros.extract.shapes import BagJson, BagTopic

GRAPH = "rosgraph_msgs/msg/Graph"


def bag_topics(path: Path, shown: str) -> tuple[BagJson | None, list[Note]]:
    """``{"path", "topics": [{"name", "type", "count"}]}`` or a located error note.
    Only regular files are opened (:func:`rclverify.traces.guard.check_trace_path`):
    a bag that is, or whose reader would open, a FIFO, device or socket is an
    error note; another such entry of a bag directory is skipped with a
    warning note."""
    from rosbags.highlevel import AnyReader  # deferred: start-up (loads rosbags and more only when called)

    try:
        skipped = check_trace_path(path)
    except TraceError as exc:
        return None, [Note(Src(shown), _entry_message(str(exc), path, "error"), "ROS-PARSE", "error")]
    warnings = [Note(Src(shown), _entry_message(w, path, "warning"), "ROS-PARSE", "warning") for w in skipped]
    try:
        with AnyReader([path]) as reader:
            topics = [(c.topic if c.topic.startswith("/") else "/" + c.topic, canon_type(c.msgtype) or c.msgtype, int(c.msgcount))
                      for c in reader.connections]
    except Exception as exc:  # rosbags raises its own reader errors on bad files
        return None, [Note(Src(shown), f"cannot read bag: {' '.join(str(exc).split())[:300]}", "ROS-PARSE", "error")]
    merged: dict[tuple[str, str], int] = {}
    for name, ty, count in topics:
        merged[(name, ty)] = merged.get((name, ty), 0) + count
    out: list[BagTopic] = [{"name": n, "type": ty, "count": c} for (n, ty), c in sorted(merged.items())]
    if any(ty == GRAPH for _n, ty, _c in topics):
        graph, note = _graph_topics(path, shown)
        out = sorted(out + graph, key=lambda t: (t["name"], t["type"], t["count"]))
        warnings += note
    return {"path": shown, "topics": out}, warnings


def _graph_topics(path: Path, shown: str) -> tuple[list[BagTopic], list[Note]]:
    """The topics the recorded graph in the bag at ``path`` has publishers on (module docstring), or an
    error note when its graph cannot be read."""
    from rclverify.lang.errors import RclError  # deferred: start-up
    from rclverify.ros.graph.graph_bag import read_bag  # deferred: start-up (loads the graph message only when called)
    from rclverify.ros.graph.graph_msg import fqn  # deferred: start-up
    try:
        dump = read_bag(path, shown)
    except RclError as exc:
        return [], [Note(Src(shown), d.message, "ROS-PARSE", "error") for d in exc.diagnostics]
    found: dict[tuple[str, str], set[str]] = {}
    for topic, roles in dump["endpoints"].items():
        for e in roles.get("pubs", []):
            ty = canon_type(e["type"]) or e["type"]
            found.setdefault((topic, ty), set()).add(fqn(e["node"], e["ns"]))
    return [{"name": t, "type": ty, "count": 0, "graph": sorted(nodes)} for (t, ty), nodes in sorted(found.items())], []


def _entry_message(text: str, path: Path, severity: str) -> str:
    """``"<entry>: <reason>"`` from the guard's ``<path>/<entry>: <severity>: <reason>``
    (the note is located at the bag; the entry is named inside it)."""
    where, _, reason = text.partition(f": {severity}: ")
    entry = where[len(str(path)):].lstrip("/")
    return f"{entry}: {reason}" if entry else reason
