"""How much of the assumption's ranges a property-test run covered
(docs/confidence.md, "tested").

For each input of the node, over the valid examples only (those the
assumption and the facts admitted, which the implementation ran on):

* a numeric input (INTEGER, NATURAL, REAL) whose range the assumption
  bounds on both sides (:func:`.strategies.assumption_bounds`, narrowed by
  the plan's ``bounds:``): the range ``[lo, hi]`` is cut into
  :data:`BUCKETS` buckets of equal width (for an integer range of fewer
  values, one bucket per value); the *coverage* is the fraction of buckets
  at least one example fell in.  The least and greatest values drawn are
  given too;
* a BOOL input, an enumeration input: the fraction of its admitted values
  drawn;
* a numeric input unbounded on a side: the least and greatest values drawn,
  no fraction (a fraction of an unbounded range means nothing);
* any other input (a function-typed table, a sequence, a set, a term): not
  measured, and said so.

Returns, per input, ``{"range", "drawn", "buckets", "covered", "fraction"}``
(``fraction`` ``None`` where not measured), and ``admitted`` (the
assumption's own range) where the plan's ``bounds:`` narrowed it: the
fraction is of the range drawn from, not of all the assumption admits.
"""
from __future__ import annotations

import math
from fractions import Fraction
from typing import Any, Mapping

from rclverify.lang.types import CheckedNode, EnumT, Scalar
from rclverify.backends.property_tests.strategies import Bound
from rclverify.backends.shapes import InputCoverage

#: Buckets a bounded numeric range is cut into.
BUCKETS = 10


def _num(v: Any) -> Fraction | None:
    if isinstance(v, bool):
        return None
    if isinstance(v, (int, Fraction)):
        return Fraction(v)
    if isinstance(v, float) and math.isfinite(v):
        return Fraction(v)
    return None


def _text(v: Fraction) -> str:
    return str(v.numerator) if v.denominator == 1 else f"{float(v):g}"


class Coverage:
    """Accumulates the valid examples' inputs of one run of ``node`` drawn
    within ``bounds`` (input name -> :class:`~.strategies.Bound`, the
    strategy's own)."""

    def __init__(self, node: CheckedNode, bounds: Mapping[str, Bound],
                 admitted: Mapping[str, Bound] | None = None) -> None:
        self.kinds: dict[str, tuple[str, Any]] = {}
        #: per input, the assumption's own range where the plan's ``bounds:`` narrowed it (text)
        self.admitted: dict[str, str] = {}
        for name, t in node.inputs.items():
            bd = bounds.get(name) or Bound()
            if admitted is not None and isinstance(t, Scalar) and t.name in ("INTEGER", "NATURAL", "REAL"):
                own = admitted.get(name) or Bound()
                lo0 = own.lo if own.lo is not None else (Fraction(0) if t.name == "NATURAL" else None)
                lo1 = bd.lo if bd.lo is not None else (Fraction(0) if t.name == "NATURAL" else None)
                if (lo0, own.hi) != (lo1, bd.hi):
                    self.admitted[name] = (f"[{'-inf' if lo0 is None else _text(lo0)}, "
                                           f"{'inf' if own.hi is None else _text(own.hi)}]")
            if isinstance(t, Scalar) and t.name == "BOOL":
                self.kinds[name] = ("finite", ("TRUE", "FALSE"))
            elif isinstance(t, EnumT):
                self.kinds[name] = ("finite", tuple(v for v in t.values if bd.enum is None or v in bd.enum)
                                    or tuple(t.values))
            elif isinstance(t, Scalar) and t.name in ("INTEGER", "NATURAL", "REAL"):
                lo = bd.lo if bd.lo is not None else (Fraction(0) if t.name == "NATURAL" else None)
                hi = bd.hi
                if t.name != "REAL" and lo is not None and hi is not None:
                    lo, hi = Fraction(math.ceil(lo)), Fraction(math.floor(hi))
                self.kinds[name] = ("numeric", (lo, hi, t.name != "REAL"))
            else:
                self.kinds[name] = ("other", str(t))
        self.seen: dict[str, set[Any]] = {n: set() for n in self.kinds}
        self.low: dict[str, Fraction] = {}
        self.high: dict[str, Fraction] = {}

    def add(self, inputs: Mapping[str, object]) -> None:
        """Count one valid example's ``inputs`` (``in.x`` or ``x`` -> value)."""
        for key, v in inputs.items():
            name = key.removeprefix("in.")
            kind = self.kinds.get(name)
            if kind is None:
                continue
            if kind[0] == "finite":
                self.seen[name].add(("TRUE" if v else "FALSE") if isinstance(v, bool) else str(v))
            elif kind[0] == "numeric":
                x = _num(v)
                if x is None:
                    continue
                self.low[name] = min(self.low.get(name, x), x)
                self.high[name] = max(self.high.get(name, x), x)
                b = self._bucket(kind[1], x)
                if b is not None:
                    self.seen[name].add(b)

    @staticmethod
    def _bucket(spec: tuple[Fraction | None, Fraction | None, bool], x: Fraction) -> int | None:
        lo, hi, integral = spec
        if lo is None or hi is None or x < lo or x > hi:
            return None
        n = _count(spec)
        if hi == lo:
            return 0
        return min(n - 1, int((x - lo) * n / (hi - lo)))

    def as_dict(self) -> dict[str, InputCoverage]:
        """Per input ``in.x``: ``range`` (text), ``drawn`` (least..greatest, or
        the values drawn), ``buckets``, ``covered``, ``fraction`` (module
        docstring; ``None`` where not measured)."""
        out: dict[str, InputCoverage] = {}
        for name, (kind, spec) in self.kinds.items():
            key = f"in.{name}"
            if kind == "finite":
                seen = sorted(self.seen[name])
                out[key] = {"range": "{" + ", ".join(spec) + "}", "drawn": ", ".join(seen),
                            "buckets": len(spec), "covered": len(set(seen) & set(spec)),
                            "fraction": round(len(set(seen) & set(spec)) / len(spec), 4) if spec else None}
            elif kind == "numeric":
                lo, hi, _ = spec
                drawn = (f"{_text(self.low[name])}..{_text(self.high[name])}" if name in self.low else "nothing")
                rng = f"[{'-inf' if lo is None else _text(lo)}, {'inf' if hi is None else _text(hi)}]"
                if lo is None or hi is None:
                    out[key] = {"range": rng, "drawn": drawn, "buckets": None, "covered": None, "fraction": None}
                else:
                    n = _count(spec)
                    out[key] = {"range": rng, "drawn": drawn, "buckets": n, "covered": len(self.seen[name]),
                                "fraction": round(len(self.seen[name]) / n, 4)}
                if name in self.admitted:
                    out[key]["admitted"] = self.admitted[name]
            else:
                out[key] = {"range": f"{spec} (not measured)", "drawn": "", "buckets": None, "covered": None,
                            "fraction": None}
        return out


def _count(spec: tuple[Fraction | None, Fraction | None, bool]) -> int:
    """The buckets of a bounded range: :data:`BUCKETS`, or one per value of a smaller integer range."""
    lo, hi, integral = spec
    assert lo is not None and hi is not None
    if integral:
        return max(1, min(BUCKETS, int(hi - lo) + 1))
    return BUCKETS

