"""The thresholds a contract's comparisons put on each variable, however they are written.

An off-by-one slip (``<`` where the guarantee says ``<=``) shows only at the
value where the comparison changes its truth.  For ``in.p <= 0.2`` that
value is the literal; for ``in.p / 2 <= 0.1``, ``2 * in.p <= 0.4``,
``-in.p >= -0.2`` or ``abs(in.p) <= Low`` it is a number written nowhere in
the contract (0.2, -0.2).  Each comparison is therefore normalised and
solved for the variables it reads, and the solutions are the thresholds the
strategies draw with their neighbours (:mod:`.strategies`;
docs/property-tests.md, "Boundaries from every constant"):

* each side of a comparison link ``L op R`` (anywhere: under connectives,
  implications, negations and quantifiers) is read as a set of affine forms
  ``a * v + b`` in one variable ``v`` (an input ``in.x``, or a variable bound
  by a quantifier, the item of a sequence) with exact rational ``a`` and
  ``b``: numeric literals and named constants of the context (evaluated,
  ``Half = Limit / 2``) are constants; ``+``, ``-`` and unary ``-`` combine
  forms; ``*`` and ``/`` by a constant scale them; ``abs(u)`` is the forms
  of ``u`` and of ``-u``; anything else (a second variable, a product of
  two variables, a division by a variable, a function application) leaves
  the link without a threshold;
* the link changes its truth where ``L - R`` is zero: for each pair of forms
  with different slopes, ``v = (bR - bL) / (aL - aR)``.

The constants' arithmetic is the semantics table's
(:data:`~rclverify.semantics.operators.OPERATORS`, :data:`~rclverify.semantics.operators.UNARY`:
their ``exact`` meaning, a division by zero undecided), and the formula
read is the one the monitors judge: the harness hands in the node read at
its fields' widths (:func:`rclverify.backends.monitors.widths.at_carried_widths`,
:func:`rclverify.semantics.widths.at_widths`), whose constants compared with a
``float32`` field are already the field's values (``0.1`` as
0.100000001490116...), so ``in.p / 2 <= 0.1`` solves to exactly the
``float32`` value the monitors' judge flips at (2 times the carried 0.1,
which is the carried 0.2).  The harness then draws each threshold at every
field width with its two neighbours of that width
(:func:`rclverify.semantics.widths.edges_at_width`).
"""
from __future__ import annotations

from fractions import Fraction
from typing import Iterable, Mapping

from rclverify.backends.property_tests.bounds import Bound
from rclverify.lang import ast
from rclverify.lang.printer import is_type
from rclverify.lang.types import REAL, CheckedNode, SeqT, Type
from rclverify.lang.walk import children
from rclverify.semantics.operators import OPERATORS, UNARY, Undecided
from rclverify.semantics.widths import FLOAT_WIDTHS, edges_at_width

#: ``(a, b)``: the affine form ``a * v + b``
Form = tuple[Fraction, Fraction]
#: at most this many forms per side (each ``abs`` doubles them)
MAX_FORMS = 16


class _Reader:
    """Reads terms as affine forms in one variable ``var`` (module docstring)."""

    def __init__(self, var: str, constants: Mapping[str, tuple[Type, ast.Expr]], bound: frozenset[str]) -> None:
        self.var = var
        self.constants = constants
        self.bound = bound

    def forms(self, e: ast.Expr, seen: tuple[str, ...] = ()) -> list[Form] | None:
        """``e`` as affine forms in :attr:`var`, ``None`` outside the fragment."""
        if isinstance(e, ast.NumLit):
            return [(Fraction(0), Fraction(e.value))]
        if isinstance(e, ast.Var):
            key = e.qualified if e.prefix is not None else e.name
            if key == self.var and (e.prefix is not None or e.name in self.bound):
                return [(Fraction(1), Fraction(0))]
            if e.prefix is None and e.name not in self.bound and e.name in self.constants and e.name not in seen:
                inner = self.forms(self.constants[e.name][1], (*seen, e.name))  # a named constant: its value
                return inner if inner is not None and all(a == 0 for a, _ in inner) else None
            return None
        if isinstance(e, ast.Unary) and e.op in ("-", "abs"):
            fs = self.forms(e.operand, seen)
            if fs is None:
                return None
            neg = UNARY["-"].exact
            if e.op == "-":
                return [(Fraction(neg(a)), Fraction(neg(b))) for a, b in fs]
            if all(a == 0 for a, _ in fs):
                return [(Fraction(0), Fraction(UNARY["abs"].exact(b))) for _, b in fs]
            return _capped([*fs, *((Fraction(neg(a)), Fraction(neg(b))) for a, b in fs)])
        if isinstance(e, ast.Binary) and OPERATORS[e.op].kind == "arithmetic":
            left, right = self.forms(e.left, seen), self.forms(e.right, seen)
            if left is None or right is None:
                return None
            out: list[Form] = []
            for f in left:
                for g in right:
                    h = _combine(e.op, f, g)
                    if h is None:
                        return None
                    out.append(h)
            return _capped(out)
        return None


def _capped(fs: list[Form]) -> list[Form] | None:
    unique = list(dict.fromkeys(fs))
    return unique if len(unique) <= MAX_FORMS else None


