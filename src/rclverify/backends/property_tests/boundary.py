"""A failing example shown at the boundary the contract names.

Hypothesis shrinks a failure to a minimal example in its own order, which
for a number is often one that draws the eye to rounding
(``speed_request = 0.5000000000000001``) and away from the value that
matters (``clearance = 2.0``, the threshold the contract names).  After a
failure, :func:`boundary_example` tries, input by input, the numbers the
node's contract names (its assumption's and guarantee's literals, the
values of the named constants they use) or its code compares with
(:mod:`.constants`) and short
values near the shrunk one (the integers either side, one decimal place),
nearest first, and keeps each replacement with which the example still
satisfies the assumption (and the used facts) and still violates the same
guarantee, checked exactly as the run checked it
(:meth:`.harness.GuaranteeRun.check_step`).  The harness then confirms the
example it reports with Z3 as before, so a shown example always fails.
The inputs at a value the contract names are listed first.
"""
from __future__ import annotations

import dataclasses
import math
from fractions import Fraction
from typing import Any, Iterable, Mapping

from rclverify.lang import ast
from rclverify.lang.walk import subexpressions
from rclverify.backends.property_tests.constants import boundary_constants

#: At most this many re-runs of the implementation per failure.
MAX_TRIES = 48


def contract_numbers(node: Any) -> list[Fraction]:
    """The numeric literals of ``node``'s assumptions and guarantees (a
    checked node), each once, in source order."""
    out: list[Fraction] = []
    for clause in (*node.node.assumes, *node.node.guarantees):
        for e in subexpressions(clause.formula):
            if isinstance(e, ast.NumLit):
                v = Fraction(e.value)
                if v not in out:
                    out.append(v)
    return out


def _numeric(v: Any) -> bool:
    return isinstance(v, (int, float, Fraction)) and not isinstance(v, bool) and (
        not isinstance(v, float) or math.isfinite(v))


def _like(old: Any, new: Fraction) -> Any:
    """``new`` in the Python type of ``old`` (an ``int`` input stays an ``int``)."""
    if isinstance(old, int):
        return int(new) if new.denominator == 1 else None
    if isinstance(old, float):
        return float(new)
    return new


def _near(v: Any, named: Iterable[Fraction]) -> list[Fraction]:
    x = Fraction(v)
    lo = Fraction(math.floor(x))
    cands = {*named, lo, lo + 1, Fraction(round(x * 10), 10)}
    cands.discard(x)
    return sorted(cands, key=lambda c: (abs(c - x), c))


def boundary_example(run: Any, inputs: Mapping[str, Any],
                     violation: type[BaseException]) -> tuple[dict[str, Any], list[str]] | None:
    """``(inputs, at_boundary)``: ``inputs`` (a failing example of ``run``, a
    :class:`.harness.GuaranteeRun` of a function) with each numeric input
    moved to a value the contract names or a short value where the example
    still fails (module docstring), and the inputs whose value the contract
    names; ``None`` when no input moved.  The failure of the returned
    example is left in ``run.last_failure``/``run.last_values`` (the
    caller's example's when ``None``).  ``violation`` the exception
    :meth:`.harness.GuaranteeRun.check_step` raises on a violation."""
    named = boundary_constants(run.checked, run.node, run.impl, contract_numbers(run.node))
    best = dict(inputs)
    saved = (run.last_failure, run.last_values)
    found: tuple[Any, Any] | None = None
    tries = 0
    for name in sorted(best):
        old = best[name]
        if not _numeric(old):
            continue
        for c in _near(old, named):
            new = _like(old, c)
            if new is None or tries >= MAX_TRIES:
                continue
            tries += 1
            trial = {**best, name: new}
            probe = dataclasses.replace(run, counts=type(run.counts)(), last_failure=None, last_values=None, unknown=set(),
                                        stop_at_failure=True, first_double=None)
            if not probe.assumption_holds(trial):
                continue
            try:
                probe.check_step(run.impl, trial, None)
            except violation:
                if _same_guarantee(probe.last_failure, saved[0]):
                    best, found = trial, (probe.last_failure, probe.last_values)
                    break
            except Exception:  # noqa: BLE001 - a decision the engines could not make: not this value
                continue
    if found is None:
        run.last_failure, run.last_values = saved
        return None
    run.last_failure, run.last_values = found
    at = [k for k, v in best.items() if _numeric(v) and Fraction(v) in named]
    return best, at


def _same_guarantee(a: Mapping[str, Any] | None, b: Mapping[str, Any] | None) -> bool:
    """The same violation: the same guarantee and conjunct, or the same kind of failure (no conjunct)."""
    if a is None or b is None:
        return False
    return a.get("guarantee") == b.get("guarantee") and a.get("conjunct") == b.get("conjunct")


def boundary_first(cex: Mapping[str, str], at: Iterable[str]) -> dict[str, str]:
    """``cex`` (the counterexample's ``{"in.x": text, ...}``) with the inputs of
    ``at`` first, the rest in their order."""
    first = [k for k in cex if k in set(at)]
    return {**{k: cex[k] for k in first}, **{k: v for k, v in cex.items() if k not in first}}
