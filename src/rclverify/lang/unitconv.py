"""The usual unit conversions: which declarable unit a bare factor converts to, and the factor's name.

A guarantee ``out.v == 3.6 * in.speed`` with ``speed : REAL [m/s]`` writes
the factor without a unit; by RCL's algebra (:mod:`.unitcheck`) the bare
``3.6`` is a pure number and the right side is in ``[m/s]``, but 3.6 is also
exactly the factor from metres per second to kilometres per hour.  Unit
inference (:mod:`.unitinfer`) keeps both readings: the *conversion*
(``[km/h]``, named first) and the *literal* one (``[m/s]``).

A factor ``k`` applied to a value in unit ``u`` converts it to the unit
``t`` when one ``u`` is ``k`` times one ``t`` (the number in ``t`` is ``k``
times the number in ``u``): ``t``'s scale is ``u``'s divided by ``k``.
:func:`convert_by` looks for such a ``t`` among :data:`TARGETS`, the units a
contract can declare (every symbol and SI-prefixed symbol of
:data:`~rclverify.lang.units.SYMBOLS`, and the compound units robot software
uses), exactly for a rational factor and within :data:`PI_SLACK` for a
decimal written for a factor with pi (``57.29578``, ``0.0174533``).

Sources: the SI Brochure, 9th edition (BIPM 2019), table 8 (``deg`` is
pi/180 rad); NIST SP 811 appendix B (1 ft = 0.3048 m exactly, 1 mi =
1.609344 km, 1 mph = 0.44704 m/s, 1 in = 2.54 cm).
"""
from __future__ import annotations

import math
from fractions import Fraction

from rclverify.lang.unit_algebra import _NAMES, Dims, Unit, _scale_text
from rclverify.lang.units import parse_unit, ratio
from rclverify.lang.units import short_decimal as short_decimal  # re-exported

#: Compound units a contract may declare, besides the symbols and prefixed symbols of the table.
_COMPOUND = ("m/s", "km/h", "mm/s", "cm/s", "m/s^2", "rad/s", "deg/s", "rad/s^2", "deg/s^2", "m/min", "km/s")
#: Relative slack when a decimal factor is read as a factor with pi (``57.2958`` for 180/pi).
PI_SLACK = 1e-4

#: The usual conversions that are no power of ten, by their exact value: their names in messages.
USUAL: dict[Fraction, str] = {Fraction(18, 5): "3.6", Fraction(3048, 10000): "0.3048",
                              Fraction(44704, 100000): "0.44704", Fraction(1609344, 1000000): "1.609344",
                              Fraction(254, 100): "2.54"}


def _targets() -> list[Unit]:
    out: dict[tuple[Dims, Fraction, int, Fraction | None], Unit] = {}
    for key, name in sorted(_NAMES.items(), key=lambda kv: (len(kv[1]), kv[1])):
        dims, f, pi, off = key
        if off is None:
            out.setdefault(key, Unit(dims, f, pi, None, name))
    for text in _COMPOUND:
        u = parse_unit(text)
        out.setdefault(u.key, u)
    return list(out.values())


#: The units a bare factor may convert to (declarable in a contract).
TARGETS: tuple[Unit, ...] = tuple(_targets())


_BY_KEY = {t.key: t for t in reversed(TARGETS)}


def named(u: Unit) -> Unit:
    """``u`` with the text of the unit of :data:`TARGETS` it is (``[m/s]``
    for the unit the algebra makes of ``[m]/[s]``), else as it is."""
    return u if u.text else _BY_KEY.get(u.key, u)


def _magnitude(f: Fraction, pi: int) -> float:
    return float(f) * math.pi ** pi


def convert_by(u: Unit, k: Fraction) -> Unit | None:
    """The unit of :data:`TARGETS` a value in ``u`` multiplied by the bare
    factor ``|k|`` is in, when ``k`` is a conversion (``convert_by([m/s],
    3.6)`` is ``[km/h]``, ``convert_by([deg], 0.0174533)`` is ``[rad]``);
    ``None`` when ``k`` is 0 or 1, ``u`` is affine, or no target fits.
    An exact match (rational scale) wins over one within :data:`PI_SLACK`."""
    k = abs(k)
    if k in (0, 1) or u.offset is not None:
        return None
    want_f, want_pi = u.factor / k, u.pi
    same = [t for t in TARGETS if t.dims == u.dims]
    for t in same:
        if t.factor == want_f and t.pi == want_pi:
            return t
    want = _magnitude(want_f, want_pi)
    for t in same:
        if t.pi != want_pi and abs(_magnitude(t.factor, t.pi) - want) <= PI_SLACK * want:
            return t
    return None


def factor_name(a: Unit, b: Unit) -> str:
    """How many ``b`` make one ``a``, named as people write it: ``"180/pi"``
    (rad against deg), ``"3.6"`` (m/s against km/h), ``"1/3.6"``,
    ``"1000"``, ``"1/1000"``, else the exact fraction.  ``a`` and ``b`` are of
    one dimension."""
    f, pi = ratio(a, b)
    if pi == 0:
        if f in USUAL:
            return USUAL[f]
        if 1 / f in USUAL:
            return f"1/{USUAL[1 / f]}"
    return _scale_text(f, pi)

