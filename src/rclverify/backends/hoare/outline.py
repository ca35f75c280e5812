"""Proof outlines: the program annotated with the assertion before each statement.

The paper presents its Hoare-logic proofs as annotated programs, one
assertion in braces between statements and the rule that justifies it
(shared/reference, lines 1514-1541 and appendix B, 1984-).  This module
renders the outline computed by :func:`rclverify.backends.hoare.wp.wp` the
same way, with assertions printed in the program language's syntax
(:func:`z3_text`), e.g.::

    { radiation_at(i) < 120 -> ... }   -- assignment axiom
    input := radiation_at(i)
    { (input < 120 -> green == green) and ... }   -- conditional rule
    if input < 120 then
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Callable, Mapping, Sequence

import z3

from rclverify.backends.hoare.wp import OutlineItem

_P_IMP, _P_OR, _P_AND, _P_NOT, _P_CMP, _P_SUM, _P_PROD, _P_NEG, _P_ATOM = range(1, 10)

_CMP = {z3.Z3_OP_LE: "<=", z3.Z3_OP_LT: "<", z3.Z3_OP_GE: ">=", z3.Z3_OP_GT: ">"}
_SORT_NAMES = {"Real": "REAL", "Int": "INTEGER", "Bool": "BOOL"}
_ARITH = {z3.Z3_OP_ADD: "+", z3.Z3_OP_SUB: "-", z3.Z3_OP_MUL: "*", z3.Z3_OP_DIV: "/", z3.Z3_OP_IDIV: "div"}


def _kind(t: z3.ExprRef) -> int:
    """Z3 declaration kind of an application (``-1`` for a variable or quantifier)."""
    ctx, a = t.ctx_ref(), t.as_ast()
    if z3.Z3_get_ast_kind(ctx, a) not in (z3.Z3_APP_AST, z3.Z3_NUMERAL_AST):
        return -1
    return int(z3.Z3_get_decl_kind(ctx, z3.Z3_get_app_decl(ctx, a)))


def number_text(v: z3.ExprRef) -> str:
    """Text of a Z3 numeral: ``15``, ``2.5`` or ``1/3``."""
    if z3.is_int_value(v):
        return str(v.as_long())
    fr = Fraction(v.numerator_as_long(), v.denominator_as_long())
    if fr.denominator == 1:
        return str(fr.numerator)
    dec = float(fr)
    return repr(dec) if Fraction(dec) == fr else f"{fr.numerator}/{fr.denominator}"


class _Printer:
    def __init__(self, names: Mapping[str, str]) -> None:
        self.names = names
        self.bound: list[str] = []  # innermost last
        # (Z3 ast id, context, bound names) -> (the term, kept alive so its id is not reused; its text).
        # The assertions of one outline share most of their subterms, and walking
        # a term through Z3's Python API is the costly part of rendering it.
        self.memo: dict[tuple[int, int, tuple[str, ...]], tuple[z3.ExprRef, str]] = {}

    def go(self, t: z3.ExprRef, context: int = 0) -> str:
        key = (t.get_id(), context, tuple(self.bound))
        hit = self.memo.get(key)
        if hit is None:
            hit = (t, self._go(t, context))
            self.memo[key] = hit
        return hit[1]

    def name(self, n: str) -> str:
        return self.names.get(n, n)

    def wrap(self, s: str, p: int, context: int) -> str:
        return f"({s})" if p < context else s

    def _go(self, t: z3.ExprRef, context: int = 0) -> str:
        # Z3's low-level API directly: the typed Python wrappers (is_true,
        # children(), ...) re-check every term's kind and sort many times and
        # were most of the time spent rendering outlines.  Same cases, same text.
        ctx, a = t.ctx_ref(), t.as_ast()
        ak = z3.Z3_get_ast_kind(ctx, a)
        if ak == z3.Z3_VAR_AST:
            idx = z3.Z3_get_index_value(ctx, a)
            return self.bound[-1 - idx] if idx < len(self.bound) else f"?{idx}"
        if ak == z3.Z3_QUANTIFIER_AST:
            return self.quantifier(z3.QuantifierRef(a, t.ctx), context)
        if ak != z3.Z3_APP_AST and ak != z3.Z3_NUMERAL_AST:
            return str(t)
        decl = z3.Z3_get_app_decl(ctx, a)
        k = z3.Z3_get_decl_kind(ctx, decl)
        if k == z3.Z3_OP_TRUE:
            return "TRUE"
        if k == z3.Z3_OP_FALSE:
            return "FALSE"
        if k == z3.Z3_OP_ANUM:
            sk = z3.Z3_get_sort_kind(ctx, z3.Z3_get_sort(ctx, a))
            num = z3.IntNumRef(a, t.ctx) if sk == z3.Z3_INT_SORT else z3.RatNumRef(a, t.ctx)
            s = number_text(num)
            return self.wrap(s, _P_PROD if "/" in s else _P_ATOM, context)
        ch = [z3.ExprRef(z3.Z3_get_app_arg(ctx, a, i), t.ctx) for i in range(z3.Z3_get_app_num_args(ctx, a))]
        if k == z3.Z3_OP_AND:
            return self.wrap(" and ".join(self.go(c, _P_AND + (1 if _kind(c) == z3.Z3_OP_AND else 0)) for c in ch),
                             _P_AND, context)
        if k == z3.Z3_OP_OR:
            return self.wrap(" or ".join(self.go(c, _P_OR + (1 if _kind(c) == z3.Z3_OP_OR else 0)) for c in ch),
                             _P_OR, context)
        if k == z3.Z3_OP_IMPLIES:
            return self.wrap(f"{self.go(ch[0], _P_IMP + 1)} -> {self.go(ch[1], _P_IMP)}", _P_IMP, context)
        if k == z3.Z3_OP_NOT:
            return self.wrap("not " + self.go(ch[0], _P_NOT), _P_NOT, context)
        if k == z3.Z3_OP_EQ:
            return self.wrap(f"{self.go(ch[0], _P_CMP + 1)} == {self.go(ch[1], _P_CMP + 1)}", _P_CMP, context)
        if k == z3.Z3_OP_DISTINCT and len(ch) == 2:
            return self.wrap(f"{self.go(ch[0], _P_CMP + 1)} != {self.go(ch[1], _P_CMP + 1)}", _P_CMP, context)
        if k in _CMP:
            return self.wrap(f"{self.go(ch[0], _P_CMP + 1)} {_CMP[k]} {self.go(ch[1], _P_CMP + 1)}", _P_CMP, context)
        if k in _ARITH:
            op = _ARITH[k]
            p = _P_SUM if op in "+-" else _P_PROD
            parts = [self.go(ch[0], p)] + [self.go(c, p + 1) for c in ch[1:]]
            return self.wrap(f" {op} ".join(parts), p, context)
        if k == z3.Z3_OP_UMINUS:
            return self.wrap("-" + self.go(ch[0], _P_NEG), _P_NEG, context)
        if k == z3.Z3_OP_TO_REAL:
            return self.go(ch[0], context)
        name = self.name(z3.FuncDeclRef(decl, t.ctx).name())
        if not ch:
            return name
        return f"{name}(" + ", ".join(self.go(c) for c in ch) + ")"

    def quantifier(self, q: z3.QuantifierRef, context: int) -> str:
        kind = "forall" if q.is_forall() else "exists" if q.is_exists() else "lambda"
        names = [q.var_name(k) for k in range(q.num_vars())]
        sorts = [str(q.var_sort(k)) for k in range(q.num_vars())]
        binds = ", ".join(f"{n} in {_SORT_NAMES.get(s, s)}" for n, s in zip(names, sorts))
        self.bound.extend(names)
        try:
            body = self.go(q.body())
        finally:
            del self.bound[len(self.bound) - len(names):]
        return f"{kind}({binds} | {body})"


def z3_text(t: z3.ExprRef, names: Mapping[str, str] | None = None) -> str:
    """Render a Z3 term in the program language's syntax (``->``, ``and``,
    ``==``, infix arithmetic, ``f(a)``, ``TRUE``), with the fewest
    parentheses the precedence needs.  ``names`` renames Z3 symbols (e.g.
    ``RadiationSensor.in.command`` -> ``in.command``)."""
    return _Printer(names or {}).go(t)


def term_printer(names: Mapping[str, str] | None = None) -> Callable[[z3.ExprRef], str]:
    """:func:`z3_text` with ``names`` for many terms: the text of each term is
    the same, and subterms the terms share are rendered once (the precondition
    and postcondition of a triple are also lines of its proof outline)."""
    return _Printer(names or {}).go


@dataclass(frozen=True)
class OutlineLine:
    """A rendered line: ``indent`` (spaces), ``text`` (``{ P }`` or code) and ``note``."""

    indent: int
    text: str
    note: str = ""


def render_outline(items: Sequence[OutlineItem], names: Mapping[str, str] | None = None,
                   precondition: z3.BoolRef | None = None, pre_note: str = "",
                   show: Callable[[z3.ExprRef], str] | None = None) -> list[OutlineLine]:
    """Turn outline items into lines; a ``precondition`` (the triple's) is
    put first, with ``pre_note`` (e.g. which VC shows it implies the next).
    ``show`` renders the assertions (default: a :func:`term_printer` of ``names``)."""
    out: list[OutlineLine] = []
    go = show or term_printer(names)  # one for all lines: they share subterms (see _Printer.memo)
    if precondition is not None:
        out.append(OutlineLine(0, "{ " + go(precondition) + " }", pre_note))
    for it in items:
        if it.kind == "assert":
            assert it.formula is not None
            out.append(OutlineLine(2 * it.depth, "{ " + go(it.formula) + " }", it.note))
        else:
            out.append(OutlineLine(2 * it.depth, it.text))
    return out


def outline_text(lines: Sequence[OutlineLine]) -> str:
    """Plain text of an outline: one line each, notes after ``--``."""
    rows = []
    for ln in lines:
        body = " " * ln.indent + ln.text
        rows.append(f"{body}    -- {ln.note}" if ln.note else body)
    return "\n".join(rows) + "\n"
