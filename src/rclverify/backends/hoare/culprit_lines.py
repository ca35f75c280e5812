"""The program lines a refuted Hoare triple blames: the numeric
constants its conditions compare with, in source order.

A triple refuted on a threshold is the program comparing with another
constant than the guarantee's (the case study's appendix-B program: 10 and
20 where the contract says 120 and 250).  Only the constants of ``if`` and
``while`` conditions are such thresholds; a constant assigned or added
(``i := i + 1``, ``output := 0``) is not, and naming its line would send
the reader to an unrelated line.
"""
from __future__ import annotations

from typing import Any, Sequence

from rclverify.backends.hoare.lang import If, Program, While


def compared_constants(program: Program) -> list[Any]:
    """The numeric literals (``Num`` nodes with a location) of every ``if``
    and ``while`` condition of ``program``, sorted by (line, column), each
    once.  Returns ``[]`` for a program without conditions."""
    found: list[Any] = []
    todo: list[Any] = list(program.body)
    while todo:
        s = todo.pop()
        if isinstance(s, If):
            found.extend(_numbers(s.cond))
            todo.extend(s.then_)
            todo.extend(s.else_)
        elif isinstance(s, While):
            found.extend(_numbers(s.cond))
            todo.extend(s.body)
    seen: dict[tuple[int, int], Any] = {}
    for n in found:
        seen.setdefault((n.loc.line, n.loc.col), n)
    return [seen[k] for k in sorted(seen)]


def _numbers(e: Any) -> list[Any]:
    """Every numeric literal (a ``Num`` with a location) under expression ``e``."""
    out: list[Any] = []
    todo = [e]
    while todo:
        x = todo.pop()
        if type(x).__name__ == "Num" and getattr(x, "loc", None) is not None:
            out.append(x)
        elif isinstance(x, (tuple, list)):
            todo.extend(x)
        elif hasattr(x, "__dataclass_fields__"):
            todo.extend(getattr(x, f) for f in x.__dataclass_fields__ if f != "loc")
    return out


def culprit_texts(program: Program, path: str) -> Sequence[str]:
    """``"path:line: constant"`` of each :func:`compared_constants`, in line order."""
    return [f"{path}:{n.loc.line}: {n.text}" for n in compared_constants(program)]
