"""The hoare backend's language printed (:mod:`.lang`, which re-exports
these): a program as text (:func:`to_text`), an expression with the
parentheses its precedence needs (:func:`expr_text`) and a statement's
header line (:func:`stmt_header`).
"""
from __future__ import annotations

from rclverify.lang import typeexpr
from rclverify.lang.ast import unhandled
from rclverify.backends.hoare.nodes import (
    Num, BoolConst, Name, Old, Call, COMPARISONS, Unary, Binary, Expr, Assign, If, While, Stmt, Program)

#: Binding strength, loosest first (the grammar's precedence).
_PREC: dict[str, int] = {"->": 1, "or": 2, "and": 3, "not": 4, "==": 5, "!=": 5, "<": 5, "<=": 5, ">": 5,
                         ">=": 5, "+": 6, "-": 6, "*": 7, "/": 7, "neg": 8}
_ATOM = 9


def _prec(e: Expr) -> int:
    if isinstance(e, Binary):
        return _PREC[e.op]
    if isinstance(e, Unary):
        if e.op == "not":
            return _PREC["not"]
        if e.op == "-":
            return _PREC["neg"]
        unhandled(e.op)
    return _ATOM


def expr_text(e: Expr, context: int = 0) -> str:
    """Render an expression in the language's concrete syntax with the fewest
    parentheses that reparse to the same tree; ``context`` is the binding
    strength of the enclosing operator (0 at top level)."""
    p = _prec(e)
    if isinstance(e, Num):
        s = e.text
    elif isinstance(e, BoolConst):
        s = "TRUE" if e.value else "FALSE"
    elif isinstance(e, Name):
        s = e.name
    elif isinstance(e, Old):
        s = f"old({e.name})"
    elif isinstance(e, Call):
        s = f"{e.func}(" + ", ".join(expr_text(a) for a in e.args) + ")"
    elif isinstance(e, Unary):
        if e.op == "not":
            s = "not " + expr_text(e.operand, p)
        elif e.op == "-":
            s = "-" + expr_text(e.operand, p)
        else:
            unhandled(e.op)
    elif e.op == "->":
        s = f"{expr_text(e.left, p + 1)} -> {expr_text(e.right, p)}"
    elif e.op in COMPARISONS:
        s = f"{expr_text(e.left, p + 1)} {e.op} {expr_text(e.right, p + 1)}"
    else:
        s = f"{expr_text(e.left, p)} {e.op} {expr_text(e.right, p + 1)}"
    return f"({s})" if p < context else s


def _type_text(t: typeexpr.TypeExpr) -> str:
    if isinstance(t, typeexpr.TBase):
        return t.name
    if isinstance(t, typeexpr.TName):
        return t.name
    if isinstance(t, typeexpr.TFunc):
        return " x ".join(_type_text(a) for a in t.args) + " --> " + _type_text(t.result)
    raise ValueError(f"type {t!r} has no concrete syntax in this language")


def stmt_header(s: Stmt) -> str:
    """One-line rendering of a statement's head: ``x := e``, ``if c then``,
    ``while c invariant I do`` or ``skip`` (used by proof outlines)."""
    if isinstance(s, Assign):
        return f"{s.target} := {expr_text(s.value)}"
    if isinstance(s, If):
        return f"if {expr_text(s.cond)} then"
    if isinstance(s, While):
        return f"while {expr_text(s.cond)} invariant {expr_text(s.invariant)} do"
    return "skip"


def _stmts_lines(stmts: tuple[Stmt, ...], depth: int) -> list[str]:
    pad = "  " * depth
    out: list[str] = []
    for s in stmts:
        if isinstance(s, If):
            out.append(pad + stmt_header(s))
            out.extend(_stmts_lines(s.then_, depth + 1))
            tail = s.else_
            while len(tail) == 1 and isinstance(tail[0], If):
                out.append(pad + f"elif {expr_text(tail[0].cond)} then")
                out.extend(_stmts_lines(tail[0].then_, depth + 1))
                tail = tail[0].else_
            if tail:
                out.append(pad + "else")
                out.extend(_stmts_lines(tail, depth + 1))
            out.append(pad + "end")
        elif isinstance(s, While):
            out.append(pad + stmt_header(s))
            out.extend(_stmts_lines(s.body, depth + 1))
            out.append(pad + "end")
        else:
            out.append(pad + stmt_header(s))
    return out


def to_text(p: Program) -> str:
    """Render a program in canonical concrete syntax (lowercase keywords,
    one declaration per line, two-space indentation, trailing newline).
    ``parse_program(to_text(p)) == p``."""
    lines = [f"var {d.name} : {_type_text(d.type)};" for d in p.vars]
    lines += [f"extern {d.name} : {_type_text(d.type)};" for d in p.externs]
    if lines:
        lines.append("")
    lines += _stmts_lines(p.body, 0)
    return "\n".join(lines) + "\n"
