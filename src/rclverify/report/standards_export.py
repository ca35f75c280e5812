"""What an assessor takes away from a report: the compliance matrix and the trace matrix as files
(CSV, and XLSX through openpyxl, the ``xlsx`` extra), and the standards' gaps in a few lines
(docs/standards.md, "Exports").

The tables are :mod:`rclverify.report.standards_sheets`' (the compliance matrix, the trace matrix, the
header saying what they were read from).  Here:

* :func:`read_typed`: the workspace's ``reports/assurance.json`` decoded once into the
  :class:`~rclverify.records.report_record.AssuranceReport` every function here reads;
* :func:`report_out_of_date`: why the written report no longer says what the workspace's files and
  recorded evidence give, compared by sha256 (``rclverify standards`` refuses to export it);
* :func:`export_header` and :func:`evidence_digests`: the header and each evidence record's sha256,
  read from the workspace's files;
* :func:`write_csv` and :func:`write_xlsx`: the writers.  A CSV cell a spreadsheet would read as a
  formula is written with a leading apostrophe (:func:`escape_cell`, OWASP's rule against CSV
  injection); an XLSX cell is always written as text.

The writers raise ``OSError`` for a file that cannot be written and
:class:`~rclverify.core.extras.MissingExtra` when openpyxl is not installed.
"""
from __future__ import annotations

import csv
import hashlib
import io
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Mapping

from rclverify.core.atomic import atomic_write_bytes, atomic_write_text
from rclverify.records.report_record import AssuranceReport
from rclverify.report.standards_rows import origin_text
from rclverify.report.standards_sheets import (MATRIX_COLUMNS, TRACE_COLUMNS, header_rows, matrix_rows,
                                               trace_rows)

#: The characters a spreadsheet reads as the start of a formula or a command (OWASP, "CSV Injection":
#: ``=``, ``+``, ``-``, ``@``, tab, carriage return); a cell that starts with one gets a leading ``'``.
FORMULA_START: tuple[str, ...] = ("=", "+", "-", "@", "\t", "\r")
#: Where the report is, in the workspace.
REPORT = "reports/assurance.json"


def escape_cell(value: str) -> str:
    """``value`` with a leading apostrophe when it starts with one of :data:`FORMULA_START` (a spreadsheet
    then shows it as text, never runs it); unchanged otherwise."""
    return "'" + value if value.startswith(FORMULA_START) else value


def _digest(path: Path) -> str:
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest()
    except OSError:
        return "missing"


def read_typed(root: Path) -> AssuranceReport:
    """``reports/assurance.json`` of the workspace ``root``, shape-checked
    (:func:`rclverify.report.lastrun.read_report`) and decoded once.  Raises
    :class:`~rclverify.lang.errors.RclError` located at the report when there is none, it is of another
    shape, or a part does not decode into its record."""
    import msgspec  # deferred: start-up (loads msgspec only when called)
    from rclverify.report.lastrun import located, read_report  # deferred: start-up (the report's readers only when called)
    data = read_report(root)
    try:
        return AssuranceReport.of(data)
    except msgspec.ValidationError as exc:
        raise located(root / REPORT, f"not an rclverify report: {exc}; run `rclverify verify` (or `doit verify`) "
                                     "to write it again") from None


def report_out_of_date(ws: Any, report: AssuranceReport) -> str | None:
    """Why ``reports/assurance.json`` of the workspace ``ws`` (a
    :class:`~rclverify.stages.workspace.Workspace`) no longer says what the workspace's files give,
    in one sentence, or ``None``.  Compared by content, never by modification time: each workspace
    profile file's sha256 now with the one the report's ``standards[].origin`` records; then the
    report built again in memory from the recorded artifacts (:func:`~rclverify.report.build.build_report`,
    every evidence record's inputs hashed anew) with the written one: its ``meta.inputs_sha256`` (the
    plan, contract and replacement files, the snapshots and model they give, each evidence record's
    input hashes, the requirement checks) and each obligation's status.  So a file edited and then
    given back an older modification time, and a ``verify`` that wrote evidence but stopped before its
    report, are each caught, and a file only touched is not.  A plan or contract that no longer
    builds a report is a reason too (the first of its errors)."""
    from rclverify.lang.errors import RclError  # deferred: start-up (the rebuild only where an export is asked)
    from rclverify.report.build import build_report  # deferred: start-up (loads the report's passes only when called)
    for s in report.standards:
        origin = s.origin
        if origin.kind == "workspace":
            was, now = origin.sha256, _digest(ws.root / origin.file)
            if was != now:
                return (f"the report was built from another {origin.file} (sha256 {was[:12]}..., now "
                        f"{now[:12]}...): {_AGAIN}")
    was_inputs = report.meta.inputs_sha256
    if not was_inputs:
        return f"the report records no inputs sha256 (written by an earlier rclverify): {_AGAIN}"
    try:
        built = build_report(ws)
    except RclError as e:
        first = str(e.diagnostics[0]) if getattr(e, "diagnostics", None) else str(e)
        return f"the workspace's files no longer build a report ({first.splitlines()[0]}): {_AGAIN}"
    now_inputs = built.meta.inputs_sha256
    if now_inputs != was_inputs:
        return (f"the report was built from other inputs than the workspace holds now (inputs sha256 "
                f"{was_inputs[:12]}..., now {now_inputs[:12]}...): {_AGAIN}")
    stated = {o.id: o.status for o in report.obligations}
    changed = sorted(o.id for o in built.obligations if stated.get(o.id) != o.status)
    if changed:
        return (f"{len(changed)} obligation(s) have another status in the recorded evidence than in the report "
                f"(e.g. {changed[0]}): {_AGAIN}")
    return None


