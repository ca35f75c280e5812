"""Probable scale mismatch of a side condition (docs/rcl-language.md, "Units of measure").

A side condition that is not discharged (:mod:`.compose`) often comes from
a range problem, but one kind is not a range problem at all: the producer
publishes millimetres where the consumer reads metres.  Its signature is two
ranges that differ by a power of ten: the producer guarantees ``out.d <=
30000``, the consumer assumes ``in.d <= 30``.  Widening the assumption to
``30000`` would make the side condition hold and the system wrong, so the
calculus says what the numbers suggest.

For each input the conjunct reads over a connection, where the two ends do
not both declare a unit (declared units are checked exactly,
:mod:`rclverify.model.system.units`) and the type is a number:

* the **producer's range** of the output: its least and greatest value
  under the producer's guarantees and assumptions (the hypotheses of the
  side condition's second variant), asked of Z3's optimiser
  (``z3.Optimize``, one objective at a time, a bounded budget);
* the **consumer's range** of the input: the same under the conjuncts of the
  consumer's assumption that mention this input alone;
* a **probable scale mismatch** when some bound of the one is, within 2 %,
  ``10^k`` times the same bound of the other (both finite and non-zero),
  with ``2 <= |k| <= 12``, and the producer's range divided by ``10^k`` lies
  inside the consumer's (with the same 2 % slack): read in the other unit,
  the producer's values would fit.  A factor of 10 is left out: ``<= 1``
  against ``<= 10`` is an ordinary margin far more often than a unit;
* else, the same rule with one of the usual conversions that are no power
  of ten (:data:`CONVERSIONS`: degrees and radians, 180/pi; km/h
  and m/s, 3.6; feet and metres, 0.3048; mph and m/s, 0.44704; miles and
  kilometres, 1.609344; inches and centimetres, 2.54), within 0.5 %.

An unbounded range, an optimiser that cannot answer in its budget, or a
non-numeric input gives nothing: the finding is a warning that points at a
likely cause, never a verdict (the side condition's own status is unchanged).
"""
from __future__ import annotations

from fractions import Fraction
from typing import Any, Iterable, Mapping, Sequence

import z3

from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.types import Checked, CheckedNode, is_numeric
from rclverify.lang.walk import free_names, subexpressions
from rclverify.semantics import wallclock
from rclverify.calculus.shapes import ScaleMismatch
from rclverify.records.findings import HealthFinding

#: Budget of one optimisation, milliseconds.
OPTIMIZE_MS = 1000
#: Relative slack when bounds are compared.
SLACK = Fraction(2, 100)
#: Powers of ten considered (magnitude).
MIN_POWER, MAX_POWER = 2, 12

#: For a power of ten, a pair of units that differ by it: (the producer's, the consumer's).
_EXAMPLES = {2: ("cm", "m"), 3: ("mm", "m"), 6: ("um", "m"), 9: ("ns", "s"),
             -2: ("m", "cm"), -3: ("km", "m"), -6: ("s", "us"), -9: ("s", "ns")}


def _conjuncts(e: ast.Expr) -> list[ast.Expr]:
    if isinstance(e, ast.Binary) and e.op == "and":
        return _conjuncts(e.left) + _conjuncts(e.right)
    return [e]


def _inputs_read(e: ast.Expr, cn: CheckedNode) -> set[str]:
    """The inputs of ``cn`` a formula mentions (``in.x`` or a bare input name)."""
    out = {v.name for v in subexpressions(e) if isinstance(v, ast.Var) and v.prefix == "in"}
    return out | {n for n in free_names(e) if n in cn.inputs}


def _bound(v: z3.ExprRef) -> Fraction | None:
    """An optimum as an exact number: a rational, ``r + -1*epsilon`` (the
    supremum ``r`` of a strict bound) or ``None`` for an unbounded one."""
    if z3.is_rational_value(v):
        return Fraction(v.as_fraction())
    if z3.is_int_value(v):
        return Fraction(v.as_long())
    text = str(v)
    if "oo" in text:
        return None
    if z3.is_add(v):
        parts = [c for c in v.children() if "epsilon" not in str(c)]
        if len(parts) == 1:
            return _bound(parts[0])
    return None


