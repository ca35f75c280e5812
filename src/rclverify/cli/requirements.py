"""``rclverify requirements`` and ``deadlines``: each requirement with its status, each end-to-end
deadline with its verdict, on the terminal (docs/requirements.md)."""
from __future__ import annotations

import argparse
import json
import sys
from typing import TYPE_CHECKING, TextIO

from rclverify.cli.common import AddCommand, workspace_of

if TYPE_CHECKING:
    from rclverify.stages.workspace import Workspace

#: Verdicts that make ``rclverify requirements`` exit 1.
BAD = ("refuted", "proved from an inconsistency", "proved vacuously", "inconclusive", "stale", "error")


def show_requirements(ws: "Workspace", out: TextIO) -> int:
    """Print every requirement of ``ws`` with its verdict and status (the
    evidence roll-up of :func:`rclverify.report.build.build_report`, from
    the artifacts recorded so far), the premises a proof used and, for a
    refuted one, the counterexample node by node.  Returns the exit code:
    1 when one is refuted, proved from an inconsistency or inconclusive."""
    from rclverify.report.build import build_report  # deferred: start-up (loads jinja2, lark and more only when called)
    from rclverify.report.explain import requirement_lines  # deferred: start-up (loads rclverify.diagnosis, rclverify.diagnosis.table and more only when called)
    report = build_report(ws)
    bad = 0
    for r in report.requirements:
        out.write("".join(line + "\n" for line in requirement_lines(r)))
        bad += r.verdict in BAD
    return 1 if bad else 0


def cmd_requirements(args: argparse.Namespace) -> int:
    """Check the requirements (only those whose inputs changed, unless
    ``--force``) and print each with its status; exit 1 when one is refuted,
    proved from an inconsistency or inconclusive."""
    from rclverify.app.pipeline import stage_check, stage_requirements  # deferred: start-up (loads rclverify.app, rclverify.app.pipeline and more only when called)
    ws = workspace_of(args)
    stage_check(ws)
    stage_requirements(ws, force=args.force)
    return show_requirements(ws, sys.stdout)


def cmd_deadlines(args: argparse.Namespace) -> int:
    """Decide every requirement's end-to-end deadline (rule D3,
    calculus/deadlines.py), write ``artifacts/deadlines/index.json`` (the
    stage's sealed record, stages/deadlines.py) and print
    each result; exit 1 when one is refuted or inconclusive."""
    from rclverify.stages.deadlines import stage_deadlines  # deferred: start-up (loads yaml, z3 and more only when called)
    from rclverify.calculus.deadlines import PROVED, show  # deferred: start-up (loads yaml, z3 and more only when called)
    from rclverify.app.pipeline import stage_check  # deferred: start-up (loads rclverify.app, rclverify.app.pipeline and more only when called)
    ws = workspace_of(args)
    stage_check(ws)  # the snapshots the record's inputs name
    results, records = stage_deadlines(ws)
    sys.stdout.write(json.dumps(records, indent=2) + "\n" if args.json else show(results))
    return 0 if all(r.status == PROVED for r in results) else 1


def add_requirements_deadlines(add: AddCommand) -> None:
    """The ``requirements`` and ``deadlines`` parsers."""
    add("requirements", cmd_requirements, "check each formal requirement with Z3 from the composed contracts and "
        "print its status", True).add_argument("--force", action="store_true", help="check every requirement again")
    add("deadlines", cmd_deadlines, "decide each requirement's end-to-end deadline with Z3 (deadlines add along "
        "the path)", True).add_argument("--json", action="store_true", help="print the results as JSON")
