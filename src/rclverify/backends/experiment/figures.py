"""Experiment data with units: per-trial CSV files and summary statistics.

A quantity is written ``"<number> <unit>"`` (``"21.4 cm"``, ``"4 mm"``) or as
a bare number (dimensionless).  Values are kept exactly as
:class:`fractions.Fraction` in the base unit of their dimension (metres,
seconds), so ``"4 mm"`` is ``Fraction(1, 250)`` m.

Summary statistics file (YAML)::

    measure: <what was measured>      # text, for the report
    better: lower | higher            # default lower: best = minimum
    count: 47
    mean: 21.4 cm
    std: 4 mm
    best: 8 cm
    worst: 43 cm

Per-trial file (CSV): a header row, one row per trial; the plan names the
``column`` measured and its ``unit``.
"""
from __future__ import annotations

import csv
import io
import re
from dataclasses import dataclass
from fractions import Fraction
from typing import Any, Mapping

from rclverify.model.plan.yamlguard import safe_load_guarded
import yaml

#: unit -> (dimension, factor to the base unit).  Base units: m, s.
UNITS: Mapping[str, tuple[str, Fraction]] = {
    "": ("1", Fraction(1)),
    "m": ("length", Fraction(1)), "cm": ("length", Fraction(1, 100)), "mm": ("length", Fraction(1, 1000)),
    "km": ("length", Fraction(1000)),
    "s": ("time", Fraction(1)), "ms": ("time", Fraction(1, 1000)), "min": ("time", Fraction(60)),
}
BASE = {"length": "m", "time": "s", "1": ""}
STATISTICS = ("count", "mean", "std", "best", "worst")
_QTY = re.compile(r"^\s*([-+]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?)\s*([A-Za-z]*)\s*$")


class DataError(ValueError):
    """A malformed quantity, statistic or data file (message says which)."""


@dataclass(frozen=True)
class Quantity:
    """An exact value in the base unit of ``dim``; ``text`` as written."""

    value: Fraction
    dim: str
    text: str

    def show(self) -> str:
        """The value as written, or in base units for a computed figure."""
        return self.text or format_value(self.value, self.dim)


def format_value(v: Fraction, dim: str) -> str:
    """``v`` (base unit of ``dim``) as a short decimal with the base unit."""
    unit = BASE.get(dim, "")
    return f"{float(v):.6g}" + (f" {unit}" if unit else "")


def quantity(raw: Any) -> Quantity:
    """Parse ``"21.4 cm"``, ``"4 mm"``, ``47`` or ``0.25`` into a :class:`Quantity`.

    Raises :class:`DataError` for anything else or an unknown unit.
    """
    if isinstance(raw, bool) or not isinstance(raw, (int, float, str)):
        raise DataError(f"expected a number with an optional unit, found {raw!r}")
    m = _QTY.match(str(raw))
    if m is None:
        raise DataError(f"expected a number with an optional unit (e.g. '25 cm'), found {raw!r}")
    num, unit = m.group(1), m.group(2)
    if unit not in UNITS:
        raise DataError(f"unknown unit {unit!r} in {raw!r}; known units: {', '.join(u for u in UNITS if u)}")
    dim, factor = UNITS[unit]
    return Quantity(Fraction(num) * factor, dim, str(raw).strip())


@dataclass(frozen=True)
class Figures:
    """The named figures of one experiment.

    ``stats`` maps ``count``/``mean``/``std``/``best``/``worst`` to
    quantities; ``trials`` (per-trial data only) holds the measured column
    in base units, trial by trial; ``column`` is its name (``""`` for a
    summary); ``better`` is ``"lower"`` or ``"higher"``; ``derived`` says
    whether the statistics were computed from trials (``std`` is then the
    sample standard deviation, given by ``variance``).
    """

    stats: Mapping[str, Quantity]
    dim: str
    better: str = "lower"
    measure: str = ""
    column: str = ""
    trials: tuple[Fraction, ...] = ()
    variance: Fraction | None = None

    @property
    def derived(self) -> bool:
        return bool(self.column)


def load_summary(text: str, file: str) -> Figures:
    """Read a summary-statistics YAML text.  Raises :class:`DataError`."""
    try:
        data = safe_load_guarded(text, file)
    except yaml.YAMLError as exc:
        raise DataError(f"{file}: invalid YAML: {getattr(exc, 'problem', exc)}") from None
    if not isinstance(data, dict):
        raise DataError(f"{file}: expected a mapping with {', '.join(STATISTICS)}")
    missing = [k for k in STATISTICS if k not in data]
    if missing:
        raise DataError(f"{file}: missing statistic(s) {', '.join(missing)}")
    stats: dict[str, Quantity] = {}
    for k in STATISTICS:
        try:
            stats[k] = quantity(data[k])
        except DataError as exc:
            raise DataError(f"{file}: {k}: {exc}") from None
    count = stats["count"]
    if count.dim != "1" or count.value.denominator != 1 or count.value < 1:
        raise DataError(f"{file}: count must be a positive whole number, found {data['count']!r}")
    dims = {stats[k].dim for k in STATISTICS[1:]}
    if len(dims) != 1:
        raise DataError(f"{file}: mean, std, best and worst must have the same dimension "
                        f"(found {', '.join(f'{k} {stats[k].text}' for k in STATISTICS[1:])})")
    better = str(data.get("better", "lower"))
    if better not in ("lower", "higher"):
        raise DataError(f"{file}: better must be 'lower' or 'higher', found {better!r}")
    return Figures(stats, dims.pop(), better, str(data.get("measure", "")))


def load_trials(text: str, file: str, column: str, unit: str, better: str = "lower") -> Figures:
    """Read a per-trial CSV text; compute count, mean, sample std, best, worst exactly.

    Raises :class:`DataError` for a missing column, a non-numeric cell or no rows.
    """
    if unit not in UNITS:
        raise DataError(f"unknown unit {unit!r}; known units: {', '.join(u for u in UNITS if u)}")
    dim, factor = UNITS[unit]
    rows = list(csv.DictReader(io.StringIO(text)))
    if not rows:
        raise DataError(f"{file}: no trials (a header row and at least one data row are needed)")
    if column not in rows[0]:
        raise DataError(f"{file}: no column {column!r}; columns: {', '.join(rows[0])}")
    values = []
    for i, row in enumerate(rows, 2):
        try:
            values.append(Fraction(str(row[column]).strip()) * factor)
        except (ValueError, ZeroDivisionError):
            raise DataError(f"{file}:{i}: {column} is not a number: {row[column]!r}") from None
    n = len(values)
    mean = sum(values, Fraction(0)) / n
    var = sum(((v - mean) ** 2 for v in values), Fraction(0)) / (n - 1) if n > 1 else Fraction(0)
    lo, hi = min(values), max(values)
    best, worst = (lo, hi) if better == "lower" else (hi, lo)
    stats = {"count": Quantity(Fraction(n), "1", str(n)), "mean": Quantity(mean, dim, ""),
             "std": Quantity(Fraction(0), dim, f"{float(var) ** 0.5:.6g} {BASE[dim]}".strip()),
             "best": Quantity(best, dim, ""), "worst": Quantity(worst, dim, "")}
    return Figures(stats, dim, better, column, column, tuple(values), var)
