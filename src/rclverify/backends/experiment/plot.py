"""SVG plots of experiment figures against the criterion's bounds (matplotlib, Agg).

Deterministic (:func:`rclverify.core.svgplot.svg_plot`): the same figures
always give the same bytes for one matplotlib version.
"""
from __future__ import annotations

import textwrap
from typing import Any, Mapping

from rclverify.backends.experiment.figures import BASE, Figures, Quantity
from rclverify.core.svgplot import svg_plot


def render_svg(fig: Figures, constants: Mapping[str, Quantity], title: str) -> str:
    """The SVG text: per-trial values (or, for a summary, best/mean +- std/worst)
    with a horizontal line for every constant of the measured dimension.
    Raises :class:`~rclverify.core.extras.MissingExtra` without matplotlib
    (the ``plots`` extra)."""
    unit = BASE.get(fig.dim, "")

    def draw(f: Any, ax: Any) -> None:
        if fig.trials:
            xs = list(range(1, len(fig.trials) + 1))
            ax.plot(xs, [float(v) for v in fig.trials], "o", markersize=3, label=f"{fig.column} per trial")
            ax.set_xlabel("trial")
        else:
            st = fig.stats
            ax.errorbar([2], [float(st["mean"].value)], yerr=[float(st["std"].value)], fmt="o", capsize=4,
                        label=f"mean ± std ({st['mean'].show()} ± {st['std'].show()})")
            ax.plot([1], [float(st["best"].value)], "v", label=f"best ({st['best'].show()})")
            ax.plot([3], [float(st["worst"].value)], "^", label=f"worst ({st['worst'].show()})")
            ax.set_xticks([1, 2, 3], ["best", "mean", "worst"])
            ax.set_xlim(0.5, 3.5)
            ax.set_xlabel(f"summary statistics of {int(st['count'].value)} trials")
        for k, (name, q) in enumerate(sorted(constants.items())):
            if q.dim == fig.dim:
                ax.axhline(float(q.value), color=f"C{3 + k}", linestyle="--", label=f"{name} ({q.show()})")
        label = f"{fig.measure or fig.column or 'measure'}" + (f" [{unit}]" if unit else "")
        ax.set_ylabel(textwrap.fill(label, 32))
        ax.set_title(title)
        ax.legend(loc="best", fontsize=7)

    return svg_plot("the experiment's plot", draw)
