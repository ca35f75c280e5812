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

The rule (docs/semantics.md, "Widths"): a comparison is read at the width
of what it compares, as C++ computes ``float`` arithmetic with ``f``
literals and numpy computes on ``float32`` arrays: each side's width is that
of the widest input or output of known width it reads, through unary
``-``, ``abs`` and ``+ - * /`` (C++'s usual arithmetic conversions: a
``float32`` with a ``float64`` is at ``float64``), and every constant part
of either side (a numeric literal, a named constant of the context, an
expression of them such as ``0.1 + 0.1``) is replaced by its value at that
width: each literal rounded to the width's nearest value (IEEE 754
round-to-nearest, ties to even; binary32 has a 24-bit significand,
exponents from -126, subnormals down to 2**-149), each operation on them
rounded as an IEEE 754 operation of the width is.  So ``x <= 0.2``, ``x <=
LowCharge`` (``LowCharge = 0.2``), ``x - 0.2 <= 0``, ``-x >= -0.2`` and
``x <= 0.1 + 0.1`` compare ``x`` with the same carried 0.2, and ``abs(x) <=
0.2`` with it too.  Everything else keeps its meaning: the recorded value
is never moved, arithmetic on recorded values is not rounded, and the
exact, double and tolerance readings of :mod:`.floatsem` then all compare
against the carried constant, so a ``<``/``<=`` slip at the threshold is
found in each of them and in each of these forms.  A constant beyond the
width's largest finite value is left as written (the field cannot carry
it; the comparison is then decided as before).

Every other primitive keeps its width and kind (rosidl's type mapping; the
ranges of OMG IDL 4.2, table 7-13: :data:`INT_RANGES`): a constant compared
with an integer field keeps its exact value (every value of the field is an
integer, compared exactly); what a field carries (:class:`Carried`: the
primitive, a ``string<=N`` bound, a ``T[<=N]`` or ``T[N]`` sequence) bounds
what the property tests draw (:func:`int_edges`) and decides whether a
value can travel at all (:func:`carried_fault`: ``uint8 cannot carry 300``).
"""
from __future__ import annotations

import dataclasses
import math
import struct
from fractions import Fraction
from typing import Any, Iterable, Mapping

from rclverify.lang import ast
from rclverify.lang.types import Type
from rclverify.lang.visit import Transformer
from rclverify.semantics.operators import OPERATORS, UNARY, Undecided

#: IDL floating-point types -> (significand bits with the hidden one, smallest normal exponent, largest exponent).
FLOAT_WIDTHS: dict[str, tuple[int, int, int]] = {"float32": (24, -126, 127), "float64": (53, -1022, 1023)}

#: IDL integer types -> (least, greatest) value: the ranges of OMG IDL 4.2 clause 7.4.1.4.4.2.1 (table 7-13,
#: integers of 8 to 64 bits; ``octet`` 0 to 255).  ``.msg``'s ``byte`` is IDL ``octet`` and its ``char`` IDL
#: ``uint8`` (rosidl_adapter's ``MSG_TYPE_TO_IDL``); both carry 0 to 255 (rclpy's setters assert it).
INT_RANGES: dict[str, tuple[int, int]] = {
    "int8": (-2 ** 7, 2 ** 7 - 1), "uint8": (0, 2 ** 8 - 1), "int16": (-2 ** 15, 2 ** 15 - 1),
    "uint16": (0, 2 ** 16 - 1), "int32": (-2 ** 31, 2 ** 31 - 1), "uint32": (0, 2 ** 32 - 1),
    "int64": (-2 ** 63, 2 ** 63 - 1), "uint64": (0, 2 ** 64 - 1), "byte": (0, 255), "octet": (0, 255),
    "char": (0, 255)}

#: rosidl's IDL names of ``.msg`` primitives (``float``, ``double``, ``boolean``) -> the ``.msg`` names used here.
IDL_ALIASES: dict[str, str] = {"float": "float32", "double": "float64", "boolean": "bool"}


def idl_name(name: str) -> str:
    """The ``.msg`` name of an IDL primitive (``double`` -> ``float64``); others as they are."""
    return IDL_ALIASES.get(name, name)


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
    every value of another width, as it is; a sequence (a ``tuple``) item by
    item.  A value beyond binary32's range becomes an infinity, as it does
    on the wire."""
    if width == "float32" and isinstance(value, tuple):
        return tuple(narrow(v, width) for v in value)
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


