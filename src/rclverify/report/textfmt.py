"""Text of the HTML report: prose with code spans, and ids in natural order.

The messages of the report dict (explanations, reasons, diagnosis
sentences, repair summaries) are written once for every format and mark
RCL text as Markdown code spans: ``guard it with `i + 1 <= 12```.  The
Markdown report keeps the backticks; the HTML report shows each span as
``<code>`` (:func:`prose`), never a literal backtick (issue 30, item 6).

Ids are shown in natural order, their digit runs compared as numbers
(``p1_i0 < p2_i1 < p10_i9``; :func:`natural_key`), wherever the HTML report
lists them.
"""
from __future__ import annotations

import re
from typing import Any, Callable, Iterable, Sequence, TypeVar

from markupsafe import Markup, escape

__all__ = ["natural_key", "natural_sorted", "natural_within", "prose"]

_T = TypeVar("_T")

_DIGITS = re.compile(r"(\d+)")


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


def prose(text: Any) -> Markup:
    """``text`` as HTML: escaped, each Markdown code span (text between two
    backtick runs of equal length) as ``<code>`` without its backticks, a
    space stripped from both ends of a span that has one at each (as
    CommonMark does).  A backtick run that no equal run closes stays as
    text.  Line breaks are kept as they are (HTML folds them)."""
    s = str(text)
    if "`" not in s:
        return Markup(escape(s))
    out: list[str] = []
    pos = 0
    while True:
        m = _TICKS.search(s, pos)
        if m is None:
            break
        close = next((c for c in _TICKS.finditer(s, m.end()) if len(c.group(0)) == len(m.group(0))), None)
        if close is None:  # no closing run: the backticks are text
            out.append(escape(s[pos:m.end()]))
            pos = m.end()
            continue
        code = s[m.end():close.start()]
        if len(code) > 2 and code.startswith(" ") and code.endswith(" ") and code.strip():
            code = code[1:-1]
        out.append(escape(s[pos:m.start()]))
        out.append(Markup("<code>%s</code>") % code)
        pos = close.end()
    out.append(escape(s[pos:]))
    return Markup("").join(out)
