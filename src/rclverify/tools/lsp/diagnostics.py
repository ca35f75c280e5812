"""Diagnostics of the unsaved text: parse, type, unit and lint errors.

:func:`analyse` checks the files :meth:`LspWorkspace.scope` groups, the
edited one from the editor's text, as ``rclverify check`` checks them from
disk (``cli.cmd_check``): syntax errors of every file; then the type checker
(:func:`rclverify.lang.typecheck.check`, with the units of measure); then the
whole-file warnings, the lint warnings, the units at both ends of each
connection, calls no node serves and, for the plan's system, the plan's
statements resolved against it.  The diagnostics are the command line's
(:class:`rclverify.lang.errors.Diagnostic`: same message, same code, located
in the same file, line and column); :func:`to_lsp` gives each its LSP range.

Two rules of the server's own (docs/editor.md): a text longer than
:data:`MAX_CHARS` characters is not analysed as you type (one ``E-lsp-size``
error at its first line says so; ``rclverify check`` still checks it); a file
that is not RCL (:func:`is_rcl`) is not analysed at all.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any, Mapping

from lsprotocol import types as lsp

from rclverify.lang import ast
from rclverify.lang.errors import Diagnostic, RclError, error
from rclverify.tools.lsp.lines import for_parser
from rclverify.tools.lsp.workspace import LspWorkspace
from rclverify.lang.filewarn import file_warnings
from rclverify.lang.lint import lint

#: The longest text (characters) analysed as you type: some 40 times the
#: 160-node file of bench/lsp_latency.py.
MAX_CHARS = 4_000_000

_TOKEN = re.compile(r"(?:in|out)\.[A-Za-z_]\w*'*|[A-Za-z_][\w/]*'*|\d+(?:\.\d+)?|\S")


def is_rcl(ws: LspWorkspace, rel: str) -> bool:
    """Whether the server checks ``rel`` as RCL as you type: a ``.rcl`` file, a contract file the plan
    names, or the plan.  Any other file of the workspace (the Python a property test runs, a Hoare
    program) is not parsed: it shows the last run's findings located in it and offers their repairs
    (docs/editor.md)."""
    return rel.endswith(".rcl") or rel == ws.plan or rel in ws.contracts()


@dataclass
class Analysis:
    """One analysis of ``rel`` among ``files`` (root-relative): the texts
    read, the diagnostics by file, the parsed files (those that parsed), the
    checked system and its model when everything type-checked, and the plan
    when it loaded (``None`` otherwise)."""

    rel: str
    files: tuple[str, ...]
    texts: dict[str, str] = field(default_factory=dict)
    diagnostics: dict[str, list[Diagnostic]] = field(default_factory=dict)
    specs: dict[str, ast.Spec] = field(default_factory=dict)
    checked: Any = None
    model: Any = None
    plan: Any = None

    def add(self, diags: Any) -> None:
        """File each :class:`Diagnostic` of ``diags`` under its file."""
        for d in diags:
            self.diagnostics.setdefault(d.loc.file, []).append(d)


def analyse(ws: LspWorkspace, rel: str, open_docs: Mapping[str, str]) -> Analysis:
    """Check ``rel`` (root-relative) with the files of its scope, open
    documents from ``open_docs`` (root-relative path -> text), the others from
    disk.  The texts are parsed, and kept in ``texts``, with ``\n`` line
    ends (:func:`.lines.for_parser`), so the parser's lines are LSP's.
    Returns the :class:`Analysis`; never raises for what a text holds
    (every problem is a diagnostic)."""
    files = ws.scope(rel)
    a = Analysis(rel, files)
    if not is_rcl(ws, rel):  # an implementation file (a property test's finding): the last run's findings only
        return a
    for f in files:
        try:
            a.texts[f] = for_parser(ws.text(f, open_docs))
        except RclError as exc:
            a.add(exc.diagnostics)
            continue
        if len(a.texts[f]) > MAX_CHARS:
            a.add([error(ast.Loc(f, 1, 1), f"file too large to check as you type ({len(a.texts[f])} characters, "
                         f"limit {MAX_CHARS}); run `rclverify check {f}`", "E-lsp-size")])
            continue
        from rclverify.lang.parser import parse_text  # deferred: optional or conditional (inside a block)
        try:
            a.specs[f] = parse_text(a.texts[f], f)
        except RclError as exc:
            a.add(exc.diagnostics)
    if len(a.specs) < len(files):
        return a
    from rclverify.lang.typecheck import check  # deferred: start-up (loads lark, rclverify.core and more only when called)
    specs = [a.specs[f] for f in files]
    try:
        a.checked = check(specs)
    except RclError as exc:
        a.add(exc.diagnostics)
        return a
    from rclverify.model.system.services import unserved  # deferred: start-up (loads rclverify.lang.types, rclverify.lang.units and more only when called)
    for s in specs:
        a.add(file_warnings(s))
        a.add(lint(s))
    connections: tuple[Any, ...] = ()
    if files == ws.contracts():
        connections = _plan(ws, a)
    from rclverify.model.system.model import build, unit_diagnostics  # deferred: start-up (loads yaml, rclverify.lang.printer and more only when called)
    try:
        a.add(unit_diagnostics(a.checked, connections))
        a.model = build(a.checked, connections)
    except RclError as exc:
        a.add(exc.diagnostics)
    a.add(unserved(a.checked))
    return a


def _plan(ws: LspWorkspace, a: Analysis) -> tuple[Any, ...]:
    """The plan read from disk and resolved against ``a.checked`` (its
    errors filed under the plan); its connections, ``()`` when it does not
    load."""
    from rclverify.model.plan.load import load_plan, resolve  # deferred: start-up (loads yaml, rclverify.lang.types and more only when called)
    try:
        plan = load_plan(ws.root, ws.plan)
    except RclError as exc:
        a.add(exc.diagnostics)
        return ()
    try:
        resolve(plan, a.checked)
    except RclError as exc:
        a.add(exc.diagnostics)
    a.plan = plan
    return tuple(plan.connections)


def utf16_col(line_text: str, col: int) -> int:
    """The LSP character offset (UTF-16 code units, 0-based) of the 0-based
    code-point column ``col`` of ``line_text`` (LSP 3.17, "Position")."""
    head = line_text[:max(col, 0)]
    return len(head.encode("utf-16-le", "surrogatepass")) // 2


def lsp_range(loc: ast.Loc, lines: list[str]) -> lsp.Range:
    """The LSP range of ``loc`` in a text split into ``lines``: its end when
    the location has one, else the token that starts there."""
    line = min(max(loc.line - 1, 0), max(len(lines) - 1, 0))
    text = lines[line] if lines else ""
    col = max(loc.col - 1, 0)
    if loc.end_line and (loc.end_line, loc.end_col) > (loc.line, loc.col):
        eline = min(loc.end_line - 1, max(len(lines) - 1, 0))
        etext = lines[eline] if lines else ""
        end = lsp.Position(eline, utf16_col(etext, loc.end_col - 1))
    else:
        m = _TOKEN.match(text, col)
        end = lsp.Position(line, utf16_col(text, m.end() if m else col + 1))
    return lsp.Range(lsp.Position(line, utf16_col(text, col)), end)


def to_lsp(d: Diagnostic, lines: list[str]) -> lsp.Diagnostic:
    """The LSP form of the command line's diagnostic ``d`` (message and code
    unchanged, source ``rclverify``)."""
    sev = lsp.DiagnosticSeverity.Error if d.severity == "error" else lsp.DiagnosticSeverity.Warning
    return lsp.Diagnostic(range=lsp_range(d.loc, lines), message=d.message, severity=sev,
                          code=d.code or None, source="rclverify")
