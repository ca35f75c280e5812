"""What an assessor takes away from a report: the compliance matrix and the trace matrix as tables
(CSV, and XLSX through openpyxl, the ``xlsx`` extra), and the standards' gaps in a few lines
(docs/standards.md, "Exports").

* The compliance matrix (:func:`matrix_rows`): one row per clause of each standard the report maps,
  with :data:`MATRIX_COLUMNS`, read from the report's ``standards`` rows (report/standards_rows.py).
* The trace matrix (:func:`trace_rows`): one row per requirement, supporting guarantee, obligation
  and evidence record (:data:`TRACE_COLUMNS`), then one per obligation of a guarantee no requirement
  names (its requirement cell empty), from the report's ``requirements``, ``obligations`` and
  ``evidence``.

Pure readings of a report dict (``reports/assurance.json``); the writers raise ``OSError`` for a file
that cannot be written and :class:`~rclverify.core.extras.MissingExtra` when openpyxl is not installed.
"""
from __future__ import annotations

import csv
import io
from pathlib import Path
from typing import Any, Mapping

from rclverify.core.atomic import atomic_write_bytes, atomic_write_text
from rclverify.report.standards_rows import origin_text

#: The compliance matrix's columns.
MATRIX_COLUMNS: tuple[str, ...] = (
    "standard", "level", "profile", "profile origin", "clause", "what it asks", "recommendation", "about",
    "independence asked", "items in scope", "items covered", "items not covered", "evidence that covers it",
    "who checked it", "status", "why", "plan's justification", "plan note at")
#: The trace matrix's columns.
TRACE_COLUMNS: tuple[str, ...] = (
    "requirement", "requirement verdict", "node", "guarantee", "guarantee status", "obligation", "backend",
    "kind", "evidence status", "tool")


def _origin(o: Mapping[str, Any]) -> str:
    if o.get("kind") == "built-in":
        return f"built-in ({o.get('edition')})"
    return f"workspace file {o.get('file')} sha256 {o.get('sha256')}"


def matrix_rows(report: Mapping[str, Any]) -> list[list[str]]:
    """The compliance matrix of ``report``: :data:`MATRIX_COLUMNS` then one row per clause, standard by
    standard in the plan's order, clause by clause in the profile's."""
    out = [list(MATRIX_COLUMNS)]
    for s in report.get("standards") or ():
        level = "" if s.get("level") is None else f"{str(s.get('level_name', '')).upper()} {s['level']}"
        for c in s.get("clauses") or ():
            scope = c.get("scope") or []
            plan = c.get("plan") or {}
            out.append([
                str(s.get("edition", "")), level, str(s.get("profile", "")), _origin(s.get("origin") or {}),
                str(c["id"]), str(c.get("title", "")), str(c.get("recommendation", "")), str(c.get("about", "")),
                str(c.get("independence", "")), str(len(scope)), str(sum(1 for x in scope if x.get("covered"))),
                "; ".join(f"{x['item']}: {x.get('detail', x.get('state', ''))}" for x in scope if not x.get("covered")),
                "; ".join(str(x) for x in c.get("covered_by") or ()), "; ".join(str(x) for x in c.get("checked_by") or ()),
                str(c.get("status", "")), str(c.get("why", "")), str(plan.get("justification", "")),
                str(plan.get("at", ""))])
    return out


def trace_rows(report: Mapping[str, Any]) -> list[list[str]]:
    """The trace matrix of ``report``: :data:`TRACE_COLUMNS` then requirement -> guarantee -> obligation ->
    evidence rows (a guarantee without an obligation, or an obligation without a record, is one row with
    the missing cells empty), then the obligations of guarantees no requirement names."""
    evidence = {str(e.get("obligation")): e for e in report.get("evidence") or ()}
    guarantee_status = {(str(n.get("name")), int(g.get("index", 0))): str(g.get("status", ""))
                        for n in report.get("nodes") or () for g in n.get("guarantees") or ()}
    obligations: dict[tuple[str, int], list[Mapping[str, Any]]] = {}
    for o in report.get("obligations") or ():
        obligations.setdefault((str(o.get("node")), int(o.get("guarantee", 0))), []).append(o)
    out = [list(TRACE_COLUMNS)]
    traced: set[tuple[str, int]] = set()

    def rows_of(rid: str, verdict: str, key: tuple[str, int]) -> None:
        obs = obligations.get(key, []) + ([] if key[1] == 0 else obligations.get((key[0], 0), []))
        for o in obs or [{}]:
            e = evidence.get(str(o.get("id")), {}) if o else {}
            out.append([rid, verdict, key[0], f"g{key[1]}", guarantee_status.get(key, ""), str(o.get("id", "")),
                        str(o.get("backend", "")), str(o.get("kind", "")), str(e.get("status", "")),
                        _tool(e)])

    for rq in report.get("requirements") or ():
        for sp in rq.get("support") or ():
            key = (str(sp.get("node")), int(sp.get("guarantee", 0)))
            traced.add(key)
            rows_of(str(rq.get("id")), str(rq.get("verdict", "")), key)
    for key in sorted(set(guarantee_status) - traced):
        rows_of("", "", key)
    return out


def _tool(e: Mapping[str, Any]) -> str:
    """An evidence record's tool and version, the tool named once when the version starts with it."""
    tool, version = str(e.get("tool", "")), str(e.get("tool_version", ""))
    return version if version.startswith(tool) else f"{tool} {version}".strip()


def _csv(rows: list[list[str]]) -> str:
    buf = io.StringIO(newline="")
    csv.writer(buf, lineterminator="\r\n").writerows(rows)  # RFC 4180 line ends
    return buf.getvalue()


def write_csv(path: Path, rows: list[list[str]]) -> None:
    """Write ``rows`` to ``path`` as RFC 4180 CSV in UTF-8 (atomically).  Raises ``OSError``."""
    atomic_write_text(path, _csv(rows))


def write_xlsx(path: Path, sheets: Mapping[str, list[list[str]]]) -> None:
    """Write ``sheets`` (sheet name -> rows, the first row its header) to ``path`` as an XLSX workbook with
    openpyxl (atomically).  Raises :class:`~rclverify.core.extras.MissingExtra` (one line naming the
    ``xlsx`` extra) when openpyxl is not installed and ``OSError`` for a file that cannot be written."""
    from rclverify.core.extras import require  # deferred: the optional extra is looked up only for an XLSX export
    openpyxl = require("openpyxl", "an XLSX export of the compliance matrix")
    styles = require("openpyxl.styles", "an XLSX export of the compliance matrix")
    Workbook, Font = openpyxl.Workbook, styles.Font
    wb = Workbook()
    first = True
    for name, rows in sheets.items():
        ws = wb.active if first else wb.create_sheet()
        assert ws is not None
        ws.title = name[:31]  # the format's limit on a sheet name
        first = False
        for i, row in enumerate(rows, 1):
            for j, value in enumerate(row, 1):
                cell = ws.cell(row=i, column=j, value=value)
                if isinstance(value, str) and value.startswith("="):
                    cell.data_type = "s"  # text, never a formula (openpyxl reads a leading '=' as one)
        for cell in ws[1]:
            cell.font = Font(bold=True)
        ws.freeze_panes = "A2"
    buf = io.BytesIO()
    wb.save(buf)
    atomic_write_bytes(path, buf.getvalue())


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


__all__ = ["MATRIX_COLUMNS", "TRACE_COLUMNS", "gaps", "matrix_rows", "trace_rows", "write_csv", "write_xlsx"]
