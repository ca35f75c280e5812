"""The grounding stage over a workspace: scan what the plan's ``ros:``
section names, ground the contracts in it, write
``artifacts/ros/graph.json`` and ``artifacts/ros/grounding.json``
(atomically), and ``rclverify ros check``.

``ros:`` keys (docs/ros.md): ``workspaces`` (directories), ``launch``
(entry launch files), ``args`` (launch arguments), ``bags``, ``mapping``
(field lists; else the plan's one mapping file,
:func:`~rclverify.model.plan.mapping_file.plan_mapping`),
``fields`` (``{topic: [field paths]}``, overrides the mapping), ``nodes``
(``{ContractNode: /graph/node}``), ``ignore`` (graph nodes left out).
Every path is workspace-relative and must stay inside the workspace.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path, PurePosixPath
from typing import Any, Sequence

from rclverify.lang import ast
from rclverify.records.stage_records import GroundedNode, GroundingContext, GroundingRecord
from rclverify.model.plan.errors import plan_error
from rclverify.model.plan.mapping_file import DEFAULT_MAPPING, plan_mapping
from rclverify.model.plan.ros_section import RosSection
from rclverify.ros.extract import names
from rclverify.ros.graph.inputs import input_files

GRAPH = "artifacts/ros/graph.json"
GROUNDING = "artifacts/ros/grounding.json"
DOT = "artifacts/ros/grounding.dot"
SVG = "artifacts/ros/grounding.svg"
CACHE = "artifacts/cache/ros-scan.pickle"


def _paths(ws: Any, key: str, vals: Sequence[str], missing: list[Any] | None = None) -> list[Path]:
    """The existing paths of ``ros.<key>`` (``vals``, as the section gives them).  A path that leaves the
    workspace is a plan error (raised); one that does not exist is appended to ``missing`` as ``(loc,
    message)``: a grounding error, which never stops the pipeline."""
    out = []
    for i, v in enumerate(vals):
        loc = ws.plan.locs.get(("ros", key, i), ast.Loc(ws.plan.file, 1, 1))
        p = PurePosixPath(str(v))
        if p.is_absolute() or ".." in p.parts:
            raise plan_error(ws.plan.file, loc.line, loc.col, f"ros.{key}: {v!r} leaves the workspace; "
                                                              f"give a path inside it", "E-path")
        if not (ws.root / p).exists():
            if missing is None:
                raise plan_error(ws.plan.file, loc.line, loc.col, f"ros.{key}: {v!r} does not exist", "E-io")
            missing.append((loc, f"ros.{key}: {v!r} does not exist; nothing of it was scanned"))
            continue
        out.append(ws.root / p)
    return out


def _fields(ws: Any, ros: RosSection) -> dict[str, list[str]]:
    import yaml  # deferred: start-up (loads yaml only when called)
    out: dict[str, list[str]] = {}
    mapping = plan_mapping(ws.plan) or DEFAULT_MAPPING  # the plan's one mapping file (ros.mapping, else the monitors entries')
    if mapping:
        try:
            data = yaml.safe_load((ws.root / mapping).read_text(encoding="utf-8")) or {}
            for t, spec in (data.get("topics") or {}).items():
                if isinstance(spec, dict) and spec.get("fields"):
                    out[str(t).lstrip("/")] = [str(f) for f in spec["fields"]]
        except (OSError, yaml.YAMLError, AttributeError):
            pass  # the monitors stage reports a bad mapping file, located
    for t, fs in ros.fields.items():
        out[t.lstrip("/")] = list(fs)
    return out


def has_ros(ws: Any) -> bool:
    return bool(ws.plan.ros)


def stage_ground(ws: Any) -> GroundingRecord:
    """Scan, ground, write both artifacts; returns the grounding dict
    (``findings``, ``counts``, ``context`` for the GSN argument)."""
    from rclverify.records.store import atomic_write_text  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    from rclverify.ros.graph.scan import scan  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    from rclverify.ros.ground.ground import ground  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    ros = RosSection.of(ws.plan.ros)
    missing: list[Any] = []
    wss = _paths(ws, "workspaces", ros.workspaces, missing)
    launch = _paths(ws, "launch", ros.launch, missing)
    bags = _paths(ws, "bags", ros.bags, missing)
    args = {k: (str(v).lower() if isinstance(v, bool) else str(v)) for k, v in ros.args.items()}
    res = scan(wss, launch, args, bags, ws.root / CACHE, base=ws.root)
    plan_loc = ws.plan.locs.get(("ros",), ast.Loc(ws.plan.file, 1, 1))
    from rclverify.ros.ground.ground import Finding  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    findings = [Finding("ROS-SCAN", "error", msg, loc, None) for loc, msg in missing]
    findings += ground(res, ws.checked, ws.plan.file, ros, _fields(ws, ros), plan_loc)
    g = res.graph
    graph_json = g.to_json()
    counts = {"error": sum(f.severity == "error" for f in findings),
              "warning": sum(f.severity == "warning" for f in findings)}
    found = [f.to_json() for f in findings]
    graph: dict[str, list[GroundedNode]] = {
        "nodes": [{"name": n["name"], "publishes": [e["topic"] for e in n["publishes"]],
                   "subscribes": [e["topic"] for e in n["subscribes"]]} for n in graph_json["nodes"]]}
    context: GroundingContext = {
        "packages": [{"name": p["name"], "version": p["version"]} for p in graph_json["packages"]],
        "files": graph_json["files"],
        "launch": [str(p.relative_to(ws.root)) for p in launch],
    }
    from rclverify.report.diagram import dot_to_svg  # deferred: start-up (loads jinja2, rclverify.core and more only when called)
    from rclverify.ros.graph.draw import grounding_dot  # deferred: start-up (loads jinja2, rclverify.ros and more only when called)
    from rclverify.ros.ground.ground import match_nodes  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    ignore = {names.normalise(n) for n in ros.ignore}
    pairs = match_nodes(ws.checked.nodes, {k: v for k, v in g.nodes.items() if k not in ignore}, dict(ros.nodes))
    dot = grounding_dot(ws.checked, graph_json, found, pairs)
    svg = dot_to_svg(dot)
    atomic_write_text(ws.path(DOT), dot)
    if svg is not None:
        atomic_write_text(ws.path(SVG), svg)
    atomic_write_text(ws.path(GRAPH), json.dumps(graph_json, indent=2) + "\n")
    from rclverify.records.records import hash_inputs  # deferred: start-up (loads rclverify.records, rclverify.records.records and more only when called)
    from rclverify.records.sealed import write_sealed  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    data: GroundingRecord = {"findings": found, "counts": counts, "graph": graph, "context": context,
                             "drawing": {"dot": DOT, "svg": SVG if svg is not None else None}, "matched": dict(pairs),
                             "inputs": hash_inputs(ws.root, input_files(ws))}
    write_sealed(ws.path(GROUNDING), data)  # sealed: the report reads it (records/sealed.py)
    return data


def run_check(root: Path, plan: str, strict: bool, json_out: str | None) -> int:
    """``rclverify ros check``: print each finding, a count line; exit 1 when
    any grounding error is found (or the plan/contract cannot be read), else 0.
    ``strict`` is kept for older command lines and changes nothing: an error is
    never a pass (26 errors with exit 0 was a wrong green)."""
    from rclverify.records.store import atomic_write_text  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    from rclverify.stages.workspace import Workspace  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    ws = Workspace(root, plan)
    if not has_ros(ws):
        print(f"{ws.plan.file}:1:1: error: the plan has no ros: section (docs/ros.md)", file=sys.stderr)
        return 1
    data = stage_ground(ws)
    for f in data["findings"]:
        r, s = f["rcl"], f["ros"]
        where = f"{r['file']}:{r['line']}:{r['col']}" if r else (f"{s['file']}:{s['line']}:{s['col']}" if s else "")
        also = f" [{s['file']}:{s['line']}:{s['col']}]" if r and s else ""
        print(f"{where}: {f['severity']}: {f['message']}{also} ({f['code']})")
    if json_out:
        atomic_write_text(Path(json_out), json.dumps(data, indent=2) + "\n")
    c = data["counts"]
    print(f"grounding: {c['error']} error(s), {c['warning']} warning(s); graph in {GRAPH}")
    return 1 if c["error"] else 0
