"""The HTML report's jinja2 filters and globals beyond those of render.py.

``prose`` (Markdown code spans as ``<code>``), ``plain`` (code spans as
their text, for attributes such as ``title``), ``natsort`` (ids in natural
order): :mod:`.textfmt`; ``readable_svg`` (a large drawing at a size whose
text can be read): :mod:`.svgfit`; ``reqbadges`` (a requirement's proof and
evidence as two badges): :mod:`.badges`; ``tally`` (statuses counted,
worst first); the global ``latex_frame(sources)``
(the LaTeX appendix's one preamble and its end):
:func:`rclverify.lang.latex.document_frame`.
"""
from __future__ import annotations

from collections import Counter
from typing import Any, Callable, Iterable, cast

import jinja2

from rclverify.lang.latex import document_frame
from rclverify.report.badges import requirement_badges
from rclverify.report.svgfit import readable_svg
from rclverify.report.textfmt import natural_sorted, plain, prose


def _natsort(items: Iterable[Any], attribute: str | None = None) -> list[Any]:
    if attribute is None:
        return natural_sorted(items)
    return natural_sorted(items, key=lambda it: it[attribute])


@jinja2.pass_environment
def _tally(env: jinja2.Environment, statuses: Iterable[Any]) -> list[tuple[str, int]]:
    """``[(status, how many)]`` of ``statuses``, worst first (the ``rank``
    global), then by word."""
    counts = Counter(str(s) for s in statuses)
    rank = cast(Callable[[str], int], env.globals["rank"])
    return sorted(counts.items(), key=lambda kv: (-rank(kv[0]), kv[0]))


def register(env: jinja2.Environment) -> None:
    """Add this module's filters and globals to ``env`` (the report's environment)."""
    env.filters.update(prose=prose, plain=plain, natsort=_natsort, readable_svg=readable_svg, reqbadges=requirement_badges,
                       tally=_tally)
    env.globals.update(latex_frame=document_frame)
