"""The pygls language server: the protocol's handlers over the modules of
this package (docs/editor.md).

* ``textDocument/didOpen``, ``didChange``, ``didSave``, ``didClose``: the
  document is checked again (:func:`.diagnostics.analyse`) in a worker
  thread, and its diagnostics published with the last run's findings in it
  (:class:`.lastrun.LastRun`).  Checks of one scope do not pile up: while
  one runs, edits only mark the text changed and one more check follows
  with the newest text.  A check that takes longer than
  :data:`TIME_LIMIT` seconds is abandoned for that text (one ``E-lsp-time``
  diagnostic says so): the server answers other requests meanwhile.
* ``hover``, ``definition``, ``references``, ``codeAction``,
  ``formatting``, ``completion``: :mod:`.hover`, :mod:`.navigate`,
  :mod:`.actions`, :mod:`.complete`, over the last analysis in which the
  system type-checked.  A file that is not RCL (:func:`.diagnostics.is_rcl`:
  the Python a property test runs) is not checked as you type: it shows the
  last run's findings in it, and ``codeAction`` offers their checked repairs.

Every request for a document outside the workspace is refused
(:class:`.workspace.Outside`: a JSON-RPC error -32602 whose message names
the file); a notification about one is ignored with a log message.  Every
request is answered (:mod:`.rpc`): one whose params do not have the
protocol's types with -32602, an unexpected exception in a handler with a
one-line -32603 error (no traceback), and the server goes on: no text and
no request can stop it.  A position past the last line is answered as a
place where nothing stands (hover ``null``, no definition, no
references); past the end of its line it means the line's end (LSP 3.17,
"Position").

Lines are LSP's (:mod:`.lines`: ``\r\n``, ``\r`` and ``\n`` end a line);
texts go to the parser with ``\n`` line ends.
"""
from __future__ import annotations

import asyncio
import os
from pathlib import Path
from typing import Any
from urllib.parse import unquote, urlparse

from lsprotocol import types as lsp
from pygls.lsp.server import LanguageServer

from rclverify import __version__
from rclverify.tools.lsp.diagnostics import Analysis, analyse, is_rcl, to_lsp
from rclverify.tools.lsp.lastrun import LastRun
from rclverify.tools.lsp.lines import split_lines
from rclverify.tools.lsp.rpc import RclProtocol, Refused, guarded, log_one_line, one_line
from rclverify.tools.lsp.workspace import PLAN, LspWorkspace, Outside
from rclverify.tools.lsp.actions import format_edits, quick_fixes
from rclverify.tools.lsp.index import symbol_at
from rclverify.tools.lsp.navigate import definition, references
from rclverify.tools.lsp.complete import MessageTypes, completions
from pygls.exceptions import FeatureRequestError
from rclverify.lang.ast import Loc
from rclverify.lang.errors import error

#: Seconds a check of the text as you type may take before it is abandoned.
TIME_LIMIT = 5.0
#: Seconds between two looks at the last run's SARIF log.
POLL = 1.0


