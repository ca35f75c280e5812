"""A property-test failure as a person reads it: the example at
the boundary the contract names (:mod:`.boundary`) and the implementation
line with the slip (:mod:`.slips`; else the line that computed the output,
:mod:`.cause`), folded into the harness's counterexample."""
from __future__ import annotations

from typing import Any

from rclverify.backends.property_tests.boundary import boundary_example, boundary_first, contract_numbers
from rclverify.backends.property_tests.cause import cause_line
from rclverify.backends.property_tests import neighbours
from rclverify.backends.property_tests.slips import slip_line


def readable_failure(run: Any, violation: type[BaseException]) -> bool:
    """Rewrite ``run.last_failure`` (a :class:`.harness.GuaranteeRun` that
    stopped at a failure): for a function, the example moved to the
    contract's boundary when it still fails there, its inputs at a named
    value first; for both a function and a class, ``cause``: the
    implementation's ``file:line`` the example takes last
    (:func:`.cause.cause_line`, the file as the plan names it).  Returns
    whether the example moved.  ``violation`` the exception ``check_step``
    raises on a violation.  Never raises for the implementation's
    failures."""
    moved = False
    inputs = run.last_values[0] if run.last_values is not None else None
    example: Any = run.last_example
    if not run.stateful and inputs is not None:
        got = boundary_example(run, inputs, violation)
        if got is not None:
            example, at = got
            cex = run.last_failure
            ins = boundary_first({k: v for k, v in cex.items() if k.startswith("in.")}, at)
            run.last_failure = {**ins, **{k: v for k, v in cex.items() if not k.startswith("in.")}}
            if at:
                run.last_failure["boundary"] = ", ".join(at)
            moved = True
        else:
            example = inputs
    if example is not None:
        step = int(run.last_failure["step"]) if "step" in run.last_failure else None
        cause = _slip(run, example, step, violation) or cause_line(run.impl, example, step, run.cfg.file)
        if cause is not None:
            run.last_failure["cause"] = cause
    return moved


def _slip(run: Any, example: Any, step: int | None, violation: type[BaseException]) -> str | None:
    line = slip_line(run.impl, example, step, contract_numbers(run.node), neighbours.judge(run, violation),
                     lambda: neighbours.neighbours(run, violation))
    return f"{run.cfg.file}:{line}" if line is not None else None
