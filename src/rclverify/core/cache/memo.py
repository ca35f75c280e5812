"""One result kept per function: for the last arguments it was called with.

A report run shows the same things several times from one report dict
(the argument in the HTML, the Markdown and ``reports/argument.*``; the
system diagram in the HTML's layout and page), and no renderer changes
that dict.  :func:`last_call` makes such a function compute once per dict
without a cache that grows: it keeps the result for the last arguments.
"""
from __future__ import annotations

import functools
from typing import Any, Callable, TypeVar

T = TypeVar("T")


def last_call(fn: Callable[..., T]) -> Callable[..., T]:
    """``fn`` returning its kept result when called again with the same
    arguments as last time: the first compared by identity (a report dict
    or an argument; it is kept alive, so its ``id`` is not reused), the
    other positional ones by equality.  Keyword arguments are passed
    through and are not compared: they must not change the result (a
    fragment cache)."""
    last: list[Any] = []

    @functools.wraps(fn)
    def call(first: Any, *rest: Any, **keywords: Any) -> T:
        if not (last and last[0] is first and last[1] == rest):
            last[:] = [first, rest, fn(first, *rest, **keywords)]
        result: T = last[2]
        return result
    return call
