"""A matplotlib figure drawn as SVG text, the same bytes for the same
figure (one matplotlib version): the Agg backend, a fixed ``svg.hashsalt``,
text kept as text and no date in the metadata.  The plots of experiment
figures (backends/experiment/plot.py) and of margins over runs
(report/margin_plot.py) are drawn through it."""
from __future__ import annotations

import io
from typing import Any, Callable


def svg_plot(what: str, draw: Callable[[Any, Any], None], size: tuple[float, float] = (6.4, 3.6)) -> str:
    """The SVG text (the XML header included) of one figure of ``size``
    inches, drawn by ``draw(figure, axes)``.  Raises
    :class:`~rclverify.core.extras.MissingExtra` without matplotlib (the
    ``plots`` extra), naming ``what`` the plot was for."""
    from rclverify.core.numeric import import_numpy  # deferred: start-up (numpy, matplotlib's, with one BLAS thread)
    import_numpy()
    from rclverify.core.extras import require  # deferred: start-up (only where a plot is drawn)
    matplotlib = require("matplotlib", what)  # raises MissingExtra (core/extras.py)
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # deferred: start-up (loads matplotlib and more only when called)
    with matplotlib.rc_context({"svg.hashsalt": "rclverify", "svg.fonttype": "none", "font.size": 9}):
        f, ax = plt.subplots(figsize=size)
        try:
            draw(f, ax)
            f.tight_layout()
            out = io.StringIO()
            f.savefig(out, format="svg", metadata={"Date": None})
        finally:
            plt.close(f)
    return out.getvalue()


__all__ = ["svg_plot"]
