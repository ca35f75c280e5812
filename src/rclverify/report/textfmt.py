"""Text of the HTML report: prose with code spans, ids in natural order, formulas and ids broken well.

The messages of the report dict (explanations, reasons, diagnosis
sentences, repair summaries) are written once for every format and mark
RCL text as Markdown code spans: ``guard it with `i + 1 <= 12```.  The
Markdown report keeps the backticks; the HTML report shows each span as
``<code>`` (:func:`prose`), never a literal backtick.

Ids are shown in natural order, their digit runs compared as numbers
(``p1_i0 < p2_i1 < p10_i9``; :func:`natural_key`), wherever the HTML report
lists them.

RCL formulas are folded when long (:func:`formula_html`, broken at their
connectives by :func:`formula_lines`); ids and paths may break only after
``/ . _`` (:func:`breakable`).
"""
from __future__ import annotations

import re
from typing import Any, Callable, Iterable, Sequence, TypeVar

from markupsafe import Markup, escape

__all__ = ["FOLD_CHARS", "breakable", "formula_html", "formula_lines", "natural_key", "natural_sorted",
           "natural_within", "prose"]

_T = TypeVar("_T")

_DIGITS = re.compile(r"(\d+)")
_WS = re.compile(r"\s*[\r\n]+\s*")


def natural_key(text: Any) -> tuple[Any, ...]:
    """Sort key of ``str(text)`` in natural order: the text cut into runs of
    digits and of other characters, digit runs compared as numbers (then by
    their text, so ``p01`` and ``p1`` still differ).  Keys of any two texts
    compare: string and number parts alternate from a string part on."""
    parts = _DIGITS.split(str(text))
    return tuple((int(p), p) if k % 2 else p for k, p in enumerate(parts))


def natural_sorted(items: Iterable[_T], key: Callable[[_T], Any] = str) -> list[_T]:
    """``items`` sorted by :func:`natural_key` of ``key(item)`` (stable)."""
    return sorted(items, key=lambda it: natural_key(key(it)))


def natural_within(items: Sequence[_T], group: Callable[[_T], Any], ident: Callable[[_T], Any]) -> list[_T]:
    """``items`` with each group's items in natural order of ``ident``, the
    groups in the order of their first item (the report lists rows node by
    node in the system's order; within a node, ids in natural order).
    Stable for equal ids."""
    first: dict[Any, int] = {}
    for it in items:
        first.setdefault(group(it), len(first))
    return sorted(items, key=lambda it: (first[group(it)], natural_key(ident(it))))


# A run of backticks opens a code span that the next run of the same length
# closes (CommonMark, "Code spans"); the span's text is taken as it is.
_TICKS = re.compile(r"`+")


def code_spans(text: Any) -> list[tuple[bool, str]]:
    """``text`` cut into ``[(is_code, piece)]``: each Markdown code span
    (text between two backtick runs of equal length, CommonMark "Code
    spans") without its backticks, a space stripped from both ends of a span
    that has one at each; the prose between them as it is.  A backtick run
    that no equal run closes stays in the prose."""
    s = str(text)
    out: list[tuple[bool, str]] = []
    pos = 0
    while "`" in s:
        m = _TICKS.search(s, pos)
        if m is None:
            break
        close = next((c for c in _TICKS.finditer(s, m.end()) if len(c.group(0)) == len(m.group(0))), None)
        if close is None:  # no closing run: the backticks are text
            out.append((False, s[pos:m.end()]))
            pos = m.end()
            continue
        code = s[m.end():close.start()]
        if len(code) > 2 and code.startswith(" ") and code.endswith(" ") and code.strip():
            code = code[1:-1]
        out += [(False, s[pos:m.start()]), (True, code)]
        pos = close.end()
    out.append((False, s[pos:]))
    return [(c, t) for c, t in out if t or c]


def prose(text: Any) -> Markup:
    """``text`` as HTML: escaped, each Markdown code span
    (:func:`code_spans`) as ``<code>`` without its backticks.  A backtick
    run that no equal run closes stays as text.  Line breaks are kept as they
    are (HTML folds them)."""
    return Markup("").join(Markup("<code>%s</code>") % t if c else escape(t) for c, t in code_spans(text))


def plain(text: Any) -> str:
    """``text`` without Markdown markup, for places that show no markup (an
    SVG drawing's labels and tooltips): each code span's text without its
    backticks (:func:`code_spans`), and a backtick run left open (a span cut
    short by a length limit) dropped."""
    return "".join(t if c else _TICKS.sub("", t) for c, t in code_spans(text))


#: Formulas longer than this (characters) are folded in the HTML report: the
#: first part shows, the whole formula opens below broken at its connectives.
FOLD_CHARS = 140
_CONNECTIVE = re.compile(r" (<->|->|and|or) |\| ")


def formula_lines(text: Any) -> str:
    """An RCL formula broken into lines before each connective (``and``,
    ``or``, ``->``, ``<->``) and after a quantifier's ``|``, each line
    indented by its bracket depth, so a long guarantee reads as its
    structure.  The words are unchanged: joining the lines with single
    spaces gives the text back (runs of whitespace aside)."""
    s = _WS.sub(" ", str(text)).strip()
    lines: list[str] = []
    depth = line_depth = 0
    start = i = 0
    while i < len(s):
        ch = s[i]
        m = _CONNECTIVE.match(s, i) if ch in " |" else None
        if m:
            cut = i + 1 if ch == "|" else i  # '|' ends its line, a connective starts the next
            lines.append("  " * line_depth + s[start:cut].strip())
            start, line_depth = (m.end() if ch == "|" else i + 1), depth
            i = m.end()
            continue
        if ch in "({[":
            depth += 1
        elif ch in ")}]":
            depth = max(0, depth - 1)
        i += 1
    lines.append("  " * line_depth + s[start:].strip())
    return "\n".join(line for line in lines if line.strip())


_BREAK_AFTER = re.compile(r"([/._])")


def breakable(text: Any) -> Markup:
    """``text`` (an identifier or a path) escaped, with a line-break
    opportunity (``<wbr>``) after each ``/``, ``.`` and ``_``, so a narrow
    column breaks it between its parts, never inside a word."""
    return Markup("<wbr>").join(escape(p) for p in re.split(r"(?<=[/._])", str(text)))


def formula_html(text: Any, limit: int = FOLD_CHARS) -> Markup:
    """A formula as HTML: ``<code>`` when at most ``limit`` characters, else
    a ``<details>`` whose summary is its start and which opens to the whole
    formula broken at its connectives (:func:`formula_lines`).  Text is
    escaped."""
    s = _WS.sub(" ", str(text)).strip()
    if len(s) <= limit:
        return Markup("<code>%s</code>") % s
    cut = s[:limit].rsplit(" ", 1)[0] if " " in s[:limit] else s[:limit]
    return Markup('<details class="formula"><summary><code>%s</code> &hellip;</summary>'
                  '<pre class="formula">%s</pre></details>') % (cut, formula_lines(s))
