"""The acceptance criterion: an RCL expression over an experiment's figures.

The criterion is parsed with the RCL parser (:func:`rclverify.lang.parser.parse_formula`),
so its syntax and locations are those of any RCL formula in the plan.  Names
it may use: the statistics ``count``, ``mean``, ``std``, ``best``,
``worst``; the plan entry's ``constants`` (``tolerance: 25 cm``); and, for
per-trial data, the measured column, which makes the criterion a statement
about every trial.  Allowed: numbers, ``+ - * /``, comparisons, ``and``,
``or``, ``not``, ``->``, ``<=>``.  Units are checked (only equal dimensions
are added or compared).

Evaluation is exact: every figure is a rational, the criterion becomes a Z3
formula (each operator's Z3 reading from the semantics table, :func:`rclverify.semantics.sorts.apply_operator`
and :func:`rclverify.semantics.translate.unary_z3`), and Z3 decides it; a per-trial standard deviation (irrational in
general) is the non-negative root of its exact variance.
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Mapping

import z3

from rclverify.semantics.connectives import conj
from rclverify.semantics.query import budgeted_solver
from rclverify.semantics.sorts import apply_operator
from rclverify.semantics.translate import unary_z3
from rclverify.lang import ast
from rclverify.backends.experiment.figures import Figures, Quantity

ARITH = {"+", "-", "*", "/"}
LOGIC = {"and", "or", "->", "<=>"}


class CriterionError(ValueError):
    """A criterion mistake at ``loc`` (relative to the plan file)."""

    def __init__(self, loc: ast.Loc, message: str) -> None:
        super().__init__(message)
        self.loc = loc
        self.message = message


def names_of(expr: ast.Expr) -> set[str]:
    """The plain names ``expr`` mentions."""
    out: set[str] = set()

    def walk(e: object) -> None:
        if isinstance(e, ast.Var):
            out.add(e.qualified)
        elif isinstance(e, ast.Binary):
            walk(e.left)
            walk(e.right)
        elif isinstance(e, ast.Unary):
            walk(e.operand)
        elif isinstance(e, ast.Compare):
            for o in e.operands:
                walk(o)
    walk(expr)
    return out


def dimension(expr: ast.Expr, dims: Mapping[str, str]) -> str:
    """Check ``expr`` and return its dimension (``"bool"`` for a formula).

    ``dims`` maps each allowed name to its dimension.  Raises
    :class:`CriterionError` at the offending sub-expression.
    """
    def d(e: ast.Expr) -> str:
        if isinstance(e, ast.NumLit):
            return "1"
        if isinstance(e, ast.BoolLit):
            return "bool"
        if isinstance(e, ast.Var):
            if e.prefix is not None or e.name not in dims:
                raise CriterionError(e.loc, f"unknown name {e.qualified!r} in the criterion; it may use: "
                                     f"{', '.join(sorted(dims))}")
            return dims[e.name]
        if isinstance(e, ast.Unary):
            inner = d(e.operand)
            if e.op == "not":
                want = "bool"
            elif e.op == "-" or e.op == "abs":
                want = inner
            elif e.op == "sqrt" or e.op == "sin" or e.op == "cos":
                raise CriterionError(e.loc, f"{e.op} is not part of an experiment criterion (a comparison of "
                                            f"measured quantities with + - * / and abs)")
            else:
                ast.unhandled(e.op)
            if (e.op == "not") != (inner == "bool"):
                raise CriterionError(e.loc, f"'{e.op}' applied to a {'number' if inner != 'bool' else 'formula'}")
            return want
        if isinstance(e, ast.Binary):
            l, r = d(e.left), d(e.right)
            if e.op in LOGIC:
                if l != "bool" or r != "bool":
                    raise CriterionError(e.loc, f"'{e.op}' needs formulas on both sides")
                return "bool"
            if "bool" in (l, r):
                raise CriterionError(e.loc, f"'{e.op}' needs numbers on both sides")
            if e.op in ("+", "-"):
                if l != r:
                    raise CriterionError(e.loc, f"'{e.op}' of a {l} and a {r} quantity: units differ")
                return l
            if e.op == "*":
                if "1" not in (l, r):
                    raise CriterionError(e.loc, f"product of two {l}/{r} quantities is not supported")
                return r if l == "1" else l
            if r == l:
                return "1"
            if r == "1":
                return l
            raise CriterionError(e.loc, f"quotient of a {l} by a {r} quantity is not supported")
        if isinstance(e, ast.Compare):
            ds = [d(o) for o in e.operands]
            if "bool" in ds or len(set(ds)) != 1:
                raise CriterionError(e.loc, "a comparison needs quantities of one dimension on every side (found "
                                     + ", ".join("formula" if x == "bool" else ("number" if x == "1" else x) for x in ds)
                                     + "); give a bound as a constant with its unit, e.g. tolerance: 25 cm")
            return "bool"
        raise CriterionError(getattr(e, "loc", ast.Loc()), "only numbers, figure names, + - * /, comparisons and "
                             "and/or/not/->/<=> may appear in a criterion")
    out = d(expr)
    if out != "bool":
        raise CriterionError(expr.loc, "the criterion must be a formula (a comparison), not a quantity")
    return out


def allowed_dims(figures: Figures, constants: Mapping[str, Quantity]) -> dict[str, str]:
    """Name -> dimension of everything a criterion over ``figures`` may name."""
    dims = {k: q.dim for k, q in figures.stats.items()}
    dims.update({k: q.dim for k, q in constants.items()})
    if figures.column:
        dims[figures.column] = figures.dim
    return dims


@dataclass(frozen=True)
class Verdict:
    """Outcome of a criterion: ``holds`` True/False/None (undecided);
    ``failing`` the 1-based trials it fails on (per-trial criteria)."""

    holds: bool | None
    failing: tuple[int, ...] = ()
    per_trial: bool = False


def _to_z3(e: ast.Expr, env: Mapping[str, z3.ArithRef]) -> z3.ExprRef:
    if isinstance(e, ast.NumLit):
        v = e.value
        return z3.RealVal(f"{v.numerator}/{v.denominator}")
    if isinstance(e, ast.BoolLit):
        return z3.BoolVal(e.value)
    if isinstance(e, ast.Var):
        return env[e.name]
    if isinstance(e, ast.Unary):
        return unary_z3(e.op, _to_z3(e.operand, env))
    if isinstance(e, ast.Binary):
        return apply_operator(e.op, _to_z3(e.left, env), _to_z3(e.right, env))
    assert isinstance(e, ast.Compare)
    xs = [_to_z3(o, env) for o in e.operands]
    return conj(*[apply_operator(op, xs[i], xs[i + 1]) for i, op in enumerate(e.ops)])


def _val(v: Fraction) -> z3.ArithRef:
    return z3.RealVal(f"{v.numerator}/{v.denominator}")


def _decide(formula: z3.ExprRef, background: list[z3.ExprRef], timeout_ms: int) -> bool | None:
    s = budgeted_solver(timeout_ms)
    s.add(*background)
    s.push()
    s.add(z3.Not(formula))
    r = s.check()
    s.pop()
    if r == z3.unsat:
        return True
    if r != z3.sat:
        return None
    # the figures fix every value, so the criterion itself must then be
    # unsatisfiable; when it is not (a division by a zero figure leaves the
    # quotient unspecified) the answer is undecided, never "fails"
    s.add(formula)
    return False if s.check() == z3.unsat else None


def evaluate(expr: ast.Expr, figures: Figures, constants: Mapping[str, Quantity], timeout_ms: int = 10000) -> Verdict:
    """Decide the (dimension-checked) criterion on ``figures`` exactly with Z3.

    A criterion naming the per-trial column must hold on every trial.
    A division by a figure that is zero leaves the quotient unspecified
    (Z3's semantics): the verdict is then undecided (``holds`` ``None``).
    """
    env: dict[str, z3.ArithRef] = {k: _val(q.value) for k, q in figures.stats.items()}
    env.update({k: _val(q.value) for k, q in constants.items()})
    background: list[z3.ExprRef] = []
    if figures.variance is not None:
        std = z3.Real("std")
        env["std"] = std
        background += [std >= 0, std * std == _val(figures.variance)]
    if figures.column and figures.column in names_of(expr):
        failing: list[int] = []
        undecided = False
        for i, v in enumerate(figures.trials, 1):
            holds = _decide(_to_z3(expr, {**env, figures.column: _val(v)}), background, timeout_ms)
            undecided |= holds is None
            if holds is False:
                failing.append(i)
        return Verdict(False if failing else (None if undecided else True), tuple(failing), True)
    return Verdict(_decide(_to_z3(expr, env), background, timeout_ms))
