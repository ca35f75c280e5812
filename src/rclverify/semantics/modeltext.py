"""Z3 model values and terms written in RCL notation (``move(1.5, 0)``,
``green``, ``0.2`` rather than ``1/5``, a function table's symbolic ``else``
branch as ``p1 == 2 and p2 == 3``), for terms of any depth (explicit
stacks).  Part of the Z3 encoding (:mod:`rclverify.semantics.encode`).
"""
from __future__ import annotations

from fractions import Fraction
from typing import Any, Callable, Sequence

import z3

from rclverify.semantics.values import decimal_text


#: How a term is rendered: its text (a leaf), or its children and what joins their texts.
_Parts = tuple[str | None, Sequence[z3.ExprRef], Callable[[list[str]], str] | None]


def _render(root: z3.ExprRef, parts: Callable[[z3.ExprRef], _Parts]) -> str:
    """Render ``root`` bottom-up with an explicit stack: Z3 models can hold
    terms thousands of levels deep (a function table's ``else`` branch as a
    chain of ``if``s), deeper than Python's recursion limit."""
    todo: list[tuple[z3.ExprRef, tuple[int, Callable[[list[str]], str]] | None]] = [(root, None)]
    done: list[str] = []
    while todo:
        e, pending = todo.pop()
        if pending is not None:  # its children are rendered: the last n texts
            n, combine = pending
            texts = done[len(done) - n:]
            del done[len(done) - n:]
            done.append(combine(texts))
            continue
        leaf, kids, join = parts(e)
        if leaf is not None or join is None:
            done.append(leaf if leaf is not None else str(e))
            continue
        todo.append((e, (len(kids), join)))
        todo.extend((k, None) for k in reversed(kids))  # the first child is rendered first
    return done[0]


def _value_parts(v: z3.ExprRef) -> _Parts:
    if z3.is_int_value(v):
        return str(v.as_long()), (), None
    if z3.is_rational_value(v):
        fr = Fraction(v.numerator_as_long(), v.denominator_as_long())
        if fr.denominator == 1:
            return str(fr.numerator), (), None
        dec = float(fr)
        if Fraction(dec) == fr:
            return repr(dec), (), None
        exact = decimal_text(fr)  # 0.2, not 1/5 (docs/values.md)
        return (exact or f"{fr.numerator}/{fr.denominator}"), (), None
    if z3.is_algebraic_value(v):
        return str(v.as_decimal(6)), (), None
    if z3.is_true(v):
        return "TRUE", (), None
    if z3.is_false(v):
        return "FALSE", (), None
    if z3.is_app(v):  # a sequence in RCL's literal notation, <a, b> (docs/values.md), never seq.unit/seq.++
        k = v.decl().kind()
        if k == z3.Z3_OP_SEQ_EMPTY:
            return "<>", (), None
        if k == z3.Z3_OP_SEQ_UNIT:
            return None, v.children(), lambda xs: f"<{xs[0]}>"
        if k == z3.Z3_OP_SEQ_CONCAT:
            return None, v.children(), lambda xs: "<" + ", ".join(x[1:-1] for x in xs if x != "<>") + ">"
    if z3.is_app(v) and v.num_args() > 0:
        name = v.decl().name()
        return None, v.children(), lambda xs: f"{name}(" + ", ".join(xs) + ")"
    if z3.is_app(v):
        return str(v.decl().name()), (), None
    return str(v), (), None


def value_to_rcl(v: z3.ExprRef) -> str:
    """Render a Z3 model value in RCL notation (``move(1.5, 0)``, ``green``, ``7/3``)."""
    return _render(v, _value_parts)


_OPS = {z3.Z3_OP_AND: " and ", z3.Z3_OP_OR: " or ", z3.Z3_OP_EQ: " == ", z3.Z3_OP_LE: " <= ", z3.Z3_OP_LT: " < ",
        z3.Z3_OP_GE: " >= ", z3.Z3_OP_GT: " > ", z3.Z3_OP_ADD: " + ", z3.Z3_OP_SUB: " - ", z3.Z3_OP_MUL: " * ",
        z3.Z3_OP_IMPLIES: " -> ", z3.Z3_OP_DIV: " / "}


