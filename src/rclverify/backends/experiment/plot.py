"""SVG plots of experiment figures against the criterion's bounds (matplotlib, Agg).

Deterministic: a fixed ``svg.hashsalt``, no date in the metadata, and the
same figures always give the same bytes for one matplotlib version.
"""
from __future__ import annotations

import io
import textwrap
from typing import Mapping

from rclverify.backends.experiment.figures import BASE, Figures, Quantity


def render_svg(fig: Figures, constants: Mapping[str, Quantity], title: str) -> str:
    """The SVG text: per-trial values (or, for a summary, best/mean +- std/worst)
    with a horizontal line for every constant of the measured dimension.
    Raises :class:`~rclverify.core.extras.MissingExtra` without matplotlib
    (the ``plots`` extra)."""
    from rclverify.core.numeric import import_numpy  # deferred: start-up (numpy, matplotlib's, with one BLAS thread)
    import_numpy()
    from rclverify.core.extras import require  # deferred: start-up (only where a plot is drawn)
    matplotlib = require("matplotlib", "the experiment's plot")  # raises MissingExtra (core/extras.py)
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # deferred: start-up (loads matplotlib and more only when called)
    unit = BASE.get(fig.dim, "")
    with matplotlib.rc_context({"svg.hashsalt": "rclverify", "svg.fonttype": "none", "font.size": 9}):
        f, ax = plt.subplots(figsize=(6.4, 3.6))
        try:
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
            f.tight_layout()
            out = io.StringIO()
            f.savefig(out, format="svg", metadata={"Date": None})
        finally:
            plt.close(f)
    return out.getvalue()