def int_edges(constants: Iterable[Fraction], width: str) -> list[int]:
    """The integers an input of IDL integer type ``width`` is drawn at beside
    arbitrary ones: the range's least and greatest value, 0, and for each
    constant ``c`` the values where a comparison with it changes its truth
    (``c - 1``, ``c``, ``c + 1`` for an integer ``c``; the integers either
    side of any other), those in the range; sorted.  Raises ``KeyError`` for
    a ``width`` not in :data:`INT_RANGES`.  The constants keep their exact
    value (docs/semantics.md, "Widths")."""
    lo, hi = INT_RANGES[width]
    out = {lo, hi, 0}
    for c in constants:
        k = c.numerator // c.denominator
        out.update((k - 1, k, k + 1) if c.denominator == 1 else (k, k + 1))
    return sorted(v for v in out if lo <= v <= hi)


@dataclasses.dataclass(frozen=True)
class Width:
    """One primitive field's IDL type as ``.msg`` names it (``float32``,
    ``uint8``, ``char``, ``bool``, ``string``; :func:`idl_name`) and, for a
    bounded string (``string<=N``), its bound ``N`` in characters (0: none)."""

    idl: str
    bound: int = 0

    def __str__(self) -> str:
        return f"{self.idl}<={self.bound}" if self.bound else self.idl


@dataclasses.dataclass(frozen=True)
class Carried:
    """How a message carries one RCL value: ``items`` the primitive of a
    scalar or of a sequence's items (one :class:`Width`), or of each
    component of a sequence of tuples (one per component, in order);
    ``seq`` whether the value is a sequence (an array field, or a path
    through the items of one: ``poses[*].position.x``), ``max_len`` its
    bound (``T[<=N]``, ``T[N]``: ``N``; ``None`` unbounded), ``fixed``
    whether it holds exactly ``max_len`` items (``T[N]``)."""

    items: tuple[Width, ...]
    seq: bool = False
    max_len: int | None = None
    fixed: bool = False

    def __str__(self) -> str:
        item = str(self.items[0]) if len(self.items) == 1 else "(" + ", ".join(map(str, self.items)) + ")"
        if not self.seq:
            return item
        return f"{item}[{'' if self.max_len is None else ('' if self.fixed else '<=') + str(self.max_len)}]"


def _number_text(v: Any) -> str:
    if isinstance(v, Fraction):
        return str(v.numerator) if v.denominator == 1 else str(float(v)) if float(v) == v else str(v)
    return repr(v)


def width_fault(value: Any, width: Width) -> str | None:
    """Why a field of primitive type ``width`` cannot carry ``value`` (an RCL
    value: ``int``, ``float``, ``Fraction``, ``bool``, ``str``), ``None``
    when it can.  The rule is rclpy's: its generated setters
    (rosidl_generator_py) assert an integer field's Python ``int`` within the
    type's range (:data:`INT_RANGES`), a floating field's ``float`` within
    its finite range (beyond it, IEEE 754's round-to-nearest overflows: a
    ``float32`` cannot carry 1e39), a ``bool`` field's ``bool`` and a
    bounded string's length.  Without the checks (Kilted's default) the
    conversion to C raises, wraps an integer (300 is heard as 44) or reads an
    ``int`` in a floating field as another number (3 as 5e-324), as
    tests/semantics/test_widths_ints.py measures; C++ would wrap the integer too, so
    the value the node computed never reaches a subscriber either way."""
    name = width.idl
    if name in INT_RANGES:
        lo, hi = INT_RANGES[name]
        if isinstance(value, bool) or not isinstance(value, int):
            return f"{name} cannot carry {_number_text(value)}: not an integer"
        return None if lo <= value <= hi else f"{name} cannot carry {value} (its values are {lo} to {hi})"
    if name in FLOAT_WIDTHS:
        if not isinstance(value, float):  # measured on Kilted: an int 3 in a float64 field is heard as 5e-324
            return (f"{name} cannot carry {_number_text(value)}: a Python {type(value).__name__}, not a float "
                    f"(rclpy's setter refuses it; unchecked, rclpy publishes another number)")
        if not math.isfinite(value):
            return None  # rclpy lets an infinity or NaN through; the mapping refuses it (no RCL number)
        if nearest_at_width(Fraction(value), name) is None:
            return f"{name} cannot carry {_number_text(value)} (beyond its largest finite value)"
        return None
    if name == "bool":
        return None if isinstance(value, bool) else f"bool cannot carry {_number_text(value)}"
    if name == "string" and width.bound and isinstance(value, str) and len(value) > width.bound:
        return f"{width} cannot carry {value!r} ({len(value)} characters)"
    return None


