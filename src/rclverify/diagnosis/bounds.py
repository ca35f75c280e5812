"""Which numeric literals of a formula are bounds, which are coefficients,
and when two numbers differ by a power of ten (docs/diagnosis.md, "Repairs
ranked by what they cost").

A repair may tighten a *bound*: a literal compared with something
(``out.speed <= 2.0``, ``0 <= in.r``).  It must never rewrite a
*coefficient* (``1000`` in ``out.d == 1000 * in.r``), a scale factor or a
unit as if it were a bound: changing ``1000`` to ``0.5`` would pass Z3 and
say nothing an engineer could implement.  A literal is a bound here when it
is a direct operand of an ordering comparison (``<``, ``<=``, ``>``,
``>=``); a coefficient when it is a direct operand of ``*`` or ``/``.
Every other literal (an index ``f(3)``, a summand ``x + 1``, a value
``out.mode == 2``) is neither.

A *threshold* is a bound in a comparison of two terms (``in.charge < 20``):
its strictness may be wrong by one value, an off-by-one at the threshold,
when the requirement names the same number with the other strictness
(``<= 20``).  :func:`thresholds` lists them and :data:`FLIP` the other
strictness.
"""
from __future__ import annotations

from fractions import Fraction
from typing import Iterator

from rclverify.lang import ast
from rclverify.lang.walk import subexpressions

_ORDERING = ("<", "<=", ">", ">=")


def _direct_literals(e: ast.Expr) -> Iterator[tuple[ast.NumLit, ast.Expr]]:
    """``(literal, parent)`` for every numeric literal under ``e`` that is a
    direct child of a comparison or an arithmetic operator."""
    for x in subexpressions(e):
        if isinstance(x, ast.Compare):
            for o in x.operands:
                if isinstance(o, ast.NumLit):
                    yield o, x
        elif isinstance(x, ast.Binary):
            for o in (x.left, x.right):
                if isinstance(o, ast.NumLit):
                    yield o, x


def bound_literals(e: ast.Expr) -> list[ast.NumLit]:
    """The literals of ``e`` that are bounds (module docstring), in source
    order: ``0`` and ``2.0`` of ``0 <= out.speed and out.speed <= 2.0``;
    none of ``out.d == 1000 * in.r``."""
    out = [lit for lit, parent in _direct_literals(e)
           if isinstance(parent, ast.Compare) and any(op in _ORDERING for op in parent.ops)]
    return sorted(out, key=lambda n: (n.loc.line, n.loc.col))


#: The other strictness of an ordering comparison (an off-by-one at a threshold).
FLIP = {"<": "<=", "<=": "<", ">": ">=", ">=": ">"}


def thresholds(e: ast.Expr) -> list[tuple[ast.Compare, ast.NumLit]]:
    """``(comparison, its literal)`` for the comparisons of ``e`` of two
    terms, one a numeric literal, by an ordering operator (``in.charge <
    20``, ``30 >= out.d``; not a chain ``0 <= x <= 1``), in source order:
    the places where an off-by-one at a threshold is written."""
    out = []
    for x in subexpressions(e):
        if isinstance(x, ast.Compare) and len(x.ops) == 1 and x.ops[0] in FLIP:
            lits = [o for o in x.operands if isinstance(o, ast.NumLit)]
            if len(lits) == 1:
                out.append((x, lits[0]))
    return sorted(out, key=lambda p: (p[1].loc.line, p[1].loc.col))


def coefficient_literals(e: ast.Expr) -> list[tuple[ast.NumLit, ast.Binary]]:
    """``(literal, the product or quotient it is in)`` for the literals of
    ``e`` that multiply or divide a term (``1000`` of ``1000 * in.r``,
    ``10`` of ``in.d / 10``; for ``/`` only the divisor), in source order."""
    out: list[tuple[ast.NumLit, ast.Binary]] = []
    for lit, parent in _direct_literals(e):
        if isinstance(parent, ast.Binary) and parent.op in ("*", "/"):
            if parent.op == "/" and lit is not parent.right:
                continue
            out.append((lit, parent))
    return sorted(out, key=lambda p: (p[0].loc.line, p[0].loc.col))


def value(text: str) -> Fraction | None:
    """A literal's text as an exact number (``"2.0"`` -> 2), ``None`` when it is not one."""
    try:
        return Fraction(text)
    except (ValueError, ZeroDivisionError):
        return None


def power_of_ten(a: Fraction, b: Fraction) -> int | None:
    """``k`` when ``a == b * 10**k`` for an integer ``k != 0`` (``30000`` and
    ``30``: 3; ``0.03`` and ``30``: -3), else ``None`` (also for zero or
    opposite signs): two ranges that differ by such a factor are a probable
    scale (unit) mismatch, millimetres against metres."""
    if a == 0 or b == 0 or (a > 0) != (b > 0):
        return None
    q = abs(a / b)
    k = 0
    while q >= 10 and q.denominator == 1 and q.numerator % 10 == 0:
        q /= 10
        k += 1
    while q < 1 and (q * 10) <= 1:
        q *= 10
        k -= 1
    return k if q == 1 and k != 0 else None


def number_text(x: Fraction) -> str | None:
    """``x`` as an exact RCL numeric literal (an integer or a finite decimal:
    ``3/2`` -> ``1.5``), ``None`` when it has no finite decimal."""
    from rclverify.semantics.values import decimal_text  # deferred: start-up (loads rclverify.lang.types, rclverify.lang.units and more only when called)
    return decimal_text(x)
