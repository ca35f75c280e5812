"""A fresh Z3 world for each unit of work, so its answers do not depend on
what the process did before.

Z3 models and unsat cores depend on the state of the context the query is
built in: the sorts, terms and their ids created before it, in the order
they were created.  The pipeline's stages share one process (a serial doit
run executes every node task in one process; an incremental run executes
only some of them), so a health check's witness or a refutation's model
could differ between an incremental run and a clean one, or between a
serial and a parallel one, though both are valid (measured: the Agent's
assumption witness read ``red`` in one and ``orange`` in the other).

:func:`fresh` starts a new Z3 main context and clears every cache that
holds Z3 objects of the old one (each such cache registers its clearing
function with :func:`on_fresh`).  The pipeline calls it at the start of each
stage of a node (compose, health, export) and of each evidence run
(:mod:`rclverify.app.pipeline`), so every unit of work starts from the same Z3
state whatever ran before it: an incremental run writes what a clean run
writes.  A new context costs about a millisecond.
"""
from __future__ import annotations

import sys
from typing import Callable

_CLEARERS: list[Callable[[], None]] = []


def on_fresh(clear: Callable[[], None]) -> Callable[[], None]:
    """Register ``clear`` (no arguments) to run at every :func:`fresh`: it
    must forget every Z3 object its module keeps.  Returns ``clear``."""
    _CLEARERS.append(clear)
    return clear


def fresh() -> None:
    """Start a new Z3 main context (``z3.main_ctx()`` makes it at its next
    use) and clear the registered caches.  Objects made before stay valid in
    their own context but must not be mixed with new ones.  A process that
    has not imported Z3 is left as it is (nothing of Z3's exists yet)."""
    z3mod = sys.modules.get("z3.z3")
    if z3mod is None:
        return
    setattr(z3mod, "_main_ctx", None)  # z3.main_ctx() creates the next one on demand
    for clear in _CLEARERS:
        clear()
