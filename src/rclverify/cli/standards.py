"""``rclverify standards``: the last report's standards gaps, and the compliance and trace matrices
exported as CSV or XLSX (report/standards_export.py, docs/standards.md "Exports"); runs nothing."""
from __future__ import annotations

import argparse
from pathlib import Path

from rclverify.cli.common import AddCommand


def cmd_standards(args: argparse.Namespace) -> int:
    """Print each mapped standard's counts and the clauses it asks that are not covered (with why) from
    ``reports/assurance.json``, and write the exports asked: ``--csv`` the compliance matrix, ``--trace``
    the trace matrix (CSV), ``--xlsx`` both as a workbook with a sheet saying what they were read from
    (each CSV starts with the same header rows).  Exit 0; 1 (one located line) when there is no report,
    it is of another shape, it no longer says what the workspace's files and recorded evidence give
    (:func:`~rclverify.report.standards_export.report_out_of_date`, by sha256), or openpyxl is missing for
    ``--xlsx``."""
    from rclverify.report.lastrun import located  # deferred: start-up (loads the report's readers only when called)
    from rclverify.report.standards_export import (REPORT, evidence_digests, export_header, gaps, matrix_rows,  # deferred: start-up (the exports, only when called)
                                                   read_typed, report_out_of_date, trace_rows, write_csv, write_xlsx)
    from rclverify.cli.common import workspace_of  # deferred: start-up
    root = Path(args.workspace)
    report = read_typed(root)
    if args.xlsx:  # a missing extra is said before the report is built again for the freshness check
        from rclverify.core.extras import require  # deferred: the optional extra is looked up only for an XLSX export
        require("openpyxl", "an XLSX export of the compliance matrix")
    why = report_out_of_date(workspace_of(args), report)
    if why:
        raise located(root / REPORT, why)
    lines = gaps(report)
    print("\n".join(lines) if lines else "the plan maps no standard (docs/standards.md)")
    header = export_header(root, report)
    matrix = matrix_rows(report, evidence_digests(root, report))
    if args.csv:
        write_csv(Path(args.csv), matrix, header)
        print(f"compliance matrix: {args.csv}")
    if args.trace:
        write_csv(Path(args.trace), trace_rows(report), header)
        print(f"trace matrix: {args.trace}")
    if args.xlsx:
        write_xlsx(Path(args.xlsx), {"about this export": [["what", "value"], *header],
                                     "compliance matrix": matrix, "trace matrix": trace_rows(report)})
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
