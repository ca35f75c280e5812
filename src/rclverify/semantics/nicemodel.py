"""Counterexamples a person can read: a Z3 model asked again for
inputs within their nodes' assumptions and for integers and short decimals.

Z3 hands back the first model it finds: ``dest_id = 501`` where the node
reading it assumes ``<= 500`` (nothing in the query said otherwise), a
rational such as ``7/3`` or ``0.0305`` where ``1`` would do.  This module
takes the query's formulas and the model its caller shows, and asks Z3
again, in a solver of its own with a small budget of resource steps (the
same answer on every machine):

1. with ``assumptions`` added (each labelled, e.g. the assumptions of the
   nodes the counterexample shows, which the query did not hold): when they
   can hold together with the query, the model is one in which they do; when
   they cannot (``unsat``), the model stays, and the labels of an unsat core
   of them are returned (``outside``): the counterexample needs an input
   outside those assumptions, which the caller says;
2. for each real-valued constant whose value is no short decimal (more than
   :data:`SHORT_DIGITS` decimal places, or no finite decimal at all), the
   nearest integers, then the value rounded to one, two and three decimal
   places, each pinned in turn and kept when the query still has a model.

The result is **re-checked**: the formulas (with the assumptions kept) and
every shown constant pinned to its new value must be satisfiable in a fresh
solver; otherwise (or on any ``unknown``) the caller's model is returned
unchanged, so a shown counterexample is always one.  A model already within
the assumptions and already short is returned as it was (the same text).

Only the budget of steps decides: when the wall-clock safety net
of any of these queries fires (:mod:`.wallclock`: a loaded machine), the
caller's model, the one the deterministic query found, is returned
unchanged, never the intermediate model a loop cut short had reached.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any, Mapping, Sequence

import z3

from rclverify.semantics import wallclock
from rclverify.semantics.wallclock import check, limit

#: Decimal places a value may have and still count as short.
SHORT_DIGITS = 3
#: Resource-step budget of each query (milliseconds' worth, :data:`rclverify.semantics.query.STEPS_PER_MS`).
BUDGET_MS = 300
#: At most this many pinning queries per model.
MAX_PINS = 24


@dataclass(frozen=True)
class Nicer:
    """What :func:`nicer_model` found.

    ``model``    RCL name -> value text (the caller's when nothing better was found);
    ``changed``  the model differs from the caller's;
    ``within``   ``True``: the model keeps every given assumption; ``False``:
                 no model of the query does (see ``outside``); ``None``: not
                 asked (no assumptions) or undecided;
    ``outside``  labels of assumptions that cannot hold with the query (an unsat core).
    """

    model: dict[str, str]
    changed: bool = False
    within: bool | None = None
    outside: list[str] = field(default_factory=list)


def short(v: Fraction) -> bool:
    """Is ``v`` an integer or a decimal of at most :data:`SHORT_DIGITS` places?"""
    return bool((v * 10 ** SHORT_DIGITS).denominator == 1)


def parse_number(text: str) -> Fraction | None:
    """A model value's text (``2``, ``-0.5``, ``7/3``) as a fraction, else ``None``."""
    try:
        return Fraction(text.strip())
    except (ValueError, ZeroDivisionError):
        return None


def candidates(v: Fraction) -> list[Fraction]:
    """Shorter values near ``v``, the simplest first: the integers either
    side, then ``v`` rounded to 1, 2 and 3 decimal places (each a short
    value, none equal to ``v``)."""
    lo = Fraction(v.numerator // v.denominator)
    out = [lo, lo + 1] if abs(v - lo) <= abs(lo + 1 - v) else [lo + 1, lo]
    for d in range(1, SHORT_DIGITS + 1):
        scale = 10 ** d
        out.append(Fraction(round(v * scale), scale))
    seen: list[Fraction] = []
    for c in out:
        if c != v and c not in seen:
            seen.append(c)
    return seen


def _solver(ctx: z3.Context) -> z3.Solver:
    s: z3.Solver = limit(z3.Solver(ctx=ctx), BUDGET_MS)
    return s


def _constants(enc: Any, shown: Mapping[str, str]) -> dict[str, z3.ExprRef]:
    """The shown arity-0 symbols of sort Int, Real or Bool: display -> Z3 constant."""
    out = {}
    for sym in enc.symbols.values():
        d = sym.decl
        if sym.display in shown and isinstance(d, z3.ExprRef) and (z3.is_arith(d) or z3.is_bool(d)):
            out[sym.display] = d
    return out


def _value(c: z3.ExprRef, text: str) -> z3.ExprRef | None:
    if z3.is_bool(c):
        return z3.BoolVal(text == "TRUE", c.ctx) if text in ("TRUE", "FALSE") else None
    v = parse_number(text)
    if v is None or (z3.is_int(c) and v.denominator != 1):
        return None
    return z3.IntVal(v.numerator, c.ctx) if z3.is_int(c) else z3.RealVal(v, c.ctx)


def _pins(consts: Mapping[str, z3.ExprRef], model: Mapping[str, str]) -> list[z3.BoolRef]:
    out = []
    for name, c in consts.items():
        v = _value(c, model.get(name, ""))
        if v is not None:
            out.append(c == v)
    return out


def nicer_model(formulas: Sequence[z3.BoolRef], enc: Any, model: Mapping[str, str], *,
                assumptions: Sequence[tuple[str, z3.BoolRef]] = ()) -> Nicer:
    """A model of ``formulas`` (the query, typing axioms of ``enc`` added)
    as readable as Z3 finds within its budget (module docstring).

    ``enc`` is the :class:`rclverify.semantics.encode.Encoder` the formulas were
    made with (its symbols name the model's values); ``model`` the caller's
    model (RCL name -> value text, :func:`rclverify.semantics.query.render_model`);
    ``assumptions`` labelled formulas to keep when they can hold.  Returns a
    :class:`Nicer`; never raises on solver trouble (the caller's model is
    kept), and keeps the caller's model when the wall-clock safety net cut
    any query (module docstring)."""
    keep = Nicer(dict(model))
    if not formulas:
        return keep
    with wallclock.watch() as w:
        nice = _nicer(formulas, enc, model, assumptions, keep)
    return keep if w.cut else nice


def _nicer(formulas: Sequence[z3.BoolRef], enc: Any, model: Mapping[str, str],
           assumptions: Sequence[tuple[str, z3.BoolRef]], keep: Nicer) -> Nicer:
    """:func:`nicer_model`'s search, whatever the wall clock did."""
    from rclverify.semantics.query import render_model  # deferred: start-up (loads lark, rclverify.core and more only when called)
    consts = _constants(enc, model)
    ctx = formulas[0].ctx
    base = list(formulas) + list(enc.axioms())
    pins = _pins(consts, model)
    try:
        within: bool | None = None
        outside: list[str] = []
        kept = [f for _, f in assumptions]
        # the caller's model within the assumptions: asked only when there are some (without them the answer
        # changes nothing below: nothing to keep, and the search starts from the caller's values anyway)
        as_is = bool(assumptions) and _check(base + kept + pins, ctx) == z3.sat
        if as_is:
            within = True
        elif assumptions:
            r = _check(base + kept, ctx)
            within = True if r == z3.sat else False if r == z3.unsat else None
            outside = _core(base, assumptions, ctx) if r == z3.unsat else []
        if not within:
            kept = []
        if (as_is or not within) and _all_short(consts, model):
            return Nicer(dict(model), False, within, outside)
        s = _solver(ctx)
        s.add(*base, *kept)
        s.push()
        s.add(*(pins if as_is or not kept else []))  # from the caller's values when they are a model of s
        if check(s) != z3.sat:
            return Nicer(dict(model), False, within, outside)
        m = s.model()
        s.pop()
        m = _round(s, consts, m)
        new = render_model(m, enc)
        new = {k: new.get(k, v) for k, v in model.items()}
        if new != dict(model) and not _recheck(base + kept, consts, new, ctx):
            return Nicer(dict(model), False, within, outside)
        return Nicer(new, new != dict(model), within, outside)
    except z3.Z3Exception:
        return keep


def _check(formulas: Sequence[z3.BoolRef], ctx: z3.Context) -> z3.CheckSatResult:
    s = _solver(ctx)
    s.add(*formulas)
    return check(s)


def _all_short(consts: Mapping[str, z3.ExprRef], model: Mapping[str, str]) -> bool:
    for name, c in consts.items():
        if z3.is_arith(c) and not z3.is_int(c):
            v = parse_number(model.get(name, ""))
            if v is None or not short(v):
                return False
    return True


def _number(m: z3.ModelRef, c: z3.ExprRef) -> Fraction | None:
    v = m.eval(c, model_completion=True)
    if z3.is_rational_value(v):
        return Fraction(v.numerator_as_long(), v.denominator_as_long())
    return None


def _round(s: z3.Solver, consts: Mapping[str, z3.ExprRef], m: z3.ModelRef) -> z3.ModelRef:
    """Pin each real constant whose value is not short to the first of its
    :func:`candidates` with which ``s`` stays satisfiable (greedy, in name
    order, at most :data:`MAX_PINS` queries); the last model found."""
    asked = 0
    for name in sorted(consts):
        c = consts[name]
        if not z3.is_arith(c) or z3.is_int(c):
            continue
        v = _number(m, c)
        if v is None or short(v):
            continue
        for cand in candidates(v):
            if asked >= MAX_PINS:
                return m
            asked += 1
            s.push()
            s.add(c == z3.RealVal(cand, c.ctx))
            if check(s) == z3.sat:
                m = s.model()  # the pin stays (no pop): later constants keep it
                break
            s.pop()
    return m


def _recheck(formulas: Sequence[z3.BoolRef], consts: Mapping[str, z3.ExprRef], model: Mapping[str, str],
             ctx: z3.Context) -> bool:
    """Do ``formulas`` hold with every shown constant at its value in ``model``
    (a fresh solver: ``sat``)?"""
    s = _solver(ctx)
    s.add(*formulas)
    pins = _pins(consts, model)
    if len(pins) < len([n for n in consts if n in model]):
        return False  # a value that does not read back (an algebraic number): not checked, not shown
    s.add(*pins)
    return bool(check(s) == z3.sat)


def _core(base: Sequence[z3.BoolRef], assumptions: Sequence[tuple[str, z3.BoolRef]], ctx: z3.Context) -> list[str]:
    """Labels of an unsat core of ``assumptions`` against ``base`` (every label when Z3 gives none)."""
    s = _solver(ctx)
    s.add(*base)
    marks = {}
    for k, (label, f) in enumerate(assumptions):
        b = z3.Bool(f"__nice_{k}", ctx)
        marks[str(b)] = label
        s.add(z3.Implies(b, f))
    if check(s, *[z3.Bool(f"__nice_{k}", ctx) for k in range(len(assumptions))]) == z3.unsat:
        found = {str(c) for c in s.unsat_core()}
        got = [lbl for k, (lbl, _) in enumerate(assumptions) if f"__nice_{k}" in found]
        if got:
            return got
    return [lbl for lbl, _ in assumptions]
