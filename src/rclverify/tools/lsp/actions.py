"""Code actions: the repairs Z3 checked as quick fixes, and the formatter.

* Quick fixes (:func:`quick_fixes`): each SARIF ``fix`` the last run wrote
  for a finding in the requested range (:mod:`.lastrun`; every one is a
  repair the diagnosis checked before the report showed it: with Z3, or a
  repair of the code by running the node's property tests again,
  docs/diagnosis.md), as a ``quickfix`` code action whose workspace edit is
  the fix's replacement, in an RCL file or in the implementation file a
  failing property test's finding is located in.  Its title says what the
  repair does, what its check showed and what it did not, as the fix's
  description does.  A stale
  finding offers no fix; nor does a fix whose file changed after the run.
* Formatting (:func:`format_edits`): ``rclverify fmt``'s canonical RCL
  (:func:`rclverify.lang.printer.to_rcl`), clause by clause: each
  ``context`` and ``node`` clause is replaced by its printed form, and the
  text between clauses is kept, so comments between clauses survive (the
  printer keeps none); a clause with a comment inside is left as written.
  A text that does not parse is not formatted (the request fails with the
  syntax error, as ``rclverify fmt`` does).

Line ends (:mod:`.lines`): positions are computed on the text with ``\n``
line ends, which has the editor's lines and columns; the text an edit
inserts is written with the document's own line end (:func:`.lines.eol_of`),
so formatting a CRLF, CR or mixed file neither adds nor loses a line end.
"""
from __future__ import annotations

import re
from typing import Any, Mapping

from lsprotocol import types as lsp

from rclverify.lang.errors import RclError
from rclverify.tools.lsp.diagnostics import utf16_col
from rclverify.tools.lsp.lastrun import LastRun
from rclverify.tools.lsp.lines import eol_of, for_parser, split_lines, with_eol
from rclverify.tools.lsp.rpc import Failed
from rclverify.records.sarif import SarifFix
from rclverify.tools.lsp.workspace import LspWorkspace, Outside
from rclverify.lang.printer import context_to_rcl, node_to_rcl
from rclverify.tools.lsp.diagnostics import MAX_CHARS

_COMMENT = re.compile(r"//|/\*")


#: What checked a repair, as a fix description of :func:`rclverify.report.sarif_diagnoses.attach_diagnoses` says it:
#: Z3 (a contract's or a program's repair), the property tests (a repair of the code, diagnosis/code_repair.py).
_CHECKERS = ("Z3 shows", "The property tests show")


def _title(description: str) -> str:
    """``"<what it does> — Z3 shows: ...; not shown: ..."`` (or ``— the property tests show: ...``) from a
    fix description of :func:`rclverify.report.sarif_diagnoses.attach_diagnoses` (the whole description when it
    has another form)."""
    for checker in _CHECKERS:
        head, sep, shown = description.partition(f" {checker}: ")
        if sep:
            what = head.split(": ")[0].rstrip(".")
            said = checker if checker.startswith("Z3") else checker[0].lower() + checker[1:]
            return f"{what} \u2014 {said}: {shown.rstrip('.')}"
    return description


def _pos(lines: list[str], line: int, col: int) -> lsp.Position:
    k = min(max(line - 1, 0), max(len(lines) - 1, 0))
    return lsp.Position(k, utf16_col(lines[k] if lines else "", col - 1))


def fix_edit(ws: LspWorkspace, open_docs: Mapping[str, str], fix: SarifFix) -> lsp.WorkspaceEdit | None:
    """The workspace edit of one SARIF ``fix`` (§3.55) whose artifact paths
    are root-relative; ``None`` when a file it edits is outside the
    workspace, unreadable, or its text is not the one the run checked."""
    changes: dict[str, list[lsp.TextEdit]] = {}
    for ch in fix.get("artifactChanges") or ():
        rel = str(ch["artifactLocation"]["uri"])
        try:
            ws.rel(ws.uri(rel))
        except Outside:
            return None
        disk = ws.disk_text(rel)
        text = open_docs.get(rel, disk)
        if text is None or text != disk:
            return None
        lines, eol = split_lines(text), eol_of(text)
        for rep in ch.get("replacements") or ():
            r = rep["deletedRegion"]
            rng = lsp.Range(_pos(lines, r["startLine"], r["startColumn"]), _pos(lines, r["endLine"], r["endColumn"]))
            changes.setdefault(ws.uri(rel), []).append(lsp.TextEdit(rng, with_eol(rep["insertedContent"]["text"], eol)))
    return lsp.WorkspaceEdit(changes=changes) if changes else None


