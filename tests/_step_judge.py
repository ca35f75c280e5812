"""rclverify's verdict on one step of a node (inputs and outputs by qualified name), by the
monitor engine's rule (docs/generate.md, "The contract layer"): the assumptions in order, then the
first false guarantee, else the first undecided one, else satisfied, with one arithmetic for all
the guarantees of the step; each clause judged by ``logic/floatsem.judge``.

The reference the generated checks are compared with where the generated Python layer (carried
in the package, no rclverify) leaves a clause undecided: tables, constructor terms and
quantifiers over unbounded numbers, which rclverify decides with its candidate values and Z3."""
from __future__ import annotations

from typing import Any

from rclverify.semantics.floatsem import Tolerance, holds_in, judge as floatjudge
from rclverify.lang.types import Checked, CheckedNode

ORDER = ("exact", "double", "tolerance")


def judge(checked: Checked, node: CheckedNode, values: dict[str, Any],
          tolerance: Tolerance | None = None) -> dict[str, Any]:
    """``{verdict, guarantee, reason, semantics}`` of the step ``values`` of ``node``."""
    weakest = "exact"
    for clause in node.node.assumes:
        j = floatjudge(clause.formula, checked, node, values, tolerance)
        if j.truth is False:
            return dict(verdict="assumption violated", guarantee=0, reason=j.reason, semantics=j.semantics)
        if j.truth is None:
            return dict(verdict="inconclusive", guarantee=0, reason=f"assumption undecided: {j.reason}", semantics="")
        weakest = max(weakest, j.semantics, key=ORDER.index)
    held, undecided = [], None
    for k, clause in enumerate(node.node.guarantees, 1):
        j = floatjudge(clause.formula, checked, node, values, tolerance)
        if j.truth is False:
            return dict(verdict="violated", guarantee=k, reason=j.reason, semantics=j.semantics)
        if j.truth is None:
            undecided = undecided or (k, j.reason)
            continue
        held.append((k, clause.formula, j.semantics))
        weakest = max(weakest, j.semantics, key=ORDER.index)
    if undecided is not None:
        return dict(verdict="inconclusive", guarantee=undecided[0], reason=undecided[1], semantics="")
    for k, formula, sem in held:
        if ORDER.index(sem) < ORDER.index(weakest) and \
                holds_in(weakest, formula, checked, node, values, tolerance) is False:
            return dict(verdict="violated", guarantee=k, reason=f"false in {weakest} arithmetic", semantics=weakest)
    return dict(verdict="satisfied", guarantee=0, reason="", semantics=weakest)
