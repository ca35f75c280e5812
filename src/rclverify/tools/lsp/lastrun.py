"""The last run's findings, shown in the file they are about.

What ``doit verify`` (or ``rclverify verify``) last wrote is read from the
workspace, never computed here: ``reports/assurance.sarif``
(:mod:`rclverify.report.sarif`: every failed side condition located at the
guarantee its diagnosis blames, health problems, failed or outstanding
evidence, lint, each with its rule id and the repairs Z3 checked as SARIF
``fixes``) and ``reports/assurance.json`` (for hover: read with its shape
checked by :func:`rclverify.report.lastrun.read_report` and decoded into its
record, :class:`~rclverify.records.report_record.AssuranceReport`, by
:func:`rclverify.report.view.decoded_parts`, which reads a report of an
earlier version with the parts it lacks empty).
Both are read again when their modification time changes.

A finding is *stale* (docs/editor.md) when its file was saved after the
run wrote the SARIF log, or when the editor's text differs from the saved
text: it is then shown as information, its message starting
``stale (the text changed after the last run):``, and its repairs are not
offered (their regions may no longer hold the text Z3 checked).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import cast

import msgspec
from lsprotocol import types as lsp

from rclverify.lang.errors import RclError
from rclverify.records.report_record import AssuranceReport
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
        self._report: tuple[float | None, AssuranceReport | None] = (None, None)

    def findings(self) -> list[Finding]:
        """Every located result of the SARIF log; ``[]`` without a readable one."""
        stamp = _stamp(self.root / SARIF)
        if stamp != self._sarif[0]:
            self._sarif = (stamp, _read_sarif(self.root / SARIF) if stamp is not None else [])
        return self._sarif[1]

    def written(self) -> float | None:
        """When the SARIF log was written (``None``: no last run)."""
        return _stamp(self.root / SARIF)

    def report(self) -> AssuranceReport | None:
        """The report of the last run as its record (see the module docstring), ``None`` when there is
        none, it is not of the report's shape or a part does not decode into its record."""
        stamp = _stamp(self.root / REPORT)
        if stamp != self._report[0]:
            from rclverify.report.lastrun import read_report  # deferred: optional or conditional (inside a block)
            from rclverify.report.view import decoded_parts  # deferred: optional or conditional (inside a block)
            try:
                rep: AssuranceReport | None = decoded_parts(read_report(self.root))
            except (RclError, msgspec.ValidationError):
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
    """The located results of the SARIF log at ``path`` (its first run; :func:`rclverify.report.sarif_view.runs_of`);
    ``[]`` when it cannot be read or is not a SARIF log (a later run writes it again); a result of another
    shape, without a rule id or naming no file is left out."""
    from rclverify.report.sarif_view import runs_of  # deferred: start-up (the report's reader only when a log is read)
    try:
        runs = runs_of(msgspec.json.decode(path.read_bytes()))
    except (OSError, msgspec.DecodeError):
        return []
    out = []
    for res in runs[0].results if runs else ():
        place = res.place()
        if place is None or res.rule_id is None:
            continue
        file, region = place
        fixes = tuple(cast(SarifFix, x) for x in res.fixes if isinstance(x, dict))
        out.append(Finding(file, region.start_line, region.start_column, res.rule_id, res.level,
                           res.message.text, fixes))
    return out
