"""Two questions a repair of a node's contract must answer besides "is the
problem gone" (docs/diagnosis.md, "Repairs ranked by what they cost"):

* **Is the node still implementable?**  A strengthened guarantee can be
  consistent (some input has an answer) and yet unimplementable: Ranger's
  ``out.d == 1000 * in.r`` with ``out.d <= 30`` added has an answer only
  for ``in.r <= 0.03``, while its assumption allows ``in.r`` up to 30.  The
  check is the usual realizability of an assume-guarantee contract for a
  stateless node: for every input the assumption and the environment facts
  allow, some output meets every guarantee (``A and facts -> exists out.
  G``, asked as a validity query; Benveniste et al., "Contracts for System
  Design", 2018, section 3: a contract is *consistent* when it has an
  implementation).  :func:`implementable`.
* **How far does the producer's contract let an output go?**  The largest
  (or smallest) value of ``out.v`` under the producer's assumption,
  guarantees and facts (Z3's ``Optimize``), which a repair compares with
  the consumer's bound: ranges that differ by a power of ten are a probable
  unit mismatch.  :func:`extreme`.

Both answer ``None``/``"inconclusive"`` where Z3 cannot decide (a
function-typed output, a timeout); the caller then does not claim the
property.
"""
from __future__ import annotations

from fractions import Fraction
from typing import Any

import z3

from rclverify.calculus.compose import free_io
from rclverify.semantics import world
from rclverify.semantics.connectives import conj
from rclverify.semantics.encode import Encoder, EncodingError
from rclverify.lang import ast
from rclverify.lang.types import Checked, FuncT
from rclverify.lang.walk import subexpressions
from rclverify.semantics import wallclock
from rclverify.semantics.query import prove

#: Budget of each query (milliseconds' worth of Z3 resource steps; the wall
#: clock is only a safety net whose firing gives no answer).
TIMEOUT_MS = 3000


def _facts(ws: Any, node: str) -> list[Any]:
    return [f.expr for f in ws.plan.facts.get(node, ())]


def implementable(ws: Any, checked: Checked, node: str) -> tuple[str, dict[str, str]]:
    """Is ``node`` of ``checked`` implementable (module docstring)?
    Returns ``("proved", {})``, ``("refuted", {input: value})`` with an
    input the assumption allows and no output answers, or
    ``("inconclusive", {})`` (a function-typed output, Z3 undecided, an
    encoding error)."""
    world.fresh()
    cn = checked.nodes[node]
    if any(isinstance(t, FuncT) for t in cn.outputs.values()):
        return "inconclusive", {}
    enc = Encoder(checked.env)
    inner = Encoder(checked.env)  # the bound outputs, with their own typing axioms
    outs = {f"out.{v}": inner.fresh(f"{node}.out.{v}!bound", f"{node}.out.{v}", t) for v, t in cn.outputs.items()}
    try:
        hyps = [enc.formula(a.formula, cn) for a in cn.node.assumes]
        body = [enc.formula(g.formula, cn, symbols=outs) for g in cn.node.guarantees]
        for f in _facts(ws, node):
            on_outputs = any(p == "out" or (p is None and n in cn.outputs and n not in cn.inputs) for p, n in free_io(f))
            if on_outputs:
                body.append(enc.formula(f, cn, symbols=outs))
            else:
                hyps.append(enc.formula(f, cn))
    except (EncodingError, KeyError, ValueError, z3.Z3Exception):
        return "inconclusive", {}
    body += inner.axioms()
    goal = z3.Exists(list(outs.values()), conj(*body)) if outs else conj(*body)
    r = prove(goal, hyps, enc, timeout_ms=TIMEOUT_MS, comment=f"repair check: is {node} implementable?")
    if r.status == "refuted":
        return "refuted", {k: v for k, v in (r.model or {}).items() if ".in." in k}
    return ("proved" if r.status == "proved" else "inconclusive"), {}


def extreme(ws: Any, checked: Checked, node: str, output: str, largest: bool) -> Fraction | None:
    """The largest (``largest``) or smallest value of ``node``'s numeric
    output ``output`` that its assumption, guarantees and environment facts
    allow, exact; ``None`` when it is unbounded, not numeric, the contract
    has a quantifier (Z3's ``Optimize`` takes none), or Z3 cannot say in its
    budget."""
    world.fresh()
    cn = checked.nodes[node]
    exprs = [a.formula for a in cn.node.assumes] + [g.formula for g in cn.node.guarantees] + _facts(ws, node)
    if any(isinstance(x, ast.Quant) for e in exprs for x in subexpressions(e)):
        return None  # Z3's Optimize does not take quantifiers (it would print a warning and answer nothing)
    enc = Encoder(checked.env)
    try:
        parts = [enc.formula(a.formula, cn) for a in cn.node.assumes]
        parts += [enc.formula(g.formula, cn) for g in cn.node.guarantees]
        parts += [enc.formula(f, cn) for f in _facts(ws, node)]
        target = enc.io_symbol(cn, "out", output)
    except (EncodingError, KeyError, ValueError, z3.Z3Exception):
        return None
    if isinstance(target, z3.FuncDeclRef) or not (z3.is_int(target) or z3.is_real(target)):
        return None
    opt = wallclock.limit(z3.Optimize(), TIMEOUT_MS)  # resource steps decide; the clock only cuts
    opt.add(*parts, *enc.axioms())
    h = opt.maximize(target) if largest else opt.minimize(target)
    try:
        if wallclock.check(opt) != z3.sat:
            return None
        v = opt.upper(h) if largest else opt.lower(h)
    except z3.Z3Exception:
        return None
    if not (z3.is_int_value(v) or z3.is_rational_value(v)):
        return None  # unbounded (oo) or an infinitesimal bound (a strict inequality)
    if z3.is_int_value(v):
        return Fraction(v.as_long())
    return Fraction(v.numerator_as_long(), v.denominator_as_long())