class RclServer(LanguageServer):
    """The RCL language server of one workspace (rooted at the client's
    workspace folder, see :mod:`.workspace`)."""

    def __init__(self) -> None:
        super().__init__("rclverify", __version__, text_document_sync_kind=lsp.TextDocumentSyncKind.Full,
                         protocol_cls=RclProtocol)
        self.ws = LspWorkspace(Path(os.getcwd()))
        self.last = LastRun(self.ws.root)
        self.analyses: dict[tuple[str, ...], Analysis] = {}
        self.good: dict[tuple[str, ...], Analysis] = {}
        self._wanted: dict[tuple[str, ...], int] = {}
        self._running: set[tuple[str, ...]] = set()
        self._published: set[str] = set()
        self.messages: Any = None

    def report_server_error(self, error: Exception, source: Any) -> None:
        """A fault outside a request (a notification pygls could not read or
        apply, e.g. ``didChange`` of a document never opened): one line in
        the editor's log (``window/logMessage``), not a pop-up; a request's
        fault is in its answer (:mod:`.rpc`)."""
        if source is FeatureRequestError:
            return
        self.window_log_message(lsp.LogMessageParams(
            lsp.MessageType.Error, one_line(f"the server could not handle a message ({type(error).__name__}: {error})")))

    # -- the workspace ---------------------------------------------------------------------------
    def set_root(self, root: Path, plan: str = PLAN) -> None:
        """Serve the workspace at ``root`` from now on."""
        self.ws = LspWorkspace(root, plan)
        self.last = LastRun(self.ws.root)

    def rel(self, uri: str) -> str:
        """The root-relative path of ``uri``; raises :class:`Refused` outside the workspace."""
        try:
            return self.ws.rel(uri)
        except Outside as exc:
            raise Refused(str(exc)) from None

    def open_texts(self) -> dict[str, str]:
        """The editor's text of every open document of the workspace, by root-relative path."""
        out = {}
        for doc in list(self.workspace.text_documents.values()):
            try:
                out[self.ws.rel(doc.uri)] = doc.source
            except Outside:
                continue
        return out

    def scope_of(self, rel: str) -> tuple[str, ...]:
        """The files checked with ``rel``; for the plan, the plan's system."""
        if rel == self.ws.plan:
            return self.ws.contracts() or (rel,)
        return self.ws.scope(rel)

    def analysis(self, rel: str, good: bool = True) -> Analysis | None:
        """The last analysis of ``rel``'s scope (``good``: the last in which it type-checked)."""
        return (self.good if good else self.analyses).get(self.scope_of(rel))

    # -- checking as you type --------------------------------------------------------------------
    async def check(self, rel: str) -> None:
        """Check ``rel``'s scope with the newest texts and publish (see the module docstring)."""
        key = self.scope_of(rel)
        self._wanted[key] = self._wanted.get(key, 0) + 1
        if key in self._running:
            return
        self._running.add(key)
        try:
            while True:
                wanted = self._wanted[key]
                await self._check_once(key)
                if self._wanted[key] == wanted:
                    break
        finally:
            self._running.discard(key)

    async def _check_once(self, key: tuple[str, ...]) -> None:
        texts = self.open_texts()
        first = key[0]
        loop = asyncio.get_running_loop()
        fut = loop.run_in_executor(self.thread_pool, analyse, self.ws, first, texts)
        try:
            a = await asyncio.wait_for(asyncio.shield(fut), TIME_LIMIT)
        except asyncio.TimeoutError:
            a = Analysis(first, key)
            for f in key:
                if f in texts:
                    a.add([error(Loc(f, 1, 1), f"checking took longer than {TIME_LIMIT:g} s; not checked as you type "
                                 f"(run `rclverify check {f}`)", "E-lsp-time")])
        except Exception as exc:  # a fault of the server, not of the text: said where the user looks
            a = Analysis(first, key)
            a.add([error(Loc(first, 1, 1), f"the language server could not check this text ({type(exc).__name__}: "
                         f"{exc}); `rclverify check {first}` checks it", "E-lsp-internal")])
        self.analyses[key] = a
        if a.checked is not None:
            self.good[key] = a
        self.publish(a, texts)

    async def watch_last_run(self) -> None:
        """Publish again every analysed scope's diagnostics when a run wrote
        a new SARIF log (checked every :data:`POLL` seconds), so that the
        findings of a run that ends while the file is open appear without an edit."""
        seen = self.last.written()
        while True:
            await asyncio.sleep(POLL)
            now = self.last.written()
            if now != seen:
                seen = now
                try:
                    texts = self.open_texts()
                    for a in list(self.analyses.values()):
                        self.publish(a, texts)
                except Exception as exc:  # a fault of the server: said in one line, and the watch goes on
                    self.window_log_message(lsp.LogMessageParams(
                        lsp.MessageType.Error, one_line(f"publishing the last run's findings failed: {exc!r}")))

    def publish(self, a: Analysis, texts: dict[str, str]) -> None:
        """Publish ``a``'s diagnostics for every file it has some for and every
        open file of its scope (and the plan), with the last run's findings
        in each; clear the files published before that have none now."""
        files = set(a.diagnostics) | (set(a.files) & set(texts)) | ({self.ws.plan} & set(texts))
        files |= {f for f in self._published if f in a.files or f == self.ws.plan}
        for f in sorted(files):
            text = texts.get(f)
            if text is None:
                text = self.ws.shown_text(f)
            lines = split_lines(text)
            diags = [to_lsp(d, lines) for d in a.diagnostics.get(f, [])]
            fresh = self.last.fresh(f, texts.get(f), self.ws.disk_text(f))
            diags += self.last.diagnostics(f, text, fresh)
            self._published.add(f)
            self.text_document_publish_diagnostics(lsp.PublishDiagnosticsParams(uri=self.ws.uri(f), diagnostics=diags))


