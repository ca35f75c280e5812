"""Contract health: every clause of a node's contract is defined where it is read.

A clause that divides by a number that can be zero has no truth value
there (docs/semantics.md, "Definedness"): a monitor cannot decide it, a
property test cannot run it, and a proof that reads it would rest on Z3's
arbitrary value of ``x / 0``.  As Dafny checks the well-formedness of a
method's specification (each ``requires`` clause under the ones before it,
each ``ensures`` clause under the ``requires``), each clause of a node's
contract is checked here:

* assumption ``k``: its well-definedness conditions
  (:func:`rclverify.semantics.definedness.conditions`) hold wherever the
  assumptions before it and the plan's environment facts do;
* guarantee ``k``: its conditions hold wherever the whole assumption and
  the facts do (a guarantee promises nothing elsewhere).

One finding per clause that divides, ``<Node>.a<k>.defined`` or
``<Node>.g<k>.defined`` (check ``defined``): ``ok``, ``problem`` (the
condition named with its ``file:line:col`` and a counterexample with the
zero divisor) or ``inconclusive``.  A contract that never divides gets no
finding.
"""
from __future__ import annotations

from typing import Sequence

import z3

from rclverify.calculus.health.finding import Finding
from rclverify.lang import ast
from rclverify.lang.types import Checked
from rclverify.semantics.definedness import conditions
from rclverify.semantics.encode import Encoder
from rclverify.semantics.query import prove


def definedness_findings(checked: Checked, node: str, facts: Sequence[tuple[ast.Expr, ast.Loc]],
                         timeout_ms: int) -> list[Finding]:
    """The ``defined`` findings of ``node`` (module docstring): assumptions
    first, then guarantees, in source order.  ``facts`` are the plan's
    environment facts (formula, where written); ``timeout_ms`` bounds each
    Z3 query (milliseconds).  Never raises on solver trouble."""
    cn = checked.nodes[node]
    enc = Encoder(checked.env)
    premises = [enc.formula(f, cn) for f, _ in facts]
    assumed: list[z3.BoolRef] = []  # the assumptions read so far, encoded
    out: list[Finding] = []
    clauses = [("assumption", k, c.formula) for k, c in enumerate(cn.node.assumes, 1)]
    clauses += [("guarantee", k, c.formula) for k, c in enumerate(cn.node.guarantees, 1)]
    whole = [enc.formula(c.formula, cn) for c in cn.node.assumes]
    for kind, k, formula in clauses:
        conds = conditions(formula)
        hyps = [*premises, *(assumed if kind == "assumption" else whole)]
        if kind == "assumption":
            assumed.append(enc.formula(formula, cn))
        if not conds:
            continue
        fid = f"{node}.{kind[0]}{k}.defined"
        where, hold = (("the assumptions before it", "hold") if kind == "assumption"
                       else ("its node's assumption", "holds"))
        duration = 0.0
        finding: Finding | None = None
        for cond in conds:
            r = prove(enc.formula(cond.formula, cn), hyps, enc, timeout_ms=timeout_ms,
                      comment=f"health {node}: is {kind} {k} defined at {cond.where} ({cond.text})? unsat means yes")
            duration += r.duration_s
            if r.status == "refuted":
                finding = Finding(fid, node, "defined", k if kind == "guarantee" else None, "problem",
                                  f"{kind.capitalize()} {k} of {node} is not defined wherever {where} {hold}: "
                                  f"{cond.describe()}.",
                                  f"Z3 found values where {where} and the environment facts hold and the divisor is "
                                  "zero (below): the clause has no truth value there, so no check can decide it.",
                                  r.model, duration_s=round(duration, 4), smt2=r.smt2)
                break
            if r.status != "proved":
                finding = Finding(fid, node, "defined", k if kind == "guarantee" else None, "inconclusive",
                                  f"Z3 could not decide whether {kind} {k} of {node} is defined: {cond.describe()}.",
                                  r.reason or "unknown", duration_s=round(duration, 4))
                break
        out.append(finding or Finding(fid, node, "defined", k if kind == "guarantee" else None, "ok",
                                      f"{kind.capitalize()} {k} of {node} is defined wherever {where} {hold}.",
                                      "Z3 proved each division's divisor non-zero there: "
                                      + "; ".join(c.describe() for c in conds) + ".",
                                      duration_s=round(duration, 4)))
    return out


__all__ = ["definedness_findings"]
