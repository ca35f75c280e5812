"""Z3 solvers with a budget, and the session that shares one solver among
the queries of a unit of work.

* A budget is milliseconds' worth of Z3 resource steps
  (:data:`rclverify.semantics.wallclock.STEPS_PER_MS`), so the answer does
  not depend on the machine's load, with a wall-clock safety net
  :data:`.wallclock.SAFETY_FACTOR` times longer (:func:`budgeted_solver`,
  :func:`tactic_solver`).
* Within a :func:`solver_session` block, each query (:func:`query_solver`;
  the queries of :mod:`rclverify.semantics.query`) is a ``push``/``pop``
  scope of one incremental solver instead of a fresh solver.
"""
from __future__ import annotations

from contextlib import contextmanager
from typing import Iterator, Sequence

import z3

from rclverify.semantics import wallclock


def budgeted_solver(timeout_ms: float, ctx: z3.Context | None = None) -> z3.Solver:
    """A solver in ``ctx`` (default: the process's main context) whose
    budget is ``timeout_ms`` milliseconds' worth of Z3 resource steps
    (:func:`.wallclock.steps`), with a wall-clock safety net
    :data:`.wallclock.SAFETY_FACTOR` times longer (at least a millisecond),
    registered so that :func:`.wallclock.check` tells its firing apart."""
    s: z3.Solver = wallclock.limit(z3.Solver(ctx=ctx), timeout_ms)
    return s


def tactic_solver(timeout_ms: float, tactics: Sequence[str], ctx: z3.Context | None = None) -> z3.Solver:
    """A solver in ``ctx`` (default: the process's main context) of the Z3
    tactics ``tactics`` applied in turn (``z3.Then``: its model is read back
    through the tactics' model converters), budgeted as
    :func:`budgeted_solver` budgets one.  The tactics preprocess what is
    asserted (``add``), not what a check assumes.  Raises
    ``z3.Z3Exception`` for a tactic name Z3 does not know."""
    s: z3.Solver = wallclock.limit(z3.Then(*tactics, ctx=ctx).solver(), timeout_ms)
    return s


class _Session:
    """The shared solver of one :func:`solver_session` block and the query
    budget its parameters are set to (set again only when a query asks for
    another: setting a parameter of a solver in use costs about as much as
    a small query)."""

    def __init__(self) -> None:
        self.solver = z3.SimpleSolver()
        self.solver.set("unsat_core", True)
        self.budget_ms: int | None = None

    def scope(self, timeout_ms: int) -> z3.Solver:
        if self.budget_ms != timeout_ms:
            wallclock.limit(self.solver, timeout_ms)
            self.budget_ms = timeout_ms
        self.solver.push()
        return self.solver


#: The :func:`solver_session` blocks under way, innermost last.
_SESSIONS: list[_Session] = []


@contextmanager
def solver_session() -> Iterator[None]:
    """Within the block, every query of this module (and every
    :func:`query_solver`) runs in one shared incremental Z3 solver, each in
    its own ``push``/``pop`` scope, instead of a fresh solver each.

    A fresh ``z3.Solver()`` costs about 1.5 ms of set-up and tear-down,
    more than most queries of a contract take to solve; a scope of an
    incremental solver costs about 0.25 ms.
    The solver is Z3's incremental SMT core (``z3.SimpleSolver``, the
    engine ``z3.Solver()`` itself switches to once a scope is pushed) with
    unsat cores enabled.  A popped scope leaves no assertion behind, so
    each query is decided on its own formulas; but a model, a core (and, on
    a query near its budget, whether Z3 gives up: the retries of
    :mod:`.retry`, in fresh solvers, then take over) may depend on the
    queries the solver answered before in the same block, so a block must
    always ask the same queries in the same order:
    each covers one unit of work whose queries follow from its inputs alone
    (one node's calculus, one node's health checks, one Hoare triple),
    never queries whose order depends on scheduling.  Blocks nest (the
    innermost is used).  The retries of :mod:`.retry` keep their own fresh
    solvers.  Usable as a decorator (``@solver_session()``).
    """
    _SESSIONS.append(_Session())
    try:
        yield
    finally:
        _SESSIONS.pop()


@contextmanager
def query_solver(timeout_ms: int, *, cores: bool = False) -> Iterator[z3.Solver]:
    """A solver for one query, budgeted like :func:`budgeted_solver`: a new
    scope of the innermost :func:`solver_session` (popped when the block
    ends), or a fresh solver outside any session.  ``cores``: the query
    needs unsat cores (always on in a session's solver, since Z3 takes that
    option only before the first assertion)."""
    if not _SESSIONS:
        fresh = budgeted_solver(timeout_ms)
        if cores:
            fresh.set("unsat_core", True)
        yield fresh
        return
    s = _SESSIONS[-1].scope(timeout_ms)
    try:
        yield s
    finally:
        s.pop()


def in_session() -> bool:
    """Whether a :func:`solver_session` block is under way in this process."""
    return bool(_SESSIONS)
