"""A Z3 model's function as an exact finite table, when it is one.

Model-based quantifier instantiation hands back functions over the reals as
one ``else`` term: nested ``if`` over conditions such as ``(p2 == 20) and
not (p1 == 40) and ...``, often with disjunctions, whose last ``else`` need
not be the value "elsewhere" (a catch-all branch of negated equalities may
come first).  Read as text, that misleads: the case study's replacement
counterexample showed ``wayP`` as 128 "elsewhere" although every point
outside its named ones maps to 0 (and the environment fact bounds ``wayP``
by 12).

When every atom of the term compares a parameter with a numeral (``p == c``)
the function is constant on each cell of the grid the numerals cut: each
parameter either equals one of its numerals or none.  :func:`finite_table`
evaluates the model on every cell (a numeral, or a fresh value standing for
"none of them") and returns the points whose value differs from the value at
the all-fresh point, which is the value elsewhere.  The table is exact; when
a cell with some fresh coordinate differs from the value elsewhere (no
single point stands for it), or the grid is larger than :data:`MAX_CELLS`,
or an atom is anything else, it returns ``None`` and the caller prints the
term.
"""
from __future__ import annotations

import itertools
from fractions import Fraction
from typing import Callable

import z3

#: Largest grid evaluated (cells = product over parameters of numerals + 1).
MAX_CELLS = 4096


def _numeral(e: z3.ExprRef) -> Fraction | None:
    if z3.is_int_value(e):
        return Fraction(e.as_long())
    if z3.is_rational_value(e):
        return Fraction(e.numerator_as_long(), e.denominator_as_long())
    return None


def _numerals(body: z3.ExprRef, arity: int) -> list[set[Fraction]] | None:
    """Per parameter (``Var(k)`` of a function interpretation is argument
    ``k``), the numerals it is compared with; ``None`` when an atom is not
    ``p == c``."""
    found: list[set[Fraction]] = [set() for _ in range(arity)]
    seen: set[int] = set()
    todo = [body]
    while todo:
        e = todo.pop()
        if e.get_id() in seen:
            continue
        seen.add(e.get_id())
        if z3.is_var(e):  # an argument used as a value (f(x) = x): not constant on the grid's cells
            return None
        if _numeral(e) is not None or z3.is_true(e) or z3.is_false(e):
            continue
        if z3.is_and(e) or z3.is_or(e) or z3.is_not(e) or z3.is_app_of(e, z3.Z3_OP_ITE):
            todo.extend(e.children())
            continue
        if z3.is_eq(e):
            a, b = e.children()
            if z3.is_var(b):
                a, b = b, a
            c = _numeral(b)
            if z3.is_var(a) and c is not None:
                found[z3.get_var_index(a)].add(c)
                continue
            return None
        if z3.is_app(e) and e.num_args() == 0:  # a constant value (enumeration, constructor)
            continue
        if z3.is_app(e) and e.decl().kind() == z3.Z3_OP_DT_CONSTRUCTOR \
                and all(_numeral(c) is not None for c in e.children()):
            continue
        return None
    return found


def finite_table(model: z3.ModelRef, d: z3.FuncDeclRef, else_body: z3.ExprRef,
                 show: Callable[[z3.ExprRef], str]) -> tuple[list[tuple[str, str]], str] | None:
    """``(rows, elsewhere)``: the points (argument texts) where the model's
    ``d`` differs from its value elsewhere, with their value texts, and that
    value; ``None`` when the interpretation is not such a table (module
    docstring).  ``else_body`` is the interpretation's ``else`` term (with
    de Bruijn variables); ``show`` prints a Z3 value in RCL."""
    arity = d.arity()
    sorts = [d.domain(k) for k in range(arity)]
    if not all(s.kind() in (z3.Z3_INT_SORT, z3.Z3_REAL_SORT) for s in sorts):
        return None
    per = _numerals(else_body, arity)
    if per is None:
        return None
    interp = model[d]
    for k in range(interp.num_entries()):  # explicit entries come first in the interpretation
        entry = interp.entry(k)
        for j in range(arity):
            c = _numeral(entry.arg_value(j))
            if c is None:
                return None
            per[j].add(c)
    cells = 1
    for p in per:
        cells *= len(p) + 1
    if cells > MAX_CELLS:
        return None

    def value(v: Fraction | None, j: int) -> z3.ExprRef:
        fresh = max((abs(c) for c in per[j]), default=Fraction(0)) + 1
        x = fresh if v is None else v
        if sorts[j].kind() == z3.Z3_INT_SORT:
            return z3.IntVal(int(x), d.ctx)
        return z3.RealVal(x, d.ctx)

    def at(point: tuple[Fraction | None, ...]) -> z3.ExprRef:
        return model.eval(d(*[value(v, j) for j, v in enumerate(point)]), model_completion=True)

    elsewhere = at(tuple(None for _ in range(arity)))
    rows: list[tuple[str, str]] = []
    options = [sorted(p) + [None] for p in per]
    for point in itertools.product(*options):
        v = at(point)
        if v.eq(elsewhere):
            continue
        if any(c is None for c in point):
            return None  # a whole line of points differs: no single row says it
        rows.append((", ".join(show(value(c, j)) for j, c in enumerate(point)), show(v)))
    return rows, show(elsewhere)
