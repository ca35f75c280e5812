"""The Agent node's decision step as a Python function, written for this
project from the paper's description of the Gwendolen agent (shared
reference, lines 1338-1372: the plans ``+!inspect``, ``+movebase_result``,
``+danger_red``/``+danger_orange``; and the Agent's table, lines 1256-1278).

One call decides the next command from the current inputs:

1. radiation ``red`` or ``orange``: return to the entrance, waypoint 0
   (the ``+danger_*`` plans);
2. otherwise, at a waypoint ``i`` that is not inspected yet: ``inspect(i)``
   (``+movebase_result(_, 3)`` performs ``inspect`` on arrival);
3. otherwise, at waypoint ``i``: move to waypoint ``i + 1`` if there is one
   (``next_location``), else back to waypoint 0.

Waypoints are given as a finite table ``wayP`` from coordinates to ids with a
default id for every other point (rclverify.semantics.values.FiniteFunction); the
position ``at`` likewise.  A waypoint's coordinates are the first table
entry with that id, or, when only the default gives that id, the first
point (0.0, 0.0), (1.0, 0.0), ... that is not in the table.
"""
from __future__ import annotations

from typing import Any

from rclverify.semantics.values import FiniteFunction, Term


def _where(wayP: FiniteFunction, i: int) -> tuple[float, float] | None:
    for key in sorted(wayP.table, key=repr):
        if wayP.table[key] == i:
            return key[0], key[1]
    if wayP.default == i:
        k = 0.0
        while (k, 0.0) in wayP.table:
            k += 1.0
        return k, 0.0
    return None


def _current(at: FiniteFunction, wayP: FiniteFunction) -> tuple[float, float] | None:
    for key in sorted(at.table, key=repr):
        if at.table[key]:
            return key[0], key[1]
    return None


def _home(wayP: FiniteFunction) -> Term:
    x, y = _where(wayP, 0) or (0.0, 0.0)
    return Term("move", (x, y))


def agent(wayP: FiniteFunction, at: FiniteFunction, radiationStatus: str, inspected: FiniteFunction) -> dict[str, Any]:
    """The next ``command`` (CommandSet) for one message of inputs."""
    if radiationStatus in ("red", "orange"):
        return {"command": _home(wayP)}
    here = _current(at, wayP)
    if here is None:
        return {"command": _home(wayP)}
    i = wayP(*here)
    if not inspected(i):
        return {"command": Term("inspect", (i,))}
    nxt = _where(wayP, i + 1)
    if nxt is None:
        return {"command": _home(wayP)}
    return {"command": Term("move", nxt)}
