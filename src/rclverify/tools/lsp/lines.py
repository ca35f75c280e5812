"""Lines as the Language Server Protocol counts them.

LSP 3.17 ("Text Documents", "Position"): a position is a 0-based line
and a character offset in that line; so that client and server split a
text into the same lines, the protocol names three end-of-line
sequences, ``\\r\\n``, ``\\n`` and ``\\r`` (a lone carriage return ends a
line too; U+2028, form feed and the other breaks Python's
``str.splitlines`` knows do not).  The RCL parser (lark) counts ``\\n``
only, so every text the server hands to the parser or maps positions in
is first brought to ``\\n`` line ends with :func:`normalize`: that keeps
each line's characters and the number of lines, so a (line, column) of
the normalized text is the same (line, column) of the editor's text.

Edits sent back (formatting, quick fixes) insert text with the
document's own line end (:func:`eol_of`, :func:`with_eol`), so a CRLF or
CR file stays one.
"""
from __future__ import annotations

import re

_BREAK = re.compile(r"\r\n|\r|\n")


def normalize(text: str) -> str:
    """``text`` with every ``\\r\\n`` and lone ``\\r`` replaced by ``\\n``
    (same lines, same characters in each line)."""
    if "\r" not in text:
        return text
    return text.replace("\r\n", "\n").replace("\r", "\n")


def split_lines(text: str) -> list[str]:
    """The lines of ``text`` without their line ends, split where LSP splits
    (``\\r\\n``, ``\\r``, ``\\n``); a text ending in a line end has an empty
    last line, ``""`` is one empty line."""
    return _BREAK.split(text)


def for_parser(text: str) -> str:
    """``text`` as the server hands it to the RCL parser: :func:`normalize`\\ d,
    and a leading byte-order mark (U+FEFF, which the parser drops and so
    would shift the columns of line 1 by one) replaced by a space, which the
    parser skips as it does the mark but counts as the editor does."""
    text = normalize(text)
    return " " + text[1:] if text.startswith("\ufeff") else text


def eol_of(text: str) -> str:
    """The line end of ``text``: the one it uses most (``\\r\\n``, ``\\n`` or
    ``\\r``; on a tie, the first to occur); ``\\n`` when it has none."""
    counts: dict[str, int] = {}
    for m in _BREAK.finditer(text):
        counts[m.group()] = counts.get(m.group(), 0) + 1
    if not counts:
        return "\n"
    best = max(counts.values())
    return next(e for e in counts if counts[e] == best)  # dicts keep first-seen order


def with_eol(text: str, eol: str) -> str:
    """``text`` (any line ends) with every line end written as ``eol``."""
    return _BREAK.sub(lambda _m: eol, text)
