"""``rclverify generate ros2 -w WS -o DIR`` (docs/generate.md).

Exit codes: 0 the tree was written; 1 the contracts do not check, or a name
the tree would carry breaks ROS 2's or the file system's rules (located
``file:line:col: error:`` diagnostics, printed by ``rclverify``'s main;
tools/generate/rosnames.py), or the mapping or a write failed (``DIR:
error: ...``; a new ``DIR`` is then not left behind); 2 usage errors.
"""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path
from typing import Any


def add_parsers(sub: Any) -> None:
    """Add the ``generate`` command and its ``ros2`` subcommand to ``rclverify``'s parser."""
    g = sub.add_parser("generate", help="generate ROS 2 packages from the checked contracts",
                       description="generate ROS 2 packages from the checked contracts (docs/generate.md)")
    gs = g.add_subparsers(dest="generate_command", required=True)
    r = gs.add_parser("ros2", help="interface packages, one ament_python package per node, launch files")
    r.add_argument("-w", "--workspace", default=".", help="workspace root (default: .)")
    r.add_argument("--plan", default="contracts/plan.yaml", help="plan file, relative to the workspace")
    r.add_argument("-o", "--output", required=True, metavar="DIR", help="directory of the generated packages")
    r.add_argument("--system", metavar="NAME",
                   help="system name, prefix of the bringup package (default: the workspace directory's name)")
    r.add_argument("--lang", choices=("python", "cpp"), default="python",
                   help="node packages: ament_python (default) or rclcpp with a ROS-free check header")
    r.set_defaults(fn=cmd_ros2)


def cmd_ros2(args: argparse.Namespace) -> int:
    """Check the workspace's contracts and write the tree; prints what changed and the logic files to read."""
    from rclverify.stages.workspace import Workspace  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    from rclverify.backends.monitors.config import ConfigError  # deferred: start-up (loads lark, yaml and more only when called)
    from rclverify.tools.generate.writer import GenerateError, write_tree  # deferred: start-up (loads jinja2, lark and more only when called)
    ws = Path(args.workspace)
    checked = Workspace(ws, args.plan).checked  # raises RclError, printed located by main
    system = args.system or ws.resolve().name
    out = Path(args.output)
    try:
        sources = {sp.file: (ws / sp.file).read_text(encoding="utf-8") for sp in checked.specs}
        rules, tolerance = monitor_rules(ws, args.plan)
        prefix = Path(os.path.relpath(out.resolve(), ws.resolve())).as_posix()
        res = write_tree(out, checked, system, sources, args.lang, rules, tolerance, prefix)
    except (GenerateError, ConfigError) as exc:
        print(exc, file=sys.stderr)
        return 1
    except (OSError, ValueError) as exc:
        print(f"{out}: error: {exc}", file=sys.stderr)
        return 1
    print(f"{out}: {len(res.written)} generated file(s) written, {len(res.unchanged)} unchanged, "
          f"{len(res.created_once)} logic file(s) created, {len(res.kept)} kept")
    for rel in res.stale_logic:
        print(f"{out / rel}: warning: this hand-written logic file's node interface changed; read it again")
    return 0


def monitor_rules(ws: Path, plan: str) -> tuple[Any, Any]:
    """The monitors' mapping rules by topic and declared tolerance of workspace ``ws``: the plan's one
    mapping file (:func:`~rclverify.model.plan.mapping_file.plan_mapping`; not the
    ``rclverify_mapping.yaml`` this command writes, whose rules are read from the one before it), else
    the default mapping file (``backends/monitors/mapping.yaml``, absent: no rules); the tolerance of
    the first ``monitors`` entry stating one overrides the file's.  Raises ``ConfigError`` (located)
    for a malformed mapping file."""
    from rclverify.backends.monitors.config import load_mapping  # deferred: start-up (loads lark, yaml and more only when called)
    from rclverify.model.plan.load import load_plan  # deferred: start-up (loads yaml, rclverify.lang and more only when called)
    from rclverify.model.plan.mapping_file import plan_mapping  # deferred: start-up (only when called)
    p = load_plan(ws, plan)
    entries = [e for es in p.evidence.values() for e in es if e.backend == "monitors"]
    rel = plan_mapping(p)
    if rel is not None and Path(rel).name == "rclverify_mapping.yaml":  # the one this command writes
        rel = next((str(m) for e in entries if (m := e.config.get("mapping"))
                    and Path(str(m)).name != "rclverify_mapping.yaml"), None)
    tol = next((e.config.get("tolerance") for e in entries if e.config.get("tolerance") is not None), None)
    cfg = load_mapping(ws, rel, tolerance=tol)
    return cfg.rules, cfg.tolerance
