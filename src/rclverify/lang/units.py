"""Units of measure: the unit algebra of RCL (docs/rcl-language.md, "Units of measure").

A unit is a *dimension* (a vector of integer exponents over the base
dimensions length, mass, time, current, temperature, amount, luminous
intensity and angle) and an exact *scale* relative to the coherent SI unit of
that dimension: a rational factor times a power of pi (``deg`` is
``pi/180 rad``).  ``mm`` is length with scale 1/1000, ``km/h`` is velocity
with scale 5/18, ``%`` is dimensionless with scale 1/100.

Two units are *the same* when dimension and scale are equal (``m/s*s`` is
``m``); two units of one dimension differ by a factor (``mm`` and ``m``: 1000);
units of different dimensions cannot be compared at all.  Angle is a base
dimension of its own (as in Boost.Units and ROS REP 103's separate angle
fields), not SI's dimensionless radian, so ``rad`` against ``m`` or ``rad/s``
against ``Hz`` is a dimension error: in robot software both mistakes are
real.  ``degC`` is an affine scale (0 degC = 273.15 K): it may stand alone,
compared and added with ``degC``, but not multiplied, divided or raised to a
power, and ``degC`` against ``K`` differs by an offset, not a factor.

Sources: the SI Brochure, 9th edition (BIPM 2019), tables 2, 4, 7 (base and
derived units, prefixes) and 8 (non-SI units accepted for use: ``min``,
``h``, ``deg``); ROS REP 103 (metres, seconds, radians as the standard units).

Unit text (between the brackets of ``d : REAL [m/s^2]``)::

    unit   := term (("*" | "/") term)*        left to right: m/s*s is m
    term   := factor ["^" ["-"] digits]
    factor := symbol | "1" | "%" | "(" unit ")"

``symbol`` is a name of :data:`SYMBOLS`, or an SI prefix of
:data:`PREFIXES` followed by a prefixable one (``mm``, ``ms``, ``kHz``); an
exact name wins over a prefixed reading (``min`` is the minute, ``cd`` the
candela, ``h`` the hour).

The units as values (the algebra, the table of symbols and prefixes, the names
of a unit) are :mod:`rclverify.lang.unit_algebra`'s, named here too; here a
unit text is read (:func:`parse_unit`) and two units are compared
(:func:`ratio`, :func:`factor_text`, :func:`power_of_ten`).
"""
from __future__ import annotations

import re

import math
from fractions import Fraction

from rclverify.lang.unit_algebra import (  # named here too: the algebra the text is read into
    ALIASES as ALIASES,
    BASE_DIMENSIONS as BASE_DIMENSIONS,
    DIMENSIONLESS as DIMENSIONLESS,
    Dims as Dims,
    ONE as ONE,
    PREFIXES as PREFIXES,
    SYMBOLS as SYMBOLS,
    Symbol as Symbol,
    Unit as Unit,
    best_name as best_name,
    canonical_text as canonical_text,
    dimension_name as dimension_name,
    lookup as lookup,
)
from rclverify.lang.unit_algebra import _scale_text


#: The largest exponent magnitude a unit text may write (``m^99`` is refused).
MAX_EXPONENT = 12
#: The longest unit text accepted between the brackets.
MAX_TEXT = 200


class UnitError(ValueError):
    """A unit text that cannot be read: ``message`` and ``offset``, the
    0-based index into the text of the character at fault."""

    def __init__(self, message: str, offset: int) -> None:
        super().__init__(message)
        self.message, self.offset = message, offset


def suggestions(name: str) -> list[str]:
    """Known symbols close to ``name`` (for a located error's candidates)."""
    pool = sorted(set(SYMBOLS) | {p + s for p in ("m", "k", "u", "c") for s, y in SYMBOLS.items() if y.prefixable})
    same = [c for c in pool if c.lower() == name.lower() and c != name]
    import difflib  # deferred: start-up (a close spelling is only looked for in an error)
    return (same + [c for c in difflib.get_close_matches(name, pool, n=3, cutoff=0.6) if c not in same])[:3]


