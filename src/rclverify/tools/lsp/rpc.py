"""Every request answered, in one sentence: the server's JSON-RPC rules.

pygls turns each message into lsprotocol's types as it reads it (a
``json.loads`` object hook).  When a request's params do not fit their
type (a position whose line is 2^31 or negative: LSP's ``uinteger`` is
0..2^31-1, "Base Types"; a field missing) the hook raises, the read loop
logs the error and shows it out of band, and the request's id is lost: the
client waits for ever.  :class:`RclProtocol` answers such a request with a
JSON-RPC error -32602 (invalid params, JSON-RPC 2.0 section 5.1) whose
message names the method and the fields at fault; a request after
``shutdown`` (which pygls drops) with -32600 (LSP 3.17, "Shutdown
Request").

When a handler raises, pygls answers -32603 with the exception's text and
its traceback in ``data``.  :func:`guarded` wraps every feature handler:
a :class:`~pygls.exceptions.JsonRpcException` the handler raises on purpose
(:class:`Refused`, :class:`Failed`) goes out as it is, with its message on
one line; any other exception becomes a one-line -32603 error with no
``data``, and the server goes on serving.  A notification handler that
fails logs one line (``window/logMessage``) instead.  What the server
writes to its standard error (the editor's log of the server) is one line
per record too (:func:`log_one_line`): pygls logs every failed request
with its traceback, which no user should have to read.
"""
from __future__ import annotations

import asyncio
import functools
import logging
import re
import sys
from typing import Any, Callable, TypeVar

from lsprotocol import types as lsp
from pygls.exceptions import JsonRpcException
from pygls.protocol import LanguageServerProtocol

log = logging.getLogger(__name__)

F = TypeVar("F", bound=Callable[..., Any])

#: Characters of a message kept at most (a URI in it may be long).
MAX_MESSAGE = 300


class Refused(JsonRpcException):
    """A request the server will not serve, e.g. about a document outside the
    workspace (JSON-RPC error -32602, invalid params), with the reason as its message."""

    CODE = -32602


class Failed(JsonRpcException):
    """A request that was well formed but cannot be served, e.g. formatting a
    text that does not parse (LSP 3.17 ``RequestFailed``, -32803), with the
    reason as its message."""

    CODE = -32803


def one_line(text: str) -> str:
    """``text`` on one line: control characters (a NUL, a line end) written as
    escapes, runs of spaces shortened, at most :data:`MAX_MESSAGE` characters."""
    out = "".join(c if c.isprintable() or c == " " else repr(c)[1:-1] for c in text)
    out = re.sub(r"\s+", " ", out).strip()
    return out if len(out) <= MAX_MESSAGE else out[:MAX_MESSAGE - 3] + "..."


def _field(path: str) -> str:
    """``$.params.text_document.uri`` -> ``textDocument.uri`` (the protocol's names)."""
    path = re.sub(r"^\$\.?(params\.?)?", "", path)
    return re.sub(r"_([a-z])", lambda m: m.group(1).upper(), path) or "params"


def invalid_params_message(method: str, exc: BaseException | None) -> str:
    """The one sentence of the -32602 answer to a ``method`` request whose
    params did not fit their type (``exc``: the converter's error)."""
    why: list[str] = []
    try:
        import cattrs  # deferred: optional or conditional (inside a block)
        for e in cattrs.transform_error(exc) if exc is not None else ():
            what, _, where = e.partition(" @ ")
            why.append(f"{_field(where)}: {what}")
    except Exception:  # not a cattrs error: the message alone
        why = []
    detail = "; ".join(why) if why else "they do not have the protocol's types"
    if re.search(r"position|range|line|character", detail, re.I):
        detail += "; LSP positions are integers 0..2147483647"
    return one_line(f"{method}: invalid params ({detail})")


class OneLineFormatter(logging.Formatter):
    """A log record on one line: level, logger, message and, for an
    exception, its type and text (never its traceback)."""

    def format(self, record: logging.LogRecord) -> str:
        msg = record.getMessage().split("\n", 1)[0]  # pygls puts a traceback in some messages
        exc = record.exc_info[1] if record.exc_info else None
        if exc is not None:
            msg += f" ({type(exc).__name__}: {exc})"
        return one_line(f"{record.levelname.lower()}: {record.name}: {msg}")


def log_one_line(level: int = logging.WARNING) -> None:
    """Log records of ``level`` and above to standard error with
    :class:`OneLineFormatter` (the server process only: called by :func:`.server.serve`)."""
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(OneLineFormatter())
    root = logging.getLogger()
    root.handlers[:] = [handler]
    root.setLevel(level)


class _Invalid:
    """A request whose params did not fit their type: its id and the answer's message."""

    jsonrpc = "2.0"

    def __init__(self, msg_id: int | str, message: str) -> None:
        self.id = msg_id
        self.message = message


class RclProtocol(LanguageServerProtocol):
    """pygls' protocol, answering the requests it cannot read (module docstring)."""

    def structure_message(self, data: dict[str, Any]) -> Any:
        try:
            return super().structure_message(data)
        except JsonRpcException as exc:
            msg_id = data.get("id") if isinstance(data, dict) else None
            if isinstance(msg_id, (int, str)) and not isinstance(msg_id, bool) and isinstance(data.get("method"), str):
                return _Invalid(msg_id, invalid_params_message(data["method"], exc.__cause__))
            raise

    def handle_message(self, message: Any) -> None:
        if isinstance(message, _Invalid):
            log.warning("%s", message.message)
            self._send_response(message.id, error=lsp.ResponseError(Refused.CODE, message.message))
            return
        method = getattr(message, "method", None)
        if self._shutdown and method not in (None, lsp.EXIT) and getattr(message, "id", None) is not None:
            # LSP 3.17 "Shutdown Request": requests after it are answered InvalidRequest (pygls drops them)
            self._send_response(message.id, error=lsp.ResponseError(
                -32600, f"{method}: the server is shutting down (it received `shutdown`)"))
            return
        super().handle_message(message)


def _answer(method: str, exc: Exception) -> JsonRpcException:
    """The error a request ``method`` is answered with when its handler raised ``exc``."""
    if isinstance(exc, JsonRpcException):
        return JsonRpcException(one_line(exc.message or type(exc).__name__), exc.code)
    return JsonRpcException(one_line(f"{method}: internal error of the language server ({type(exc).__name__}: "
                                     f"{exc}); it goes on serving"), -32603)


def guarded(method: str, notification: bool = False) -> Callable[[F], F]:
    """Wrap the handler of ``method`` (a function ``(ls, params)``, plain or
    ``async``) as the module docstring says; ``notification``: it answers
    nothing, so a failure is logged (one line) instead."""
    def wrap(fn: F) -> F:
        def failed(ls: Any, exc: Exception) -> None:
            answer = _answer(method, exc)
            if notification:
                log.warning("%s", answer.message)
                ls.window_log_message(lsp.LogMessageParams(lsp.MessageType.Error, answer.message))
                return None
            raise answer from None  # pygls logs it (one line, see log_one_line) and answers with it

        if asyncio.iscoroutinefunction(fn):
            @functools.wraps(fn)
            async def run_async(ls: Any, params: Any) -> Any:
                try:
                    return await fn(ls, params)
                except Exception as exc:
                    return failed(ls, exc)
            return run_async  # type: ignore[return-value]

        @functools.wraps(fn)
        def run(ls: Any, params: Any) -> Any:
            try:
                return fn(ls, params)
            except Exception as exc:
                return failed(ls, exc)
        return run  # type: ignore[return-value]
    return wrap