def _combine(op: str, f: Form, g: Form) -> Form | None:
    """``f op g`` as an affine form, the coefficients computed by the operator's exact meaning;
    ``None`` when it is not affine (a product of two forms in the variable, a division by one) or
    undefined (a division by zero)."""
    (a, b), (c, d) = f, g
    exact = OPERATORS[op].exact
    try:
        if op in ("+", "-"):
            return Fraction(exact(a, c)), Fraction(exact(b, d))
        if op == "*":
            if a == 0:
                return Fraction(exact(b, c)), Fraction(exact(b, d))
            if c == 0:
                return Fraction(exact(a, d)), Fraction(exact(b, d))
            return None
        if op == "/" and c == 0:
            return Fraction(exact(a, d)), Fraction(exact(b, d))
    except Undecided:
        return None
    return None


def link_roots(left: ast.Expr, right: ast.Expr, var: str, constants: Mapping[str, tuple[Type, ast.Expr]],
               bound: frozenset[str] = frozenset()) -> list[Fraction]:
    """The values of the variable ``var`` (``"in.p"``, or a bound name in ``bound``) at which
    ``left`` and ``right`` are equal, where a comparison of the two can change its truth (module
    docstring); ``constants`` the context's ``name -> (type, defining expression)``.  Sorted, each
    once; ``[]`` when a side is outside the fragment or neither side depends on ``var``."""
    reader = _Reader(var, constants, bound)
    fl, fr = reader.forms(left), reader.forms(right)
    if fl is None or fr is None:
        return []
    out: set[Fraction] = set()
    for a, b in fl:
        for c, d in fr:
            if a != c:
                out.add((d - b) / (a - c))
    return sorted(out)


def _variables(e: ast.Expr, bound: frozenset[str]) -> set[str]:
    """The inputs (``in.x``) and bound variables that ``e`` reads."""
    found: set[str] = set()
    stack = [e]
    while stack:
        x = stack.pop()
        if isinstance(x, ast.Var):
            if x.prefix == "in":
                found.add(x.qualified)
            elif x.prefix is None and x.name in bound:
                found.add(x.name)
        stack.extend(children(x))
    return found


def _walk(e: ast.Expr, bound: frozenset[str], constants: Mapping[str, tuple[Type, ast.Expr]],
          out: set[Fraction]) -> None:
    if isinstance(e, ast.Compare):
        for left, right in zip(e.operands, e.operands[1:]):
            for var in sorted(_variables(left, bound) | _variables(right, bound)):
                out.update(link_roots(left, right, var, constants, bound))
    if isinstance(e, ast.Quant):
        names: set[str] = set()
        for b in e.bindings:
            if not is_type(b.domain):
                _walk(b.domain, bound | frozenset(names), constants, out)  # type: ignore[arg-type]
            names.update(b.names)
        _walk(e.body, bound | frozenset(names), constants, out)
        return
    if isinstance(e, ast.TupleQuant):
        if not is_type(e.domain):
            _walk(e.domain, bound, constants, out)  # type: ignore[arg-type]
        _walk(e.body, bound | frozenset(e.names), constants, out)
        return
    for c in children(e):
        _walk(c, bound, constants, out)


def solved_thresholds(node: CheckedNode, constants: Mapping[str, tuple[Type, ast.Expr]],
                      formulas: Iterable[ast.Expr] = ()) -> list[Fraction]:
    """Every threshold ``node``'s assumptions and guarantees (and ``formulas``, e.g. the plan's
    facts) put on an input or a quantified variable (module docstring), exact, sorted, each once.
    ``node`` is read as given: hand in the node read at its fields' widths for the thresholds the
    monitors judge at (:func:`rclverify.backends.monitors.widths.at_carried_widths`).  Never raises."""
    out: set[Fraction] = set()
    for clause in (*node.node.assumes, *node.node.guarantees):
        _walk(clause.formula, frozenset(), constants, out)
    for f in formulas:
        _walk(f, frozenset(), constants, out)
    return sorted(out)


def drawn_thresholds(node: CheckedNode, solved: Iterable[Fraction], bounds: Mapping[str, Bound],
                     widths: Mapping[str, str]) -> list[Fraction]:
    """The values a REAL input draws in the thresholds' own choice
    (:attr:`.strategies.InputSpace.thresholds`), sorted: each of the ``solved`` thresholds
    (:func:`solved_thresholds`) that is no end of an input's ``bounds`` (input name -> its
    :class:`~.bounds.Bound`; those ends are drawn as edges already), at the floating width of every
    input field that has one (``widths``: ``"in.x"`` -> ``float32``/``float64``; the value of that
    width nearest the threshold and its two neighbours, :func:`~rclverify.semantics.widths.edges_at_width`),
    and at ``float64`` when a REAL input (or a sequence of REAL) has no field width (a Python float)."""
    ends = {x for bd in bounds.values() for x in (bd.lo, bd.hi) if x is not None}
    at = {w for k, w in widths.items() if k.startswith("in.") and w in FLOAT_WIDTHS}
    if any(f"in.{n}" not in widths for n, t in node.inputs.items()
           if t == REAL or (isinstance(t, SeqT) and t.elem == REAL)):
        at.add("float64")
    kept = [t for t in solved if t not in ends]
    return sorted({e for w in sorted(at) for e in edges_at_width(kept, w)})


__all__ = ["MAX_FORMS", "drawn_thresholds", "link_roots", "solved_thresholds"]
