"""Syntax errors of the RCL parser worded for a person: a lark exception
becomes one located ``E-syntax`` diagnostic, ``file:line:col: error:
unexpected X; expected one of A, B, ...``, whose expected set is what the
LALR(1) automaton would accept at that point (keywords included), with an
unterminated ``/*`` comment and the end of input named as such.
"""
from __future__ import annotations

import re
from typing import Any, Callable, Iterable

from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken
from lark.parsers.lalr_analysis import Shift

from rclverify.lang import ast
from rclverify.lang.errors import RclError, error


def _accepts(state: Any) -> set[str] | None:
    """Terminals the LALR automaton accepts in parser state ``state``.

    The expected set lark attaches to an error is either the contextual
    lexer's terminal set (which omits keywords the NAME pattern absorbs, and
    may include follow tokens of merged states) or the raw action-table row.
    Simulating the reductions for each candidate terminal, without touching the
    value stack, gives exactly the tokens that would let the parse continue.
    Returns ``None`` when ``state`` is not a lark ``ParserState``.
    """
    try:
        states = state.parse_conf.states
        end_state = state.parse_conf.end_state
        base_stack = list(state.state_stack)
    except AttributeError:
        return None
    accepted: set[str] = set()
    for term in states[base_stack[-1]]:
        if not term.isupper():
            continue
        stack = list(base_stack)
        while True:
            entry = states[stack[-1]].get(term)
            if entry is None:
                break
            action, arg = entry
            if action is Shift:
                accepted.add(term)
                break
            size = len(arg.expansion)
            if size:
                del stack[-size:]
            stack.append(states[stack[-1]][arg.origin.name][1])
            if term == "$END" and stack[-1] == end_state:
                accepted.add(term)
                break
    return accepted


def _unterminated_comment(text: str) -> int | None:
    """Offset of a ``/*`` that is never closed, or ``None``."""
    for m in _COMMENT_SCAN.finditer(text):
        if m.group(0) == "/*":
            return m.start()
    return None


_COMMENT_SCAN = re.compile(r"//[^\n]*|/\*.*?\*/|/\*", re.S)


def _line_col(text: str, offset: int) -> tuple[int, int]:
    line = text.count("\n", 0, offset) + 1
    return line, offset - (text.rfind("\n", 0, offset) + 1) + 1


def syntax_error(exc: UnexpectedInput, file: str, text: str, dline: int, dcol: int,
                 describe: Callable[[str], str]) -> RclError:
    """Turn a lark exception raised on ``text`` (the text of ``file``, its
    first line shifted by ``dline`` lines and ``dcol`` columns) into a
    located ``E-syntax`` diagnostic: ``unexpected X; expected one of A, B,
    ...`` at the offending token, each terminal named by ``describe``."""
    line = getattr(exc, "line", 0) or 0
    col = getattr(exc, "column", 0) or 0
    expected: Iterable[str] | None = _accepts(getattr(exc, "state", None))
    if expected is None:
        expected = getattr(exc, "expected", None) or getattr(exc, "allowed", None)
    hint = ""
    open_comment = _unterminated_comment(text)
    pos = getattr(exc, "pos_in_stream", None)
    if open_comment is not None and (pos is None or pos >= open_comment):
        line, col = _line_col(text, open_comment)
        msg, expected = "unterminated /* comment (no closing */)", None
    elif isinstance(exc, UnexpectedEOF) or (isinstance(exc, UnexpectedToken) and exc.token.type == "$END"):
        line, col = _line_col(text, len(text.rstrip()))
        msg = "unexpected end of input"
    elif isinstance(exc, UnexpectedToken):
        msg = f"unexpected {exc.token.value!r}"
        if exc.token.value == "=" and expected and "CMP_OP" in expected:
            hint = " (equality is written '==')"
    elif isinstance(exc, UnexpectedCharacters):
        msg = f"unexpected character {exc.char!r}"
    else:  # pragma: no cover - lark has no other subclasses today
        msg, expected = str(exc).splitlines()[0], None
    if expected:
        names = sorted({describe(t) for t in expected})
        if names:
            msg += "; expected " + (names[0] if len(names) == 1 else "one of " + ", ".join(names))
    msg += hint
    if line == 1:
        col += dcol
    return RclError([error(ast.Loc(file, line + dline, col), msg, "E-syntax")])
