"""Neighbour examples of a failure, and the harness's judgement of an
implementation on one example: what :mod:`.slips` weighs a one-token
correction against.

The neighbours are :data:`NEIGHBOURS` examples Hypothesis draws from the
run's own input space (the same strategy, assumption filter, facts and
seed as the run; generation only, nothing shrunk; the harness calls this
without Hypothesis's pool of local constants, as it runs), each judged on
the implementation as it is.  A correction must keep every neighbour that met
the guarantee meeting it: a change that repairs the one failing example by
breaking others is no correction.  An example is judged exactly as the run
judged it (:meth:`.harness.GuaranteeRun.body`, on a copy of the run that
counts nothing of the run's own); Z3's ``unknown`` on it is no pass.
"""
from __future__ import annotations

import dataclasses
from typing import Any, Callable

from rclverify.backends.property_tests.hypothesis_lib import (HealthCheck, Phase, Verbosity, given, hypothesis,
                                                             settings, st)

#: Examples drawn per failure to weigh corrections against.
NEIGHBOURS = 40


def judge(run: Any, violation: type[BaseException]) -> Callable[[Any, Any], bool]:
    """``judge(impl, example) -> bool``: does ``impl`` (a function or a
    class, as ``run.impl``) meet ``run``'s guarantee on ``example`` (a
    function's inputs, a class's steps), checked as the run checks it?
    ``violation`` the exception the run's check raises on a violation."""
    def met(impl: Any, example: Any) -> bool:
        probe = dataclasses.replace(run, impl=impl, counts=type(run.counts)(), last_failure=None, last_values=None,
                                    unknown=set(), stop_at_failure=True, first_double=None, coverage=None)
        try:
            probe.body(example)
        except violation:
            return False
        except Exception:  # noqa: BLE001 - a decision the engines could not make: no pass
            return False
        return bool(probe.counts.inconclusive == 0)
    return met


def neighbours(run: Any, violation: type[BaseException]) -> list[tuple[Any, bool]]:
    """``[(example, met the guarantee)]``: up to :data:`NEIGHBOURS`
    examples drawn as ``run`` draws them (module docstring), judged on
    ``run.impl``; ``[]`` when Hypothesis cannot draw them (a health check)."""
    probe = dataclasses.replace(run, counts=type(run.counts)(), last_failure=None, last_values=None, unknown=set(),
                                first_double=None, coverage=None)
    drawn: list[Any] = []

    def keep(example: Any) -> None:
        drawn.append(example)
    strategy: st.SearchStrategy[Any] = probe.strategy()
    test = hypothesis.seed(run.cfg.seed)(settings(
        max_examples=NEIGHBOURS, database=None, deadline=None, phases=[Phase.generate], print_blob=False,
        verbosity=Verbosity.quiet, suppress_health_check=list(HealthCheck))(given(strategy)(keep)))
    try:
        test()
    except Exception:  # noqa: BLE001 - no neighbours (the run itself reported what Hypothesis said)
        return []
    met = judge(run, violation)
    return [(ex, met(run.impl, ex)) for ex in drawn]
