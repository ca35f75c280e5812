"""The nesting limit of RCL formulas and types: input nested deeper than
:data:`NESTING_LIMIT` is a located ``E-depth`` error at parse time instead of
a ``RecursionError`` in a later stage (docs/rcl-language.md, "Robustness
limits").
"""
from __future__ import annotations

from itertools import accumulate
from typing import Any

from rclverify.lang import ast

from rclverify.lang import typeexpr
from rclverify.lang.errors import RclError, error

#: Deepest nesting of expressions and types the parser accepts (AST depth;
#: parentheses alone do not count, a balanced ``and``/``or`` chain of n
#: operands counts log2(n)).  Deeper input is a located ``E-depth`` error
#: instead of a ``RecursionError`` in a later stage (docs/rcl-language.md).
NESTING_LIMIT = 200


#: Fields that hold subtrees, per AST class (leaves are absent).
_CHILD_FIELDS: dict[type, tuple[str, ...]] = {
    ast.Binary: ("left", "right"), ast.Unary: ("operand",), ast.Compare: ("operands",),
    ast.Member: ("elem", "collection"), ast.Apply: ("args",), ast.SetLit: ("items",), ast.SeqLit: ("items",),
    ast.TupleLit: ("items",), ast.Quant: ("bindings", "body"), ast.Binding: ("domain",),
    ast.TupleQuant: ("domain", "body"), ast.SeqRange: ("lo", "hi"), ast.ConstDecl: ("value", "type"),
    ast.TypeDecl: ("type",), ast.IOVar: ("type",), typeexpr.TFunc: ("args", "result"), typeexpr.TSet: ("elem",),
    typeexpr.TSeq: ("elem",), typeexpr.TTuple: ("elems",), typeexpr.TConstructors: ("ctors",), typeexpr.Constructor: ("args",),
}


def _too_deep(root: Any) -> Any | None:
    """The first node (pre-order) at depth NESTING_LIMIT + 1 under ``root``,
    or ``None``.  Iterative."""
    stack: list[tuple[Any, int]] = [(root, 1)]
    fields = _CHILD_FIELDS
    while stack:
        node, d = stack.pop()
        if d > NESTING_LIMIT:
            return node
        for f in fields.get(type(node), ()):
            v = getattr(node, f)
            if isinstance(v, tuple):
                stack.extend((x, d + 1) for x in v)
            elif v is not None:
                stack.append((v, d + 1))
    return None


def check_nesting(tree: Any, text: str, dline: int = 0) -> None:
    """Raise a located ``E-depth`` :class:`RclError` when a formula or type
    in ``tree`` (a :class:`~rclverify.lang.ast.Spec` or an expression parsed
    from ``text``, its lines shifted by ``dline``) nests deeper than
    :data:`NESTING_LIMIT` (AST depth: parentheses alone do not count, a
    balanced ``and``/``or`` chain of n operands counts log2(n)).

    Every level of nesting takes at least one character, so only the
    declarations and clauses whose text is longer than the limit are
    walked: the check costs next to nothing on ordinary contracts."""
    roots: list[Any] = []
    if isinstance(tree, ast.Spec):
        for c in tree.contexts:
            roots += c.decls
        for n in tree.nodes:
            roots += n.inputs + n.outputs
            roots += [cl.formula for cl in n.assumes + n.guarantees]
    else:
        roots.append(tree)
    starts: list[int] | None = None
    for r in roots:
        loc = r.loc
        if loc.end_line == loc.line:
            if loc.end_col - loc.col <= NESTING_LIMIT:
                continue
        else:
            if starts is None:
                starts = [0, *accumulate(len(line) + 1 for line in text.split("\n"))]
            a, b = loc.line - dline - 1, loc.end_line - dline - 1
            if 0 <= a < b < len(starts) and starts[b] + loc.end_col - starts[a] - loc.col <= NESTING_LIMIT:
                continue
        bad = _too_deep(r)
        if bad is not None:
            raise RclError([error(bad.loc, f"too deeply nested (limit {NESTING_LIMIT})", "E-depth")])
