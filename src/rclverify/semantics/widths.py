"""The contract's decimal constants compared the way a field carries them.

RCL speaks of reals; a ROS field carries an IEEE 754 value of its IDL type's
width (rosidl's type mapping: ``float32`` is binary32, ``float64`` binary64).
A threshold written ``0.2`` cannot be carried by a ``float32`` field: the
field's nearest value is 0.20000000298023223876953125.  A node that compares
at the field's width (``percentage <= 0.2f`` in C++, or a Python node that
decides on the value it publishes before the wire narrows it) answers "at or
below" for the carried 0.2, which is above the decimal 0.2: judged against
the decimal, the correct ``<=`` reads as a violation and the ``<`` slip as
correct (an inverted verdict).

The rule (docs/semantics.md, "Widths"): in a comparison between an input or
output whose field's width is known and a constant (a numeric literal, or
its negation), the constant is replaced by the value of that width nearest
to it (IEEE 754 round-to-nearest, ties to even; binary32 has a 24-bit
significand, exponents from -126, subnormals down to 2**-149).  Everything
else keeps its meaning: the recorded value is never moved, and the exact,
double and tolerance readings of :mod:`.floatsem` then all compare against
the carried constant, so a ``<``/``<=`` slip at the threshold is found in
each of them.  A constant beyond the width's largest finite value is left as
written (the field cannot carry it; the comparison is then decided as
before).
"""
from __future__ import annotations

import dataclasses
import math
import struct
from decimal import Decimal
from fractions import Fraction
from typing import Any, Iterable, Mapping

from rclverify.lang import ast
from rclverify.lang.visit import Transformer

#: IDL floating-point types -> (significand bits with the hidden one, smallest normal exponent, largest exponent).
FLOAT_WIDTHS: dict[str, tuple[int, int, int]] = {"float32": (24, -126, 127), "float64": (53, -1022, 1023)}


def nearest_at_width(q: Fraction, width: str) -> Fraction | None:
    """The value of IDL type ``width`` (``float32`` or ``float64``) nearest
    to the exact ``q`` (ties to the even significand), or ``None`` when
    ``q`` lies beyond the width's largest finite value.  Source: IEEE 754-2019
    clause 4.3.1, roundTiesToEven."""
    bits, emin, emax = FLOAT_WIDTHS[width]
    if q == 0:
        return Fraction(0)
    a = abs(q)
    e = a.numerator.bit_length() - a.denominator.bit_length()
    if Fraction(2) ** e > a:
        e -= 1
    quantum = Fraction(2) ** (max(e, emin) - (bits - 1))
    n = a / quantum
    k = n.numerator // n.denominator
    rest = n - k
    if rest > Fraction(1, 2) or (rest == Fraction(1, 2) and k % 2 == 1):
        k += 1
    v = k * quantum
    if v > (2 - Fraction(2) ** (1 - bits)) * Fraction(2) ** emax:
        return None
    return v if q > 0 else -v


def narrow(value: Any, width: str) -> Any:
    """``value`` as a field of IDL type ``width`` carries it: a Python
    ``float`` rounded to binary32 for ``float32`` (round to nearest, ties to
    even: the conversion a publisher's message makes); anything else, and
    every value of another width, as it is.  A value beyond binary32's range
    becomes an infinity, as it does on the wire."""
    if width != "float32" or not isinstance(value, float):
        return value
    try:
        return float(struct.unpack("<f", struct.pack("<f", value))[0])
    except OverflowError:
        return math.copysign(math.inf, value)


def edges_at_width(constants: Iterable[Fraction], width: str) -> list[Fraction]:
    """For each constant, the value of ``width`` nearest to it and that
    value's two neighbours of the same width: the thresholds as the field
    carries them, for the property tests to draw (docs/property-tests.md)."""
    out: set[Fraction] = set()
    for c in constants:
        v = nearest_at_width(c, width)
        if v is None:
            continue
        out.add(v)
        if width == "float32":
            bits = struct.unpack("<i", struct.pack("<f", float(v)))[0]
            for b in (bits - 1, bits + 1):
                try:
                    f = struct.unpack("<f", struct.pack("<i", b))[0]
                except struct.error:
                    continue
                if math.isfinite(f):
                    out.add(Fraction(f))
        else:
            out.update(Fraction(math.nextafter(float(v), d)) for d in (-math.inf, math.inf))
    return sorted(out)


def _constant(e: ast.Expr) -> Fraction | None:
    if isinstance(e, ast.NumLit):
        return e.value
    if isinstance(e, ast.Unary) and e.op == "-" and isinstance(e.operand, ast.NumLit):
        return -e.operand.value
    return None


def _literal(v: Fraction, like: ast.Expr) -> ast.Expr:
    """``v`` (a dyadic rational: finitely many decimal digits) as a literal where ``like`` stood."""
    text = str(Decimal(v.numerator) / Decimal(v.denominator)) if v.denominator != 1 else str(v.numerator)
    if "E" in text or "e" in text:  # Decimal's exponent form: write the digits out
        text = format(Decimal(v.numerator) / Decimal(v.denominator), "f")
    loc: ast.Loc = like.loc if isinstance(like, (ast.NumLit, ast.Unary)) else ast.NumLit("0").loc
    if v < 0:
        return ast.Unary("-", ast.NumLit(text.lstrip("-"), loc), loc)
    return ast.NumLit(text, loc)


def at_widths(e: ast.Expr, widths: Mapping[str, str]) -> ast.Expr:
    """``e`` with every constant compared directly with an input or output of
    known width (``widths``: ``"in.x"``/``"out.y"`` -> ``float32`` or
    ``float64``; for a sequence, its items' width, which a variable bound by
    ``r in in.xs`` carries) replaced by its nearest value of that width
    (module docstring); ``e`` itself when nothing changes."""
    if not widths:
        return e
    out: ast.Expr = _AtWidths().visit(e, widths)
    return out


class _AtWidths(Transformer):
    """:func:`at_widths` as a :class:`~rclverify.lang.visit.Transformer`: comparisons and binders
    are its own; every other node is rebuilt only where something below it changed."""

    def visit_Quant(self, e: ast.Quant, widths: Mapping[str, str]) -> ast.Expr:
        inner = dict(widths)  # `r in in.ranges`: r carries the sequence's item width; another binder shadows
        for b in e.bindings:
            d = b.domain
            w = widths.get(d.qualified) if isinstance(d, ast.Var) and d.prefix else None
            for n in b.names:
                if w is not None:
                    inner[n] = w
                else:
                    inner.pop(n, None)
        body = self.visit(e.body, inner)
        return dataclasses.replace(e, body=body) if body is not e.body else e

    def visit_Compare(self, e: ast.Compare, widths: Mapping[str, str]) -> ast.Expr:
        ops = [self.visit(o, widths) for o in e.operands]
        for i in range(len(ops) - 1):
            for var_at, const_at in ((i, i + 1), (i + 1, i)):
                var = e.operands[var_at]
                width = widths.get(var.qualified) if isinstance(var, ast.Var) else None
                c = _constant(e.operands[const_at]) if width else None
                v = nearest_at_width(c, width) if width and c is not None else None
                if v is not None and v != c:
                    ops[const_at] = _literal(v, e.operands[const_at])
        return dataclasses.replace(e, operands=tuple(ops)) if any(a is not b for a, b in zip(ops, e.operands)) else e


__all__ = ["FLOAT_WIDTHS", "at_widths", "edges_at_width", "narrow", "nearest_at_width"]
