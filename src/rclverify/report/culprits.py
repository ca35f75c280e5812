"""Which nodes the problems blame (issue 48: the first screen names the culprit, not its victims).

A problem by root cause (:mod:`.problems`) names its culprits by id: ``guarantee:Node:k``,
``contract:Node``, ``assumption:Node:k``, a program line.  The nodes whose guarantee or contract is a
culprit are where the repair goes; the dashboard of the HTML report and the terminal table mark them.
"""
from __future__ import annotations

from typing import Any, Iterable, Mapping


def culprit_nodes(groups: Iterable[Any]) -> set[str]:
    """The nodes a problem's culprit (``groups``: the problems by root cause)
    is a guarantee or the contract of (``guarantee:Node:k``,
    ``contract:Node``; issue 48: the dashboard marks them, so that the first
    screen blames the culprit, not its victims)."""
    out = set()
    for g in groups:
        if not isinstance(g, Mapping):
            continue  # a summary's problems are sentences, not groups
        for c in g.get("culprits") or ():
            if not isinstance(c, Mapping):
                continue
            kind, _, rest = str(c.get("id", "")).partition(":")
            if kind in ("guarantee", "contract") and rest:
                out.add(rest.split(":", 1)[0])
    return out


__all__ = ["culprit_nodes"]
