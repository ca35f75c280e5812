"""``rclverify status`` and ``explain``: what the last run's report says, running nothing
(report/lastrun.py, report/explain.py)."""
from __future__ import annotations

import argparse
import json
from pathlib import Path

from rclverify.cli.common import AddCommand


def cmd_status(args: argparse.Namespace) -> int:
    """Print the last run's overall line, problems (ROS grounding errors
    among them), requirements line and summary table from
    ``artifacts/report/summary.json`` (the JSON report when there is none);
    runs nothing.  Exit 0; 1 (one located line) when neither is there or the
    file read is of another shape (:mod:`rclverify.report.lastrun`)."""
    from rclverify.report.summary import print_last_run  # deferred: start-up (loads rclverify.records, rclverify.records.records and more only when called)
    print_last_run(Path(args.workspace))
    return 0


def cmd_explain(args: argparse.Namespace) -> int:
    """Print what the last JSON report (``reports/assurance.json``) says of
    ``args.id``: any id an output shows (:mod:`rclverify.report.explain`:
    requirement, node, guarantee, obligation, side condition, health check,
    diagnosis, problem number, SARIF rule, ROS or lint code, argument
    element).  Exit 0; 1 (one located line, with the closest ids) for an
    unknown id or a report of another shape."""
    from rclverify.report.explain import explain, id_kinds, near_ids  # deferred: start-up (loads rclverify.diagnosis, rclverify.diagnosis.table and more only when called)
    from rclverify.report.lastrun import located, read_report  # deferred: start-up (loads rclverify.lang.ast, rclverify.report and more only when called)
    root = Path(args.workspace)
    report = read_report(root)
    extra = []
    for name in ("reports/assurance.sarif", "reports/argument.json"):
        try:  # optional: their ids are looked up when they are there and readable
            extra.append(json.loads((root / name).read_text(encoding="utf-8")))
        except (OSError, ValueError):
            extra.append(None)
    try:
        lines = explain(report, args.id, *extra)
        near = [] if lines is not None else near_ids(report, args.id, *extra)
    except (KeyError, TypeError, AttributeError, ValueError) as exc:  # a deeper field of another shape
        raise located(root / "reports/assurance.json", f"not an rclverify report: cannot read it ({exc!r}); "
                      "run `rclverify verify` (or `doit verify`) to write it again") from None
    if lines is None:  # an unverified guarantee, a derived property: a finding with no record of its own
        from rclverify.report.diagnosis_text import finding_lines  # deferred: optional or conditional (inside a block)
        lines = finding_lines(report, args.id) or None
    if lines is not None:
        print("\n".join(lines))
        return 0
    hint = f"; did you mean {', '.join(near)}?" if near else ""
    kinds = id_kinds(report)
    raise located(root / "reports/assurance.json", f"no problem or obligation {args.id!r} in the last report, "
                  f"nor any other id it shows{hint}"
                  + (f" (ids: {kinds})" if kinds else " (it has no requirement, node or problem)"))


def add_status_explain(add: AddCommand) -> None:
    """The ``status`` and ``explain`` parsers."""
    add("status", cmd_status, "print the last run's summary and problems (runs nothing)", True)
    add("explain", cmd_explain, "print what the last report says of an id: a requirement, node, guarantee "
        "(Agent.g3), problem, obligation, side condition, health check, SARIF rule or ROS code", True).add_argument(
        "id", help="any id an output shows (`rclverify status` lists the problems and their findings)")
