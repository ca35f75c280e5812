"""Numbers at an IDL width: what a ROS field of a primitive type can carry
(rosidl's type mapping; the ranges of OMG IDL 4.2, table 7-13).

* a rational rounded to the nearest value of ``float32``/``float64`` (IEEE 754
  round-to-nearest, ties to even, subnormals included: :func:`nearest_at_width`,
  :func:`narrow`), the edges the property tests draw at a width
  (:func:`edges_at_width`, :func:`int_edges`), and such a value's exact
  decimal digits (:func:`exact_decimal`);
* what a field carries (:class:`Width`, :class:`Carried`: the primitive, a
  ``string<=N`` bound, a ``T[<=N]`` or ``T[N]`` sequence) and why a value
  cannot travel in it (:func:`width_fault`, :func:`carried_fault`).

:mod:`rclverify.semantics.widths` reads a formula's constants at these widths
and names everything here too.
"""
from __future__ import annotations

import dataclasses
import math
import struct
from fractions import Fraction
from typing import Any, Iterable


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
