"""SVG plot of one guarantee's margins over its runs (matplotlib, Agg).

One column per run: the margins the run kept (its smallest, at most
:data:`~rclverify.backends.monitors.verdicts.KEPT_MARGINS`; docs/semantics.md,
"Margins over runs"; at most :data:`POINTS_PER_RUN` of them drawn, evenly
spaced in rank), the run's smallest marked, a line at 0 (the
boundary: below it the guarantee failed) and the quantiles the kept
margins decide.  Deterministic (:func:`rclverify.core.svgplot.svg_plot`).
"""
from __future__ import annotations

import math
from typing import Any, Sequence

from rclverify.core.svgplot import svg_plot
from rclverify.records.margin_rows import MarginRow


def _label(trace: str, most: int = 24) -> str:
    name = trace.rstrip("/").rsplit("/", 1)[-1] or trace
    return name if len(name) <= most else "…" + name[-(most - 1):]


#: At most this many of a run's kept margins are drawn, evenly spaced in rank (the smallest and the largest
#: among them): a column of more overlaps itself, and each marker is a hundred bytes of SVG.
POINTS_PER_RUN = 32


def _spread(ys: Sequence[float]) -> list[float]:
    """``ys`` (ascending), or :data:`POINTS_PER_RUN` of them evenly spaced in rank."""
    if len(ys) <= POINTS_PER_RUN:
        return list(ys)
    last = len(ys) - 1
    return [ys[round(i * last / (POINTS_PER_RUN - 1))] for i in range(POINTS_PER_RUN)]


def render_svg(row: MarginRow, runs: Sequence[tuple[str, Sequence[float]]]) -> str:
    """The SVG text of ``row``'s margins: ``runs`` is ``[(trace, kept margins)]``
    (floats, ``-inf`` for a margin without distance, not drawn).  Raises
    :class:`~rclverify.core.extras.MissingExtra` without matplotlib (the
    ``plots`` extra)."""
    unit = f" [{row.unit}]" if row.unit else ""

    def draw(f: Any, ax: Any) -> None:
        for x, (_, kept) in enumerate(runs, start=1):
            ys = _spread([v for v in kept if math.isfinite(v)])
            ax.plot([x] * len(ys), ys, "o", color="C0", markersize=2.5, alpha=0.5,
                    label=f"kept margins (at most {POINTS_PER_RUN} a run drawn)" if x == 1 else None)
            if ys:
                ax.plot([x], [ys[0]], "v", color="C3", markersize=6, label="run's smallest" if x == 1 else None)
        ax.axhline(0.0, color="black", linewidth=0.8)
        for k, (name, b) in enumerate((("p5", row.p5), ("p50", row.p50))):
            if b.low is not None and b.low == b.high:
                ax.axhline(float(b.low), color=f"C{1 + k}", linestyle="--",
                           label=f"{name} over {row.count} answers ({b.low:g})")
        ax.set_xticks(range(1, len(runs) + 1), [_label(t) for t, _ in runs], rotation=30, ha="right",
                      fontsize=7)
        ax.set_xlim(0.5, len(runs) + 0.5)
        ax.set_xlabel("run")
        ax.set_ylabel(f"margin{unit}")
        ax.set_title(f"{row.node} guarantee {row.guarantee}")
        ax.legend(loc="best", fontsize=7)

    text = svg_plot("the margins' plot", draw)
    return text[text.index("<svg"):]


__all__ = ["POINTS_PER_RUN", "render_svg"]
