"""Units of measure checked in declarations and formulas (docs/rcl-language.md, "Units of measure").

The type checker (:mod:`rclverify.lang.typecheck`) calls :class:`UnitChecker`
after a node's types are known: :meth:`UnitChecker.declare` reads the unit of
each declaration, :meth:`UnitChecker.clause` checks one clause.  Every
violation is reported through ``err(loc, message, code)``; nothing raises.

A term has a *quantity kind* (:class:`Q`):

* ``unit``: its unit is known (a variable or constant that declares one, a
  number written with one, ``1000 [mm/m]``, and what ``+ - * /`` make of
  them);
* ``number``: a bare number, or a term made of bare numbers only.  In a sum
  or comparison it takes the unit of the other side (``in.d <= 30``); in a
  product it is a pure number (``2 * in.d`` has the unit of ``in.d``);
* ``unknown``: a variable or constant without a declared unit, a bound
  variable, a function's result.  Nothing is checked against it: a contract
  without units keeps its meaning, and a partly annotated one is checked
  where both sides are known.

The rules (each adds a located error; "same unit" is same dimension, same
scale and same offset, :class:`~rclverify.lang.units.Unit`):

* ``a + b``, ``a - b``, ``a < b`` (every comparison), the items of a set or
  sequence literal and ``e in {...}``: two known units must be the same.
  Different dimensions: ``E-unit-dimension``; one dimension at two scales:
  ``E-unit-scale``, naming the factor (``[mm]`` against ``[m]``: 1000) and
  the conversion to write, since RCL never converts implicitly; ``degC``
  against ``K``: ``E-unit-offset``.
* ``a * b``, ``a / b``: units multiply and divide; an affine unit
  (``degC``) there is ``E-unit-affine``.
* A unit on a declaration whose type is not a number: ``E-unit-type``; a
  unit text that cannot be read: ``E-unit-syntax``/``E-unit-unknown``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Callable, Mapping, cast

from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.types import CheckedNode, Scalar, Type, is_numeric
from rclverify.lang.units import BASE_DIMENSIONS, ONE, Unit, UnitError, best_name, describe, dimension_name, factor_text, parse_unit
from rclverify.lang.printer import level, is_type
from rclverify.lang.units import ratio

Report = Callable[[ast.Loc, str, str], None]


@dataclass(frozen=True)
class Q:
    """The quantity kind of a term: ``kind`` is ``"unit"`` (``unit`` set),
    ``"number"`` or ``"unknown"``; ``expr`` is the term (for messages)."""

    kind: str
    unit: Unit | None = None
    expr: ast.Expr | None = None


NUMBER = Q("number")
UNKNOWN = Q("unknown")

#: Longest term text quoted in a message.
_SHOWN = 60


def _show(e: ast.Expr | None) -> str:
    if e is None:
        return "this term"
    text = expr_to_rcl(e)
    return text if len(text) <= _SHOWN else text[:_SHOWN - 3] + "..."


def unit_loc(ann: ast.UnitAnn, offset: int) -> ast.Loc:
    """The location of character ``offset`` of a unit's text (after its ``[``).
    The text is kept without blanks, so the column is exact for units
    written without blanks and points into the brackets otherwise."""
    loc = ann.loc
    return ast.Loc(loc.file, loc.line, loc.col + 1 + offset, loc.end_line, loc.end_col)


def read_unit(ann: ast.UnitAnn, t: Type | None, what: str, err: Report) -> Unit | None:
    """The unit ``ann`` denotes for a declaration ``what`` (``"input d of
    Lidar"``) of type ``t`` (``None``: not known, e.g. a failed type), or
    ``None`` after reporting why it cannot have one."""
    if t is not None and not (isinstance(t, Scalar) and is_numeric(t)):
        err(ann.loc, f"{what} has type {t}; only a number (REAL, INTEGER, NATURAL) can have a unit of measure",
            "E-unit-type")
        return None
    try:
        return parse_unit(ann.text)
    except UnitError as exc:
        code = "E-unit-unknown" if exc.message.startswith("unknown unit") else "E-unit-syntax"
        err(unit_loc(ann, exc.offset), exc.message, code)
        return None


def _angle_hint(a: Unit, b: Unit) -> str:
    """When ``a`` and ``b`` differ only in their power of angle: the text
    saying so and how to write it, else "".  Angle is a base dimension in
    RCL (docs/rcl-language.md, "Units of measure"), so an arc length is a
    radius in ``[m/rad]`` times an angle in ``[rad]``."""
    angle = BASE_DIMENSIONS.index("angle")
    if any(x != y for k, (x, y) in enumerate(zip(a.dims, b.dims)) if k != angle):
        return ""
    d = b.dims[angle] - a.dims[angle]
    more = "the second side" if d > 0 else "the first side"
    power = "rad" if abs(d) == 1 else f"rad^{abs(d)}"
    per = "1 [1/rad]" if abs(d) == 1 else f"1 [rad^-{abs(d)}]"
    return (f"; they differ only by angle ({more} has {power} more): angle is a base dimension in RCL, "
            f"not dimensionless, so a radius that turns an angle into a length is in [m/rad] (length per "
            f"radian turned); declare that quantity per radian, or, in a formula, multiply {more} by {per} "
            f"to say that the radian is meant")


def mismatch(a: Unit, b: Unit) -> tuple[str, str] | None:
    """``(code, reason)`` when the units ``a`` and ``b`` may not meet in a
    sum or comparison (see the module docstring), else ``None``."""
    if a == b:
        return None
    if a.dims != b.dims:
        return "E-unit-dimension", (f"different dimensions ({dimension_name(a.dims)} against "
                                    f"{dimension_name(b.dims)}){_angle_hint(a, b)}")
    if a.offset is not None or b.offset is not None:
        return "E-unit-offset", factor_text(a, b)
    return "E-unit-scale", f"one dimension ({dimension_name(a.dims)}) at two scales, {factor_text(a, b)}"


class UnitChecker:
    """Checks the units of one system's declarations and formulas.

    ``err(loc, message, code)`` records a diagnostic; ``constants`` maps a
    context constant's name to its unit (filled by :meth:`constant`)."""

    def __init__(self, err: Report) -> None:
        self.err = err
        self.constants: dict[str, Unit] = {}

    # -- declarations ---------------------------------------------------------------
    def declare(self, n: ast.Node, types: Mapping[str, Type]) -> dict[str, Unit]:
        """The units of ``n``'s inputs and outputs that declare one, keyed
        ``"in.x"``/``"out.y"``; ``types`` maps the same keys to the resolved
        types (a declaration whose type failed is absent)."""
        out: dict[str, Unit] = {}
        for group, prefix, word in ((n.inputs, "in", "input"), (n.outputs, "out", "output")):
            for v in group:
                key = f"{prefix}.{v.name}"
                if v.unit is None or key not in types:
                    continue
                u = read_unit(v.unit, types[key], f"{word} {v.name} of {n.name}", self.err)
                if u is not None:
                    out[key] = u
        return out

    def constant(self, d: ast.ConstDecl, t: Type | None) -> None:
        """Record the unit of context constant ``d`` (type ``t``): the
        declared one, checked against its value's, or its value's."""
        value = self.term(d.value, None, frozenset())
        if d.unit is not None:
            u = read_unit(d.unit, t, f"constant {d.name}", self.err)
            if u is None:
                return
            self.same(Q("unit", u, ast.Var(d.name)), value, d.value.loc, f"the value of constant {d.name}")
            self.constants[d.name] = u
        elif value.kind == "unit" and value.unit is not None:
            self.constants[d.name] = value.unit

    # -- formulas -----------------------------------------------------------------------
    def clause(self, e: ast.Expr, node: CheckedNode) -> None:
        """Check the units of one (well-typed) clause of ``node``."""
        self.term(e, node, frozenset())

    def same(self, a: Q, b: Q, loc: ast.Loc, where: str) -> Q:
        """``a`` and ``b`` meet in ``where`` (an operator or place, for the
        message): report a mismatch of two known units at ``loc``; return
        the kind of the result (the known one wins; unknown after a
        mismatch, so one mistake gives one message)."""
        if a.kind == "unit" and b.kind == "unit":
            assert a.unit is not None and b.unit is not None
            bad = mismatch(a.unit, b.unit)
            if bad is not None:
                code, reason = bad
                hint = ""
                if code == "E-unit-scale":
                    hint = f"; RCL does not convert units: {_conversion(a, b)}"
                self.err(loc, f"unit mismatch in {where}: {_show(a.expr)} is {describe(a.unit)} but "
                              f"{_show(b.expr)} is {describe(b.unit)}: {reason}{hint}", code)
                return UNKNOWN  # reported once: what contains it is not checked again
            return a
        if a.kind == "unit":
            return a
        if b.kind == "unit":
            return b
        return a if a.kind == "unknown" else b

    def term(self, e: ast.Expr, node: CheckedNode | None, bound: frozenset[str]) -> Q:
        """The quantity kind of ``e`` (see :class:`Q`), reporting the unit
        errors inside it."""
        if isinstance(e, ast.NumLit):
            if e.unit is None:
                return Q("number", None, e)
            u = read_unit(e.unit, None, "a number", self.err)
            return Q("unit", u, e) if u is not None else UNKNOWN
        if isinstance(e, ast.Var):
            return self.var(e, node, bound)
        if isinstance(e, ast.Unary):
            q = self.term(e.operand, node, bound)
            if e.op == "-" or e.op == "abs":
                return Q(q.kind, q.unit, e)
            if e.op == "not":
                return UNKNOWN
            if e.op == "sqrt" or e.op == "sin" or e.op == "cos":
                return self.math(e, q)
            ast.unhandled(e.op)
        if isinstance(e, ast.Binary):
            a, b = self.term(e.left, node, bound), self.term(e.right, node, bound)
            if e.op in ("+", "-"):
                r = self.same(a, b, e.right.loc, f"'{e.op}'")
                return Q(r.kind, r.unit, e)
            if e.op in ("*", "/"):
                return self.product(e, a, b)
            return UNKNOWN
        if isinstance(e, ast.Compare):
            qs = [self.term(o, node, bound) for o in e.operands]
            for op, a, (right, bq) in zip(e.ops, qs, zip(e.operands[1:], qs[1:])):
                self.same(a, bq, right.loc, f"'{op}'")
            return UNKNOWN
        if isinstance(e, ast.Member):
            q = self.term(e.elem, node, bound)
            c = self.term(e.collection, node, bound)
            if isinstance(e.collection, (ast.SetLit, ast.SeqLit)):
                self.same(q, c, e.collection.loc, "'!in'" if e.negated else "'in'")
            return UNKNOWN
        if isinstance(e, (ast.SetLit, ast.SeqLit)):
            acc: Q = NUMBER if e.items else UNKNOWN
            for it in e.items:
                acc = self.same(acc, self.term(it, node, bound), it.loc, "a collection's items")
            return Q(acc.kind, acc.unit, e) if acc.kind != "number" else acc
        if isinstance(e, ast.Apply):
            for arg in e.args:
                self.term(arg, node, bound)
            return UNKNOWN
        if isinstance(e, ast.TupleLit):
            for it in e.items:
                self.term(it, node, bound)
            return UNKNOWN
        if isinstance(e, ast.SeqRange):
            self.term(e.lo, node, bound)
            self.term(e.hi, node, bound)
            return UNKNOWN
        if isinstance(e, ast.Quant):
            inner = set(bound)
            for binding in e.bindings:
                if not _is_type(binding.domain):
                    self.term(cast(ast.Expr, binding.domain), node, bound)
                inner.update(binding.names)
            self.term(e.body, node, frozenset(inner))
            return UNKNOWN
        if isinstance(e, ast.TupleQuant):
            if not _is_type(e.domain):
                self.term(cast(ast.Expr, e.domain), node, bound)
            self.term(e.body, node, bound | frozenset(e.names))
            return UNKNOWN
        return UNKNOWN

    def var(self, v: ast.Var, node: CheckedNode | None, bound: frozenset[str]) -> Q:
        if v.prefix is None and v.name in bound:
            return UNKNOWN
        if node is not None:
            if v.prefix is not None:
                u = node.unit_of(v.prefix, v.name)
                return Q("unit", u, v) if u is not None else UNKNOWN
            if v.name in node.inputs or v.name in node.outputs:
                u = node.unit_of("in" if v.name in node.inputs else "out", v.name)
                return Q("unit", u, v) if u is not None else UNKNOWN
        if v.prefix is None and v.name in self.constants:
            return Q("unit", self.constants[v.name], v)
        return UNKNOWN

    def math(self, e: ast.Unary, q: Q) -> Q:
        """``sqrt``: each dimension's exponent halved (an odd exponent, a scale
        that is no rational square or an affine unit is ``E-unit-dimension``);
        ``sin``/``cos``: a dimensionless or ``[rad]`` argument (another angle
        unit ``E-unit-scale`` with the factor, any other dimension
        ``E-unit-dimension``), a dimensionless value."""
        u = q.unit if q.kind == "unit" else None
        if e.op == "sqrt":
            if q.kind == "number":
                return Q("number", None, e)
            if u is None:
                return UNKNOWN
            root = _square_root(u)
            if root is None:
                self.err(e.operand.loc, f"sqrt of {_show(e.operand)} in {describe(u)}: the unit has no square root "
                                        f"(an odd exponent, an affine scale or a scale that is no rational square)",
                         "E-unit-dimension")
                return UNKNOWN
            name = best_name(root)
            return Q("unit", Unit(root.dims, root.factor, root.pi, None, name or f"sqrt({u.text})"), e)
        if u is not None and u.dims != ONE.dims:
            rad = parse_unit("rad")
            if u.dims == rad.dims:
                if u != rad:
                    self.err(e.operand.loc, f"{e.op} takes radians; {_show(e.operand)} is {describe(u)}: "
                                            f"{factor_text(u, rad)}; convert it to [rad]", "E-unit-scale")
            else:
                self.err(e.operand.loc, f"{e.op} takes a dimensionless or [rad] argument; {_show(e.operand)} is "
                                        f"{describe(u)}", "E-unit-dimension")
        return Q("number", None, e)

    def product(self, e: ast.Binary, a: Q, b: Q) -> Q:
        for side, q in ((e.left, a), (e.right, b)):
            if q.kind == "unit" and q.unit is not None and q.unit.offset is not None:
                self.err(side.loc, f"{_show(side)} is {describe(q.unit)}, an affine scale (0 degC = 273.15 K): it "
                                   f"cannot be multiplied or divided; declare the temperature in [K]",
                         "E-unit-affine")
                return UNKNOWN
        if a.kind == "unknown" or b.kind == "unknown":
            return UNKNOWN
        if a.kind == "number" and b.kind == "number":
            return Q("number", None, e)
        ua = a.unit if a.kind == "unit" else None
        ub = b.unit if b.kind == "unit" else None
        if e.op == "*":
            u = ua.times(ub, f"{_wrap(ua.text)}*{_wrap(ub.text)}") if ua is not None and ub is not None else (ua or ub)
        elif ua is not None and ub is not None:
            u = ua.over(ub, f"{_wrap(ua.text)}/{_wrap(ub.text)}")
        else:
            u = ua if ua is not None else ub.power(-1, f"1/{_wrap(ub.text)}")  # type: ignore[union-attr]
        assert u is not None
        name = best_name(u)  # [mm/m]*[m] is shown as [mm]
        return Q("unit", Unit(u.dims, u.factor, u.pi, u.offset, name) if name else u, e)


def _square_root(u: Unit) -> Unit | None:
    """The unit whose square is ``u``, or ``None`` (an odd exponent, an odd
    power of pi, an affine unit or a factor that is no rational square)."""
    if u.offset is not None or u.pi % 2 or any(d % 2 for d in u.dims):
        return None
    n, d = math.isqrt(u.factor.numerator), math.isqrt(u.factor.denominator)
    if n * n != u.factor.numerator or d * d != u.factor.denominator:
        return None
    return Unit(tuple(k // 2 for k in u.dims), Fraction(n, d), u.pi // 2, None)


def _conversion(a: Q, b: Q) -> str:
    """How to write the comparison with the units right: a bare number of
    one side that is the factor becomes the factor with its unit
    (``out.d == 1000 * in.r`` -> ``1000 [mm/m] * in.r``); otherwise the
    factor with its unit multiplies the other side (``1000 [mm/m] * in.r``)."""
    assert a.unit is not None and b.unit is not None
    for x, y in ((b, a), (a, b)):
        e = x.expr
        if isinstance(e, ast.Binary) and e.op == "*":
            assert x.unit is not None and y.unit is not None
            f, pi = ratio(x.unit, y.unit)
            for lit in (e.left, e.right):
                if isinstance(lit, ast.NumLit) and lit.unit is None and not pi and lit.value == f:
                    fixed = ast.NumLit(lit.text, lit.loc, ast.UnitAnn(f"{_wrap(y.unit.text)}/{_wrap(x.unit.text)}"))
                    new = ast.Binary("*", fixed, e.right) if lit is e.left else ast.Binary("*", e.left, fixed)
                    return f"write the factor with its unit, {_show(new)}"
    for x, y in ((b, a), (a, b)):
        if isinstance(x.expr, ast.NumLit) and x.expr.unit is not None:
            assert x.unit is not None and y.unit is not None
            f, pi = ratio(x.unit, y.unit)
            if not pi:
                value = x.expr.value * f
                num = str(value.numerator) if value.denominator == 1 else _decimal(value)
                return f"write {num} [{y.unit.text}] for {_show(x.expr)}"
    f, pi = ratio(b.unit, a.unit)
    if pi:
        return "the factor involves pi and has no exact decimal: declare both in one unit"
    num = str(f.numerator) if f.denominator == 1 else _decimal(f)
    shown = _show(b.expr)
    if b.expr is not None and level(b.expr) < 8:
        shown = f"({shown})"
    return f"multiply by the factor with its unit, {num} [{_wrap(a.unit.text)}/{_wrap(b.unit.text)}] * {shown}"


def _wrap(text: str) -> str:
    return f"({text})" if any(c in text for c in "*/") else (text or "?")


def _decimal(f: Fraction) -> str:
    """An exact decimal text of ``f`` when it has one (denominator 2^a 5^b), else a fraction."""
    d, k = f.denominator, 0
    while d % 2 == 0 or d % 5 == 0:
        d //= 2 if d % 2 == 0 else 5
        k += 1
    if d != 1:
        return f"{f.numerator}/{f.denominator}"
    text = f"{f.numerator * 10**k // f.denominator:0{k + 1}d}"
    return (text[:-k] + "." + text[-k:]).rstrip("0").rstrip(".") if k else text


def _is_type(d: object) -> bool:
    return is_type(d)
