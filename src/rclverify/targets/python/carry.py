"""A node's contract as data the generated Python package carries (``<pkg>/contract_eval.py``).

A generated node must judge its contract in any ROS 2 Python, where
rclverify is not installed.  Its package therefore carries the
judgement itself: ``contract_eval.py`` (from ``templates/contract_eval.py.j2``)
is a small evaluator with rclverify's three readings of a formula on
recorded values (exact, the node's IEEE-754 doubles, the declared tolerance;
``semantics/floatsem.py``), and ``contract.py`` holds each clause as a JSON tree
made here from the type-checked AST.  Everything that needs the checker is
settled here, at generation time: names resolved (an I/O variable, a
bound variable, an enumeration value, a context constant's expression),
which clauses the double and tolerance readings can change
(``logic/floatsens.float_sensitive``), which comparisons read a recorded
value, the finite domains of quantifiers (``logic/eval_shapes``), and the
inputs and outputs each clause reads (``backends/monitors/verdicts``).

The tree's nodes (lists, first item the kind):
``["num", numerator, denominator]``, ``["lit", value]`` (a boolean, an
enumeration value's name, a string), ``["io", "in.x"]``, ``["bound", name]``,
``["unary", op, e]``, ``["bin", op, l, r]``,
``["cmp", [ops], [operands], reads_io]``, ``["member", negated, elem, [items]]``
(a literal set), ``["quant", kind, [[name, domain], ...], body]`` with a domain
``["bool"]``, ``["vals", [..]]``, ``["setlit", [items]]``, ``["range", [ints]]``,
``["unused"]`` (a number the body does not read) or ``["none", reason]``, and
``["unsupported", reason, [io keys]]`` for what the carried evaluator does
not judge (function tables, constructor terms, sets and sequences as values,
type membership): evaluated, it is undecided with the reason ("no value for
in.x" first when a value it reads is missing), never a guess.
"""
from __future__ import annotations

from typing import Any, Mapping

import jinja2

from rclverify.lang.walk import names, reads
from rclverify.semantics.eval_shapes import MAX_RANGE, _integer_range, _unused
from rclverify.semantics.floatsens import float_sensitive
from rclverify.semantics.operators import OPERATORS, UNARY, Operator
from rclverify.semantics.widths import at_widths
from rclverify.lang import ast
from rclverify.lang import typeexpr
from rclverify.lang import types as T
from rclverify.lang.types import Checked, CheckedNode
from rclverify.lang.printer import expr_to_rcl
from rclverify.targets.shapes import Carried, CarriedClause

#: a note every undecided reason of an uncarried part ends with
NOT_CARRIED = "not judged by the carried contract layer (rclverify's monitor judges it)"