def _range(term: z3.ArithRef, facts: Sequence[z3.BoolRef]) -> tuple[Fraction | None, Fraction | None] | None:
    """``(least, greatest)`` of ``term`` under ``facts`` (``None`` for an
    unbounded side), or ``None`` when the optimiser cannot say."""
    out: list[Fraction | None] = []
    for maximise in (False, True):
        o = z3.Optimize()
        wallclock.limit(o, OPTIMIZE_MS)  # steps decide, the clock is a net
        o.add(*facts)
        h = o.maximize(term) if maximise else o.minimize(term)
        if o.check() != z3.sat:
            return None
        out.append(_bound(h.value()))
    return out[0], out[1]


def _show(x: Fraction | None, inf: str) -> str:
    if x is None:
        return inf
    return str(x.numerator) if x.denominator == 1 else f"{float(x):g}"


def _near(a: Fraction, b: Fraction) -> bool:
    return abs(a - b) <= SLACK * abs(b)


def scale_power(producer: tuple[Fraction | None, Fraction | None],
                consumer: tuple[Fraction | None, Fraction | None]) -> int | None:
    """``k`` when the producer's range is ``10^k`` times the consumer's (the
    rule of the module docstring), else ``None``.  Ranges are ``(least,
    greatest)``, ``None`` for unbounded."""
    candidates = set()
    for p, c in zip(producer, consumer):
        if p is None or c is None or p == 0 or c == 0 or (p > 0) != (c > 0):
            continue
        r = p / c
        for k in range(MIN_POWER, MAX_POWER + 1):
            for kk in (k, -k):
                if _near(r, Fraction(10) ** kk):
                    candidates.add(kk)
    for k in sorted(candidates, key=abs):
        f = Fraction(10) ** k
        lo_p, hi_p = producer
        lo_c, hi_c = consumer
        lo_ok = lo_c is None or (lo_p is not None and lo_p / f >= lo_c - SLACK * abs(lo_c))
        hi_ok = hi_c is None or (hi_p is not None and hi_p / f <= hi_c + SLACK * abs(hi_c))
        if lo_ok and hi_ok:
            return k
    return None


#: The usual conversions that are no power of ten: (factor the producer's values are of the consumer's,
#: its text, the producer's unit, the consumer's unit), both directions.
_BASE_CONVERSIONS = [(Fraction(180) / Fraction(3.141592653589793), "180/pi", "deg", "rad"),
                     (Fraction(36, 10), "3.6", "km/h", "m/s"),
                     (1 / Fraction(3048, 10000), "1/0.3048", "ft", "m"),
                     (1 / Fraction(44704, 100000), "1/0.44704", "mph", "m/s"),
                     (1 / Fraction(1609344, 1000000), "1/1.609344", "mi", "km"),
                     (Fraction(254, 100), "2.54", "cm", "in")]
CONVERSIONS = _BASE_CONVERSIONS + [(1 / f, (t[2:] if t.startswith("1/") else f"1/{t}"), c, p)
                                   for f, t, p, c in _BASE_CONVERSIONS]
#: Relative slack when a bound ratio is compared with a named conversion (tighter than a power of ten's).
NAMED_SLACK = Fraction(5, 1000)


def named_conversion(producer: tuple[Fraction | None, Fraction | None],
                     consumer: tuple[Fraction | None, Fraction | None]) -> tuple[Fraction, str, str, str] | None:
    """The usual conversion (:data:`CONVERSIONS`) by which the producer's range
    is the consumer's read in another unit, as :func:`scale_power` does for
    powers of ten: ``(factor, its text, the producer's unit, the consumer's
    unit)``, or ``None``."""
    for f, text, pu, cu in CONVERSIONS:
        ratio_ok = False
        for p, c in zip(producer, consumer):
            if p is None or c is None or p == 0 or c == 0 or (p > 0) != (c > 0):
                continue
            if abs(p / c - f) <= NAMED_SLACK * f:
                ratio_ok = True
        if not ratio_ok:
            continue
        lo_p, hi_p = producer
        lo_c, hi_c = consumer
        lo_ok = lo_c is None or (lo_p is not None and lo_p / f >= lo_c - NAMED_SLACK * abs(lo_c))
        hi_ok = hi_c is None or (hi_p is not None and hi_p / f <= hi_c + NAMED_SLACK * abs(hi_c))
        if lo_ok and hi_ok:
            return f, text, pu, cu
    return None


