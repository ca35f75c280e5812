"""A large Graphviz drawing at a size where its text can be read.

The HTML report fits a drawing into the page width (``max-width: 100%``),
which is right for a small one; the assurance argument of the case study is
2,500 by 3,800 points with 9-point labels, and fitted into 1,200 px its text
was about 4 px tall.  :func:`readable_svg` gives such a
drawing a fixed size at which its smallest text is at least
:data:`MIN_TEXT_PX` CSS pixels; the page shows it in a box that scrolls
(``div.diagram.scroll``), so the page itself stays as tall as before.
"""
from __future__ import annotations

import re
from typing import Any

from markupsafe import Markup

__all__ = ["MIN_TEXT_PX", "readable_svg", "smallest_font"]

#: Smallest text of a drawing shown at its fixed size, in CSS pixels.
MIN_TEXT_PX = 10.0

_ROOT = re.compile(r"<svg\b[^>]*>", re.S)
_VIEWBOX = re.compile(r'viewBox="\s*[-\d.]+[\s,]+[-\d.]+[\s,]+([\d.]+)[\s,]+([\d.]+)\s*"')
_SIZE = re.compile(r'\s(width|height)="[^"]*"')
_FONT = re.compile(r'font-size="([\d.]+)"')


def smallest_font(svg: str) -> float | None:
    """The smallest ``font-size`` attribute of ``svg`` (user units), or ``None``."""
    sizes = [float(x) for x in _FONT.findall(svg) if float(x) > 0]
    return min(sizes) if sizes else None


def readable_svg(svg: Any, min_px: float = MIN_TEXT_PX) -> Markup:
    """``svg`` (Graphviz output: a root ``<svg>`` with a ``viewBox``) with
    its root's ``width`` and ``height`` set in CSS pixels so that its
    smallest text is ``min_px`` pixels tall, and the class ``fixed`` (the
    report's CSS does not shrink it to the page).  Returned unchanged when
    it has no text or no viewBox.  The SVG is trusted markup (``dot``'s
    output on DOT text whose labels are escaped)."""
    text = str(svg)
    root = _ROOT.search(text)
    font = smallest_font(text)
    box = _VIEWBOX.search(root.group(0)) if root else None
    if root is None or box is None or font is None:
        return Markup(text)
    scale = min_px / font
    width, height = float(box.group(1)) * scale, float(box.group(2)) * scale
    tag = _SIZE.sub("", root.group(0))
    tag = tag[:4] + f' class="fixed" width="{width:.0f}px" height="{height:.0f}px"' + tag[4:]
    return Markup(text[:root.start()] + tag + text[root.end():])
