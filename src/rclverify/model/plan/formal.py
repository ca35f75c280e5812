"""Formal requirement statements: RCL over node-qualified variables.

A requirement's ``formal:`` (and each ``assuming:`` formula) is an RCL
formula (docs/rcl-language.md) whose I/O variables are written with the node
they belong to: ``ObstacleDetector.out.distance``, ``MotorDriver.in.speed_cmd``.
The context's types, constants, enumeration values and constructors are in
scope as in a contract; a bare ``in.x``/``out.x`` (no node) is an error,
since a requirement speaks about the whole system (docs/requirements.md).

How it is read: every ``Node.in.x``/``Node.out.y`` is replaced in the text
by a placeholder name of the same length (so every column the parser and
the type checker report is the column in the plan), the formula is parsed by
the RCL parser, and the placeholders become variables named
``Node.in.x``/``Node.out.y`` of a system-wide pseudo node whose inputs and
outputs are all the nodes' I/O variables.  The encoder
(:class:`rclverify.semantics.encode.Encoder`) then maps each one to its node's
symbol, so a consumer's input and its producer's output are one symbol.

Errors (an unknown node or variable, an input written as an output or the
reverse, an unqualified ``in.x``, a type error, a term that is not a
formula) are located :class:`~rclverify.lang.errors.RclError` diagnostics at
the requirement's text.
"""
from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass
from typing import Any, Mapping

from rclverify.lang import ast

from rclverify.lang import typeexpr
from rclverify.lang.errors import RclError, error
from rclverify.lang.types import BOOL, Checked, CheckedNode, Type

#: ``Node.in.x`` / ``Node.out.y`` (primes allowed, as in RCL names).
QUALIFIED = re.compile(r"(?<![A-Za-z0-9_.'])([A-Za-z_][A-Za-z0-9_]*)\.(in|out|state)\.([A-Za-z_][A-Za-z0-9_]*'*)")
#: An unqualified ``in.x`` / ``out.x``.
UNQUALIFIED = re.compile(r"(?<![A-Za-z0-9_.'])(in|out)\.([A-Za-z_][A-Za-z0-9_]*)")
#: The pseudo node's name (never a valid RCL node name, so never a real one).
SYSTEM = "<system>"


@dataclass(frozen=True)
class Source:
    """Where a formula's text is: the text to parse and the line and column
    of its first character (a YAML block scalar is given as its source lines
    with column 1)."""

    text: str
    line: int
    col: int
    file: str

    @property
    def loc(self) -> ast.Loc:
        """Where the formula's first character (after indentation) is."""
        return _loc_at(self, len(self.text) - len(self.text.lstrip()))


@dataclass(frozen=True)
class Formal:
    """A parsed, type-checked formal statement.

    ``expr``      the formula; its I/O variables are bare names ``Node.in.x``;
    ``scope``     the pseudo node those names are inputs/outputs of;
    ``mentions``  the ``(node, "in"|"out", var)`` triples it mentions, in
                  order of first appearance.
    """

    expr: ast.Expr
    scope: CheckedNode
    mentions: tuple[tuple[str, str, str], ...]

    @property
    def nodes(self) -> tuple[str, ...]:
        seen: dict[str, None] = {}
        for n, _, _ in self.mentions:
            seen.setdefault(n, None)
        return tuple(seen)


def system_scope(checked: Checked, states: Mapping[tuple[str, str], Type] | None = None) -> CheckedNode:
    """The pseudo node whose inputs are every ``Node.in.x`` (and every
    declared ``Node.state.v`` of ``states``) and whose outputs are every
    ``Node.out.y`` of the checked contracts."""
    ins: dict[str, Type] = {f"{n}.state.{v}": t for (n, v), t in (states or {}).items()}
    outs: dict[str, Type] = {}
    for name, cn in checked.nodes.items():
        ins.update({f"{name}.in.{v}": t for v, t in cn.inputs.items()})
        outs.update({f"{name}.out.{v}": t for v, t in cn.outputs.items()})
    node = ast.Node(SYSTEM, (), (), (), (), ())
    return CheckedNode(node, ins, outs)


def _loc_at(src: Source, offset: int) -> ast.Loc:
    """The plan location of character ``offset`` of ``src.text``."""
    before = src.text[:offset]
    line = src.line + before.count("\n")
    col = (offset - before.rfind("\n")) if "\n" in before else src.col + offset
    return ast.Loc(src.file, line, col)


def parse_formal(src: Source, checked: Checked, what: str = "requirement",
                 states: Mapping[tuple[str, str], Type] | None = None) -> Formal:
    """Parse and type-check one formal statement (module docstring).

    ``states`` (``{(node, name): type}``, :mod:`.state`) are the declared
    state variables the statement may name as ``Node.state.v``: only a
    temporal statement's operands are given them (:mod:`.temporal`); in a
    state requirement ``Node.state.v`` is an ``E-name`` error.

    Returns a :class:`Formal`; raises :class:`RclError` with located
    diagnostics (``E-name`` for names, ``E-type`` for typing, RCL syntax
    errors as the parser gives them).
    """
    expr, scope, mentions, t = read_expr(src, checked, what, states)
    if t != BOOL:
        raise RclError([error(src.loc, f"{what}: must be a formula, found a term of type {t}", "E-type")])
    return Formal(expr, scope, mentions)


