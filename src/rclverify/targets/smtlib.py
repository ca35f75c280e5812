"""RCL formulas of the arithmetic fragment as SMT-LIB2 text, without Z3.

The in-context check of a side condition (:mod:`.context`) asserts the
contracts of a node's whole upstream cone; along a chain of N nodes the
cones add up to N*N/2 contracts, and building each through the Z3 Python
API (:class:`~rclverify.semantics.encode.Encoder`) cost some 0.2 ms per
formula: 14 s for the side conditions of a 200-node chain, almost all of it
in the API's wrappers.  Z3's own parser reads the same assertions from text
in a few milliseconds.  This module writes that text for the fragment it
covers, once per node and process (a pure function of the formula and the
connections, so caching it changes no answer: nothing of Z3 is kept), and
:mod:`.context` parses the cone's texts with the symbols' declarations
given (``z3.parse_smt2_string(..., decls=...)``).

The fragment: ``TRUE``/``FALSE``, numerals, inputs and outputs of type
``BOOL``, ``INTEGER``, ``NATURAL`` or ``REAL`` (as the encoder names them:
a connected input is its producer's output symbol), ``not``, unary ``-``,
``and or -> <=>``, ``+ - * /`` and (chained) comparisons ``== != < <= > >=``.
Its meaning is the encoder's (shared/DESIGN.md, "Semantics"): an integer
meets a real as a real (Z3's parser inserts ``to_real`` as the encoder's
``coerce`` does), ``/`` is real division, a NATURAL symbol's ``>= 0`` is the
encoder's axiom.  Anything else (quantifiers, functions, enumerations,
sets, constants of the context) is outside: :func:`to_smt` returns ``None``
and the caller encodes with the encoder.  ``tests/calculus/test_calculus_context.py``
checks both ways give the same verdicts.
"""
from __future__ import annotations

from typing import Mapping

from rclverify.lang import ast
from rclverify.lang.types import BOOL, INTEGER, NATURAL, REAL, CheckedNode, Type
from rclverify.semantics.operators import OPERATORS

#: The RCL types of the fragment and their SMT-LIB sorts.
SORTS: Mapping[Type, str] = {BOOL: "Bool", INTEGER: "Int", NATURAL: "Int", REAL: "Real"}



class Outside(Exception):
    """The formula leaves the fragment."""


def quote(name: str) -> str:
    """An SMT-LIB quoted symbol (``|N0.out.x1|``)."""
    return f"|{name}|"


def to_smt(e: ast.Expr, node: CheckedNode, symbol: Mapping[tuple[str, str], str],
           used: dict[str, str]) -> str | None:
    """``e`` (a type-checked formula of ``node``) as an SMT-LIB2 term, or
    ``None`` outside the fragment (module docstring).

    ``symbol`` maps ``(prefix, var)`` of the node's I/O to the Z3 symbol
    name the encoder gives it (the connections applied); ``used`` collects
    ``{symbol name: SMT-LIB sort}`` of the symbols the term mentions."""
    try:
        return _term(e, node, symbol, used)
    except Outside:
        return None


def _io(v: ast.Var, node: CheckedNode, symbol: Mapping[tuple[str, str], str], used: dict[str, str]) -> str:
    prefix = v.prefix or ("in" if v.name in node.inputs else "out" if v.name in node.outputs else None)
    if prefix is None:
        raise Outside  # a context constant, an enumeration value or a bound name
    t = (node.inputs if prefix == "in" else node.outputs).get(v.name)
    if t is None or t not in SORTS:
        raise Outside
    name = symbol[(prefix, v.name)]
    used[name] = SORTS[t]
    return quote(name)


def _term(e: ast.Expr, node: CheckedNode, symbol: Mapping[tuple[str, str], str], used: dict[str, str]) -> str:
    # an explicit stack would be needed for very deep formulas; the parser bounds nesting (lang/parser.py)
    if isinstance(e, ast.BoolLit):
        return "true" if e.value else "false"
    if isinstance(e, ast.NumLit):
        v = e.value
        if v.denominator == 1:
            return str(v.numerator) if v >= 0 else f"(- {-v.numerator})"
        num = f"{abs(v.numerator)}.0"
        body = f"(/ {num} {v.denominator}.0)"
        return body if v >= 0 else f"(- {body})"
    if isinstance(e, ast.Var):
        return _io(e, node, symbol, used)
    if isinstance(e, ast.Unary):
        inner = _term(e.operand, node, symbol, used)
        if e.op == "not":
            return f"(not {inner})"
        if e.op == "-":
            return f"(- {inner})"
        if e.op == "abs":  # SMT-LIB's abs is of the Ints theory only: one ite for both sorts
            return f"(ite (>= {inner} 0) {inner} (- {inner}))"
        if e.op == "sqrt" or e.op == "sin" or e.op == "cos":  # no SMT-LIB theory symbol: the encoder's facts
            raise Outside
        ast.unhandled(e.op)
    if isinstance(e, ast.Binary):
        op = OPERATORS[e.op].smtlib  # the semantics table's SMT-LIB symbol (semantics/operators.py)
        if op is None:
            raise Outside
        return f"({op} {_term(e.left, node, symbol, used)} {_term(e.right, node, symbol, used)})"
    if isinstance(e, ast.Compare):
        xs = [_term(o, node, symbol, used) for o in e.operands]
        # != has no SMT-LIB symbol of its own (the table's is None): the negated equality
        parts = [(f"(not (= {a} {b}))" if op == "!=" else f"({OPERATORS[op].smtlib} {a} {b})")
                 for op, a, b in zip(e.ops, xs, xs[1:])]
        return parts[0] if len(parts) == 1 else "(and " + " ".join(parts) + ")"
    raise Outside