def _term_parts(e: z3.ExprRef) -> _Parts:
    if z3.is_int_value(e) or z3.is_rational_value(e) or z3.is_true(e) or z3.is_false(e):
        return value_to_rcl(e), (), None
    if not z3.is_app(e):
        return str(e), (), None
    k = e.decl().kind()
    kids = e.children()
    if k in _OPS and kids:
        op = _OPS[k]
        return None, kids, lambda xs: "(" + op.join(xs) + ")"
    if k == z3.Z3_OP_NOT:
        return None, kids[:1], lambda xs: f"not {xs[0]}"
    if k == z3.Z3_OP_ITE:
        return None, kids, lambda xs: f"(if {xs[0]} then {xs[1]} else {xs[2]})"
    if k == z3.Z3_OP_DISTINCT:
        return None, kids, lambda xs: "(" + " != ".join(xs) + ")"
    if k == z3.Z3_OP_TO_REAL and kids:
        return None, kids[:1], lambda xs: xs[0]
    if kids:
        name = e.decl().name()
        return None, kids, lambda xs: f"{name}(" + ", ".join(xs) + ")"
    return value_to_rcl(e), (), None


def term_to_rcl(e: z3.ExprRef) -> str:
    """Render a Z3 term from a model in RCL notation, e.g. a function
    table's symbolic ``else`` branch: ``p1 == 2 and p2 == 3``.  Terms of any
    depth (an explicit stack).

    The text is :func:`_render` with :func:`_term_parts` (what
    :func:`_term_to_rcl_reference` does), computed once per distinct
    subterm: a model's ``else`` branch is a DAG whose chain of ``if``s
    shares its conditions, and walking it as a tree through the Python Z3
    wrappers cost some 9 CPU seconds of the case study's cold run (health
    models of 270,000-430,000 characters).  Inner nodes are read with Z3's
    low-level API (``z3.Z3_get_app_arg`` ...) on the raw terms (no wrapper object per node); leaves (values,
    constants, bound variables) are rendered by :func:`_term_parts` as
    before."""
    ctx = e.ctx
    c = ctx.ref()
    ast_id, ast_kind, n_args, arg = z3.Z3_get_ast_id, z3.Z3_get_ast_kind, z3.Z3_get_app_num_args, z3.Z3_get_app_arg
    app_decl, decl_kind = z3.Z3_get_app_decl, z3.Z3_get_decl_kind
    app_kind = z3.Z3_APP_AST
    memo: dict[int, str] = {}
    names: dict[int, str] = {}
    root = e.as_ast()
    todo: list[tuple[Any, bool]] = [(root, False)]
    while todo:
        a, ready = todo.pop()
        aid = ast_id(c, a)
        if not ready:
            if aid in memo:
                continue
            n = n_args(c, a) if ast_kind(c, a) == app_kind else 0
            if n == 0:
                memo[aid] = _render(z3.z3._to_expr_ref(a, ctx), _term_parts)
                continue
            todo.append((a, True))
            todo.extend((arg(c, a, i), False) for i in range(n - 1, -1, -1))
            continue
        n = n_args(c, a)
        xs = [memo[ast_id(c, arg(c, a, i))] for i in range(n)]
        d = app_decl(c, a)
        k = decl_kind(c, d)
        if k in _OPS:
            memo[aid] = "(" + _OPS[k].join(xs) + ")"
        elif k == z3.Z3_OP_NOT:
            memo[aid] = f"not {xs[0]}"
        elif k == z3.Z3_OP_ITE:
            memo[aid] = f"(if {xs[0]} then {xs[1]} else {xs[2]})"
        elif k == z3.Z3_OP_DISTINCT:
            memo[aid] = "(" + " != ".join(xs) + ")"
        elif k == z3.Z3_OP_TO_REAL:
            memo[aid] = xs[0]
        else:
            did = ast_id(c, d)
            if did not in names:
                names[did] = z3.FuncDeclRef(d, ctx).name()
            memo[aid] = f"{names[did]}(" + ", ".join(xs) + ")"
    return memo[ast_id(c, root)]


def _term_to_rcl_reference(e: z3.ExprRef) -> str:
    """:func:`term_to_rcl` as a walk of the whole tree through the Python
    wrappers: the definition the fast version must agree with (tests)."""
    return _render(e, _term_parts)