def parse_unit(text: str) -> Unit:
    """The unit written ``text`` (the text between the brackets, e.g.
    ``"m/s^2"``).  Raises :class:`UnitError` with the offset of the fault:
    an unknown symbol (with candidates), a malformed text, an exponent
    beyond :data:`MAX_EXPONENT`, ``degC`` inside a product or power."""
    if len(text) > MAX_TEXT:
        raise UnitError(f"unit text too long ({len(text)} characters, limit {MAX_TEXT})", 0)
    p = _Reader(text)
    p.skip()
    if p.at_end():
        raise UnitError("empty unit; write e.g. [m], [m/s] or [1] for a dimensionless quantity", 0)
    u = p.unit()
    p.skip()
    if not p.at_end():
        raise UnitError(f"unexpected {text[p.i]!r} in unit; units are written like m/s^2 or kg*m/s^2", p.i)
    if p.affine_at is not None:
        if normal_text(text) != "degC":
            raise UnitError("degC is an affine scale (0 degC = 273.15 K): it cannot be multiplied, divided or "
                            "raised to a power; use K for a temperature in a product", p.affine_at)
        return SYMBOLS["degC"].unit
    return Unit(u.dims, u.factor, u.pi, None, normal_text(text))


def normal_text(text: str) -> str:
    """``text`` as a unit is printed back: blanks beside an operator removed
    (``m / s^2`` -> ``m/s^2``), a blank between two factors a product
    (``N m`` -> ``N*m``, never the symbol ``Nm``)."""
    tight = re.sub(r"\s*([*/^()])\s*", r"\1", text.strip())
    tight = re.sub(r"\^([+-])\s+", r"^\1", tight)
    return re.sub(r"\s+", "*", tight)


class _Reader:
    """Recursive descent over a unit text (the grammar of the module
    docstring); ``affine_at`` is the offset of a ``degC`` read (``None``
    when there is none)."""

    def __init__(self, text: str) -> None:
        self.text, self.i = text, 0
        self.affine_at: int | None = None

    def at_end(self) -> bool:
        return self.i >= len(self.text)

    def skip(self) -> None:
        while not self.at_end() and self.text[self.i] in " \t":
            self.i += 1

    def peek(self) -> str:
        self.skip()
        return "" if self.at_end() else self.text[self.i]

    def unit(self) -> Unit:
        u = self.term()
        while True:
            before = self.i
            c = self.peek()
            if c in ("*", "/"):
                op_at = self.i
                self.i += 1
                v = self.term()
                u = u.times(v) if c == "*" else u.over(v)
            elif c and self.i > before and (c.isalnum() or c in "(%"):
                op_at = before  # a blank between two factors is a product (N m), never glued into one symbol
                u = u.times(self.term())
            else:
                return u
            if max((abs(d) for d in u.dims), default=0) > MAX_EXPONENT:  # m/s/s/... as much as s^-13
                raise UnitError(f"exponent out of range (at most {MAX_EXPONENT} in magnitude)", op_at)

    def term(self) -> Unit:
        u = self.factor()
        after = self.i
        if self.peek() != "^":
            self.i = after  # the blanks after it are the caller's (a blank may be a product)
            return u
        self.i += 1
        self.skip()
        k_at = self.i
        sign = 1
        if self.peek() in ("-", "+"):
            sign = -1 if self.text[self.i] == "-" else 1
            self.i += 1
        j = self.i
        while j < len(self.text) and self.text[j].isdigit():
            j += 1
        if j == self.i:
            raise UnitError("an exponent must be an integer, e.g. s^2 or s^-1", k_at)
        digits = self.text[self.i:j]
        self.i = j
        k = sign * int(digits) if len(digits) <= 4 else MAX_EXPONENT + 1
        if abs(k) > MAX_EXPONENT:
            raise UnitError(f"exponent out of range (at most {MAX_EXPONENT} in magnitude)", k_at)
        return u.power(k)

    def factor(self) -> Unit:
        c = self.peek()
        start = self.i
        if c == "(":
            self.i += 1
            inner = self.unit()
            if self.peek() != ")":
                raise UnitError("missing ')' in unit", self.i)
            self.i += 1
            return inner
        if c == "%":
            self.i += 1
            return SYMBOLS["%"].unit
        j = self.i
        while j < len(self.text) and (self.text[j].isalnum() or self.text[j] == "_"):
            j += 1
        word = self.text[self.i:j]
        if not word:
            raise UnitError(f"expected a unit symbol, found {c!r}" if c else "expected a unit symbol at the end",
                            self.i)
        self.i = j
        if word == "1":
            return ONE
        u = lookup(word)
        if u is None:
            near = [ALIASES[word.lower()]] if word.lower() in ALIASES else suggestions(word)
            hint = f"; did you mean {', '.join(repr(n) for n in near)}?" if near else ""
            raise UnitError(f"unknown unit {word!r}{hint} (the accepted units: docs/rcl-language.md, "
                            "'Units of measure')", start)
        if u.offset is not None and self.affine_at is None:
            self.affine_at = start
        return u