def probable_mismatches(checked: Checked, links: Iterable[Any], enc: Any, node: str,
                        conjunct: ast.Expr) -> tuple[ScaleMismatch, ...]:
    """The probable scale mismatches behind one side condition of ``node``:
    ``conjunct`` is the assumption conjunct, ``links`` the connections into
    ``node`` (:meth:`~rclverify.model.system.model.SystemModel.links_into`),
    ``enc`` the side condition's :class:`~rclverify.semantics.encode.Encoder`
    (its aliases make a consumer input the producer's output symbol).

    Returns one record per mismatched input: ``{"producer":
    "Lidar.out.d", "consumer": "Controller.in.d", "producer_range": [lo,
    hi], "consumer_range": [lo, hi]`` (texts, ``-oo``/``+oo`` when
    unbounded), ``"power": k`` (0 for a named conversion), ``"factor":
    "1000"`` or ``"180/pi"``, ``"message": the sentence}``.
    Never raises for solver trouble (nothing is found then)."""
    cn = checked.nodes[node]
    read = _inputs_read(conjunct, cn)
    out: list[ScaleMismatch] = []
    for l in links:
        if l.to_var not in read or l.from_node not in checked.nodes:
            continue
        pn = checked.nodes[l.from_node]
        t = cn.inputs.get(l.to_var)
        if t is None or not is_numeric(t) or (cn.unit_of("in", l.to_var) is not None
                                              and pn.unit_of("out", l.from_var) is not None):
            continue
        try:
            term = enc.io_symbol(pn, "out", l.from_var)
            prod = [enc.formula(c.formula, pn) for c in pn.node.guarantees + pn.node.assumes]
            own = [c for a in cn.node.assumes for c in _conjuncts(a.formula) if _inputs_read(c, cn) == {l.to_var}]
            cons = [enc.formula(c, cn) for c in own]
            axioms = enc.axioms()
            p_range = _range(term, prod + axioms)
            c_range = _range(term, cons + axioms) if cons else None
        except Exception:  # an encoding error or a solver failure: nothing to say (a hint, never a verdict)
            continue
        if p_range is None or c_range is None:
            continue
        k = scale_power(p_range, c_range)
        if k is not None:
            factor = str(10 ** k) if k > 0 else f"1/{10 ** -k}"
            pu, cu = _EXAMPLES.get(k, ("..", ".."))
        else:
            named = named_conversion(p_range, c_range)
            if named is None:
                continue
            k = 0
            _, factor, pu, cu = named
        writer, reader = f"{l.from_node}.out.{l.from_var}", f"{node}.in.{l.to_var}"
        pr = [_show(p_range[0], "-oo"), _show(p_range[1], "+oo")]
        cr = [_show(c_range[0], "-oo"), _show(c_range[1], "+oo")]
        said = expr_to_rcl(own[0]) if len(own) == 1 else " and ".join(expr_to_rcl(c) for c in own[:3])
        msg = (f"probable scale mismatch: {writer} ranges over [{pr[0]}, {pr[1]}] ({l.from_node}'s guarantees and "
               f"assumptions) and {reader} over [{cr[0]}, {cr[1]}] ({node} assumes {said}): they differ by a "
               f"factor of {factor}, as a value in [{pu}] read as [{cu}] would. Declare the unit of each end "
               f"(e.g. {l.from_var} : REAL [{pu}] in the outputs of {l.from_node}, {l.to_var} : REAL [{cu}] in the "
               f"inputs of {node}) so that RCL checks the connection, and convert in {l.from_node} rather than "
               f"widen {node}'s assumption")
        out.append({"producer": writer, "consumer": reader, "producer_range": pr, "consumer_range": cr,
                    "power": k, "factor": factor, "message": msg})
    return tuple(out)


def scale_findings(side_conditions: Iterable[Mapping[str, Any]]) -> list[HealthFinding]:
    """Contract-health findings (:class:`~rclverify.records.findings.HealthFinding`,
    status ``warning``) for the
    probable scale mismatches recorded on side conditions that are failed
    or inconclusive (a stale or altered record gives none): check
    ``probable-scale-mismatch``, id ``<side condition>.scale``, the
    consumer's node."""
    out: list[HealthFinding] = []
    for sc in side_conditions:
        if sc.get("status") not in ("failed", "inconclusive"):
            continue
        for k, m in enumerate(sc.get("scale_mismatch") or (), 1):
            out.append(HealthFinding(
                id=f"{sc['id']}.scale" + (f"{k}" if k > 1 else ""), node=sc["node"], check="probable-scale-mismatch",
                guarantee=None, status="warning", message=f"side condition {sc['id']}: {m['message']}",
                explanation=(f"Side condition {sc['id']} ({sc.get('conjunct', '')}) is {sc['status']}; "
                             f"the ranges of its two ends differ by a factor of {m['factor']}, "
                             "which a unit mismatch explains better than a range problem.")))
    return out