def read_expr(src: Source, checked: Checked, what: str = "requirement",
              states: Mapping[tuple[str, str], Type] | None = None
              ) -> tuple[ast.Expr, CheckedNode, tuple[tuple[str, str, str], ...], Type]:
    """Parse and type one RCL expression over ``Node.in.x``/``Node.out.y``
    (and ``Node.state.v`` of ``states``), read as :func:`parse_formal` reads
    a formula but of any type: returns ``(expr, scope, mentions, type)``
    with the fields of :class:`Formal` and the inferred type.  Raises
    :class:`RclError` with located diagnostics (as :func:`parse_formal`)."""
    from rclverify.lang.parser import parse_formula  # deferred: start-up (loads lark, rclverify.core and more only when called)
    from rclverify.lang.typecheck import infer  # deferred: start-up (loads lark, rclverify.core and more only when called)
    diags = []
    names: dict[str, str] = {}  # placeholder -> Node.in.x
    mentions: dict[tuple[str, str, str], None] = {}
    pieces: list[str] = []
    last = 0
    for k, m in enumerate(QUALIFIED.finditer(src.text)):
        node, prefix, var = m.group(1), m.group(2), m.group(3)
        loc = _loc_at(src, m.start())
        cn = checked.nodes.get(node)
        if cn is None:
            diags.append(error(loc, f"{what}: no node named {node!r} in the system; nodes are: "
                                    f"{', '.join(checked.nodes) or 'none'}", "E-name"))
        elif prefix == "state":
            if (node, var) not in (states or {}):
                declared = [f"{n}.state.{v}" for n, v in (states or {})]
                diags.append(error(loc, f"{what}: {node}.state.{var} is not a state variable read here: "
                                        + (f"the declared ones are {', '.join(declared)}, read only under a temporal "
                                           "operator" if declared else "declare it in the plan's state: section and "
                                           "read it under a temporal operator (docs/plan.md)"), "E-name"))
            else:
                mentions.setdefault((node, prefix, var), None)
        else:
            table, other = (cn.inputs, cn.outputs) if prefix == "in" else (cn.outputs, cn.inputs)
            kind, okind = ("input", "output") if prefix == "in" else ("output", "input")
            if var not in table:
                if var in other:
                    diags.append(error(loc, f"{what}: {var!r} is an {okind} of {node}, not an {kind}: write "
                                            f"{node}.{'out' if prefix == 'in' else 'in'}.{var}", "E-name"))
                else:
                    diags.append(error(loc, f"{what}: node {node} has no {kind} named {var!r}; its {kind}s are: "
                                            f"{', '.join(table) or 'none'}", "E-name"))
            else:
                mentions.setdefault((node, prefix, var), None)
        width = m.end() - m.start()
        ph = f"__q{k}_"
        ph = ph + "_" * (width - len(ph)) if len(ph) <= width else ph
        names[ph] = f"{node}.{prefix}.{var}"
        pieces.append(src.text[last:m.start()] + ph)
        last = m.end()
    pieces.append(src.text[last:])
    text = "".join(pieces)
    for m in UNQUALIFIED.finditer(text):
        diags.append(error(_loc_at(src, m.start()), f"{what}: {m.group(0)} names no node; a requirement speaks "
                                                    f"about the system: write Node.{m.group(1)}.{m.group(2)}",
                           "E-name"))
    if diags:
        raise RclError(diags)
    try:
        expr = parse_formula(text, src.file, src.line, src.col)
    except RclError as exc:  # the parser saw placeholders: its messages name what the plan wrote
        raise RclError([dataclasses.replace(d, message=_unplaceholder(d.message, names)) for d in exc.diagnostics]) \
            from None
    expr = _rename(expr, names)
    scope = system_scope(checked, states)
    return expr, scope, tuple(mentions), infer(expr, scope, checked.env)


def _unplaceholder(message: str, names: Mapping[str, str]) -> str:
    """``message`` with every placeholder the parser was given written back
    as the ``Node.in.x`` it stands for (no internal name reaches a user)."""
    for ph in sorted(names, key=len, reverse=True):
        message = message.replace(ph, names[ph])
    return message


def _rename(e: Any, names: Mapping[str, str]) -> Any:
    """``e`` with every placeholder variable renamed to its ``Node.in.x``
    (recursive over the AST's dataclass fields; the parser bounds nesting)."""
    if isinstance(e, ast.Var):
        return dataclasses.replace(e, name=names[e.name]) if e.name in names else e
    if isinstance(e, typeexpr.TName) and e.name in names:  # a binder's domain `r in Node.in.xs`: the variable, not a type
        return ast.Var(names[e.name], None, e.loc)
    if isinstance(e, tuple):
        return tuple(_rename(x, names) for x in e)
    if not dataclasses.is_dataclass(e) or isinstance(e, (ast.Loc, type)):
        return e
    changes = {}
    for f in dataclasses.fields(e):
        if f.name == "loc":
            continue
        v = getattr(e, f.name)
        nv = _rename(v, names)
        if nv is not v:
            changes[f.name] = nv
    return dataclasses.replace(e, **changes) if changes else e
