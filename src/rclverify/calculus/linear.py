"""Quantifier elimination over linear arithmetic, and its result as RCL.

The quotient (:mod:`.quotient`) states a contract as ``exists``/``forall``
over the variables a node cannot see; for linear real (and integer)
arithmetic Z3's ``qe`` tactic (Loos-Weispfenning and Fourier-Motzkin style
projection for the reals, Cooper-style for the integers; the method Pacti
applies to polyhedra) turns that into a quantifier-free formula over the
node's own inputs and outputs, exactly.

That formula is correct but unreadable (``qe`` leaves nested negations of
case splits), so :func:`clauses_under` rewrites it as a conjunction of
clauses and drops, with Z3 checking each step, every literal and every
clause that the context (the computed assumption) and the other clauses
make unnecessary: the result is equivalent to the input wherever the
context holds.  :func:`to_rcl` prints a formula of the fragment (Boolean
connectives, comparisons, ``+ - *``, numerals, the named symbols) as RCL,
and returns ``None`` for anything else (``mod``, ``divisible``, a quantifier
``qe`` could not eliminate), so the caller knows it left the fragment.
"""
from __future__ import annotations

from fractions import Fraction
from typing import Mapping, Sequence

import z3

from rclverify.semantics.connectives import conj, disj
from rclverify.semantics.retry import has_quantifier
from rclverify.semantics.values import decimal_text
from rclverify.semantics import wallclock

#: At most this many clauses are examined one by one (beyond: printed as ``qe`` left them).
MAX_CLAUSES = 200
#: Budget of each tactic and check, in milliseconds (a command, not a pipeline stage).
STEP_MS = 20_000


def eliminate(f: z3.BoolRef) -> z3.BoolRef | None:
    """``f`` (with quantifiers over arithmetic constants) without
    quantifiers, by Z3's ``qe`` then ``simplify``; ``None`` when Z3 leaves a
    quantifier or gives up."""
    g = z3.Goal(ctx=f.ctx)
    g.add(f)
    try:
        r = z3.TryFor(z3.Then("simplify", "qe", "simplify", ctx=f.ctx), STEP_MS, ctx=f.ctx)(g)
    except z3.Z3Exception:
        return None
    out = r.as_expr()
    return None if has_quantifier(out) else out


def _nnf_clauses(e: z3.BoolRef) -> list[list[z3.BoolRef]] | None:
    """CNF of ``e`` (negations pushed to the atoms, ``Or`` distributed over
    ``And``) as lists of literals; ``None`` beyond :data:`MAX_CLAUSES`."""
    def cnf(x: z3.BoolRef, positive: bool) -> list[list[z3.BoolRef]] | None:
        if z3.is_not(x):
            return cnf(x.arg(0), not positive)
        if z3.is_and(x) or z3.is_or(x):
            conjunctive = z3.is_and(x) == positive
            parts = [cnf(c, positive) for c in x.children()]
            if any(p is None for p in parts):
                return None
            if conjunctive:
                return [c for p in parts for c in p]  # type: ignore[union-attr]
            out: list[list[z3.BoolRef]] = [[]]
            for p in parts:
                out = [a + b for a in out for b in p]  # type: ignore[union-attr]
                if len(out) > MAX_CLAUSES:
                    return None
            return out
        if z3.is_implies(x):
            return cnf(z3.Or(z3.Not(x.arg(0)), x.arg(1)), positive)
        if z3.is_true(x):
            return [] if positive else [[]]
        if z3.is_false(x):
            return [[]] if positive else []
        return [[x if positive else _negate(x)]]
    return cnf(e, True)


def _negate(a: z3.BoolRef) -> z3.BoolRef:
    """The negation of an atom, as a comparison where one exists."""
    if z3.is_le(a):
        return a.arg(0) > a.arg(1)
    if z3.is_lt(a):
        return a.arg(0) >= a.arg(1)
    if z3.is_ge(a):
        return a.arg(0) < a.arg(1)
    if z3.is_gt(a):
        return a.arg(0) <= a.arg(1)
    return z3.Not(a)


def _valid(hyps: Sequence[z3.BoolRef], goal: z3.BoolRef) -> bool:
    s = z3.Solver(ctx=goal.ctx)
    wallclock.limit(s, STEP_MS)  # steps decide, the clock is a net
    s.add(*hyps)
    s.add(z3.Not(goal))
    return bool(s.check() == z3.unsat)