class _Tree:
    """Serialises the formulas of one node (``checked``'s environment, ``node``'s I/O)."""

    def __init__(self, checked: Checked, node: CheckedNode) -> None:
        self.env = checked.env
        self.node = node

    def expr(self, e: Any, scope: frozenset[str]) -> list[Any]:
        """The tree of expression ``e`` with the quantifier-bound names ``scope``."""
        if isinstance(e, ast.BoolLit):
            return ["lit", e.value]
        if isinstance(e, ast.StrLit):
            return ["lit", e.value]
        if isinstance(e, ast.NumLit):
            v = e.value
            return ["num", v.numerator, v.denominator]
        if isinstance(e, ast.Var):
            return self.var(e, scope)
        if isinstance(e, ast.Unary):
            return ["unary", e.op, self.expr(e.operand, scope)]
        if isinstance(e, ast.Binary):
            return ["bin", e.op, self.expr(e.left, scope), self.expr(e.right, scope)]
        if isinstance(e, ast.Compare):
            return ["cmp", list(e.ops), [self.expr(o, scope) for o in e.operands], self.reads_io(e, scope)]
        if isinstance(e, ast.Member) and isinstance(e.collection, ast.SetLit):
            return ["member", e.negated, self.expr(e.elem, scope), [self.expr(i, scope) for i in e.collection.items]]
        if isinstance(e, ast.Quant):
            return self.quant(e, scope)
        return self.unsupported(e, f"{type(e).__name__} ({_what(e)})")

    def var(self, v: ast.Var, scope: frozenset[str]) -> list[Any]:
        """A name, resolved as the evaluator resolves it (bound, enumeration value, constant, I/O)."""
        if v.prefix is None and v.name in scope:
            return ["bound", v.name]
        if v.prefix is None and v.name in self.env.enum_values:
            return ["lit", v.name]
        if v.prefix is None and v.name in self.env.constants:
            return self.expr(self.env.constants[v.name][1], frozenset())
        if v.prefix is None and v.name in self.env.ctors:
            return self.unsupported(v, f"constructor term {v.name}")
        return ["io", self.key(v)]

    def key(self, v: ast.Var) -> str:
        """The qualified I/O name of ``v`` (a bare name: an input first, as ``Evaluator.io``)."""
        if v.prefix is not None:
            return v.qualified
        return ("in." if v.name in self.node.inputs else "out.") + v.name

    def unsupported(self, e: Any, what: str) -> list[Any]:
        """An uncarried part: its reason and the I/O values it reads."""
        found: list[ast.Var] = []
        _vars(e, found)
        io = self.io_names()
        keys = [self.key(v) for v in found if v.prefix is not None or v.name in io]
        return ["unsupported", f"{what}: {NOT_CARRIED}", list(dict.fromkeys(keys))]

    def io_names(self) -> frozenset[str]:
        return frozenset(self.node.inputs) | frozenset(self.node.outputs)

    def reads_io(self, e: ast.Compare, scope: frozenset[str]) -> bool:
        """Does comparison ``e`` read a recorded value (floatsem's ``_reads_io``)?"""
        found: list[ast.Var] = []
        _vars(e.operands, found)
        io = self.io_names()
        return any(v.prefix is not None or (v.name in io and v.name not in scope) for v in found)

    def quant(self, e: ast.Quant, scope: frozenset[str]) -> list[Any]:
        inner = scope | frozenset(e.variables)
        doms = [[n, self.domain(e, bd, n, scope)] for bd in e.bindings for n in bd.names]
        return ["quant", e.kind, doms, self.expr(e.body, inner)]

    def domain(self, e: ast.Quant, bd: ast.Binding, name: str, scope: frozenset[str]) -> list[Any]:
        """The finite domain of ``name`` as floatsem's ``_finite_domain`` finds it."""
        dom = bd.domain
        if isinstance(dom, typeexpr.TEnum):
            return ["vals", list(dom.values)]
        typ: Any = None
        if isinstance(dom, typeexpr.TBase):
            typ = T.Scalar(dom.name) if dom.name in ("REAL", "INTEGER", "NATURAL", "BOOL") else None
        elif isinstance(dom, typeexpr.TName):
            typ = self.env.types.get(dom.name)
        elif isinstance(dom, ast.SetLit):
            return ["setlit", [self.expr(i, scope) for i in dom.items]]
        if isinstance(typ, T.EnumT):
            return ["vals", list(typ.values)]
        if isinstance(typ, T.Scalar):
            if typ.name == "BOOL":
                return ["bool"]
            if e.kind in ("forall", "exists") and _unused(e, name, bd):
                return ["unused"]
            bounded = _integer_range(e.body, name, typ.name, e.kind)
            if bounded is not None and len(bounded) <= MAX_RANGE:
                return ["range", list(bounded)]
            return ["none", f"{name} ranges over {typ.name} without a literal bound: not enumerable outside "
                            f"exact arithmetic; {NOT_CARRIED}"]
        return ["none", f"quantifier over {type(dom).__name__}: {NOT_CARRIED}"]


def _what(e: Any) -> str:
    """A short text of ``e`` for a reason."""
    try:
        return expr_to_rcl(e)
    except Exception:  # noqa: BLE001 - only a label; the node type is named anyway
        return "?"


def _vars(e: Any, out: list[ast.Var]) -> None:
    """Every variable under ``e`` in source order."""
    if isinstance(e, ast.Var):
        out.append(e)
        return
    if isinstance(e, tuple):
        for x in e:
            _vars(x, out)
        return
    if isinstance(e, ast.Loc) or not hasattr(e, "__dataclass_fields__"):
        return
    for f in e.__dataclass_fields__:
        _vars(getattr(e, f), out)


