"""The wall-clock safety net of every Z3 query, and how its firing is told
apart from the deterministic budget (docs/decisions.md,
"Results never depend on the wall clock").

A query's budget is Z3's resource counter (``rlimit``): the same steps on
every machine, so the same answer and the same model.  Each solver also
gets a wall-clock ``timeout`` :data:`SAFETY_FACTOR` times the time that
budget takes on an idle core, a safety net against a search whose steps
are slow.  On a loaded machine that net can fire *before* the budget runs
out, and an ``unknown`` then sends the caller down another path (the next
candidate of a readable-model loop, the next instance of a scan, a retry
strategy), whose answer would be a different model shown as if it were
the answer.  Z3 does not say which limit stopped it (both give
``canceled`` once a solver has scopes), so :func:`check` times the call:
an ``unknown`` that took at least the solver's wall-clock limit was cut
by the clock (a budget that runs out first stops it earlier).

The rule: a cut is never an answer and never a reason to try something
else.  Its callers either keep the result the deterministic step already
had (a readable model keeps the first model) or say "inconclusive: took
longer than N s" (:func:`cut_reason`).  A unit of work (one node's health
checks) can ask, with :func:`watch`, whether anything in it was cut.

Solvers register their limits with :func:`limit` (budgeted ones) or
:func:`note_limit` (a limit set elsewhere); :func:`check` of a solver
never registered counts no cut.  A budget that runs out only after the
net's time (a machine :data:`SAFETY_FACTOR` times slower than the calibration) also counts
as cut: inconclusive, never a different answer.  Nets are at least
:data:`MIN_WALL_MS`: Z3 does not always honour a net of a few milliseconds
(its timer can fire before the search starts), and a first look of a few
steps takes about a millisecond to set up.
"""
from __future__ import annotations

import threading
import time
import weakref
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any, Iterator

import z3

#: Z3 resource steps per millisecond of a query's budget: a ``timeout_ms``
#: budget is enforced as Z3's ``rlimit`` of ``timeout_ms * STEPS_PER_MS``
#: steps (Z3 does some 2,000 steps per millisecond on the heavy quantified
#: queries of the case study on one idle core, up to 4,000 on light ones,
#: which finish well inside their budget), so an answer does not
#: depend on the machine's load: a serial run, ``doit -n 2`` and a busy CI
#: machine decide the same queries.
STEPS_PER_MS = 2_000
#: The wall-clock safety net, a multiple of a budget's time on an idle core:
#: far above it, so that on a loaded machine the budget of steps, which gives
#: the same answer everywhere, runs out first.  A query whose steps are slow
#: (3 s of an idle core for a 2,000 ms budget: quantifier elimination over a
#: sequence's items) given a tenth of a core by the load takes 30 s, past a
#: net of ten times its budget; at a hundred times the process would need
#: less than a hundredth of a core for the net to fire.
SAFETY_FACTOR = 100
#: The shortest net (ms): a smaller one fires on the cost of starting a check
#: (a first look of a few steps takes a millisecond), not on the search.
MIN_WALL_MS = 1_000

_LIMITS: "weakref.WeakKeyDictionary[Any, int]" = weakref.WeakKeyDictionary()


class _Tally(threading.local):
    cuts = 0
    last_ms = 0


_TALLY = _Tally()


def steps(budget_ms: float) -> int:
    """The Z3 resource limit of a budget of ``budget_ms`` milliseconds
    (:data:`STEPS_PER_MS`), at least one step (Z3 reads 0 as no limit)."""
    return max(1, int(budget_ms * STEPS_PER_MS))


def wall_ms(budget_ms: float) -> int:
    """The wall-clock limit (ms) of a budget of ``budget_ms`` milliseconds'
    worth of resource steps: :data:`SAFETY_FACTOR` times it, at least
    :data:`MIN_WALL_MS` (and 1), both read when called (so a test can make
    the net tiny)."""
    return max(1, MIN_WALL_MS, int(budget_ms * SAFETY_FACTOR))


def note_limit(s: Any, timeout_ms: int) -> Any:
    """Set solver ``s``'s wall-clock ``timeout`` to ``timeout_ms`` (ms) and
    remember it for :func:`check`; returns ``s``."""
    s.set("timeout", int(timeout_ms))
    _LIMITS[s] = int(timeout_ms)
    return s


def limit(s: Any, budget_ms: float | None = None, *, rlimit: int | None = None) -> Any:
    """Bound solver ``s`` (a ``z3.Solver`` or ``z3.Optimize``): Z3 resource
    steps ``rlimit`` (default: ``budget_ms`` milliseconds' worth,
    :func:`steps`), and the wall-clock net :func:`wall_ms` of
    ``budget_ms``; returns ``s``."""
    if rlimit is None:
        rlimit = steps(budget_ms or 0)
    s.set("rlimit", int(rlimit))
    return note_limit(s, wall_ms(budget_ms or 0))


def check(s: Any, *assumptions: Any) -> z3.CheckSatResult:
    """``s.check(*assumptions)``, counting a cut of the wall-clock net (an
    ``unknown`` that took at least ``s``'s registered limit) in this
    thread's tally (:func:`watch`).  Raises what ``s.check`` raises."""
    t0 = time.monotonic()
    r = s.check(*assumptions)
    if r == z3.unknown:
        lim = _LIMITS.get(s)
        if lim is not None and (time.monotonic() - t0) * 1000 >= lim:
            _TALLY.cuts += 1
            _TALLY.last_ms = lim
    return r


def steps_taken(s: Any) -> int:
    """Z3's resource counter of solver ``s``'s context: the steps every
    query of that context has taken so far (read before and after a query,
    the steps it took; a budget over several queries counts these)."""
    return int(s.statistics().get_key_value("rlimit count"))


def check_cut(s: Any, *assumptions: Any) -> tuple[z3.CheckSatResult, bool]:
    """:func:`check`, and whether the wall-clock net cut this very check."""
    seen = _TALLY.cuts
    r = check(s, *assumptions)
    return r, _TALLY.cuts != seen


def why_unknown(s: Any, cut: bool) -> str:
    """Why solver ``s`` answered ``unknown``: the net's reason
    (:func:`cut_reason`) when ``cut``, else Z3's own."""
    return cut_reason() if cut else str(s.reason_unknown())


def cuts() -> int:
    """How many checks of this thread the wall-clock net cut so far."""
    return _TALLY.cuts


def cut_reason(limit_ms: int | None = None) -> str:
    """The reason an inconclusive result gives when the net cut it."""
    ms = _TALLY.last_ms if limit_ms is None else limit_ms
    return (f"took longer than {ms / 1000:g} s of wall-clock time (the safety net of its resource budget: "
            "the machine was too loaded to decide it here; nothing is concluded)")


@dataclass
class Watch:
    """What :func:`watch` saw: ``cut`` once a check in the block was cut."""
    start: int

    @property
    def cut(self) -> bool:
        return _TALLY.cuts != self.start


@contextmanager
def watch() -> Iterator[Watch]:
    """A block whose :class:`Watch` tells whether any :func:`check` in it
    (this thread) was cut by the wall clock."""
    yield Watch(_TALLY.cuts)


__all__ = ["MIN_WALL_MS", "SAFETY_FACTOR", "STEPS_PER_MS", "steps", "Watch", "check", "check_cut", "cut_reason", "cuts", "limit", "note_limit", "steps_taken", "wall_ms", "watch", "why_unknown"]