def quick_fixes(ws: LspWorkspace, open_docs: Mapping[str, str], rel: str,
                params: lsp.CodeActionParams, last: LastRun | None = None) -> list[lsp.CodeAction]:
    """The quick fixes for the findings of the last run in ``rel`` on the
    lines of ``params.range`` (see the module docstring), one per distinct
    fix, in the SARIF log's order."""
    last = last or LastRun(ws.root)
    text = open_docs.get(rel)
    if not last.fresh(rel, text, ws.disk_text(rel)):
        return []
    lo, hi = params.range.start.line + 1, params.range.end.line + 1
    seen: set[str] = set()
    out = []
    for f in last.findings():
        if f.file != rel or not lo <= f.line <= hi:
            continue
        for fix in f.fixes:
            described = fix.get("description")
            desc = str(described.get("text", "repair") if described else "repair")
            if desc in seen:
                continue
            edit = fix_edit(ws, open_docs, fix)
            if edit is None:
                continue
            seen.add(desc)
            diags = [d for d in params.context.diagnostics if d.code == f.rule]
            out.append(lsp.CodeAction(title=_title(desc), kind=lsp.CodeActionKind.QuickFix, edit=edit,
                                      diagnostics=diags or None, is_preferred=len(seen) == 1))
    return out


def format_edits(rel: str, text: str) -> list[lsp.TextEdit]:
    """The edits that bring ``text`` (the file ``rel``) to ``rclverify
    fmt``'s form clause by clause (see the module docstring); ``[]`` when it
    is in that form.  ``text`` may have any line ends; the inserted text
    has the document's (module docstring).  Raises :class:`.rpc.Failed`
    (LSP ``RequestFailed``) with the located syntax error when ``text``
    does not parse, or when it is longer than
    :data:`.diagnostics.MAX_CHARS` (it is not parsed as you type either)."""
    from rclverify.lang.parser import parse_text  # deferred: start-up (loads lark, rclverify.core and more only when called)
    if len(text) > MAX_CHARS:
        raise Failed(f"{rel}: not formatted in the editor: {len(text)} characters, over the limit of {MAX_CHARS} "
                     f"(run `rclverify fmt {rel}`)")
    eol, text = eol_of(text), for_parser(text)
    try:
        spec = parse_text(text, rel)
    except RclError as exc:
        raise Failed(str(exc.diagnostics[0])) from None
    lines = split_lines(text)
    edits = []
    clauses: list[Any] = [(c, context_to_rcl(c)) for c in spec.contexts] + [(n, node_to_rcl(n)) for n in spec.nodes]
    for clause, printed in clauses:
        loc = clause.loc
        if not loc.end_line:
            continue
        old = _slice(lines, loc.line, loc.col, loc.end_line, loc.end_col)
        printed = printed.rstrip("\n")
        if old == printed or _COMMENT.search(old):
            continue
        edits.append(lsp.TextEdit(lsp.Range(_pos(lines, loc.line, loc.col), _pos(lines, loc.end_line, loc.end_col)),
                                  with_eol(printed, eol)))
    return edits


def _slice(lines: list[str], line: int, col: int, end_line: int, end_col: int) -> str:
    if line == end_line:
        return lines[line - 1][col - 1:end_col - 1]
    return "\n".join([lines[line - 1][col - 1:], *lines[line:end_line - 1], lines[end_line - 1][:end_col - 1]])