def clauses_under(f: z3.BoolRef, context: Sequence[z3.BoolRef] = ()) -> z3.BoolRef:
    """A formula equivalent to ``f`` wherever ``context`` holds, as few
    clauses and literals as Z3 shows suffice (module docstring): each
    literal of each clause is dropped when ``context`` and ``f`` imply the
    clause without it, then each clause that ``context`` and the remaining
    clauses imply.  Deterministic: clauses and literals are taken in the
    order of their SMT-LIB text.  ``f`` itself when its CNF is larger than
    :data:`MAX_CLAUSES`."""
    cls = _nnf_clauses(f)
    if cls is None:
        return f
    ctx = list(context)
    unique: dict[str, list[z3.BoolRef]] = {}
    for c in cls:
        lits = {lit.sexpr(): lit for lit in c}
        unique.setdefault(" ".join(sorted(lits)), [lits[k] for k in sorted(lits)])
    clauses = [unique[k] for k in sorted(unique)]
    if any(not c for c in clauses):
        return z3.BoolVal(False, f.ctx)
    whole = ctx + [f]
    shrunk: list[list[z3.BoolRef]] = []
    for c in clauses:
        kept_lits = list(c)
        for lit in list(kept_lits):
            rest = [x for x in kept_lits if not x.eq(lit)]
            if rest and _valid(whole, disj(*rest) if len(rest) > 1 else rest[0]):
                kept_lits = rest
        shrunk.append(kept_lits)
    kept = list(shrunk)
    for c in list(shrunk):
        others = [disj(*x) if len(x) > 1 else x[0] for x in kept if x is not c]
        if _valid(ctx + others, disj(*c) if len(c) > 1 else c[0]):
            kept = [x for x in kept if x is not c]
    parts = [disj(*c) if len(c) > 1 else c[0] for c in kept]
    return conj(*parts) if len(parts) > 1 else parts[0] if parts else z3.BoolVal(True, f.ctx)


_CMP = {z3.Z3_OP_LE: "<=", z3.Z3_OP_LT: "<", z3.Z3_OP_GE: ">=", z3.Z3_OP_GT: ">", z3.Z3_OP_EQ: "=="}


def to_rcl(e: z3.ExprRef, names: Mapping[str, str]) -> str | None:
    """RCL text of ``e`` (module docstring's fragment), each free constant
    named by ``names`` (Z3 name -> RCL name, e.g. ``"N0.out.x1" ->
    "in.x1"``); ``None`` outside the fragment or for an unnamed constant."""
    try:
        return _rcl(e, names, top=True)
    except _Outside:
        return None


class _Outside(Exception):
    pass


def _num(v: z3.ExprRef) -> str:
    if z3.is_int_value(v):
        n = v.as_long()
        return str(n) if n >= 0 else f"-{-n}"
    fr = Fraction(v.numerator_as_long(), v.denominator_as_long())
    if fr.denominator == 1:
        return str(fr.numerator) if fr >= 0 else f"-{-fr.numerator}"
    text = decimal_text(abs(fr))
    body = text if text else f"({abs(fr.numerator)} / {fr.denominator})"
    return body if fr >= 0 else f"-{body}"


def _rcl(e: z3.ExprRef, names: Mapping[str, str], top: bool = False) -> str:
    if z3.is_true(e):
        return "TRUE"
    if z3.is_false(e):
        return "FALSE"
    if z3.is_int_value(e) or z3.is_rational_value(e):
        return _num(e)
    if not z3.is_app(e):
        raise _Outside
    k = e.decl().kind()
    kids = e.children()
    wrap = (lambda s: s) if top else (lambda s: f"({s})")
    if k == z3.Z3_OP_UNINTERPRETED and not kids:
        name = names.get(e.decl().name())
        if name is None:
            raise _Outside
        return name
    if k == z3.Z3_OP_TO_REAL:
        return _rcl(kids[0], names, top)
    if k == z3.Z3_OP_AND:
        return wrap(" and ".join(_rcl(c, names) for c in kids))
    if k == z3.Z3_OP_OR:
        return wrap(" or ".join(_rcl(c, names) for c in kids))
    if k == z3.Z3_OP_NOT:
        return wrap(f"not {_rcl(kids[0], names)}")
    if k == z3.Z3_OP_IMPLIES:
        return wrap(f"{_rcl(kids[0], names)} -> {_rcl(kids[1], names)}")
    if k in _CMP:
        if k == z3.Z3_OP_EQ and z3.is_bool(kids[0]):
            return wrap(f"{_rcl(kids[0], names)} <=> {_rcl(kids[1], names)}")
        return wrap(f"{_rcl(kids[0], names)} {_CMP[k]} {_rcl(kids[1], names)}")
    if k == z3.Z3_OP_ADD:
        return wrap(" + ".join(_rcl(c, names) for c in kids))
    if k == z3.Z3_OP_SUB:
        return wrap(" - ".join(_rcl(c, names) for c in kids))
    if k == z3.Z3_OP_MUL:
        return wrap(" * ".join(_rcl(c, names) for c in kids))
    if k == z3.Z3_OP_UMINUS:
        return wrap(f"-{_rcl(kids[0], names)}")
    raise _Outside