def carried_fault(value: Any, carried: Carried) -> str | None:
    """Why a field carrying ``carried`` cannot hold ``value`` (a scalar, or a
    sequence as a tuple of items, each a tuple of components for a sequence of
    tuples), ``None`` when it can: :func:`width_fault` of the scalar or of
    each item, and a sequence's length against its bound (rclpy asserts
    ``len(value) <= N`` for ``T[<=N]`` and ``== N`` for ``T[N]``)."""
    if not carried.seq:
        return width_fault(value, carried.items[0])
    if not isinstance(value, (tuple, list)):
        return None
    n, bound = len(value), carried.max_len
    if bound is not None and (n != bound if carried.fixed else n > bound):
        return f"{carried} cannot carry {n} item(s) ({'exactly' if carried.fixed else 'at most'} {bound})"
    for i, item in enumerate(value):
        parts = item if len(carried.items) > 1 and isinstance(item, tuple) else (item,)
        for k, (p, w) in enumerate(zip(parts, carried.items)):
            why = width_fault(p, w)
            if why:
                where = f"item {i}" + (f", component {k + 1}" if len(carried.items) > 1 else "")
                return f"{where}: {why}"
    return None


def exact_decimal(v: Fraction) -> str:
    """The decimal digits of ``v``, a dyadic rational (``n / 2**k``, as every value of a binary
    floating width is), written out exactly: ``0.1000000000000000055511151231257827021181583404541015625``
    for the double nearest 0.1 (all its 55 significant digits; ``decimal``'s default context would
    round to 28).  Raises ``ValueError`` for a denominator that is not a power of two."""
    a, den = abs(v), v.denominator
    k = den.bit_length() - 1
    if den != 1 << k:
        raise ValueError(f"{v} has no finite binary expansion")
    digits = str(a.numerator * 5 ** k).rjust(k + 1, "0")
    text = digits if k == 0 else f"{digits[:-k]}.{digits[-k:]}"
    return ("-" if v < 0 else "") + text


def _literal(v: Fraction, like: ast.Expr) -> ast.Expr:
    """``v`` (a dyadic rational: finitely many decimal digits) as a literal where ``like`` stood,
    its digits exact (:func:`exact_decimal`)."""
    text = exact_decimal(v)
    loc: ast.Loc = like.loc
    if v < 0:
        return ast.Unary("-", ast.NumLit(text.lstrip("-"), loc), loc)
    return ast.NumLit(text, loc)


#: the floating widths from narrowest to widest: an operation on two widths is at the wider (C++'s usual
#: arithmetic conversions, numpy's type promotion)
_WIDER = {"float32": 0, "float64": 1}


def at_widths(e: ast.Expr, widths: Mapping[str, str],
              constants: Mapping[str, tuple[Type, ast.Expr]] | None = None) -> ast.Expr:
    """``e`` with every constant read at the width of what it is combined
    with (module docstring, and docs/semantics.md, "Widths"): in a
    comparison, each side's width is that of the widest input or output of
    known width it reads (``widths``: ``"in.x"``/``"out.y"`` -> ``float32``
    or ``float64``; for a sequence, its items' width, which a variable bound
    by ``r in in.xs`` carries) through ``-``, ``abs``, ``+ - * /``; a pair
    of sides with a width has every constant part on either side (a
    literal, a named constant of ``constants``, the context's definitions
    ``name -> (type, defining expression)``, or an expression of them,
    ``0.1 + 0.1``) replaced by its value at that width: each literal rounded
    to the width (IEEE 754 round to nearest, ties to even), each operation
    on them rounded as an IEEE 754 operation of that width is.  So ``x <=
    0.2``, ``x <= LowCharge``, ``x - 0.2 <= 0``, ``-x >= -0.2``, ``x <= 0.1
    + 0.1`` and, for ``x >= 0``, ``abs(x) <= 0.2`` compare ``x`` with the
    same carried value.  ``e`` itself when nothing changes."""
    if not widths:
        return e
    out: ast.Expr = _AtWidths(constants or {}).visit(e, _Scope(widths, frozenset()))
    return out


@dataclasses.dataclass(frozen=True)
class _Scope:
    """What :class:`_AtWidths` reads at a point of the formula: the widths of
    the names visible there and the bound names (which hide a constant's)."""

    widths: Mapping[str, str]
    bound: frozenset[str]