SERVER = RclServer()


def _root_of(params: lsp.InitializeParams) -> Path | None:
    uri = None
    if params.workspace_folders:
        uri = params.workspace_folders[0].uri
    elif params.root_uri:
        uri = params.root_uri
    try:
        if uri:
            parsed = urlparse(uri)
            if parsed.scheme == "file" and "\x00" not in unquote(parsed.path):
                return Path(unquote(parsed.path))
        if params.root_path and "\x00" not in params.root_path:
            return Path(params.root_path)
    except ValueError:  # a malformed URI: the server's working directory stays the root
        pass
    return None


def _is_dir(p: Path) -> bool:
    try:
        return p.is_dir()
    except (OSError, ValueError):
        return False


@SERVER.feature(lsp.INITIALIZE)
@guarded(lsp.INITIALIZE)
def _initialize(ls: RclServer, params: lsp.InitializeParams) -> None:
    root = _root_of(params)
    opts = params.initialization_options if isinstance(params.initialization_options, dict) else {}
    plan = str(opts.get("plan") or PLAN)
    if root is not None and _is_dir(root):
        ls.set_root(root, plan)


@SERVER.feature(lsp.INITIALIZED)
@guarded(lsp.INITIALIZED, notification=True)
def _initialized(ls: RclServer, params: lsp.InitializedParams) -> None:
    asyncio.ensure_future(ls.watch_last_run())


def _notified(ls: RclServer, uri: str) -> str | None:
    try:
        return ls.ws.rel(uri)
    except Outside as exc:
        ls.window_log_message(lsp.LogMessageParams(lsp.MessageType.Warning, str(exc)))
        return None


async def _check_uri(ls: RclServer, uri: str) -> None:
    """Check the document ``uri`` again (opened, changed or saved) when it is in the workspace."""
    rel = _notified(ls, uri)
    if rel is not None:
        await ls.check(rel)


@SERVER.feature(lsp.TEXT_DOCUMENT_DID_OPEN)
@guarded(lsp.TEXT_DOCUMENT_DID_OPEN, notification=True)
async def _did_open(ls: RclServer, params: lsp.DidOpenTextDocumentParams) -> None:
    await _check_uri(ls, params.text_document.uri)


@SERVER.feature(lsp.TEXT_DOCUMENT_DID_CHANGE)
@guarded(lsp.TEXT_DOCUMENT_DID_CHANGE, notification=True)
async def _did_change(ls: RclServer, params: lsp.DidChangeTextDocumentParams) -> None:
    await _check_uri(ls, params.text_document.uri)


@SERVER.feature(lsp.TEXT_DOCUMENT_DID_SAVE)
@guarded(lsp.TEXT_DOCUMENT_DID_SAVE, notification=True)
async def _did_save(ls: RclServer, params: lsp.DidSaveTextDocumentParams) -> None:
    await _check_uri(ls, params.text_document.uri)


@SERVER.feature(lsp.TEXT_DOCUMENT_DID_CLOSE)
@guarded(lsp.TEXT_DOCUMENT_DID_CLOSE, notification=True)
def _did_close(ls: RclServer, params: lsp.DidCloseTextDocumentParams) -> None:
    rel = _notified(ls, params.text_document.uri)
    if rel is not None and rel in ls._published:
        ls._published.discard(rel)
        ls.text_document_publish_diagnostics(lsp.PublishDiagnosticsParams(uri=params.text_document.uri, diagnostics=[]))


def text_of(ls: RclServer, uri: str) -> tuple[str, str]:
    """``(root-relative path, text)`` of the document ``uri`` (the editor's,
    else the saved one); raises :class:`Refused` outside the workspace."""
    rel = ls.rel(uri)
    doc = ls.workspace.text_documents.get(unquote(uri))  # pygls files open documents under the unquoted URI
    if doc is not None:
        return rel, doc.source
    return rel, ls.ws.disk_text(rel) or ""


