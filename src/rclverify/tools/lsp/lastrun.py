"""The last run's findings, shown in the file they are about.

What ``doit verify`` (or ``rclverify verify``) last wrote is read from the
workspace, never computed here: ``reports/assurance.sarif``
(:mod:`rclverify.report.sarif`: every failed side condition located at the
guarantee its diagnosis blames, health problems, failed or outstanding
evidence, lint, each with its rule id and the repairs Z3 checked as SARIF
``fixes``) and ``reports/assurance.json`` (the report dict, read with its
shape checked by :func:`rclverify.report.lastrun.read_report`, for hover).
Both are read again when their modification time changes.

A finding is *stale* (docs/editor.md) when its file was saved after the
run wrote the SARIF log, or when the editor's text differs from the saved
text: it is then shown as information, its message starting
``stale (the text changed after the last run):``, and its repairs are not
offered (their regions may no longer hold the text Z3 checked).
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import cast

from lsprotocol import types as lsp

from rclverify.lang.errors import RclError
from rclverify.records.report_schema import Report
from rclverify.tools.lsp.diagnostics import utf16_col
from rclverify.tools.lsp.lines import split_lines
from rclverify.records.sarif import SarifFix

SARIF = "reports/assurance.sarif"
REPORT = "reports/assurance.json"
STALE = "stale (the text changed after the last run): "

_LEVEL = {"error": lsp.DiagnosticSeverity.Error, "warning": lsp.DiagnosticSeverity.Warning,
          "note": lsp.DiagnosticSeverity.Information}


@dataclass(frozen=True)
class Finding:
    """One SARIF result of the last run in ``file`` (root-relative) at
    1-based ``line``/``col``: rule id, level, message and its SARIF fixes."""

    file: str
    line: int
    col: int
    rule: str
    level: str
    message: str
    fixes: tuple[SarifFix, ...]


def _stamp(p: Path) -> float | None:
    try:
        return p.stat().st_mtime
    except OSError:
        return None


class LastRun:
    """The last run of the workspace ``root``, read lazily and again when its files change."""

    def __init__(self, root: Path) -> None:
        self.root = root
        self._sarif: tuple[float | None, list[Finding]] = (None, [])
        self._report: tuple[float | None, Report | None] = (None, None)

    def findings(self) -> list[Finding]:
        """Every located result of the SARIF log; ``[]`` without a readable one."""
        stamp = _stamp(self.root / SARIF)
        if stamp != self._sarif[0]:
            self._sarif = (stamp, _read_sarif(self.root / SARIF) if stamp is not None else [])
        return self._sarif[1]

    def written(self) -> float | None:
        """When the SARIF log was written (``None``: no last run)."""
        return _stamp(self.root / SARIF)

    def report(self) -> Report | None:
        """The report dict of the last run (its shape checked by
        :func:`rclverify.report.lastrun.read_report`), ``None`` when there is
        none or it is not of the report's shape."""
        stamp = _stamp(self.root / REPORT)
        if stamp != self._report[0]:
            from rclverify.report.lastrun import read_report  # deferred: optional or conditional (inside a block)
            try:
                rep: Report | None = cast(Report, read_report(self.root))  # shape-checked as it is read
            except RclError:
                rep = None
            self._report = (stamp, rep)
        return self._report[1]

    def fresh(self, rel: str, text: str | None, disk: str | None) -> bool:
        """Whether the findings in ``rel`` still describe ``text`` (the
        editor's text; ``disk`` the saved one): see the module docstring."""
        run, saved = self.written(), _stamp(self.root / rel)
        if run is None or saved is None or saved > run:
            return False
        return text is None or text == disk

    def diagnostics(self, rel: str, text: str, fresh: bool) -> list[lsp.Diagnostic]:
        """The findings in ``rel`` as LSP diagnostics over ``text`` (code:
        the SARIF rule id; ``data``: the fixes, when ``fresh``)."""
        lines = split_lines(text)
        out = []
        for f in self.findings():
            if f.file != rel:
                continue
            line = min(max(f.line - 1, 0), max(len(lines) - 1, 0))
            here = lines[line] if lines else ""
            start = utf16_col(here, f.col - 1)
            rng = lsp.Range(lsp.Position(line, start), lsp.Position(line, max(utf16_col(here, len(here)), start)))
            out.append(lsp.Diagnostic(
                range=rng, message=f.message if fresh else STALE + f.message,
                severity=_LEVEL.get(f.level, lsp.DiagnosticSeverity.Warning) if fresh
                else lsp.DiagnosticSeverity.Information,
                code=f.rule, source="rclverify (last run)",
                data={"fixes": list(f.fixes)} if fresh and f.fixes else None))
        return out


def _read_sarif(path: Path) -> list[Finding]:
    """The located results of the SARIF log at ``path``; ``[]`` when it
    cannot be read or is not a SARIF log (a later run writes it again)."""
    try:
        log = json.loads(path.read_text(encoding="utf-8"))
        results = log["runs"][0]["results"]
    except (OSError, ValueError, KeyError, IndexError, TypeError):
        return []
    out = []
    for r in results if isinstance(results, list) else ():
        try:
            phys = r["locations"][0]["physicalLocation"]
            region = phys.get("region") or {}
            fixes = tuple(cast(SarifFix, x) for x in r.get("fixes") or () if isinstance(x, dict))
            out.append(Finding(str(phys["artifactLocation"]["uri"]), int(region.get("startLine", 1)),
                               int(region.get("startColumn", 1)), str(r["ruleId"]), str(r.get("level", "warning")),
                               str(r["message"]["text"]), fixes))
        except (KeyError, IndexError, TypeError, ValueError):
            continue
    return out
