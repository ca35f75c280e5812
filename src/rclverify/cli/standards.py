"""``rclverify standards``: the last report's standards gaps, and the compliance and trace matrices
exported as CSV or XLSX (report/standards_export.py, docs/standards.md "Exports"); runs nothing."""
from __future__ import annotations

import argparse
from pathlib import Path

from rclverify.cli.common import AddCommand


def cmd_standards(args: argparse.Namespace) -> int:
    """Print each mapped standard's counts and the clauses it asks that are not covered (with why) from
    ``reports/assurance.json``, and write the exports asked: ``--csv`` the compliance matrix, ``--trace``
    the trace matrix (CSV), ``--xlsx`` both as a workbook.  Exit 0; 1 (one located line) when there is
    no report or it is of another shape, or openpyxl is missing for ``--xlsx``."""
    from rclverify.report.lastrun import read_report  # deferred: start-up (loads the report's readers only when called)
    from rclverify.report.standards_export import gaps, matrix_rows, trace_rows, write_csv, write_xlsx  # deferred: start-up (the exports, only when called)
    report = read_report(Path(args.workspace))
    lines = gaps(report)
    print("\n".join(lines) if lines else "the plan maps no standard (docs/standards.md)")
    if args.csv:
        write_csv(Path(args.csv), matrix_rows(report))
        print(f"compliance matrix: {args.csv}")
    if args.trace:
        write_csv(Path(args.trace), trace_rows(report))
        print(f"trace matrix: {args.trace}")
    if args.xlsx:
        write_xlsx(Path(args.xlsx), {"compliance matrix": matrix_rows(report), "trace matrix": trace_rows(report)})
        print(f"workbook: {args.xlsx}")
    return 0


def add_standards(add: AddCommand) -> None:
    """The ``standards`` parser."""
    sp = add("standards", cmd_standards, "the last report's standards gaps; export the compliance matrix and the "
             "trace matrix (runs nothing)", True)
    sp.add_argument("--csv", metavar="FILE", help="write the compliance matrix as CSV")
    sp.add_argument("--trace", metavar="FILE", help="write the trace matrix (requirement, guarantee, obligation, "
                    "evidence) as CSV")
    sp.add_argument("--xlsx", metavar="FILE", help="write both as an XLSX workbook (the xlsx extra: openpyxl)")