@SERVER.feature(lsp.TEXT_DOCUMENT_FORMATTING)
@guarded(lsp.TEXT_DOCUMENT_FORMATTING)
def _formatting(ls: RclServer, params: lsp.DocumentFormattingParams) -> list[lsp.TextEdit] | None:
    rel, text = text_of(ls, params.text_document.uri)
    return format_edits(rel, text)


@SERVER.feature(lsp.TEXT_DOCUMENT_CODE_ACTION,
                lsp.CodeActionOptions(code_action_kinds=[lsp.CodeActionKind.QuickFix]))
@guarded(lsp.TEXT_DOCUMENT_CODE_ACTION)
def _code_action(ls: RclServer, params: lsp.CodeActionParams) -> list[lsp.CodeAction]:
    rel, _text = text_of(ls, params.text_document.uri)
    return quick_fixes(ls.ws, ls.open_texts(), rel, params, ls.last)


def _symbol(ls: RclServer, uri: str, pos: lsp.Position) -> tuple[Any, Any] | None:
    """``(analysis, symbol)`` at ``pos`` of ``uri``, ``None`` when nothing known stands there."""
    rel, text = text_of(ls, uri)
    a = ls.analysis(rel) or ls.analysis(rel, good=False)
    if a is None:
        return None
    sym = symbol_at(a, rel, text, pos.line, pos.character, plan=rel == ls.ws.plan)
    return (a, sym) if sym is not None else None


@SERVER.feature(lsp.TEXT_DOCUMENT_HOVER)
@guarded(lsp.TEXT_DOCUMENT_HOVER)
def _hover(ls: RclServer, params: lsp.HoverParams) -> lsp.Hover | None:
    from rclverify.tools.lsp.hover import hover  # deferred: start-up (loads jinja2, rclverify.tools.lsp and more only when called)
    found = _symbol(ls, params.text_document.uri, params.position)
    return hover(found[0], found[1], ls.last.report()) if found else None


@SERVER.feature(lsp.TEXT_DOCUMENT_DEFINITION)
@guarded(lsp.TEXT_DOCUMENT_DEFINITION)
def _definition(ls: RclServer, params: lsp.DefinitionParams) -> list[lsp.Location] | None:
    found = _symbol(ls, params.text_document.uri, params.position)
    return definition(ls.ws, found[0], ls.open_texts(), found[1]) or None if found else None


@SERVER.feature(lsp.TEXT_DOCUMENT_REFERENCES)
@guarded(lsp.TEXT_DOCUMENT_REFERENCES)
def _references(ls: RclServer, params: lsp.ReferenceParams) -> list[lsp.Location] | None:
    found = _symbol(ls, params.text_document.uri, params.position)
    if not found:
        return None
    return references(ls.ws, found[0], ls.open_texts(), found[1], params.context.include_declaration) or None


@SERVER.feature(lsp.TEXT_DOCUMENT_COMPLETION, lsp.CompletionOptions(trigger_characters=[".", "[", " "]))
@guarded(lsp.TEXT_DOCUMENT_COMPLETION)
def _completion(ls: RclServer, params: lsp.CompletionParams) -> lsp.CompletionList:
    rel, text = text_of(ls, params.text_document.uri)
    if not is_rcl(ls.ws, rel):  # the Python a property test runs: no RCL keywords in it
        return lsp.CompletionList(is_incomplete=False, items=[])
    if ls.messages is None or ls.messages.root != ls.ws.root:
        ls.messages = MessageTypes(ls.ws.root)
    a = ls.analysis(rel) or ls.analysis(rel, good=False)
    items = completions(a, rel, text, params.position.line, params.position.character, ls.messages)
    return lsp.CompletionList(is_incomplete=False, items=items)


def serve(root: Path | None = None, plan: str = PLAN) -> int:
    """Serve over stdio until the client exits (``root``: the workspace when
    the client names none); returns the exit code 0."""
    if root is not None:
        SERVER.set_root(root, plan)
    log_one_line()
    SERVER.start_io()
    return 0
