"""The near-miss threshold of a monitors entry: how small a satisfied
guarantee's margin may be before the report names it (docs/monitors.md,
"Near misses"; docs/semantics.md, "Margins").

The plan's monitors entry may say::

    - backend: monitors
      traces: [runs/robot.jsonl]
      near_miss: {value: 0.1, time: 20 ms}

``value``: a space margin (:mod:`rclverify.semantics.robustness`) below it,
on a guarantee no run of the entry violated, is a near miss; a number > 0,
with a unit as RCL writes one (``0.1 mm``, ``2 deg``, ``0.05 m/s``;
:func:`rclverify.lang.units.parse_unit`) or bare.  With a unit it is
converted to each margin's unit, the unit of the comparison that decides
the margin (``0.1 mm`` is 0.0001 on a guarantee in ``[m]``), and applies
to the margins of its dimension only (:meth:`NearMiss.value_in`); bare, it
is read in each margin's own unit, which is one reading only when the
node's guarantees compare quantities of one dimension: a bare number on
guarantees of different dimensions (``[mm]`` and ``[m/s]``) is refused,
the guarantees named, and so is a unit no guarantee's comparisons carry
(:func:`value_fault`).  ``time``: the same for a deadline's time margin
(:mod:`.time_margins`), a duration with its unit as in RCL (``20 ms``).
Either may be left out; one at least is given.  :func:`parse_near_miss`
reads it, raising :class:`NearMissError` (with the key path that is wrong)
for anything else; the plan's check calls it and :func:`value_fault` at load
(:mod:`rclverify.backends.entry_checks`), so a bad threshold is a located
plan error before any run.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

from rclverify.lang import ast
from rclverify.lang.timing import UNITS, parse_duration
from rclverify.lang.types import Checked
from rclverify.lang.units import Unit, UnitError, dimension_name, parse_unit, ratio
from rclverify.lang.walk import subexpressions

#: a number and a unit, ``0.1 mm``, ``5e-3 m/s``
_WITH_UNIT = re.compile(r"^\s*([-+]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?)\s*(\S.*?)?\s*$")


class NearMissError(ValueError):
    """A ``near_miss:`` that does not read; ``key`` the path of the bad key within it."""

    def __init__(self, message: str, key: tuple[str, ...] = ()) -> None:
        super().__init__(message)
        self.key = key


@dataclass(frozen=True)
class NearMiss:
    """A threshold: ``value`` (a space margin, ``None``: not asked) in
    ``value_unit`` (``None``: a bare number, read in each margin's unit),
    ``time_ns`` (a time margin in integer nanoseconds, rounded up; ``None``:
    not asked); ``time_text`` the duration as written."""

    value: float | None = None
    time_ns: int | None = None
    time_text: str = ""
    value_unit: Unit | None = None

    @property
    def value_text(self) -> str:
        """The value as the plan writes it: ``0.1 mm``, ``0.05``."""
        return f"{self.value:g}" + (f" {self.value_unit.text}" if self.value_unit is not None else "")

    def value_in(self, unit: str) -> float | None:
        """The space threshold in a margin's unit ``unit`` (its text, ``""``: none declared): the
        bare value itself; a value with a unit multiplied by how many ``unit`` make one of its unit
        (:func:`rclverify.lang.units.ratio`: ``0.1 mm`` in ``m`` is 0.0001); ``None`` when no space
        threshold is asked, or the value has a unit and ``unit`` is none, does not read, is of
        another dimension or is an affine scale (``degC``): the threshold does not apply there."""
        if self.value is None or self.value_unit is None:
            return self.value
        to = _unit_or_none(unit)
        if to is None or to.dims != self.value_unit.dims or to.offset is not None or self.value_unit.offset is not None:
            return None
        f, pi = ratio(self.value_unit, to)
        return self.value * float(f) * math.pi ** pi


def parse_near_miss(raw: Any) -> NearMiss | None:
    """``raw`` (the entry's ``near_miss`` value, ``None`` when absent) as a
    :class:`NearMiss`.  Raises :class:`NearMissError` for a value that is
    not a mapping of ``value`` (a finite number > 0) and/or ``time`` (a
    duration: a positive number and a unit of ``ns``, ``us``, ``ms``, ``s``,
    ``min``, ``h``)."""
    if raw is None:
        return None
    if not isinstance(raw, dict) or not raw:
        raise NearMissError("near_miss must be a mapping with value (a margin, a number > 0) and/or time "
                            "(a duration such as '20 ms')")
    unknown = sorted(str(k) for k in raw if k not in ("value", "time"))
    if unknown:
        raise NearMissError(f"near_miss has no key {unknown[0]!r} (its keys: value, time)", (unknown[0],))
    value, unit = _value(raw.get("value"))
    time_ns, text = None, ""
    if "time" in raw:
        text = str(raw["time"])
        t = parse_duration(text)
        if t is None:
            raise NearMissError(f"near_miss time {text!r} must be a positive number and a unit, e.g. '20 ms' "
                                f"(units: {', '.join(UNITS)})", ("time",))
        time_ns = math.ceil(t * 10**9)
    return NearMiss(value, time_ns, text, unit)


def _value(raw: Any) -> tuple[float | None, Unit | None]:
    """``(number, unit)`` of a ``near_miss`` ``value``: a bare number or a number and a unit."""
    if raw is None:
        return None, None
    why = (f"near_miss value must be a finite number > 0, bare (read in each guarantee's unit) or with a unit "
           f"(0.1 mm, converted to each guarantee's), not {raw!r}")
    unit = None
    if isinstance(raw, str):
        m = _WITH_UNIT.match(raw)
        if m is None:
            raise NearMissError(why, ("value",))
        number: Any = float(m.group(1))
        if m.group(2):
            try:
                unit = parse_unit(m.group(2))
            except UnitError as exc:
                raise NearMissError(f"near_miss value {raw!r}: {exc.message}", ("value",)) from None
    else:
        number = raw
    if isinstance(number, bool) or not isinstance(number, (int, float)) or not math.isfinite(number) or number <= 0:
        raise NearMissError(why, ("value",))
    return float(number), unit


def _unit_or_none(text: str) -> Unit | None:
    try:
        return parse_unit(text) if text else None
    except UnitError:
        return None


def guarantee_units(checked: Checked, node: str) -> dict[int, list[str]]:
    """``{k: [unit text, ...]}``: for each guarantee ``k`` (1-based) of ``node``, the units of the
    comparisons that can decide its space margin, as the margins name them
    (:func:`rclverify.semantics.robustness.atom_words`), each once, in source order; a guarantee
    whose comparisons carry no declared unit is left out."""
    from rclverify.semantics.robustness import atom_words  # deferred: start-up (z3 and the evaluator, at the plan's check only)
    cn = checked.nodes[node]
    out: dict[int, list[str]] = {}
    for k, g in enumerate(cn.node.guarantees, 1):
        bound = frozenset(n for e in subexpressions(g.formula) if isinstance(e, ast.Quant)
                          for b in e.bindings for n in b.names)
        found: list[str] = []
        for e in subexpressions(g.formula):
            if isinstance(e, ast.Compare):
                for i in range(len(e.ops)):
                    unit = atom_words(checked, cn, e, i, bound)[1]
                    if unit and unit not in found:
                        found.append(unit)
        if found:
            out[k] = found
    return out


def value_fault(t: NearMiss, units: dict[int, list[str]], node: str) -> str | None:
    """Why the space threshold of ``t`` has no one reading on ``node``'s guarantees, whose margins'
    units are ``units`` (:func:`guarantee_units`), ``None`` when it has: a bare number on guarantees
    of more than one dimension (each guarantee named with its units), or a value with a unit of a
    dimension none of the guarantees' comparisons carries."""
    if t.value is None:
        return None
    dims: dict[Any, list[str]] = {}
    for k, texts in units.items():
        for text in texts:
            u = _unit_or_none(text)
            if u is not None:
                dims.setdefault(u.dims, []).append(f"guarantee {k} in [{text}] ({dimension_name(u.dims)})")
    if t.value_unit is None:
        if len(dims) <= 1:
            return None
        named = "; ".join(w for ws in dims.values() for w in ws)
        return (f"near_miss value {t.value_text} is a bare number, but {node}'s guarantees compare quantities of "
                f"{len(dims)} dimensions ({named}): a margin of {t.value_text} means another thing in each; give the "
                f"value a unit (e.g. {t.value_text} {_example(units)}), converted to each guarantee's unit and applied "
                f"to the guarantees of its dimension")
    if t.value_unit.dims in dims:
        return None
    have = "; ".join(w for ws in dims.values() for w in ws) or "no guarantee's comparison declares a unit"
    return (f"near_miss value {t.value_text} is a {dimension_name(t.value_unit.dims)}, but no guarantee of {node} "
            f"compares one ({have}): it would apply to no margin")


def _example(units: dict[int, list[str]]) -> str:
    return next(iter(next(iter(units.values()))))


__all__ = ["NearMiss", "NearMissError", "guarantee_units", "parse_near_miss", "value_fault"]
