"""The near-miss threshold of a monitors entry: how small a satisfied
guarantee's margin may be before the report names it (docs/monitors.md,
"Near misses"; docs/semantics.md, "Margins").

The plan's monitors entry may say::

    - backend: monitors
      traces: [runs/robot.jsonl]
      near_miss: {value: 0.1, time: 20 ms}

``value``: a space margin (:mod:`rclverify.semantics.robustness`) below it,
on a guarantee no run of the entry violated, is a near miss; a number > 0,
in the unit of the comparison that decides the margin (the report names
that unit with the margin).  ``time``: the same for a deadline's time margin
(:mod:`.time_margins`), a duration with its unit as in RCL (``20 ms``).
Either may be left out; one at least is given.  :func:`parse_near_miss`
reads it, raising :class:`NearMissError` (with the key path that is wrong)
for anything else; the plan's check calls it at load
(:mod:`rclverify.backends.entry_checks`), so a bad threshold is a located
plan error before any run.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from rclverify.lang.timing import UNITS, parse_duration


class NearMissError(ValueError):
    """A ``near_miss:`` that does not read; ``key`` the path of the bad key within it."""

    def __init__(self, message: str, key: tuple[str, ...] = ()) -> None:
        super().__init__(message)
        self.key = key


@dataclass(frozen=True)
class NearMiss:
    """A threshold: ``value`` (a space margin, ``None``: not asked) and
    ``time_ns`` (a time margin in integer nanoseconds, rounded up; ``None``:
    not asked); ``time_text`` the duration as written."""

    value: float | None = None
    time_ns: int | None = None
    time_text: str = ""


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
    value = raw.get("value")
    if value is not None and (isinstance(value, bool) or not isinstance(value, (int, float))
                              or not math.isfinite(value) or value <= 0):
        raise NearMissError(f"near_miss value must be a finite number > 0 (a margin in the unit of the "
                            f"comparison that decides it), not {value!r}", ("value",))
    time_ns, text = None, ""
    if "time" in raw:
        text = str(raw["time"])
        t = parse_duration(text)
        if t is None:
            raise NearMissError(f"near_miss time {text!r} must be a positive number and a unit, e.g. '20 ms' "
                                f"(units: {', '.join(UNITS)})", ("time",))
        time_ns = math.ceil(t * 10**9)
    return NearMiss(None if value is None else float(value), time_ns, text)


__all__ = ["NearMiss", "NearMissError", "parse_near_miss"]
