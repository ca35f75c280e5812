"""The well-definedness conditions of an RCL formula, generated from the semantics table.

A formula that applies a partial operator outside its domain (RCL's
partial operators are ``/``, a zero divisor, and ``sqrt``, a negative
argument) has no truth value: the
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
  :data:`~rclverify.semantics.operators.OPERATORS` and
  :data:`~rclverify.semantics.operators.UNARY`) gives one condition:
  the restricted operand differs from the excluded value (``d != 0``), or
  for ``sqrt`` is at least 0 (``in.a >= 0``);
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

A named constant of a context (``K = 10 / Zero ;``) is read by the same
rule: its defining expression's conditions are closed formulas over the
context's constants, decided by the reference evaluator when the contracts
are checked (:func:`constant_faults`); one that is false (``Zero != 0``
with ``Zero = 0``) is an error at the constant's definition, as the same
division written inside a clause is a problem of that clause
(docs/rcl-language.md, "Constants").
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Union, cast

from rclverify.lang import ast
from rclverify.lang.errors import Diagnostic, error
from rclverify.lang.printer import expr_to_rcl, is_type
from rclverify.lang.types import Checked, CheckedNode
from rclverify.lang.walk import children, subexpressions
from rclverify.semantics.evaluator import Evaluator
from rclverify.semantics.operators import OPERATORS, UNARY, Operator, Undecided
from rclverify.semantics.values import render

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
        entry = UNARY[self.op] if self.op in UNARY and self.op not in OPERATORS else OPERATORS[self.op]
        return f"the {entry.name} at {self.where} needs {self.text}"


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
    if isinstance(e, ast.Unary):
        _walk(e.operand, frames, out)
        p = UNARY[e.op].partial
        if p is not None:
            cmp = cast(ast.CompareOp, p.relation)
            requires = ast.Compare((cmp,), (e.operand, ast.NumLit(str(p.excluded), e.loc)), e.loc)
            out.append(Condition(e.op, p.failure, e.loc, requires, _close(requires, frames)))
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


#: the node a context's constants are evaluated in: no inputs, no outputs, no clauses
_CONTEXT = CheckedNode(ast.Node("<context>", (), (), (), (), ()), {}, {})


def constant_faults(checked: Checked) -> list[Diagnostic]:
    """The context constants of ``checked`` (every file's ``context { ... }``)
    whose definition is undefined: one located error per constant, at its
    definition (``file:line:col`` of its name), naming the first condition of
    its defining expression (:func:`conditions`) that the reference evaluator
    (:class:`~rclverify.semantics.evaluator.Evaluator`, exact arithmetic)
    finds false, e.g. ``constant K is undefined: the division at
    c.rcl:2:28 needs Zero != 0, which is false (Zero = 0)``.  A condition the
    evaluator cannot decide (it reads a constant that is itself undefined,
    reported at that constant) adds nothing.  Source of the rule: the
    module docstring (Dafny's well-formedness of a definition's body).
    Returns ``[]`` when every constant is defined; never raises."""
    out: list[Diagnostic] = []
    ev = Evaluator(checked, _CONTEXT, {})
    for spec in checked.specs:
        for ctx in spec.contexts:
            for d in ctx.decls:
                if not isinstance(d, ast.ConstDecl) or checked.env.constants.get(d.name, (None, None))[1] is not d.value:
                    continue
                for cond in conditions(d.value):
                    try:
                        holds = ev.eval(cond.formula, {})
                    except (Undecided, TypeError, ValueError, ZeroDivisionError):
                        continue  # not decided here: an undefined constant it reads is reported at its own definition
                    if holds is False:
                        out.append(error(d.loc, f"constant {d.name} is undefined: {cond.describe()}, which is false"
                                         f"{_values_of(cond.requires, checked, ev)}", "E-undefined-constant"))
                        break
    return out


def _values_of(e: ast.Expr, checked: Checked, ev: Evaluator) -> str:
    """`` (Zero = 0)``: the values of the named constants ``e`` reads, "" when it reads none."""
    shown: dict[str, str] = {}
    for x in subexpressions(e):
        if isinstance(x, ast.Var) and x.prefix is None and x.name in checked.env.constants and x.name not in shown:
            try:
                shown[x.name] = render(ev.eval(x, {}))
            except (Undecided, TypeError, ValueError, ZeroDivisionError):
                continue
    return f" ({', '.join(f'{k} = {v}' for k, v in shown.items())})" if shown else ""


__all__ = ["Condition", "conditions", "conjoin", "constant_faults", "defined", "guarded", "right_guard"]
