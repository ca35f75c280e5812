"""The ``ast`` reader of Python node sources: a file Python 3 parses becomes
the :class:`~.pyrecords.PyModule` record (imports, calls with their
arguments, assignments, returns, classes, functions with their parameters)
that :func:`~.sources_py.extract` reads, as the tolerant reader
(:mod:`.sources_py_tolerant`) gives it for a file Python 3 does not parse.
The code is never imported or run.  Source of the syntax: the Python 3
language reference (the ``ast`` module's grammar).
"""
from __future__ import annotations

import ast
from typing import Any, Callable

from rclverify.ros.extract.model import Src
from rclverify.ros.extract.pyconst import DISCOVERY
from rclverify.ros.extract.pyrecords import PyCall, PyModule, PyVal, percent


def _dotted(e: ast.AST) -> str | None:
    if isinstance(e, ast.Name):
        return e.id
    if isinstance(e, ast.Attribute):
        base = _dotted(e.value)
        return f"{base}.{e.attr}" if base else None
    return None


def ast_module(tree: ast.AST, shown: str) -> PyModule:
    """The :class:`PyModule` of the parsed file ``tree`` (shown as ``shown``
    in locations), its calls in source order."""
    r = _Reader(shown)
    for n in ast.walk(tree):
        step = _STATEMENTS.get(type(n))
        if step is not None:
            step(r, n)
    if isinstance(tree, ast.Module):
        r.scopes(tree.body, "", False)
    r.mod.calls.sort(key=lambda c: (c.src.line, c.src.col))  # source order, as the tolerant reader gives
    return r.mod


