"""What an assessor takes away from a report: the compliance matrix and the trace matrix as files
(CSV, and XLSX through openpyxl, the ``xlsx`` extra), and the standards' gaps in a few lines
(docs/standards.md, "Exports").

The tables are :mod:`rclverify.report.standards_sheets`' (the compliance matrix, the trace matrix, the
header saying what they were read from).  Here:

* :func:`report_out_of_date`: why the written report is older than the last ``verify`` or than its
  inputs (``rclverify standards`` refuses to export it);
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


def _inputs(root: Path, report: Mapping[str, Any]) -> list[str]:
    """The workspace files the report was built from that can be named without rebuilding it: the plan,
    its contract files, the workspace's own profile files and the review records."""
    meta = report.get("meta") or {}
    files = [str(meta.get("plan", "")), *(str(c) for c in meta.get("contracts") or ())]
    files += [str((s.get("origin") or {}).get("file")) for s in report.get("standards") or ()
              if (s.get("origin") or {}).get("kind") == "workspace"]
    files += [str(e.get("tool_version")) for e in report.get("evidence") or () if e.get("backend") == "review"]
    return [f for f in dict.fromkeys(files) if f and (root / f).is_file()]


def report_out_of_date(root: Path, report: Mapping[str, Any]) -> str | None:
    """Why ``reports/assurance.json`` of the workspace ``root`` is older than the last ``verify`` or than
    its inputs, in one sentence, or ``None``: a file it was built from (:func:`_inputs`) or an evidence
    record (``artifacts/evidence/*.json``, written by a ``verify`` that did not reach its report) was
    modified after it."""
    try:
        written = (root / REPORT).stat().st_mtime_ns
    except OSError:
        return None
    newer = [f for f in _inputs(root, report) if (root / f).stat().st_mtime_ns > written]
    if newer:
        return (f"the report is older than {', '.join(newer[:3])}{' ...' if len(newer) > 3 else ''} (modified "
                "since it was written): run `rclverify verify` and export again")
    records = sorted((root / "artifacts/evidence").glob("*.json")) if (root / "artifacts/evidence").is_dir() else []
    late = [p.name for p in records if p.stat().st_mtime_ns > written]
    if late:
        return (f"the report is older than the last verify's evidence ({len(late)} record(s) written since, "
                f"e.g. artifacts/evidence/{late[0]}): that verify did not write its report; run `rclverify "
                "verify` and export again")
    return None


def evidence_digests(root: Path, report: Mapping[str, Any]) -> dict[str, str]:
    """Obligation -> hex sha256 of its evidence record file ``artifacts/evidence/<id>.json`` (``missing``
    when it cannot be read), for each evidence row of ``report``."""
    return {str(e.get("obligation")): _digest(root / "artifacts/evidence" / f"{e.get('obligation')}.json")
            for e in report.get("evidence") or ()}


def export_header(root: Path, report: Mapping[str, Any]) -> list[list[str]]:
    """The header of an export of the workspace ``root``'s ``report`` (:func:`~.standards_sheets.header_rows`),
    with the report file's sha256 and modification time and the plan's and contracts' sha256."""
    path = root / REPORT
    try:
        when = datetime.fromtimestamp(path.stat().st_mtime, timezone.utc).isoformat(timespec="seconds")
    except OSError:
        when = "unknown"
    meta = report.get("meta") or {}
    files = [str(meta.get("plan", "")), *(str(c) for c in meta.get("contracts") or ())]
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


def gaps(report: Mapping[str, Any]) -> list[str]:
    """The standards' gaps in a few lines: per standard, its counts and the clauses it asks at the level
    that are not covered, each with its why (empty when the report maps no standard)."""
    out = []
    for s in report.get("standards") or ():
        level = "" if s.get("level") is None else f" {str(s.get('level_name', '')).upper()} {s['level']}"
        counts = ", ".join(f"{n} {k}" for k, n in (s.get("counts") or {}).items() if n)
        out.append(f"{s.get('edition')}{level} ({origin_text(s.get('origin') or {})}): {counts}")
        clauses = {str(c["id"]): c for c in s.get("clauses") or ()}
        for cid in s.get("required_not_covered") or ():
            c = clauses.get(str(cid), {})
            out.append(f"  {cid} [{c.get('recommendation', '')}] {c.get('title', '')}: {c.get('why', '')}")
    return out


__all__ = ["FORMULA_START", "MATRIX_COLUMNS", "REPORT", "TRACE_COLUMNS", "escape_cell", "evidence_digests",
           "export_header", "gaps", "matrix_rows", "report_out_of_date", "trace_rows", "write_csv", "write_xlsx"]
