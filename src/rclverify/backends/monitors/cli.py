"""``rclverify monitor [-w WS] TRACE...``: check recorded runs against every node's contract.

Exit status: 0 when no contract is violated, 1 when one is, 2 for a trace
or configuration that cannot be read (a located message on stderr; the
verdicts of the traces already checked are printed first).
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from ...rcl.errors import RclError
from ...traces import TraceError, read_trace
from .backend import monitoring_details, summary_line, tool_versions, verdict_status
from .check import check_trace
from .config import ConfigError, load_mapping


def monitor_command(args: argparse.Namespace) -> int:
    """Run the command; returns the exit code (never raises for user input)."""
    from ...pipeline import Workspace
    root = Path(args.workspace)
    ws = Workspace(root, args.plan)
    checked = ws.checked  # raises RclError, printed located by the caller
    try:
        cfg = load_mapping(root, args.mapping, args.horizon)
    except ConfigError as exc:
        print(f"{exc}" if ":" in str(exc).split(" ")[0] else f"{args.mapping}: error: {exc}", file=sys.stderr)
        return 2
    violated = False
    report: list[dict[str, Any]] = []
    for trace in args.traces:
        path = Path(trace)
        try:
            events, results = check_trace(checked, list(checked.nodes.values()),
                                          read_trace(path, [root / d for d in cfg.msg_dirs]), cfg.rules, cfg.horizon)
        except TraceError as exc:
            _emit(report, args.json)
            print(str(exc), file=sys.stderr)
            return 2
        except Exception as exc:  # a recorded run is user input: a located message, never a traceback
            _emit(report, args.json)
            print(f"{trace}: error: the trace could not be checked: {type(exc).__name__}: {exc}", file=sys.stderr)
            return 2
        for res in results:
            status, explanation = verdict_status(res, trace)
            violated = violated or status == "failed"
            entry = {"node": res.node, "status": status, "explanation": explanation,
                     **monitoring_details(res, trace, events, "", tool_versions(), cfg.horizon)}
            entry.pop("sha256")
            report.append(entry)
            if not args.json:
                print(f"{trace}: {summary_line(res)}")
                print(f"  {status}: {explanation}")
    _emit(report, args.json)
    return 1 if violated else 0


def _emit(report: list[dict[str, Any]], as_json: bool) -> None:
    if as_json:
        print(json.dumps(report, indent=2, sort_keys=True))


__all__ = ["monitor_command", "RclError"]
