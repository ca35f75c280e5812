"""The tolerant reader of Python node sources: a file Python 3's ``ast``
cannot parse (a Python 2 script with ``print "x"`` or ``except E, e:``, a
file with a syntax error) is read with tree-sitter's Python grammar
(``tree-sitter-python``), which accepts Python 2's print and exec statements
and recovers from errors: what lies in its ERROR regions is not read, and
those lines are named in the note the caller emits.

The result is the same :class:`~.sources_py.PyModule` record the ``ast``
reader gives (imports, calls with their arguments, assignments), so one
extractor (:func:`~.sources_py.extract`) reads both.
Source of the syntax: the Python 2.7 and 3 language references.
"""
from __future__ import annotations

from typing import Any, Callable

from rclverify.ros.extract import treesitter
from rclverify.ros.extract.model import Src
from rclverify.ros.extract.pyrecords import PyCall, PyModule, PyVal, percent

MAX_DEPTH = 100  # nesting read; deeper expressions are left as text


def _ranges(lines: list[int]) -> str:
    """``[3, 7, 8, 9]`` -> ``"3, 7-9"``."""
    spans: list[list[int]] = []
    for ln in sorted(set(lines)):
        if spans and spans[-1][1] == ln - 1:
            spans[-1][1] = ln
        else:
            spans.append([ln, ln])
    return ", ".join(str(a) if a == b else f"{a}-{b}" for a, b in spans)


def tolerant_module(text: str, shown: str) -> tuple[Any, str]:
    """``(PyModule or None, what was not read)`` for ``text``: the second part is
    ``"every line read"`` or ``"lines 3, 7-9 not read"`` (the ERROR regions and
    missing tokens tree-sitter reported). ``None`` only when the grammar is not
    installed (said in the second part)."""
    try:
        parser = treesitter.parser("python")
    except ImportError:
        return None, "tree-sitter-python is not installed, so the file was not read"
    root = parser.parse(text.encode("utf-8", errors="replace")).root_node
    r = _Reader(shown)
    unread: list[int] = []
    stack = [root]
    while stack:
        n = stack.pop()
        t = n.type
        if t == "ERROR" or n.is_missing:
            unread.extend(range(n.start_point[0] + 1, n.end_point[0] + 2))
        step = _STATEMENTS.get(t)
        if step is not None:
            step(r, n, n.start_point[0] + 1)
        stack.extend(reversed(n.children))
    mod = r.mod
    mod.calls.sort(key=lambda c: (c.src.line, c.src.col))
    word = "line" if len(set(unread)) == 1 else "lines"
    return mod, (f"{word} {_ranges(unread)} not read (syntax tree-sitter could not recover)"
                 if unread else "every line read")


def _dotted(n: Any) -> str | None:
    """``a.b.c`` for a name or a chain of attributes, else ``None``."""
    if n.type == "identifier":
        return treesitter.text(n)
    if n.type == "attribute":
        o, a = n.child_by_field_name("object"), n.child_by_field_name("attribute")
        base = _dotted(o) if o is not None else None
        return f"{base}.{treesitter.text(a)}" if base and a is not None else None
    return None


