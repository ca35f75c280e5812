"""The well-definedness conditions of an RCL formula, generated from the semantics table.

A formula that applies a partial operator outside its domain (RCL's one
partial operator is ``/``: a zero divisor) has no truth value: the
reference evaluator raises :class:`~rclverify.semantics.operators.Undecided`,
the property tests and monitors cannot decide it, and a proof must not
discharge it.  Z3 reads ``x / 0`` as an unspecified total function, so a
proof path that only asked Z3 for the formula would prove ``r == n / d``
with ``d = 0``.  Every proof path therefore proves the formula's
well-definedness conditions too, generated here once, as Why3, Dafny and
SPARK generate theirs (Dafny's reference manual, "Well-formedness of
specifications"; Why3's ``div`` precondition; SPARK's division check,
"Run-time checks" of the SPARK user's guide):

* every application of a partial operator (:attr:`Operator.partial` in
  :data:`~rclverify.semantics.operators.OPERATORS`) gives one condition:
  the restricted operand differs from the excluded value (``d != 0``);
* a condition holds under the guards that precede it: the connectives are
  read left to right with their short circuit
  (:attr:`Operator.decisive`): in ``a and b`` and ``a -> b`` the right
  operand's conditions are needed only where ``a`` holds, in ``a or b``
  only where it does not; ``<=>`` evaluates both (no guard);
* inside a quantifier (``forall``, ``exists``, ``exists_unique``) the
  body's conditions hold for every value of its variables (Dafny's rule:
  the body must be well-formed for all bound values); a quantifier's
  domain and every other subterm (comparison chains, memberships, function
  arguments, ranges) are read unconditionally.

The conditions are RCL formulas themselves (``forall (k in NATURAL | k > 2
-> in.d != 0)``), so every path encodes and evaluates them as it does any
formula, with the same symbols.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Union

from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl, is_type
from rclverify.lang.walk import children
from rclverify.semantics.operators import OPERATORS, Operator

#: what a condition is read under: a guard formula, or a quantifier whose variables it holds for
Frame = Union[ast.Expr, ast.Quant, ast.TupleQuant]


@dataclass(frozen=True)
class Condition:
    """One well-definedness condition of a formula.

    ``op`` the partial operator's symbol; ``failure`` what violating it is
    called (``"division by zero"``); ``loc`` where the application is
    written (its ``file:line:col``); ``requires`` the condition on its
    operand as written there (``in.d != 0``); ``formula`` the condition
    closed under its guards and quantifiers, a formula over the
    formula's free names that must hold."""

    op: str
    failure: str
    loc: ast.Loc
    requires: ast.Expr
    formula: ast.Expr

    @property
    def text(self) -> str:
        """The condition on the operand as RCL text (``in.d != 0``)."""
        return expr_to_rcl(self.requires)

    @property
    def where(self) -> str:
        """``file:line:col`` of the partial operator's application."""
        return f"{self.loc.file}:{self.loc.line}:{self.loc.col}"

    def describe(self) -> str:
        """One phrase for messages: ``the division at f.rcl:3:9 needs in.d != 0``."""
        return f"the {OPERATORS[self.op].name} at {self.where} needs {self.text}"


def right_guard(entry: Operator, left: ast.Expr) -> ast.Expr | None:
    """The guard under which a connective evaluates its right operand, from
    its short circuit in the semantics table: ``left`` when a false left
    operand decides it (``and``, ``->``), ``not left`` when a true one does
    (``or``), ``None`` when both are always evaluated (``<=>``)."""
    if entry.decisive is None:
        return None
    return left if entry.decisive is False else ast.Unary("not", left, left.loc)


def _close(requires: ast.Expr, frames: tuple[Frame, ...]) -> ast.Expr:
    f = requires
    for fr in reversed(frames):
        if isinstance(fr, ast.Quant):
            f = ast.Quant("forall", fr.bindings, f, fr.loc)
        elif isinstance(fr, ast.TupleQuant):
            f = ast.TupleQuant("forall", fr.names, fr.domain, f, fr.loc, fr.name_locs)
        else:
            f = ast.Binary("->", fr, f, fr.loc)
    return f


def _walk(e: ast.Expr, frames: tuple[Frame, ...], out: list[Condition]) -> None:
    if isinstance(e, ast.Binary):
        entry = OPERATORS[e.op]
        _walk(e.left, frames, out)
        if entry.kind == "connective":
            g = right_guard(entry, e.left)
            _walk(e.right, frames if g is None else (*frames, g), out)
            return
        _walk(e.right, frames, out)
        p = entry.partial
        if p is not None:
            operand = (e.left, e.right)[p.operand]
            requires = ast.Compare(("!=",), (operand, ast.NumLit(str(p.excluded), e.loc)), e.loc)
            out.append(Condition(e.op, p.failure, e.loc, requires, _close(requires, frames)))
        return
    if isinstance(e, ast.Quant):
        for b in e.bindings:
            if not is_type(b.domain):
                _walk(b.domain, frames, out)  # type: ignore[arg-type]
        _walk(e.body, (*frames, e), out)
        return
    if isinstance(e, ast.TupleQuant):
        if not is_type(e.domain):
            _walk(e.domain, frames, out)  # type: ignore[arg-type]
        _walk(e.body, (*frames, e), out)
        return
    for c in children(e):
        _walk(c, frames, out)


def conditions(e: ast.Expr) -> tuple[Condition, ...]:
    """The well-definedness conditions of formula or term ``e``, one per
    application of a partial operator, left to right (module docstring).
    Empty when ``e`` applies none.  Pure; never raises."""
    out: list[Condition] = []
    _walk(e, (), out)
    return tuple(out)


def conjoin(parts: list[ast.Expr], loc: ast.Loc) -> ast.Expr:
    """``parts`` joined by ``and`` (``TRUE`` when empty)."""
    if not parts:
        return ast.BoolLit(True, loc)
    f = parts[0]
    for p in parts[1:]:
        f = ast.Binary("and", f, p, loc)
    return f


def defined(e: ast.Expr) -> ast.Expr:
    """The formula ``e`` is defined where: the conjunction of its
    conditions' formulas (``TRUE`` for a formula of total operators)."""
    return conjoin([c.formula for c in conditions(e)], e.loc)


def guarded(e: ast.Expr) -> ast.Expr:
    """``defined(e) and e`` (``e`` itself when it applies no partial
    operator): the formula a proof path proves for ``e``, true exactly where
    ``e`` is defined and holds."""
    conds = conditions(e)
    if not conds:
        return e
    return ast.Binary("and", conjoin([c.formula for c in conds], e.loc), e, e.loc)


__all__ = ["Condition", "conditions", "conjoin", "defined", "guarded", "right_guard"]