#: What a stale report's sentence ends with.
_AGAIN = "run `rclverify verify` and export again"


def evidence_digests(root: Path, report: AssuranceReport) -> dict[str, str]:
    """Obligation -> hex sha256 of its evidence record file ``artifacts/evidence/<id>.json`` (``missing``
    when it cannot be read), for each evidence row of ``report``."""
    return {e.obligation: _digest(root / "artifacts/evidence" / f"{e.obligation}.json") for e in report.evidence}


def export_header(root: Path, report: AssuranceReport) -> list[list[str]]:
    """The header of an export of the workspace ``root``'s ``report`` (:func:`~.standards_sheets.header_rows`),
    with the report file's sha256 and modification time and the plan's and contracts' sha256."""
    path = root / REPORT
    try:
        when = datetime.fromtimestamp(path.stat().st_mtime, timezone.utc).isoformat(timespec="seconds")
    except OSError:
        when = "unknown"
    files = [report.meta.plan, *report.meta.contracts]
    return header_rows(report, _digest(path), when, {f: _digest(root / f) for f in files if f})


def _csv(rows: list[list[str]]) -> str:
    buf = io.StringIO(newline="")
    csv.writer(buf, lineterminator="\r\n").writerows([[escape_cell(str(v)) for v in row] for row in rows])
    return buf.getvalue()  # RFC 4180 line ends


def write_csv(path: Path, rows: list[list[str]], header: list[list[str]] | None = None) -> None:
    """Write ``rows`` to ``path`` (named on the command line: a FIFO or device is written in place,
    bounded in time, :func:`rclverify.core.atomic.atomic_write_bytes`) as RFC 4180 CSV in UTF-8
    (atomically), each cell escaped (:func:`escape_cell`); ``header``: ``[what, value]`` rows written
    first, then one empty row, then ``rows`` (its first row the column names).  Raises ``OSError``."""
    atomic_write_text(path, _csv((header + [[]] if header else []) + rows), named=True)


def write_xlsx(path: Path, sheets: Mapping[str, list[list[str]]]) -> None:
    """Write ``sheets`` (sheet name -> rows, the first row its header) to ``path`` as an XLSX workbook with
    openpyxl (atomically; ``path`` is named on the command line, as in :func:`write_csv`).  Raises :class:`~rclverify.core.extras.MissingExtra` (one line naming the
    ``xlsx`` extra) when openpyxl is not installed and ``OSError`` for a file that cannot be written."""
    from rclverify.core.extras import require  # deferred: the optional extra is looked up only for an XLSX export
    openpyxl = require("openpyxl", "an XLSX export of the compliance matrix")
    styles = require("openpyxl.styles", "an XLSX export of the compliance matrix")
    Workbook, Font = openpyxl.Workbook, styles.Font
    illegal = require("openpyxl.cell.cell", "an XLSX export of the compliance matrix").ILLEGAL_CHARACTERS_RE
    wb = Workbook()
    first = True
    for name, rows in sheets.items():
        ws = wb.active if first else wb.create_sheet()
        assert ws is not None
        ws.title = name[:31]  # the format's limit on a sheet name
        first = False
        for i, row in enumerate(rows, 1):
            for j, value in enumerate(row, 1):
                if isinstance(value, str):  # a control character the format cannot hold, shown as U+FFFD
                    value = illegal.sub("\ufffd", value)
                cell = ws.cell(row=i, column=j, value=value)
                if isinstance(value, str):
                    cell.data_type = "s"  # text, never a formula (openpyxl reads a leading '=' as one)
        for cell in ws[1]:
            cell.font = Font(bold=True)
        ws.freeze_panes = "A2"
    buf = io.BytesIO()
    wb.save(buf)
    atomic_write_bytes(path, buf.getvalue(), named=True)


def gaps(report: AssuranceReport) -> list[str]:
    """The standards' gaps in a few lines: per standard, its counts and the clauses it asks at the level
    that are not covered, each with its why (empty when the report maps no standard)."""
    out = []
    for standard in report.standards:
        level = "" if standard.level is None else f" {standard.level_name.upper()} {standard.level}"
        counts = ", ".join(f"{n} {k}" for k, n in standard.counts.items() if n)
        out.append(f"{standard.edition}{level} ({origin_text(standard.origin)}): {counts}")
        clauses = {clause.id: clause for clause in standard.clauses}
        for cid in standard.required_not_covered:
            clause = clauses.get(cid)
            out.append(f"  {cid} [{clause.recommendation if clause else ''}] {clause.title if clause else ''}: "
                       f"{clause.why if clause else ''}")
    return out


__all__ = ["FORMULA_START", "MATRIX_COLUMNS", "REPORT", "TRACE_COLUMNS", "escape_cell", "evidence_digests", "read_typed",
           "export_header", "gaps", "matrix_rows", "report_out_of_date", "trace_rows", "write_csv", "write_xlsx"]