class _Reader:
    """The :class:`PyModule` of one file read from tree-sitter's tree: one
    record per call (made once per call node), values as :class:`PyVal`."""

    def __init__(self, shown: str) -> None:
        self.shown = shown
        self.mod = PyModule()
        self.made: dict[int, PyCall] = {}

    def loc(self, n: Any) -> Src:
        return Src(self.shown, n.start_point[0] + 1, n.start_point[1] + 1)

    def call(self, c: Any, depth: int) -> PyCall:
        """The record of call node ``c`` (its function's dotted name, ``super().f``
        or ``.f`` for a method of another expression, and its arguments)."""
        if c.id not in self.made:
            f = c.child_by_field_name("function")
            func = _dotted(f) if f is not None else None
            if func is None and f is not None and f.type == "attribute":
                o = f.child_by_field_name("object")
                a = treesitter.text(f.child_by_field_name("attribute"))
                is_super = o is not None and o.type == "call" and treesitter.text(o.child_by_field_name("function")) == "super"
                func = f"super().{a}" if is_super else f".{a}"
            pc = PyCall(func or "", [], {}, self.loc(c))
            self.made[c.id] = pc
            a = c.child_by_field_name("arguments")
            for x in (a.named_children if a is not None else []):
                if x.type == "keyword_argument":
                    k, v = x.child_by_field_name("name"), x.child_by_field_name("value")
                    if k is not None and v is not None:
                        pc.kwargs[treesitter.text(k)] = self.val(v, depth + 1)
                elif x.type != "comment":
                    pc.args.append(self.val(x, depth + 1))
        return self.made[c.id]

    def _string(self, n: Any, depth: int) -> PyVal | None:
        """A string literal, an f-string as its parts; ``None`` for bytes."""
        prefix = treesitter.text(n.children[0]) if n.children else ""
        if "b" not in prefix.lower() and not any(c.type == "interpolation" for c in n.children):
            return PyVal("str", "".join(treesitter.text(c) for c in n.children if c.type == "string_content"),
                         self.loc(n))
        if "b" not in prefix.lower() and depth <= MAX_DEPTH:
            parts = []
            for c in n.children:
                if c.type == "string_content":
                    parts.append(PyVal("str", treesitter.text(c), self.loc(c)))
                elif c.type == "interpolation":
                    e = c.child_by_field_name("expression")
                    plain = e is not None and len(c.named_children) == 1
                    parts.append(self.val(e, depth + 1) if plain else PyVal("other", treesitter.text(c), self.loc(c)))
            return PyVal("cat", treesitter.text(n), self.loc(n), parts=parts)
        return None

    def val(self, n: Any, depth: int) -> PyVal:
        """The value of expression ``n``: a string, ``%`` formatting, ``+``, a
        dotted name, a call (with the calls on its result), else its text."""
        loc = self.loc
        if n.type == "string":
            got = self._string(n, depth)
            if got is not None:
                return got
        left = n.child_by_field_name("left") if n.type == "binary_operator" else None
        if left is not None and treesitter.text(n.child_by_field_name("operator")) == "%" and depth <= MAX_DEPTH:
            fmt = self.val(left, depth + 1)  # '/%s/pose' % name
            right = n.child_by_field_name("right")
            args = [x for x in right.named_children if x.type != "comment"] if right.type == "tuple" else [right]
            if fmt.kind == "str":
                return percent(fmt.text, [self.val(a, depth + 1) for a in args], treesitter.text(n), loc(n))
        if n.type == "binary_operator" and treesitter.text(n.child_by_field_name("operator")) == "+" \
                and depth <= MAX_DEPTH:
            return PyVal("cat", treesitter.text(n), loc(n), parts=[self.val(n.child_by_field_name("left"), depth + 1),
                                                                   self.val(n.child_by_field_name("right"), depth + 1)])
        d = _dotted(n)
        if d is not None:
            return PyVal("name", d, loc(n))
        if depth > MAX_DEPTH:
            return PyVal("other", treesitter.text(n), loc(n))
        inner, x = [], n  # a call and the attributes/calls on its result: get_parameter('t').value
        while x is not None and x.type in ("call", "attribute"):
            if x.type == "call":
                inner.append(self.call(x, depth + 1))
                x = x.child_by_field_name("function")
            else:
                x = x.child_by_field_name("object")
        if n.type == "call":
            return PyVal("call", treesitter.text(n), loc(n), self.call(n, depth), inner)
        return PyVal("other", treesitter.text(n), loc(n), None, inner)

    def function(self, n: Any, line: int) -> None:
        """A function's qualified name, lines, parameters and their defaults
        (``self`` dropped for a method that is not a ``staticmethod``)."""
        if n.child_by_field_name("name") is None:
            return
        names: list[str] = []
        p = n.parent
        while p is not None:
            if p.type in ("class_definition", "function_definition") and p.child_by_field_name("name") is not None:
                nm = treesitter.text(p.child_by_field_name("name"))
                names.insert(0, nm if p.type == "class_definition" else f"{nm}.<locals>")
            p = p.parent
        prefix = "".join(f"{x}." for x in names)
        anchor = n.parent if n.parent is not None and n.parent.type == "decorated_definition" else n
        holder = anchor.parent.parent if anchor.parent is not None else None
        direct = holder is not None and holder.type == "class_definition"
        params: list[str] = []
        defaults: list[PyVal | None] = []
        ps = n.child_by_field_name("parameters")
        for x in ps.named_children if ps is not None else []:
            if x.type in ("identifier", "typed_parameter"):
                ident = x if x.type == "identifier" else next(
                    (c for c in x.named_children if c.type == "identifier"), None)
                params.append(treesitter.text(ident))
                defaults.append(None)
            elif x.type in ("default_parameter", "typed_default_parameter"):
                params.append(treesitter.text(x.child_by_field_name("name")))
                v = x.child_by_field_name("value")
                defaults.append(self.val(v, 1) if v is not None else None)
        deco = n.parent.type == "decorated_definition" and "staticmethod" in treesitter.text(n.parent)
        if direct and not deco and params:
            params, defaults = params[1:], defaults[1:]
        self.mod.functions.append((prefix + treesitter.text(n.child_by_field_name("name")), n.start_point[0] + 1,
                                   n.end_point[0] + 1, params, defaults))

    def import_(self, n: Any, line: int) -> None:
        for x in n.children_by_field_name("name"):
            if x.type == "aliased_import":
                self.mod.bind_import(treesitter.text(x.child_by_field_name("alias")),
                                     treesitter.text(x.child_by_field_name("name")), line)
            else:
                self.mod.bind_import(treesitter.text(x).split(".")[0], treesitter.text(x).split(".")[0], line)

    def import_from(self, n: Any, line: int) -> None:
        m = treesitter.text(n.child_by_field_name("module_name")).lstrip(".")
        if any(c.type == "wildcard_import" for c in n.children):
            self.mod.star.append(m)
        for x in n.children_by_field_name("name"):
            if x.type == "aliased_import":
                self.mod.bind_import(treesitter.text(x.child_by_field_name("alias")),
                                     f"{m}.{treesitter.text(x.child_by_field_name('name'))}".lstrip("."), line)
            else:
                self.mod.bind_import(treesitter.text(x), f"{m}.{treesitter.text(x)}".lstrip("."), line)

    def call_statement(self, n: Any, line: int) -> None:
        self.mod.calls.append(self.call(n, 0))

    def return_(self, n: Any, line: int) -> None:
        if n.named_children:
            self.mod.returns.append((line, self.val(n.named_children[0], 0)))

    def class_(self, n: Any, line: int) -> None:
        name = n.child_by_field_name("name")
        if name is None:
            return
        self.mod.classes.append((treesitter.text(name), n.start_point[0] + 1, n.end_point[0] + 1))
        sup = n.child_by_field_name("superclasses")
        self.mod.bases[treesitter.text(name)] = [
            d for d in (_dotted(b) for b in (sup.named_children if sup is not None else [])) if d]

    def assignment(self, n: Any, line: int) -> None:
        left, right = n.child_by_field_name("left"), n.child_by_field_name("right")
        d = _dotted(left) if left is not None else None
        if d is not None and right is not None:
            self.mod.assigns.append((d, self.val(right, 0)))


#: What the reader records of each kind of tree-sitter node it reads (the rest it only walks through).
_STATEMENTS: dict[str, Callable[[_Reader, Any, int], None]] = {
    "import_statement": _Reader.import_, "import_from_statement": _Reader.import_from,
    "function_definition": _Reader.function, "call": _Reader.call_statement, "return_statement": _Reader.return_,
    "class_definition": _Reader.class_, "assignment": _Reader.assignment,
}