class _AtWidths(Transformer):
    """:func:`at_widths` as a :class:`~rclverify.lang.visit.Transformer`: comparisons and binders
    are its own; every other node is rebuilt only where something below it changed."""

    def __init__(self, constants: Mapping[str, tuple[Type, ast.Expr]]) -> None:
        self.constants = constants

    def visit_Quant(self, e: ast.Quant, sc: _Scope) -> ast.Expr:
        inner = dict(sc.widths)  # `r in in.ranges`: r carries the sequence's item width; another binder shadows
        for b in e.bindings:
            d = b.domain
            w = sc.widths.get(d.qualified) if isinstance(d, ast.Var) and d.prefix else None
            for n in b.names:
                if w is not None:
                    inner[n] = w
                else:
                    inner.pop(n, None)
        body = self.visit(e.body, _Scope(inner, sc.bound | frozenset(e.variables)))
        return dataclasses.replace(e, body=body) if body is not e.body else e

    def visit_TupleQuant(self, e: ast.TupleQuant, sc: _Scope) -> ast.Expr:
        inner = {k: v for k, v in sc.widths.items() if k not in e.names}
        body = self.visit(e.body, _Scope(inner, sc.bound | frozenset(e.names)))
        return dataclasses.replace(e, body=body) if body is not e.body else e

    def width(self, e: ast.Expr, sc: _Scope) -> str | None:
        """The floating width ``e`` is computed at: its widest input or output of known width."""
        if isinstance(e, ast.Var):
            w = sc.widths.get(e.qualified)
            return w if w in FLOAT_WIDTHS else None
        if isinstance(e, ast.Unary) and e.op != "not":
            return self.width(e.operand, sc)
        if isinstance(e, ast.Binary) and OPERATORS[e.op].kind == "arithmetic":
            found = [w for w in (self.width(e.left, sc), self.width(e.right, sc)) if w is not None]
            return max(found, key=_WIDER.__getitem__) if found else None
        return None

    def value(self, e: ast.Expr, width: str | None, bound: frozenset[str], seen: tuple[str, ...] = ()
              ) -> Fraction | None:
        """The value of ``e`` if it is a constant expression: exact (``width``
        ``None``) or at ``width`` (every literal and every operation rounded to
        it); ``None`` when ``e`` reads a variable, a value is beyond the
        width's range or a division is by zero."""
        v: Any
        if isinstance(e, ast.NumLit):
            v = e.value
        elif isinstance(e, ast.Var) and e.prefix is None and e.name in self.constants and e.name not in bound \
                and e.name not in seen:
            return self.value(self.constants[e.name][1], width, frozenset(), (*seen, e.name))
        elif isinstance(e, ast.Unary) and e.op != "not":
            x = self.value(e.operand, width, bound, seen)
            if x is None or e.op == "-" or e.op == "abs":
                return None if x is None else Fraction(UNARY[e.op].exact(x))  # exact at every width
            try:  # sqrt, sin, cos: rounded to the width below
                v = Fraction(UNARY[e.op].exact(x))
            except Undecided:
                return None
        elif isinstance(e, ast.Binary) and OPERATORS[e.op].kind == "arithmetic":
            x, y = self.value(e.left, width, bound, seen), self.value(e.right, width, bound, seen)
            if x is None or y is None:
                return None
            try:
                v = Fraction(OPERATORS[e.op].exact(x, y))
            except Undecided:
                return None
        else:
            return None
        return Fraction(v) if width is None else nearest_at_width(Fraction(v), width)

    def at(self, e: ast.Expr, width: str, sc: _Scope) -> ast.Expr:
        """``e`` (a side of a comparison at ``width``) with its constant parts at ``width``."""
        v = self.value(e, width, sc.bound)
        if v is not None:
            return e if v == self.value(e, None, sc.bound) else _literal(v, e)
        if isinstance(e, ast.Binary) and OPERATORS[e.op].kind == "arithmetic":
            left, right = self.at(e.left, width, sc), self.at(e.right, width, sc)
            return e if (left is e.left and right is e.right) else dataclasses.replace(e, left=left, right=right)
        if isinstance(e, ast.Unary) and e.op != "not":
            operand = self.at(e.operand, width, sc)
            return e if operand is e.operand else dataclasses.replace(e, operand=operand)
        return e

    def visit_Compare(self, e: ast.Compare, sc: _Scope) -> ast.Expr:
        ops = [self.visit(o, sc) for o in e.operands]
        for i in range(len(ops) - 1):
            found = [w for w in (self.width(e.operands[i], sc), self.width(e.operands[i + 1], sc)) if w is not None]
            if found:
                w = max(found, key=_WIDER.__getitem__)
                ops[i], ops[i + 1] = self.at(ops[i], w, sc), self.at(ops[i + 1], w, sc)
        return dataclasses.replace(e, operands=tuple(ops)) if any(a is not b for a, b in zip(ops, e.operands)) else e


__all__ = ["FLOAT_WIDTHS", "IDL_ALIASES", "INT_RANGES", "Carried", "Width", "at_widths", "carried_fault",
           "edges_at_width", "exact_decimal", "idl_name", "int_edges", "narrow", "nearest_at_width", "width_fault"]
