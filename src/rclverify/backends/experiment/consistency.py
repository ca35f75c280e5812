"""Bounds that the summary statistics of any sample obey.

Given a count ``n``, a mean ``m``, a standard deviation ``s`` and the
smallest and largest trial ``a <= b`` (best/worst, by ``better``), any real
sample satisfies:

* ``s >= 0`` and ``a <= m <= b``;
* with one trial at each extreme, ``((n-1)a + b)/n <= m <= (a + (n-1)b)/n``;
* Samuelson's inequality: no trial lies further than ``s * sqrt(n-1)`` from
  the mean (population ``s``; Samuelson 1968);
* the spread bound: the sum of squared deviations is at least that of the
  sample with one trial at ``a``, one at ``b`` and the other ``n-2`` equal,
  so ``s^2 >= SS_min / n``;
* the Bhatia-Davis inequality: the population variance is at most
  ``(b - m)(m - a)``.

Whether ``s`` is the sample (``n-1``) or the population (``n``) deviation is
rarely reported, so every bound is applied in its weakest form over both
conventions: a flag means no sample of either kind has these figures.  All
comparisons are exact (squares of rationals, no square roots).
"""
from __future__ import annotations

from fractions import Fraction

from rclverify.backends.experiment.figures import Figures
from rclverify.backends.experiment.figures import BASE, UNITS
from rclverify.backends.shapes import FigureJson


def _display_unit(text: str, dim: str) -> tuple[str, Fraction]:
    """The unit ``text`` is written in (``"21.4 cm"`` -> cm), else the base unit."""
    word = text.split()[-1] if len(text.split()) == 2 else ""
    if word in UNITS and UNITS[word][0] == dim:
        return word, UNITS[word][1]
    return BASE.get(dim, ""), Fraction(1)


def check(fig: Figures) -> list[dict[str, str]]:
    """Flags for statistics of ``fig`` that cannot all be true together.

    Returns ``[{"bound": name, "explanation": sentence with the figures}]``
    (empty when consistent).  Computed statistics (per-trial data) are
    consistent by construction and return ``[]``.
    """
    if fig.derived:
        return []
    st = fig.stats
    n, m, s = st["count"].value, st["mean"].value, st["std"].value
    lo_name, hi_name = ("best", "worst") if fig.better == "lower" else ("worst", "best")
    a, b = st[lo_name].value, st[hi_name].value
    d = fig.dim
    unit, factor = _display_unit(st["mean"].text, d)

    def show(v: Fraction | float) -> str:
        return f"{float(v) / float(factor):.4g}" + (f" {unit}" if unit else "")
    shown = {k: st[k].show() for k in st}
    flags: list[dict[str, str]] = []

    def flag(bound: str, text: str) -> None:
        flags.append({"bound": bound, "explanation": text})

    if s < 0:
        flag("non-negative deviation", f"the standard deviation {shown['std']} is negative")
    if a > b:
        flag("order of extremes", f"the {lo_name} trial ({shown[lo_name]}) is above the {hi_name} trial ({shown[hi_name]}) "
             f"although {'lower' if fig.better == 'lower' else 'higher'} is better")
        return flags
    if not a <= m <= b:
        flag("mean between extremes", f"the mean {shown['mean']} is not between the smallest trial {show(a)} and the "
             f"largest {show(b)}")
        return flags
    if n == 1:
        if a != b or s != 0:
            flag("single trial", f"with one trial, best, worst and mean coincide and the deviation is 0; found best "
                 f"{shown['best']}, worst {shown['worst']}, std {shown['std']}")
        return flags
    lo_mean, hi_mean = ((n - 1) * a + b) / n, (a + (n - 1) * b) / n
    if not lo_mean <= m <= hi_mean:
        flag("mean with one trial at each extreme",
             f"with {n} trials, one at {show(a)} and one at {show(b)}, the mean lies between {show(lo_mean)} and "
             f"{show(hi_mean)}; the reported mean is {shown['mean']}")
        return flags
    far = max(b - m, m - a)
    if far * far > s * s * (n - 1):
        flag("Samuelson's inequality",
             f"a trial {show(far)} from the mean ({'worst' if (b - m) >= (m - a) else 'best'} trial) needs a standard "
             f"deviation of at least {show(far)} / sqrt({n - 1}) = {show(float(far) / float(n - 1) ** 0.5)}"
             f" with {n} trials; the reported deviation is {shown['std']}")
    ss_min = (a - m) ** 2 + (b - m) ** 2
    if n > 2:
        c = (n * m - a - b) / (n - 2)
        ss_min += (n - 2) * (c - m) ** 2
    if s * s * n < ss_min:
        flag("spread of best and worst",
             f"{n} trials with smallest {show(a)}, largest {show(b)} and mean {shown['mean']} have a standard deviation "
             f"of at least {show(float(ss_min / n) ** 0.5)} (population; "
             f"{show(float(ss_min / (n - 1)) ** 0.5)} as a sample deviation); the reported deviation is "
             f"{shown['std']}")
    if s * s * (n - 1) > n * (b - m) * (m - a):
        top = n * (b - m) * (m - a) / (n - 1)
        flag("Bhatia-Davis inequality",
             f"trials between {show(a)} and {show(b)} with mean {shown['mean']} have a standard deviation of at most "
             f"{show(float(top) ** 0.5)} (sample deviation, {n} trials); the reported deviation is {shown['std']}")
    return flags


def figures_json(fig: Figures) -> dict[str, FigureJson]:
    """The figures as JSON: each statistic as written and in base units."""
    return {k: {"as_written": q.show(), "base_value": str(q.value) if not (fig.derived and k == "std") else None,
                "dimension": q.dim} for k, q in fig.stats.items()}