def carried(checked: Checked, node: CheckedNode, widths: Mapping[str, str] | None = None) -> Carried:
    """What ``contract.py`` carries for ``node``: ``assumes`` and ``guarantees`` (each
    ``{"tree", "fs", "fs_tol"}``: the clause's tree and whether the double and the tolerance
    readings can change it), ``ins`` (the inputs the contract reads, in declaration order),
    ``per`` (guarantee k -> [inputs, outputs] it reads) and ``enums`` (variable -> the values
    of its enumeration), as ``contract.py.j2`` renders them.

    ``widths`` (``"in.x"``/``"out.y"`` -> ``float32`` or ``float64``: the IDL width of the field
    each variable travels in) reads every comparison at the width of what it compares
    (:func:`rclverify.semantics.widths.at_widths`; docs/semantics.md, "Widths"): the tree holds
    each constant compared with a ``float32`` field as the exact rational of its ``float32``
    value, so the carried readings judge ``in.p <= 0.2`` against 0.20000000298023223876953125 as
    rclverify's monitor does."""
    tree = _Tree(checked, node)

    def clause(c: Any) -> CarriedClause:
        f = at_widths(c.formula, widths or {}, checked.env.constants)
        return {"tree": tree.expr(f, frozenset()), "fs": float_sensitive(f, checked, node),
                "fs_tol": float_sensitive(f, checked, node, tolerant=True)}
    needed: set[str] = set()
    for c in list(node.node.assumes) + list(node.node.guarantees):
        names(c.formula, needed)
    ins = [f"in.{n}" for n in node.inputs if f"in.{n}" in needed or n in needed]
    per: dict[str, list[list[str]]] = {}
    for k, c in enumerate(node.node.guarantees, 1):
        got: set[str] = set()
        reads(c.formula, got)
        per[str(k)] = [sorted(f"in.{n}" for n in node.inputs if f"in.{n}" in got or n in got),
                       sorted(f"out.{n}" for n in node.outputs if f"out.{n}" in got or n in got)]
    enums = {f"{side}.{n}": list(t.values) for side, io in (("in", node.inputs), ("out", node.outputs))
             for n, t in io.items() if isinstance(t, T.EnumT)}
    return {"assumes": [clause(c) for c in node.node.assumes],
            "guarantees": [clause(c) for c in node.node.guarantees],
            "ins": ins, "per": per, "enums": enums}


_ENV = jinja2.Environment(loader=jinja2.PackageLoader("rclverify.targets.python", "templates"),
                          keep_trailing_newline=True, autoescape=False, undefined=jinja2.StrictUndefined)


_ENV.filters["py"] = repr


def evaluator_text(marker: str, operators: Mapping[str, Operator] = OPERATORS,
                   unary: Mapping[str, Operator] = UNARY) -> str:
    """The text of ``contract_eval.py``, the evaluator a generated Python package carries
    (module docstring), headed by the comment ``marker`` (what rewrites the file).

    Its operators are written from the semantics table ``operators`` (binary) and ``unary``
    (:mod:`rclverify.semantics.operators`): each entry's Python text, the connectives'
    short circuit and what a zero divisor does, so an operator added to the table reaches
    generated packages with no edit here.  Raises ``ValueError`` naming an entry that lacks
    the Python text the evaluator needs (``python``, or ``python_reading`` for arithmetic)."""
    need = [(o, "python") for o in unary.values()] + [
        (o, "python_reading" if o.kind == "arithmetic" else "python") for o in operators.values()]
    missing = [f"{o.symbol!r} ({field})" for o, field in need if not getattr(o, field)]
    if missing:
        raise ValueError(f"the semantics table gives no Python text for {', '.join(missing)}: "
                         "the carried evaluator cannot be written")
    by_kind = {k: [o for _, o in sorted(operators.items()) if o.kind == k]
               for k in ("connective", "comparison", "arithmetic")}
    return _ENV.get_template("contract_eval.py.j2").render(
        marker=marker, unary=[o for _, o in sorted(unary.items())], connectives=by_kind["connective"],
        comparisons=by_kind["comparison"], arithmetic=by_kind["arithmetic"])
