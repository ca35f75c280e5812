"""Units of measure as values: the unit algebra of RCL (docs/rcl-language.md,
"Units of measure").

A unit is a *dimension* (a vector of integer exponents over the base
dimensions length, mass, time, current, temperature, amount, luminous
intensity and angle) and an exact *scale* relative to the coherent SI unit of
that dimension: a rational factor times a power of pi (``deg`` is
``pi/180 rad``); ``degC`` alone has an offset (an affine scale).  Here are the
:class:`Unit` and its products and powers, the table of symbols
(:data:`SYMBOLS`) and SI prefixes (:data:`PREFIXES`) a symbol is looked up in
(:func:`lookup`), and the names a unit is shown by (:func:`best_name`,
:func:`canonical_text`, :func:`dimension_name`).

Sources: the SI Brochure, 9th edition (BIPM 2019), tables 2, 4, 7 (base and
derived units, prefixes) and 8 (non-SI units accepted for use: ``min``,
``h``, ``deg``); ROS REP 103 (metres, seconds, radians as the standard units).
Reading a unit text and comparing units are :mod:`rclverify.lang.units`'s.
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction


#: Base dimensions, in the order of a unit's exponent vector, and their words.
BASE_DIMENSIONS: tuple[str, ...] = ("length", "mass", "time", "current", "temperature", "amount",
                                    "luminous intensity", "angle")
_N = len(BASE_DIMENSIONS)
Dims = tuple[int, ...]


def _d(**exps: int) -> Dims:
    """An exponent vector from keyword exponents (``L``, ``M``, ``T``, ``I``,
    ``K``, ``N``, ``J``, ``A`` for angle)."""
    keys = ("L", "M", "T", "I", "K", "N", "J", "A")
    return tuple(exps.get(k, 0) for k in keys)


DIMENSIONLESS: Dims = (0,) * _N


@dataclass(frozen=True)
class Unit:
    """A unit of measure: ``dims`` (exponents over :data:`BASE_DIMENSIONS`),
    ``factor`` (exact rational) and ``pi`` (power of pi) of its scale
    relative to the coherent SI unit, ``offset`` (kelvin at its zero: only
    ``degC``, an affine scale; ``None`` for every other unit).  ``text`` is
    how it was written (shown in messages; not compared)."""

    dims: Dims
    factor: Fraction = Fraction(1)
    pi: int = 0
    offset: Fraction | None = None
    text: str = ""

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Unit) and self.key == other.key

    def __hash__(self) -> int:
        return hash(self.key)

    @property
    def key(self) -> tuple[Dims, Fraction, int, Fraction | None]:
        """What makes two units the same: dimension, scale and offset."""
        return (self.dims, self.factor, self.pi, self.offset)

    def __str__(self) -> str:
        return f"[{self.text or best_name(self) or canonical_text(self)}]"

    def times(self, other: "Unit", text: str = "") -> "Unit":
        """The product of two units (no affine unit may take part)."""
        return Unit(tuple(a + b for a, b in zip(self.dims, other.dims)), self.factor * other.factor,
                    self.pi + other.pi, None, text)

    def power(self, k: int, text: str = "") -> "Unit":
        """The unit raised to the integer ``k``."""
        return Unit(tuple(a * k for a in self.dims), self.factor ** k, self.pi * k, None, text)

    def over(self, other: "Unit", text: str = "") -> "Unit":
        """The quotient of two units."""
        return self.times(other.power(-1), text)


ONE = Unit(DIMENSIONLESS, text="1")


@dataclass(frozen=True)
class Symbol:
    """One unit symbol of the table: its unit and whether SI prefixes apply."""

    unit: Unit
    prefixable: bool
    name: str


def _sym(name: str, dims: Dims, factor: Fraction | int = 1, pi: int = 0, *, prefixable: bool = True,
         offset: Fraction | None = None, what: str = "") -> tuple[str, Symbol]:
    return name, Symbol(Unit(dims, Fraction(factor), pi, offset, name), prefixable, what)


#: The unit symbols RCL accepts (docs/rcl-language.md has the same table).
SYMBOLS: dict[str, Symbol] = dict([
    _sym("m", _d(L=1), what="metre"),
    _sym("g", _d(M=1), Fraction(1, 1000), what="gram"),
    _sym("s", _d(T=1), what="second"),
    _sym("min", _d(T=1), 60, prefixable=False, what="minute"),
    _sym("h", _d(T=1), 3600, prefixable=False, what="hour"),
    _sym("A", _d(I=1), what="ampere"),
    _sym("K", _d(K=1), what="kelvin"),
    _sym("degC", _d(K=1), prefixable=False, offset=Fraction(27315, 100), what="degree Celsius (affine)"),
    _sym("mol", _d(N=1), what="mole"),
    _sym("cd", _d(J=1), prefixable=False, what="candela"),
    _sym("rad", _d(A=1), what="radian"),
    _sym("deg", _d(A=1), Fraction(1, 180), 1, prefixable=False, what="degree of angle"),
    _sym("rpm", _d(A=1, T=-1), Fraction(1, 30), 1, prefixable=False, what="revolution per minute"),
    _sym("Hz", _d(T=-1), what="hertz"),
    _sym("N", _d(L=1, M=1, T=-2), what="newton"),
    _sym("Pa", _d(L=-1, M=1, T=-2), what="pascal"),
    _sym("J", _d(L=2, M=1, T=-2), what="joule"),
    _sym("W", _d(L=2, M=1, T=-3), what="watt"),
    _sym("C", _d(T=1, I=1), what="coulomb"),
    _sym("V", _d(L=2, M=1, T=-3, I=-1), what="volt"),
    _sym("Ohm", _d(L=2, M=1, T=-3, I=-2), what="ohm"),
    _sym("T", _d(M=1, T=-2, I=-1), what="tesla"),
    _sym("percent", DIMENSIONLESS, Fraction(1, 100), prefixable=False, what="per cent"),
    _sym("%", DIMENSIONLESS, Fraction(1, 100), prefixable=False, what="per cent"),
])

#: Spellings people write for a symbol (offered as the candidate of an unknown unit).
ALIASES: dict[str, str] = {"sec": "s", "secs": "s", "second": "s", "seconds": "s", "meter": "m", "metre": "m",
                           "meters": "m", "metres": "m", "msec": "ms", "usec": "us", "nsec": "ns", "hz": "Hz",
                           "degree": "deg", "degrees": "deg", "radian": "rad", "radians": "rad", "celsius": "degC",
                           "ohm": "Ohm", "pct": "%", "kelvin": "K", "kmh": "km/h", "mps": "m/s"}

#: SI prefixes (SI Brochure table 7) that may precede a prefixable symbol;
#: ``u`` is micro (ASCII for the micro sign, which is accepted too).
PREFIXES: dict[str, Fraction] = {
    "p": Fraction(1, 10**12), "n": Fraction(1, 10**9), "u": Fraction(1, 10**6), "m": Fraction(1, 1000),
    "c": Fraction(1, 100), "d": Fraction(1, 10), "h": Fraction(100), "k": Fraction(1000), "M": Fraction(10**6),
    "G": Fraction(10**9), "\u00b5": Fraction(1, 10**6), "\u03bc": Fraction(1, 10**6),
}

#: Names of dimensions that have one (shown beside a unit in messages).
_NAMED: dict[Dims, str] = {
    DIMENSIONLESS: "dimensionless", _d(L=1, T=-1): "velocity", _d(L=1, T=-2): "acceleration",
    _d(L=1, T=-3): "jerk", _d(A=1, T=-1): "angular velocity", _d(A=1, T=-2): "angular acceleration",
    _d(T=-1): "frequency", _d(L=1, M=1, T=-2): "force", _d(L=-1, M=1, T=-2): "pressure",
    _d(L=2, M=1, T=-2): "energy", _d(L=2, M=1, T=-3): "power", _d(L=2, M=1, T=-3, I=-1): "voltage",
    _d(L=2): "area", _d(L=3): "volume", _d(T=1, I=1): "charge", _d(L=2, M=1, T=-3, I=-2): "resistance",
    _d(M=1, T=-2, I=-1): "magnetic flux density", _d(L=2, M=1, T=-2, A=-1): "torque",
}


def lookup(name: str) -> Unit | None:
    """The unit of one symbol (``"mm"`` -> millimetre), or ``None`` when
    ``name`` is neither a symbol of :data:`SYMBOLS` nor an SI prefix
    followed by a prefixable one."""
    if name in SYMBOLS:
        return SYMBOLS[name].unit
    for p, f in PREFIXES.items():
        rest = name[len(p):]
        if name.startswith(p) and rest in SYMBOLS and SYMBOLS[rest].prefixable:
            u = SYMBOLS[rest].unit
            return Unit(u.dims, u.factor * f, u.pi, None, name)
    return None


def best_name(u: Unit) -> str | None:
    """The shortest symbol of the table, prefixed or not, that denotes ``u``
    (``mm`` for the unit the algebra makes of ``[mm/m]*[m]``), ``None`` when
    there is none."""
    return _NAMES.get(u.key)


def _all_names() -> dict[tuple[Dims, Fraction, int, Fraction | None], str]:
    out: dict[tuple[Dims, Fraction, int, Fraction | None], str] = {}
    names = [n for n in SYMBOLS if n != "percent"]
    names += [p + n for p in PREFIXES if p.isascii() for n, y in SYMBOLS.items() if y.prefixable]
    for n in sorted(names, key=len):
        u = lookup(n)
        if u is not None:
            out.setdefault(u.key, n)
    return out


def dimension_name(dims: Dims) -> str:
    """``"length"``, ``"velocity"``, ``"length^2*time^-1"``: the dimension in words."""
    if dims in _NAMED:
        return _NAMED[dims]
    parts = [name if e == 1 else f"{name}^{e}" for name, e in zip(BASE_DIMENSIONS, dims) if e]
    return "*".join(parts)


def canonical_text(u: Unit) -> str:
    """A text for a unit made by the algebra (no written text): its SI base
    form with the scale in front, e.g. ``1/1000*m``."""
    syms = ("m", "kg", "s", "A", "K", "mol", "cd", "rad")
    parts = [s if e == 1 else f"{s}^{e}" for s, e in zip(syms, u.dims) if e]
    body = "*".join(parts)
    scale = _scale_text(u.factor, u.pi)
    if not body:
        return scale
    return body if scale == "1" else f"{scale}*{body}"


def _scale_text(f: Fraction, pi: int) -> str:
    """``f * pi^pi`` as text: ``1000``, ``1/1000``, ``pi/180``, ``180/pi``."""
    pi_up = "" if pi <= 0 else "pi" + (f"^{pi}" if pi > 1 else "")
    pi_down = "" if pi >= 0 else "pi" + (f"^{-pi}" if pi < -1 else "")
    num = pi_up if f.numerator == 1 and pi_up else "*".join(x for x in (str(f.numerator), pi_up) if x)
    den = "*".join(x for x in ("" if f.denominator == 1 else str(f.denominator), pi_down) if x)
    return num if not den else f"{num}/{den}"


_NAMES = _all_names()
