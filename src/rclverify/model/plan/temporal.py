"""Temporal requirement statements: a small layer above the RCL formula.

Syntax (docs/requirements.md, "Temporal requirements"), read only in a
requirement's ``formal:`` so that RCL's grammar and every contract keep
their meaning::

    T ::= always T | eventually T | eventually[<= N] T
        | next T | previous T | F until F | F -> T | F

where ``F`` is a state formula read by :func:`rclverify.model.plan.formal.parse_formal`
(``Node.in.x``/``Node.out.y``).  The operators bind like prefixes, ``until``
splits the text at its first occurrence outside brackets.  An operand is
parsed from the statement's text with everything else blanked out by
spaces, so every line and column the RCL parser and type checker report is
the one in the plan.  A statement with no temporal operator is a
:class:`~rclverify.model.plan.formal.Formal`, unchanged.

Errors (a bound that is not a natural number in the digits 0-9, an empty
operand) are located :class:`~rclverify.lang.errors.RclError` diagnostics
(``E-syntax``); a bound above :data:`MAX_BOUND` is ``E-temporal``.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any, Mapping

from rclverify.lang.errors import RclError, error
from rclverify.lang.types import Checked, Type
from rclverify.model.plan.formal import Formal, Source, _loc_at, parse_formal

_PREFIX = re.compile(r"\s*(always|eventually|next|previous)\b")
_BOUND = re.compile(r"\s*\[\s*<=\s*([^\]]*)\]")
_DIGITS = re.compile(r"[0-9]+", re.ASCII)
#: The largest N of ``eventually[<= N]``: deciding it unrolls the composed
#: system N steps and, where no run stopping before the goal is excluded by
#: induction, searches such runs step by step (cost growing with N squared;
#: docs/requirements.md, "Limits").
MAX_BOUND = 1000
_UNTIL = re.compile(r"(?<![A-Za-z0-9_.'])until(?![A-Za-z0-9_'])")


@dataclass(frozen=True)
class Temporal:
    """A temporal statement: ``op`` is ``always`` | ``eventually`` |
    ``next`` | ``previous`` | ``until`` | ``->`` (a state formula implying a
    temporal statement: the response pattern); ``args`` its one or two operands
    (each a :class:`Temporal` or a :class:`Formal`); ``bound`` the step
    bound of ``eventually[<= N]`` (None: unbounded)."""

    op: str
    args: tuple["Temporal | Formal", ...]
    bound: int | None = None


def _blank(text: str, start: int, end: int) -> str:
    """``text`` with everything outside [start, end) replaced by spaces
    (newlines kept), so offsets inside are unchanged."""
    def keep(s: str) -> str:
        return re.sub(r"[^\n]", " ", s)

    return keep(text[:start]) + text[start:end] + keep(text[end:])


def _until_at(text: str, start: int, end: int) -> int | None:
    """Offset of the first ``until`` in [start, end) outside brackets."""
    for m in _UNTIL.finditer(text, start, end):
        seg = text[start:m.start()]
        if sum(seg.count(c) for c in "([{") == sum(seg.count(c) for c in ")]}"):
            return m.start()
    return None


def _response_at(text: str, start: int, end: int) -> int | None:
    """Offset of the first ``->`` in [start, end) outside brackets whose
    right side begins with a temporal operator (the response pattern)."""
    depth = 0
    for k in range(start, end - 1):
        depth += text[k] in "([{"
        depth -= text[k] in ")]}"
        if depth == 0 and text[k:k + 2] == "->" and (k == start or text[k - 1] != "<") \
                and _PREFIX.match(text, k + 2, end) is not None:
            return k
    return None


def _closing(text: str, i: int, end: int) -> int | None:
    """Offset of the bracket closing the one at ``i`` (before ``end``)."""
    depth = 0
    for k in range(i, end):
        depth += text[k] in "([{"
        depth -= text[k] in ")]}"
        if depth == 0:
            return k
    return None


def parse_temporal(src: Source, checked: Checked, what: str = "requirement",
                   states: Mapping[tuple[str, str], Type] | None = None) -> Temporal | Formal:
    """Parse and type-check a possibly temporal statement (module docstring).

    ``states`` are the plan's declared state variables (:mod:`.state`),
    readable as ``Node.state.v`` in the operands of a temporal operator
    only.  Returns a :class:`Temporal`, or a :class:`Formal` if it has no
    temporal operator; raises :class:`RclError` with located diagnostics.
    """
    out = _parse(src, 0, len(src.text), checked, what, states or {})
    if isinstance(out, Formal) and states:  # a state requirement: Node.state.v is an error there
        return parse_formal(src, checked, what)
    return out


def operands(t: "Temporal | Formal") -> list[Formal]:
    """The state formulas of a statement, left to right."""
    if isinstance(t, Formal):
        return [t]
    return [f for a in t.args for f in operands(a)]


def _parse(src: Source, start: int, end: int, checked: Checked, what: str,
           states: Mapping[tuple[str, str], Type]) -> Temporal | Formal:
    text = src.text
    if not text[start:end].strip():
        raise RclError([error(_loc_at(src, start), f"{what}: a temporal operator needs an operand",
                              "E-syntax")])
    i = start + len(text[start:end]) - len(text[start:end].lstrip())
    j = start + len(text[start:end].rstrip())
    if text[i] == "(" and _closing(text, i, j) == j - 1:
        return _parse(src, i + 1, j - 1, checked, what, states)
    m = _PREFIX.match(text, start, end)
    if m:
        op, pos, bound = m.group(1), m.end(), None
        if op == "eventually":
            b = _BOUND.match(text, pos, end)
            if b:
                bound, pos = _bound(src, b, what), b.end()
        return Temporal(op, (_parse(src, pos, end, checked, what, states),), bound)
    imp = _response_at(text, start, end)
    if imp is not None:  # `P -> eventually[<= N] Q` / `P -> next Q`: the response pattern (under always)
        rhs = _parse(src, imp + 2, end, checked, what, states)
        return Temporal("->", (_parse(src, start, imp, checked, what, states), rhs))
    u = _until_at(text, start, end)
    if u is not None:
        return Temporal("until", (_parse(src, start, u, checked, what, states),
                                  _parse(src, u + 5, end, checked, what, states)))
    leaf = src if start == 0 and end == len(text) else Source(_blank(text, start, end), src.line, src.col, src.file)
    try:
        return parse_formal(leaf, checked, what, states)
    except RclError as exc:
        nested = _NESTED.search(text, start, end)
        if nested is not None:  # `always (P -> eventually Q)`: an operator inside a state formula
            raise RclError([error(_loc_at(src, nested.start(1)), f"{what}: {nested.group(1)!r} inside a state "
                                  "formula is not decided; write always F, always next F, eventually F, "
                                  "eventually[<= N] F, next F, F until G, always (F -> eventually[<= N] G) or "
                                  "always (F -> next G) with F, G state formulas (docs/requirements.md, "
                                  "Temporal requirements)", "E-temporal")]) from None
        slip = _misspelled(src, start, end, checked, what)
        if slip is None:
            raise
        raise RclError([slip]) from None


#: A temporal operator standing as a word inside what should be a state formula.
_NESTED = re.compile(r"(?<![\w.'])(always|eventually|next|previous|until)(?![\w.'(])")


#: The temporal operators, for the suggestion of a misspelled one.
OPERATORS = ("always", "eventually", "next", "previous", "until")
_WORD = re.compile(r"(?<![\w.'])([A-Za-z_][A-Za-z0-9_]*)(?![\w.'(])")
_RCL_WORDS = {"and", "or", "not", "in", "forall", "exists", "TRUE", "FALSE", "true", "false"}


def _misspelled(src: Source, start: int, end: int, checked: Checked, what: str) -> Any:
    """A located error naming the first word of ``src.text[start:end]``
    that is no name of the system and reads like a misspelled temporal
    operator (``eventualy``: did you mean ``eventually``?), or ``None``."""
    known = set(checked.env.constants) | set(checked.env.enum_values) | set(checked.env.ctors) | _RCL_WORDS
    segment = src.text[start:end]
    first = start + len(segment) - len(segment.lstrip())
    for m in _WORD.finditer(src.text, start, end):
        word = m.group(1)
        if word in known or word in OPERATORS:
            continue
        # a prefix operator is the operand's first word; `until` stands between two operands
        import difflib  # deferred: start-up (a close spelling is only looked for in an error)
        close = difflib.get_close_matches(word.lower(), OPERATORS if m.start(1) == first else ("until",), n=1,
                                          cutoff=0.75)
        if close:
            return error(_loc_at(src, m.start(1)), f"{what}: unknown temporal operator {word!r}: did you mean "
                                                    f"{close[0]!r}? The operators are always, eventually, "
                                                    "eventually[<= N], next, previous and until "
                                                    "(docs/requirements.md, Temporal requirements)", "E-syntax")
    return None


def _bound(src: Source, b: "re.Match[str]", what: str) -> int:
    """The step bound of ``eventually[<= N]`` (``b`` the match of
    :data:`_BOUND`): ASCII digits only (``str.isdigit`` also takes ``'²'``
    and other scripts' digits), at most :data:`MAX_BOUND`; else a located
    error at the bound (``E-syntax``, ``E-temporal``)."""
    text = b.group(1).strip()
    at = _loc_at(src, b.start(1) + len(b.group(1)) - len(b.group(1).lstrip()))
    if not _DIGITS.fullmatch(text):
        raise RclError([error(at, f"{what}: the bound of eventually[<= N] must be a natural number of steps "
                                  f"written in the digits 0-9, found {text!r}", "E-syntax")])
    digits = text.lstrip("0") or "0"
    if len(digits) > len(str(MAX_BOUND)) or int(digits) > MAX_BOUND:  # no int() of a huge literal
        shown = digits if len(digits) <= 20 else f"{digits[:8]}...({len(digits)} digits)"
        raise RclError([error(at, f"{what}: the bound of eventually[<= N] is at most {MAX_BOUND} steps, found "
                                  f"{shown}; state a longer response as eventually F with a ranking function "
                                  f"(docs/requirements.md, Temporal requirements)", "E-temporal")])
    return int(digits)


def shape(t: Temporal | Formal, loc: Any) -> str:
    """The decided shape of a statement (module table): ``always``,
    ``always next``, ``eventually``, ``next``, ``until``, ``response``
    (``always (P -> eventually[<= N] Q)``, ``always (P -> eventually Q)``
    or ``always (P -> next Q)``: the response pattern, FRET's "whenever P,
    within N steps Q" and "whenever P, eventually Q");
    raises :class:`RclError` (``E-temporal`` at ``loc``) for another nesting."""
    if isinstance(t, Temporal):
        a = t.args[0]
        if t.op == "always" and isinstance(a, Temporal) and a.op == "->" and isinstance(a.args[0], Formal):
            r = a.args[1]
            if isinstance(r, Temporal) and isinstance(r.args[0], Formal) and r.op in ("next", "eventually"):
                return "response"
        if t.op in ("always", "eventually", "next") and isinstance(a, Formal):
            return t.op
        if t.op == "always" and isinstance(a, Temporal) and a.op == "next" and isinstance(a.args[0], Formal):
            return "always next"
        if t.op == "until" and all(isinstance(x, Formal) for x in t.args):
            return "until"
    raise RclError([error(loc, "this nesting of temporal operators is not decided; write always F, always next F, "
                               "eventually F, eventually[<= N] F, next F, F until G, always (F -> eventually[<= N] G), "
                               "always (F -> eventually G) or always (F -> next G) with F, G state formulas "
                               "(docs/requirements.md, Temporal requirements)", "E-temporal")])
