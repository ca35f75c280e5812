"""A node's parameter constraints used as assumptions: do they ensure what its contract assumes of the input they set?

A node whose NoDL document declares a parameter and whose contract has an
input of the same name (the parameter's name as :func:`.contract.rcl_name_of`
reads it, or its last dotted part: ``limits.max_speed`` feeds
``in.max_speed``) reads that input from the parameter.  ROS 2 refuses a
value outside the parameter's validators when it is set (the validation
``generate_parameter_library`` generates runs in the node's set-parameters
callback), so the declared constraints hold of every value the input takes:
they are an assumption the contract may rely on.  Each top-level conjunct of
the contract's ``assume`` clauses that mentions that input and no other I/O
variable is a side condition, decided by Z3 (:func:`rclverify.semantics.query.prove`):
``constraints(x) => conjunct(x)``.

* proved: the declaration discharges it (:attr:`Side.status` ``proved``),
  reported as discharged, no finding;
* refuted: a value the declaration allows breaks the node's assumption:
  ``nodl-parameter-assume``, an error located at the conjunct and at the
  parameter, with Z3's counterexample;
* inconclusive (Z3 gave no answer in its budget): a warning.

The constraints read are the numeric ones (:data:`NUMERIC`: ``bounds``,
``lt``, ``gt``, ``lt_eq``, ``gt_eq``, ``one_of``) of an ``int`` or
``double`` parameter; ``read_only`` adds nothing (a read-only parameter is
set once, within the same validators).
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import z3

from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.types import Checked, CheckedNode, Scalar
from rclverify.lang.walk import subexpressions
from rclverify.model.nodl.contract import rcl_name_of
from rclverify.model.nodl.document import Document, Parameter
from rclverify.model.nodl.findings import Finding

#: The validators read as Z3 constraints (with or without ``<>``).
NUMERIC = ("bounds", "lt", "gt", "lt_eq", "gt_eq", "one_of")
#: Z3's budget per side condition, in milliseconds.
TIMEOUT_MS = 5_000


@dataclass(frozen=True)
class Side:
    """One side condition: node, parameter, the conjunct as RCL text, Z3's ``status``
    (``proved``, ``refuted``, ``inconclusive``) and, refuted, the counterexample (RCL name -> value)."""

    node: str
    parameter: str
    conjunct: str
    status: str
    model: tuple[tuple[str, str], ...] = ()


def _conjuncts(e: ast.Expr) -> list[ast.Expr]:
    if isinstance(e, ast.Binary) and e.op == "and":
        return _conjuncts(e.left) + _conjuncts(e.right)
    return [e]


def _io(e: ast.Expr, cn: CheckedNode) -> set[tuple[str, str]]:
    """The I/O variables ``e`` mentions, as ``(prefix, name)`` (a bare name of an input or output too)."""
    out: set[tuple[str, str]] = set()
    for x in subexpressions(e):
        if isinstance(x, ast.Var):
            if x.prefix in ("in", "out"):
                out.add((x.prefix, x.name))
            elif x.prefix is None and (x.name in cn.inputs or x.name in cn.outputs):
                out.add(("in" if x.name in cn.inputs else "out", x.name))
    return out


def _number(v: Any) -> z3.ArithRef:
    return z3.RealVal(str(Fraction(str(v))))


def constraint(p: Parameter, x: z3.ArithRef) -> z3.BoolRef | None:
    """The parameter's numeric validators (:data:`NUMERIC`) as a Z3 formula over ``x``; ``None``
    when it has none (or an argument is not a number)."""
    xr = z3.ToReal(x) if x.is_int() else x
    parts: list[z3.BoolRef] = []
    try:
        for raw, arg in p.validation:
            name = raw[:-2] if raw.endswith("<>") else raw
            a = arg if isinstance(arg, list) else [arg]
            if name == "bounds":
                parts += [_number(a[0]) <= xr, xr <= _number(a[1])]
            elif name in ("lt", "gt", "lt_eq", "gt_eq"):
                v = _number(a[0])
                parts.append({"lt": xr < v, "gt": xr > v, "lt_eq": xr <= v, "gt_eq": xr >= v}[name])
            elif name == "one_of":
                parts.append(z3.Or([xr == _number(v) for v in a[0]]))
    except (ValueError, TypeError, IndexError, ZeroDivisionError):
        return None
    return z3.And(parts) if parts else None


def _fed(cn: CheckedNode, p: Parameter) -> str | None:
    """The numeric input of ``cn`` parameter ``p`` sets, by name (module docstring)."""
    for name in (rcl_name_of(p.name), rcl_name_of(p.name.rsplit(".", 1)[-1])):
        t = cn.inputs.get(name)
        if isinstance(t, Scalar) and t.name in ("REAL", "INTEGER", "NATURAL"):
            return name
    return None


def check_parameters(cn: CheckedNode, doc: Document, checked: Checked) -> tuple[list[Side], list[Finding]]:
    """The side conditions of node ``cn``'s parameters declared in ``doc`` (module docstring):
    every one decided, and a finding per one not proved."""
    from rclverify.semantics.encode import Encoder  # deferred: start-up (loads z3's encoding only when a parameter feeds an input)
    from rclverify.semantics.query import prove  # deferred: start-up (loads z3's encoding only when a parameter feeds an input)
    sides: list[Side] = []
    out: list[Finding] = []
    for p in doc.parameters:
        name = _fed(cn, p) if p.type in ("int", "double") else None
        if name is None:
            continue
        enc = Encoder(checked.env)
        x = enc.io_symbol(cn, "in", name)
        c = constraint(p, x)
        if c is None:
            continue
        for clause in cn.node.assumes:
            for conj in _conjuncts(clause.formula):
                if _io(conj, cn) != {("in", name)}:
                    continue
                text = expr_to_rcl(conj)
                r = prove(enc.formula(conj, cn), [c], enc, timeout_ms=TIMEOUT_MS,
                          comment=f"NoDL parameter {p.name} of {cn.name} ensures: {text}")
                model = tuple(sorted((r.model or {}).items()))
                sides.append(Side(cn.name, p.name, text, r.status, model))
                if r.status == "proved":
                    continue
                allowed = ", ".join(f"{k} = {v}" for k, v in model) or "some value"
                if r.status == "refuted":
                    out.append(Finding("nodl-parameter-assume",
                                       f"node {cn.name} assumes {text} of input {name}, which parameter {p.name} "
                                       f"sets; its declared constraints allow {allowed}, which breaks it",
                                       (conj.loc, p.loc)))
                else:
                    out.append(Finding("nodl-parameter-assume",
                                       f"node {cn.name}: Z3 could not decide whether parameter {p.name}'s declared "
                                       f"constraints ensure the assumption {text} ({r.reason or 'no answer'})",
                                       (conj.loc, p.loc), "warning"))
    return sides, out


__all__ = ["NUMERIC", "Side", "check_parameters", "constraint"]
