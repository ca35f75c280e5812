"""Which message of a run is the first published on an input: the value of
``first(in.x)`` on a recorded run (docs/semantics.md, "The first published
value").

A contract that reads ``first(in.x)`` is judged, on each message of
``in.x``, with ``first(in.x)`` TRUE on the first message of that topic the
run carries and FALSE on every later one, when the run is known to start
before that message: its log carries the start-of-run marker (the line of
topic ``rclverify/run``, kind ``run``, a live monitor writes first,
:mod:`.run_origin`) before the topic's first message.  Without the marker
the recording may have begun after the topic's first message, so the value
is unknown: the engine is given the reason instead of a Boolean, the
evaluator (:class:`rclverify.semantics.evaluator.Evaluator`) reports it,
and a verdict the value decides is ``inconclusive`` with that reason.
"""
from __future__ import annotations

from typing import Iterable

from rclverify.lang import ast, walk

#: a run whose log lacks the start-of-run marker: why ``first(in.x)`` is unknown
NO_START = ("whether this message on {k} is the first published on it is unknown: the log has no start-of-run "
            "marker (the rclverify/run line a live monitor writes first), so the recording may have begun after "
            "the topic's first message")


class FirstMessages:
    """The ``first(in.x)`` values of one node's monitor.

    ``keys`` maps each ``first(in.x)`` the formulas read to its input
    ``in.x``; :meth:`start` records the start-of-run marker; :meth:`mark`
    sets, in the monitor's values, the value for a message that set the
    inputs ``trig``: a Boolean, or the reason it is unknown (a string)."""

    def __init__(self, formulas: Iterable[ast.Expr]) -> None:
        found: dict[str, str] = {}
        for f in formulas:
            for x in walk.subexpressions(f):
                if isinstance(x, ast.First):
                    found[f"first(in.{x.arg.name})"] = f"in.{x.arg.name}"
        self.keys = found
        self.from_start = False
        self.seen: set[str] = set()

    def start(self) -> None:
        """The run's start-of-run marker was read: every message after it is in the recording."""
        self.from_start = True

    def mark(self, trig: Iterable[str], values: dict[str, object]) -> None:
        """The message setting the inputs ``trig``: each ``first(in.x)`` of those inputs, in ``values``."""
        for fk, k in self.keys.items():
            if k in trig:
                values[fk] = (k not in self.seen) if self.from_start else NO_START.format(k=k)
                self.seen.add(k)


__all__ = ["FirstMessages", "NO_START"]
