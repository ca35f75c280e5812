"""The tolerance of recorded numbers: numbers closer than a declared bound
are one value to the comparisons of a recorded run (docs/monitors.md,
"Numbers on the wire").

A :class:`Tolerance` is declared in the mapping file or the plan's
``monitors`` entry (``tolerance: {abs: 1.0e-9, rel: 1.0e-9, ulps: 4}``) and
read by :func:`parse_tolerance`; :mod:`rclverify.semantics.floatsem` judges
in it as its third semantics.
"""
from __future__ import annotations

import math
import struct
from dataclasses import dataclass
from fractions import Fraction
from typing import Any, Mapping

from rclverify.semantics.shapes import ToleranceJSON


class ToleranceError(ValueError):
    """A malformed tolerance declaration; ``key`` is the key at fault (``()`` for the whole value)."""

    def __init__(self, message: str, *key: str) -> None:
        super().__init__(message)
        self.key = key


@dataclass(frozen=True)
class Tolerance:
    """Numbers closer than this are one value to the comparisons of a recorded run.

    ``abs`` (in the variable's unit), ``rel`` (a fraction of the larger
    magnitude) and ``ulps`` (units in the last place of the doubles nearest
    the two values): two numbers are close when any bound that is set holds.
    Declared in the mapping file or the plan's ``monitors`` entry
    (``tolerance: {abs: 1.0e-9, rel: 1.0e-9, ulps: 4}``)."""

    abs: Fraction = Fraction(0)
    rel: Fraction = Fraction(0)
    ulps: int = 0

    def close(self, x: Any, y: Any) -> bool:
        """Whether numbers ``x`` and ``y`` are within the tolerance (exact rational arithmetic)."""
        a, b = Fraction(x), Fraction(y)
        d = abs(a - b)
        if d <= self.abs or d <= self.rel * max(abs(a), abs(b)):
            return True
        return bool(self.ulps) and ulp_distance(float(a), float(b)) <= self.ulps

    def text(self) -> str:
        """``abs 1e-09, rel 1e-09, ulps 4`` (the bounds that are set)."""
        parts = [f"{k} {_num_text(v)}" for k, v in (("abs", self.abs), ("rel", self.rel), ("ulps", self.ulps)) if v]
        return ", ".join(parts) or "none"

    def to_json(self) -> ToleranceJSON:
        """The bounds as JSON (:class:`rclverify.semantics.shapes.ToleranceJSON`)."""
        return {"abs": float(self.abs), "rel": float(self.rel), "ulps": self.ulps}

    def __bool__(self) -> bool:
        return bool(self.abs or self.rel or self.ulps)


def _num_text(v: Any) -> str:
    return str(v) if isinstance(v, int) else repr(float(v))


def ulp_distance(a: float, b: float) -> int:
    """How many steps from double ``a`` to double ``b`` (0 when they compare
    equal, so ``-0.0`` and ``0.0`` are 0 apart; a NaN is infinitely far)."""
    if a == b:
        return 0
    if math.isnan(a) or math.isnan(b):
        return 1 << 64

    def ordered(x: float) -> int:
        i: int = struct.unpack("<q", struct.pack("<d", x))[0]
        return i if i >= 0 else -(i & 0x7FFFFFFFFFFFFFFF)
    return abs(ordered(a) - ordered(b))


def parse_tolerance(raw: Any) -> Tolerance | None:
    """A :class:`Tolerance` from a mapping file's or plan entry's ``tolerance``
    (``None``: none declared).  Each bound is a finite number >= 0 (a YAML
    string such as ``1e-9``, which YAML 1.1 reads as text, is read as the
    number it spells); ``ulps`` an integer.  Raises :class:`ToleranceError`
    naming the key."""
    if raw is None:
        return None
    if not isinstance(raw, Mapping):
        raise ToleranceError(f"tolerance must map abs, rel or ulps to a number, not {raw!r}")
    unknown = sorted(str(k) for k in raw if k not in ("abs", "rel", "ulps"))
    if unknown:
        raise ToleranceError(f"tolerance: unknown key {unknown[0]!r} (expected abs, rel, ulps)", unknown[0])
    out: dict[str, Fraction] = {}
    ulps = 0
    for key in ("abs", "rel", "ulps"):
        if key not in raw:
            continue
        v = raw[key]
        if isinstance(v, str):
            try:
                v = float(v)
            except ValueError:
                pass
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0:
            raise ToleranceError(f"tolerance: {key} must be a finite number >= 0, not {raw[key]!r}", key)
        if key == "ulps":
            if float(v) != int(v):
                raise ToleranceError(f"tolerance: ulps must be a whole number, not {raw[key]!r}", key)
            ulps = int(v)
        else:
            out[key] = Fraction(v)
    return Tolerance(out.get("abs", Fraction(0)), out.get("rel", Fraction(0)), ulps)
