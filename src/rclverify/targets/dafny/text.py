"""Dafny text spelled from values: exact ``real`` literals, string literals,
and the parentheses the translation of formulas (:mod:`.translate`) puts
around compound sub-expressions and takes off a whole formula.  Also the
type both sides of ``==`` widen to (Dafny keeps ``int`` and ``real`` apart).
"""
from __future__ import annotations

import re
from fractions import Fraction

from rclverify.model.plan.errors import PlanError
from rclverify.lang import ast
from rclverify.lang.errors import error
from rclverify.lang.types import TupleT, Type, numeric_join
from rclverify.semantics.values import decimal_text


def real_literal(value: Fraction) -> str:
    """Exact Dafny ``real`` literal text of ``value`` (``120.0``, ``0.125``, ``-2.5``).

    Values whose decimal expansion does not terminate are written as a
    quotient ``(1.0 / 3.0)``.
    """
    text = decimal_text(value)
    if text is None:
        v = abs(value)
        return f"({'-' if value < 0 else ''}{v.numerator}.0 / {v.denominator}.0)"
    return text if "." in text else text + ".0"


def dafny_string(value: str, loc: ast.Loc) -> str:
    """A Dafny string literal for ``value``: ``"`` and ``\\`` escaped,
    other characters outside printable ASCII as ``\\u`` and four hex
    digits (``\\u00e9``).  Raises
    :class:`PlanError` (located) for characters beyond U+FFFF, which Dafny 2
    string literals cannot spell."""
    out = []
    for ch in value:
        if ch in ('"', "\\"):
            out.append("\\" + ch)
        elif " " <= ch <= "~":
            out.append(ch)
        elif ord(ch) <= 0xFFFF:
            out.append(f"\\u{ord(ch):04x}")
        else:
            raise PlanError([error(loc, f"the string literal holds {ch!r}, beyond U+FFFF, which a Dafny string "
                                        "literal cannot spell", "E-dafny")])
    return '"' + "".join(out) + '"'


def value_join(a: Type, b: Type) -> Type | None:
    """The type both sides of ``==`` widen to: the numeric join, taken
    component by component for tuples; ``None`` when no widening applies."""
    if isinstance(a, TupleT) and isinstance(b, TupleT) and len(a.elems) == len(b.elems):
        parts = [x if x == y else value_join(x, y) for x, y in zip(a.elems, b.elems)]
        return None if any(p is None for p in parts) else TupleT(tuple(p for p in parts if p is not None))
    return numeric_join(a, b)


def wrap(s: str) -> str:
    """Parenthesise ``s`` unless it is already atomic or parenthesised as a whole."""
    if re.fullmatch(r"[A-Za-z0-9_'.]+", s) or _balanced_parens(s):
        return s
    return f"({s})"


def _balanced_parens(s: str) -> bool:
    if not (s.startswith("(") and s.endswith(")")):
        return False
    depth = 0
    for k, ch in enumerate(s):
        depth += ch == "("
        depth -= ch == ")"
        if depth == 0 and k < len(s) - 1:
            return False
    return True


def strip_parens(s: str) -> str:
    """Drop one pair of parentheses enclosing the whole of ``s``."""
    return s[1:-1] if _balanced_parens(s) else s