def ratio(a: Unit, b: Unit) -> tuple[Fraction, int]:
    """How many ``b`` make one ``a``: ``(rational, power of pi)``; both of
    one dimension (``ratio(m, mm) == (1000, 0)``, ``ratio(rad, deg) == (180, -1)``)."""
    return a.factor / b.factor, a.pi - b.pi


def factor_text(a: Unit, b: Unit) -> str:
    """The factor between two units of one dimension, as a sentence part:
    ``"a factor of 1000 (1 m = 1000 mm)"``, ``"a factor of 180/pi (1 rad =
    180/pi deg)"``; the larger unit is named first.  An affine pair (``degC``
    against ``K``) is ``"an offset of 273.15 K"``."""
    if a.offset is not None or b.offset is not None:
        off = (a.offset or Fraction(0)) - (b.offset or Fraction(0))
        if a.factor == b.factor and a.pi == b.pi:
            return f"an offset of {_decimal(abs(off))} K (0 {_name(a if a.offset is not None else b)} = " \
                   f"{_decimal(abs(off))} K), not a factor"
        return "a different affine scale"
    f, pi = ratio(a, b)
    big, small = (a, b) if float(f) * math.pi ** pi >= 1 else (b, a)
    if (big, small) == (b, a):
        f, pi = 1 / f, -pi
    n = short_decimal(f) if not pi else None  # 3.6, 0.3048: the usual conversions as people write them
    n = n or _scale_text(f, pi)
    return f"a factor of {n} (1 {_name(big)} = {n} {_name(small)})"


def short_decimal(f: Fraction) -> str | None:
    """``"3.6"`` for 18/5: a non-integer with an exact decimal of at most 6
    places, as the usual conversions are written (``0.3048``, ``1.609344``);
    else ``None``."""
    if f.denominator == 1:
        return None
    for k in range(1, 7):
        if (f * 10**k).denominator == 1:
            return f"{float(f):.{k}f}"
    return None


def power_of_ten(a: Unit, b: Unit) -> int | None:
    """``k`` when ``a`` is exactly ``10^k`` times ``b`` (same dimension), else ``None``."""
    f, pi = ratio(a, b)
    if pi or a.dims != b.dims:
        return None
    k = 0
    while f.numerator % 10 == 0 and f.denominator == 1 and f != 1 and k < 40:
        f, k = f / 10, k + 1
    while f.denominator % 10 == 0 and f.numerator == 1 and f != 1 and k > -40:
        f, k = f * 10, k - 1
    return k if f == 1 else None


def _decimal(f: Fraction) -> str:
    return str(f.numerator) if f.denominator == 1 else f"{float(f):g}"


def _name(u: Unit) -> str:
    return u.text or best_name(u) or canonical_text(u)


def describe(u: Unit) -> str:
    """``"[mm] (length)"``: a unit with its dimension, for messages."""
    return f"{u} ({dimension_name(u.dims)})"



#: The time units of deadlines (``within 200 ms``): every symbol of
#: :data:`SYMBOLS` or prefixed symbol of dimension time that
#: :mod:`rclverify.lang.timing` accepts, in seconds.
TIME_UNITS: dict[str, Fraction] = {name: lookup(name).factor for name in ("ns", "us", "ms", "s", "min", "h")}  # type: ignore[union-attr]
