"""A recording of the running ROS 2 graph, to check NoDL documents against after the fact (docs/nodl.md,
"A recorded graph").

ROS 2 Kilted's ``rosgraph_msgs`` (2.3.0, the PyPI wheels rclverify's ROS 2 Python carries) holds
``Clock`` only: no graph message is published or recorded there.  So the graph is read as rclpy's
graph API gives it, through the rclpy agent ``ros diff --ros2`` uses
(``get_node_names_and_namespaces``, ``get_publishers_info_by_topic`` and the rest:
:func:`rclverify.runtime.rclpy_source.agent.graph_dump`), and a recording is that dump in a JSON
file of its own (``nodl check --ros2 --source rclpy --record-graph FILE`` writes one,
``nodl check --graph FILE`` reads it back):

``{"kind": "rclverify-ros2-graph", "version": 1, "rmw": ..., "source": ..., "nodes": [...], "endpoints": {...}}``

with ``nodes`` each ``{"name", "ns", "pubs", "subs", "servers", "clients"}`` (the by-node lists, each a
list of ``[name, [types]]``) and ``endpoints`` each topic's ``{"pubs": [...], "subs": [...]}``, an
endpoint ``{"gid" (hex), "node", "ns", "type", "hash", "reliable", "durability" (volatile or
transient_local), "deadline_ns", "liveliness", "lease_ns"}`` (and ``"hash"``, the type hash, where the
source gave one).  ``source`` (optional) is the label of the live reading the recording was made from: the
DDS source's ``DDS domain N`` (``--source dds --record-graph``: the domain's graph in the same form,
:func:`rclverify.ros.live.dds_record.dds_dump`); without it the label is ``rclpy on <rmw>``
(:func:`source_of`).  Both ``nodl check --graph`` and ``ros diff --graph`` read a recording and name its
source so, so their findings and items from a recording are those of the live reading.
:func:`read_record` checks that shape and refuses anything else with one located error
(``E-graph-record``) at the offending value.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from rclverify.core.within import read_regular
from rclverify.lang import ast
from rclverify.lang.errors import RclError, error
from rclverify.model.nodl.jsonpos import load_json_located

#: The recording's kind and version.
KIND, VERSION = "rclverify-ros2-graph", 1
#: The largest recording read (bytes).
MAX_BYTES = 64 * 1024 * 1024
#: An endpoint's fields and their JSON types.
_ENDPOINT = {"gid": str, "node": str, "ns": str, "type": str, "reliable": bool, "durability": str,
             "deadline_ns": int, "liveliness": str, "lease_ns": int}

Path_ = tuple[Any, ...]


def record_text(dump: dict[str, Any]) -> str:
    """The recording of ``dump`` (the agent's graph: ``rmw``, ``nodes``, ``endpoints``) as JSON text, keys sorted."""
    data = {"kind": KIND, "version": VERSION, "rmw": dump.get("rmw", ""), "nodes": dump.get("nodes", []),
            "endpoints": dump.get("endpoints", {})}
    if dump.get("source"):
        data["source"] = dump["source"]
    return json.dumps(data, indent=1, sort_keys=True) + "\n"


class _Check:
    def __init__(self, locs: dict[Path_, ast.Loc], file: str) -> None:
        self.locs, self.file = locs, file

    def fail(self, path: Path_, message: str) -> RclError:
        p = path
        while p and p not in self.locs:
            p = p[:-1]
        where = ".".join(repr(x) if isinstance(x, str) and "/" in x else str(x) for x in path) or "the recording"
        return RclError([error(self.locs.get(p, ast.Loc(self.file, 1, 1)), f"{where}: {message}", "E-graph-record")])

    def typed(self, value: Any, path: Path_, kind: type, what: str) -> Any:
        if not isinstance(value, kind) or (kind is int and isinstance(value, bool)):
            raise self.fail(path, f"is {what}")
        return value

    def names_types(self, value: Any, path: Path_) -> None:
        for i, pair in enumerate(self.typed(value, path, list, "a list of [name, [types]]")):
            ok = isinstance(pair, list) and len(pair) == 2 and isinstance(pair[0], str) and \
                isinstance(pair[1], list) and all(isinstance(t, str) for t in pair[1])
            if not ok:
                raise self.fail(path + (i,), "is [name, [types]]")

    def endpoint(self, e: Any, path: Path_) -> None:
        self.typed(e, path, dict, "an endpoint (gid, node, ns, type, reliable, durability, ...)")
        for key, kind in _ENDPOINT.items():
            if key not in e:
                raise self.fail(path, f"an endpoint has {key!r}")
            self.typed(e[key], path + (key,), kind, f"a {kind.__name__}")
        if e["durability"] not in ("volatile", "transient_local"):
            raise self.fail(path + ("durability",), "is volatile or transient_local")
        try:
            bytes.fromhex(e["gid"])
        except ValueError:
            raise self.fail(path + ("gid",), "is hexadecimal") from None


def read_record(path: Path, shown: str | None = None) -> dict[str, Any]:
    """The graph dump a recording at ``path`` holds (module docstring), in the agent's form.

    Raises :class:`RclError` (``E-graph-record``, ``E-nodl-json``) located at a value that is not the
    recording's, or at line 1 when the file cannot be read."""
    file = shown or str(path)
    try:
        text = read_regular(path, MAX_BYTES).decode("utf-8")
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise RclError([error(ast.Loc(file, 1, 1), f"cannot read the recorded graph: {exc}", "E-graph-record")]) from None
    data, locs = load_json_located(text, file)
    c = _Check(locs, file)
    c.typed(data, (), dict, "a JSON object")
    if data.get("kind") != KIND or data.get("version") != VERSION:
        raise c.fail(("kind",), f"a recorded graph has kind {KIND!r} and version {VERSION}")
    c.typed(data.get("rmw", ""), ("rmw",), str, "a text")
    c.typed(data.get("source", ""), ("source",), str, "a text")
    for i, n in enumerate(c.typed(data.get("nodes"), ("nodes",), list, "a list of nodes")):
        c.typed(n, ("nodes", i), dict, "a node (name, ns, pubs, subs, servers, clients)")
        for key in ("name", "ns"):
            c.typed(n.get(key), ("nodes", i, key), str, "a text")
        for key in ("pubs", "subs", "servers", "clients"):
            c.names_types(n.get(key, []), ("nodes", i, key))
    for topic, roles in c.typed(data.get("endpoints"), ("endpoints",), dict, "a map of topics").items():
        c.typed(roles, ("endpoints", topic), dict, "{pubs: [...], subs: [...]}")
        for role in ("pubs", "subs"):
            for j, e in enumerate(c.typed(roles.get(role, []), ("endpoints", topic, role), list, "a list")):
                c.endpoint(e, ("endpoints", topic, role, j))
    out = {"what": "graph_all", "rmw": data.get("rmw", ""), "nodes": data["nodes"], "endpoints": data["endpoints"]}
    if data.get("source"):
        out["source"] = data["source"]
    return out


def source_of(dump: dict[str, Any]) -> str:
    """The label of the reading ``dump`` came from: its ``source`` (the DDS source's ``DDS domain N``),
    else ``rclpy on <rmw>`` (module docstring)."""
    return str(dump.get("source") or f"rclpy on {dump.get('rmw', '')}")


__all__ = ["KIND", "VERSION", "read_record", "record_text", "source_of"]
