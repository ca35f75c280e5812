"""What stands at a position of a document: the symbol under the cursor,
resolved against the last analysis of its scope (:mod:`.diagnostics`).

A symbol is one of (``Symbol.kind``):

* ``node``: a node name (its clause, a plan entry ``Agent:``, ``node:
  Agent`` or the ``Agent`` of ``Agent.in.at`` in a plan statement);
* ``io``: an input or output, ``in.x``/``out.y`` inside a node, its name in
  the node's ``inputs(...)``/``outputs(...)``, or ``Node.in.x`` in the plan;
* ``guarantee``: the keyword ``guarantee`` (or ``G``) of a node's
  guarantee, with its 1-based index;
* ``decl``: a name a ``context`` clause declares (type, constant,
  function-typed constant, enumeration value, constructor);
* ``requirement``: a requirement id of the plan.

Names in comments are not symbols.  Positions are LSP positions (0-based
line, UTF-16 character); locations found are :class:`rclverify.lang.ast.Loc`.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any, Iterator

from rclverify.lang import ast

from rclverify.lang import typeexpr
from rclverify.tools.lsp.diagnostics import Analysis
from rclverify.tools.lsp.lines import normalize, split_lines

_WORD = re.compile(r"(?<![\w.])(?:in|out|state)\.[A-Za-z_]\w*'*|[A-Za-z_]\w*(?:\.(?:in|out|state)\.[A-Za-z_]\w*'*)?'*")
_COMMENTS = re.compile(r"//[^\n]*|/\*.*?(?:\*/|\Z)", re.S)
_YAML_COMMENT = re.compile(r"(?:^|\s)#[^\n]*")


@dataclass(frozen=True)
class Symbol:
    """The symbol at a position: ``kind`` (module docstring), ``name`` (the
    node, declaration or requirement; for ``io`` the variable), ``node`` (for
    ``io`` and ``guarantee``), ``prefix`` (``in``/``out`` for ``io``) and
    ``index`` (for ``guarantee``)."""

    kind: str
    name: str
    node: str = ""
    prefix: str = ""
    index: int = 0


def code_point_col(line: str, char16: int) -> int:
    """The 0-based code-point column of the UTF-16 offset ``char16`` in ``line``."""
    units = 0
    for k, ch in enumerate(line):
        if units >= char16:
            return k
        units += 2 if ord(ch) > 0xFFFF else 1
    return len(line)


def comment_spans(text: str, yaml: bool = False) -> list[tuple[int, int]]:
    """``(start, end)`` offsets of the comments of ``text`` (RCL ``//`` and
    ``/* */``; ``#`` for YAML)."""
    return [m.span() for m in (_YAML_COMMENT if yaml else _COMMENTS).finditer(text)]


def word_at(text: str, line: int, char16: int, yaml: bool = False) -> tuple[str, int, int] | None:
    """``(word, start, end)`` (0-based code-point columns) of the name at
    the LSP position, ``None`` on anything else or in a comment (a
    position past the end of the document, ``None``; past the end of its
    line, the line's end, as LSP 3.17 "Position" says)."""
    text = normalize(text)
    lines = split_lines(text)
    if not 0 <= line < len(lines):
        return None
    here = lines[line]
    col = code_point_col(here, char16)
    offset = sum(len(x) + 1 for x in lines[:line]) + col
    if any(a <= offset < b for a, b in comment_spans(text, yaml)):
        return None
    for m in _WORD.finditer(here):
        if m.start() <= col <= m.end():
            return m.group(), m.start(), m.end()
    return None


def node_at(a: Analysis, rel: str, line1: int) -> ast.Node | None:
    """The node of ``rel`` whose clause holds the 1-based line ``line1``."""
    spec = a.specs.get(rel)
    for n in spec.nodes if spec else ():
        if n.loc.line <= line1 <= (n.loc.end_line or n.loc.line):
            return n
    return None


def all_nodes(a: Analysis) -> dict[str, ast.Node]:
    """Every node of the analysed files by name (first declaration wins)."""
    out: dict[str, ast.Node] = {}
    for spec in a.specs.values():
        for n in spec.nodes:
            out.setdefault(n.name, n)
    return out


def declarations(a: Analysis) -> dict[str, tuple[str, Any]]:
    """Every name the context clauses declare -> ``(what, declaration)``:
    ``what`` is ``type``, ``constant``, ``function`` (a function-typed
    constant or type), ``enumeration value`` or ``constructor``; the
    declaration is the :class:`~rclverify.lang.ast.TypeDecl` or
    :class:`~rclverify.lang.ast.ConstDecl` (for values and constructors, their type's)."""
    out: dict[str, tuple[str, Any]] = {}
    for spec in a.specs.values():
        for c in spec.contexts:
            for d in c.decls:
                if isinstance(d, ast.TypeDecl):
                    out.setdefault(d.name, ("function" if isinstance(d.type, typeexpr.TFunc) else "type", d))
                    if isinstance(d.type, typeexpr.TEnum):
                        for v in d.type.values:
                            out.setdefault(v, ("enumeration value", d))
                    elif isinstance(d.type, typeexpr.TConstructors):
                        for ctor in d.type.ctors:
                            out.setdefault(ctor.name, ("constructor", d))
                else:
                    out.setdefault(d.name, ("constant", d))
    return out


def symbol_at(a: Analysis, rel: str, text: str, line: int, char16: int, plan: bool = False) -> Symbol | None:
    """The :class:`Symbol` at the LSP position of ``rel`` (whose text is
    ``text``; ``plan``: it is the plan) in the analysis ``a``, ``None`` when
    nothing known stands there."""
    found = word_at(text, line, char16, yaml=plan)
    if found is None:
        return None
    word, start, end = found
    nodes = all_nodes(a)
    if plan:
        return _plan_symbol(a, word, start, split_lines(text)[line], nodes)
    node = node_at(a, rel, line + 1)
    if "." in word and node is not None:
        prefix, _, var = word.partition(".")
        if prefix in ("in", "out"):
            return Symbol("io", var, node.name, prefix)
        return None
    if node is not None:
        for prefix, vs in (("in", node.inputs), ("out", node.outputs)):
            for v in vs:
                if v.name == word and v.loc.line == line + 1 and v.loc.col == start + 1:
                    return Symbol("io", word, node.name, prefix)
        if word in ("guarantee", "G"):
            for k, g in enumerate(node.guarantees, 1):
                if g.loc.line == line + 1 and g.loc.col == start + 1:
                    return Symbol("guarantee", node.name, node.name, index=k)
    if word in nodes:
        return Symbol("node", word)
    decls = declarations(a)
    if word in decls:
        return Symbol("decl", word)
    return None


def _plan_symbol(a: Analysis, word: str, start: int, line_text: str, nodes: dict[str, ast.Node]) -> Symbol | None:
    if "." in word:  # `Agent.in.x`; a bare `in.x` (no node before it) names nothing in the plan
        parts = word.split(".", 2)
        head = parts[0]
        if len(parts) == 3 and head in nodes and parts[1] in ("in", "out"):
            return Symbol("io", parts[2], head, parts[1])
        return Symbol("node", head) if head in nodes else None
    plan = a.plan
    if plan is not None and any(r.id == word for r in plan.requirements):
        return Symbol("requirement", word)
    if word in nodes:
        return Symbol("node", word)
    return None


def occurrences(text: str, name: str, yaml: bool = False) -> Iterator[tuple[int, int, int]]:
    """``(line, start, end)`` (0-based, code points) of every whole-word
    occurrence of ``name`` in ``text`` (any line ends, LSP's lines) outside comments."""
    text = normalize(text)
    spans = comment_spans(text, yaml)
    pattern = re.compile(r"(?<![\w.'])" + re.escape(name) + r"(?![\w'])")
    starts = [0]
    for line in split_lines(text):
        starts.append(starts[-1] + len(line) + 1)
    import bisect  # deferred: start-up (loads bisect only when called)
    for m in pattern.finditer(text):
        if any(a <= m.start() < b for a, b in spans):
            continue
        k = bisect.bisect_right(starts, m.start()) - 1
        yield k, m.start() - starts[k], m.end() - starts[k]