class _Reader:
    """One file's :class:`PyModule` read from its ``ast``: one record per
    call (made once per call node), values as :class:`PyVal`."""

    def __init__(self, shown: str) -> None:
        self.shown = shown
        self.mod = PyModule()
        self.made: dict[int, PyCall] = {}

    def loc(self, e: ast.AST) -> Src:
        return Src(self.shown, getattr(e, "lineno", 1), getattr(e, "col_offset", 0) + 1)

    def call(self, c: ast.Call) -> PyCall:
        """The record of call ``c`` (its function's dotted name, ``super().f``
        or ``.f`` for a method of another expression, and its arguments)."""
        if id(c) not in self.made:
            f = c.func
            func = _dotted(f) or ""
            if isinstance(f, ast.Attribute) and isinstance(f.value, ast.Call) and _dotted(f.value.func) == "super":
                func = f"super().{f.attr}"
            elif not func and isinstance(f, ast.Attribute):
                func = f".{f.attr}"
            self.made[id(c)] = PyCall(func, [self.val(a) for a in c.args],
                                      {k.arg: self.val(k.value) for k in c.keywords if k.arg}, self.loc(c))
        return self.made[id(c)]

    def val(self, e: ast.AST) -> PyVal:
        """The value of expression ``e``: a string, a dotted name, ``+``,
        ``%`` formatting, an f-string, a call (with the calls on its result),
        else its text."""
        loc, val = self.loc, self.val
        if isinstance(e, ast.Constant) and isinstance(e.value, str):
            return PyVal("str", e.value, loc(e))
        d = _dotted(e)
        if d is not None:
            return PyVal("name", d, loc(e))
        if isinstance(e, ast.BinOp) and isinstance(e.op, ast.Add):
            return PyVal("cat", ast.unparse(e), loc(e), parts=[val(e.left), val(e.right)])
        if isinstance(e, ast.BinOp) and isinstance(e.op, ast.Mod) and isinstance(e.left, ast.Constant) \
                and isinstance(e.left.value, str):  # '/%s/pose' % name
            args = e.right.elts if isinstance(e.right, ast.Tuple) else [e.right]
            return percent(e.left.value, [val(a) for a in args], ast.unparse(e), loc(e))
        if isinstance(e, ast.JoinedStr):
            parts = [val(x.value) if isinstance(x, ast.FormattedValue) and x.conversion == -1 and x.format_spec is None
                     else val(x) if isinstance(x, ast.Constant) else PyVal("other", ast.unparse(x), loc(e))
                     for x in e.values]
            return PyVal("cat", ast.unparse(e), loc(e), parts=parts)
        chain, x = [], e  # a call and the attributes/calls on its result: get_parameter('t').value
        while isinstance(x, (ast.Call, ast.Attribute)):
            if isinstance(x, ast.Call):
                chain.append(self.call(x))
                x = x.func
            else:
                x = x.value
        if isinstance(e, ast.Call):
            return PyVal("call", ast.unparse(e), loc(e), self.call(e), chain)
        return PyVal("other", ast.unparse(e), loc(e), None, chain if isinstance(e, ast.Attribute) else [])

    def scopes(self, body: list[ast.stmt], prefix: str, in_class: bool) -> None:
        """The functions under ``body`` with their qualified names (``prefix``),
        parameters and defaults (``self`` dropped in a class but for a
        ``staticmethod``)."""
        for st in body:
            if isinstance(st, ast.ClassDef):
                self.scopes(st.body, f"{prefix}{st.name}.", True)
            elif isinstance(st, (ast.FunctionDef, ast.AsyncFunctionDef)):
                a = st.args
                pos = a.posonlyargs + a.args
                static = any(_dotted(d) == "staticmethod" for d in st.decorator_list)
                names = [x.arg for x in pos] + [x.arg for x in a.kwonlyargs]
                defaults: list[PyVal | None] = [None] * (len(pos) - len(a.defaults)) + [self.val(d) for d in a.defaults]
                defaults += [self.val(d) if d is not None else None for d in a.kw_defaults]
                if in_class and not static and names:
                    names, defaults = names[1:], defaults[1:]
                self.mod.functions.append((f"{prefix}{st.name}", st.lineno,
                                           getattr(st, "end_lineno", None) or st.lineno, names, defaults))
                self.scopes(st.body, f"{prefix}{st.name}.<locals>.", False)
            else:
                for fld in ("body", "orelse", "finalbody", "handlers"):
                    inner = getattr(st, fld, None)
                    if isinstance(inner, list):
                        self.scopes([x for x in inner if isinstance(x, ast.stmt)] +
                                    [y for h in inner if isinstance(h, ast.ExceptHandler) for y in h.body],
                                    prefix, in_class)

    def import_from(self, n: ast.ImportFrom) -> None:
        if not (n.module or n.level):
            return
        for a in n.names:  # a relative import names the package's own module (``from . import names``)
            if a.name == "*":
                if n.module:
                    self.mod.star.append(n.module)
            else:
                self.mod.bind_import(a.asname or a.name, f"{n.module}.{a.name}" if n.module else a.name, n.lineno)

    def import_(self, n: ast.Import) -> None:
        for a in n.names:
            self.mod.bind_import(a.asname or a.name.split(".")[0], a.name if a.asname else a.name.split(".")[0],
                                 n.lineno)

    def call_node(self, n: ast.Call) -> None:
        self.mod.calls.append(self.call(n))

    def return_(self, n: ast.Return) -> None:
        if n.value is not None:
            self.mod.returns.append((n.lineno, self.val(n.value)))

    def class_(self, n: ast.ClassDef) -> None:
        self.mod.classes.append((n.name, n.lineno, getattr(n, "end_lineno", None) or n.lineno))
        self.mod.bases[n.name] = [d for d in (_dotted(b) for b in n.bases) if d]

    def for_(self, n: ast.For) -> None:
        if isinstance(n.iter, ast.Call) and (_dotted(n.iter.func) or "").rsplit(".", 1)[-1] in DISCOVERY:
            # for name, types in node.get_topic_names_and_types(): names found at run time (pyconst)
            for t in (n.target.elts if isinstance(n.target, ast.Tuple) else [n.target]):
                if isinstance(t, ast.Name):
                    self.mod.assigns.append((t.id, self.val(n.iter)))

    def assign(self, n: ast.Assign | ast.AnnAssign) -> None:
        if n.value is None:
            return
        for t in (n.targets if isinstance(n, ast.Assign) else [n.target]):
            d = _dotted(t)
            if d is not None:
                self.mod.assigns.append((d, self.val(n.value)))
            elif isinstance(t, ast.Tuple) and t.elts and isinstance(t.elts[0], ast.Name) and isinstance(
                    n.value, ast.Call) and (_dotted(n.value.func) or "").endswith(".parse_known_args"):
                self.mod.assigns.append((t.elts[0].id, self.val(n.value)))  # args, rest = p.parse_known_args()


#: What the reader records of each kind of ``ast`` node (the rest it only walks through).
_STATEMENTS: dict[type, Callable[[_Reader, Any], None]] = {
    ast.ImportFrom: _Reader.import_from, ast.Import: _Reader.import_, ast.Call: _Reader.call_node,
    ast.Return: _Reader.return_, ast.ClassDef: _Reader.class_, ast.For: _Reader.for_,
    ast.Assign: _Reader.assign, ast.AnnAssign: _Reader.assign,
}
