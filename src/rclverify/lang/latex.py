"""LaTeX rendering of RCL contracts in the style of the paper's tables.

``to_latex(spec)`` renders a whole file: the context clauses and one block
per node (inputs, outputs, topics, assumptions, guarantees), using the
notation of the paper's contract tables and appendix A (shared/reference
lines 1102-1304, 1890-1983): ``\\forall``, ``\\exists``, ``\\exists!``,
``\\land``, ``\\lor``, ``\\lnot``, ``\\Rightarrow``, ``\\iff``, ``\\in``,
``\\notin``, ``\\leq``, ``\\geq``, ``\\neq``, ``\\mathbb{R}``/``\\mathbb{Z}``/
``\\mathbb{N}``/``\\mathbb{B}`` for the base types, ``\\times`` and
``\\rightarrow`` in function types, ``\\emptyset`` for ``{}``.  ``in.``/``out.``
prefixes are kept as in the tables, primes stay ``'``, underscores are
escaped.  The quantifier separator is ``\\bullet`` (as in the tables).

Parentheses follow the RCL precedence table of :mod:`rclverify.lang.printer`;
in addition a quantifier, whose scope extends as far right as possible in
mathematical notation, is parenthesised whenever something follows it.

The document structure comes from the jinja2 template
``templates/contracts.tex.j2`` of this package.
"""
from __future__ import annotations

import re
from functools import lru_cache
from pathlib import PurePath
from typing import Sequence, Union

import jinja2

from rclverify.lang import ast

from rclverify.lang import typeexpr
from rclverify.lang.types import qualified_base
from rclverify.lang.printer import (BINARY_LEVEL, FLAT_CHAINS, MINUS_LEVEL, NOT_LEVEL, SUM_LEVEL, chain_operands, clarifying_parens,
                      is_type, level, operand_levels, progress_to_rcl)

_TEX_SPECIALS = {
    "\\": r"\textbackslash{}", "_": r"\_", "{": r"\{", "}": r"\}", "$": r"\$", "&": r"\&",
    "#": r"\#", "%": r"\%", "^": r"\^{}", "~": r"\~{}",
}
_BASE = {"REAL": r"\mathbb{R}", "INTEGER": r"\mathbb{Z}", "NATURAL": r"\mathbb{N}", "BOOL": r"\mathbb{B}",
         "STRING": r"\mathsf{STRING}"}
_BINARY = {
    "<=>": r"\iff", "->": r"\Rightarrow", "or": r"\lor", "and": r"\land",
    "+": "+", "-": "-", "*": r"\cdot", "/": "/",
}
_COMPARE = {"==": "=", "!=": r"\neq", "<": "<", "<=": r"\leq", ">": ">", ">=": r"\geq"}
_QUANT = {"forall": r"\forall", "exists": r"\exists", "exists_unique": r"\exists!\,"}


def escape(text: str) -> str:
    """``text`` with LaTeX's special characters escaped (``_`` -> ``\\_``)."""
    return "".join(_TEX_SPECIALS.get(ch, ch) for ch in text)


def name_to_latex(name: str) -> str:
    """A name in math mode: one letter stays as is (``x``), longer names are
    ``\\mathit{...}``; trailing primes stay ``'`` (``x''``, ``\\mathit{in.at}``)."""
    base = name.rstrip("'")
    primes = name[len(base):]
    if len(base) == 1:
        return base + primes
    return r"\mathit{" + escape(base) + "}" + primes


def _var(v: ast.Var) -> str:
    """A variable; a base type used as a set (``x in NATURAL``) is its
    blackboard letter, a qualified built-in term (``REAL.REAL``) the product
    of the letters (``\\mathbb{R} \\times \\mathbb{R}``)."""
    if v.prefix is None and (v.name in _BASE or qualified_base(v.name) is not None):
        return r" \times ".join(_BASE[p] for p in v.name.split("."))
    return name_to_latex(v.qualified)


def _number(text: str) -> str:
    low = text.lower()
    if "e" in low:
        mantissa, exponent = low.split("e", 1)
        return f"{mantissa} \\times 10^{{{exponent.lstrip('+')}}}"
    return text


# ---------------------------------------------------------------------------
# Types
# ---------------------------------------------------------------------------

def type_to_latex(t: typeexpr.TypeExpr) -> str:
    """Math-mode LaTeX of a type, e.g. ``\\mathbb{R} \\times \\mathbb{R}
    \\rightarrow \\mathbb{N}`` for ``REAL x REAL --> NATURAL``.  Raises
    ``TypeError`` for a value that is not a type."""
    if isinstance(t, typeexpr.TBase):
        return _BASE[t.name]
    if isinstance(t, typeexpr.TName):
        return _var(ast.Var(t.name, None, t.loc))
    if isinstance(t, typeexpr.TEnum):
        return r"\{" + ", ".join(name_to_latex(v) for v in t.values) + r"\}"
    if isinstance(t, typeexpr.TConstructors):
        return r"\{" + ", ".join(_ctor(c) for c in t.ctors) + r"\}"
    if isinstance(t, typeexpr.TFunc):
        def factor(a: typeexpr.TypeExpr) -> str:
            s = type_to_latex(a)
            return f"({s})" if isinstance(a, typeexpr.TFunc) else s
        return r" \times ".join(factor(a) for a in t.args) + r" \rightarrow " + factor(t.result)
    if isinstance(t, typeexpr.TEmpty):
        return r"\emptyset"
    if isinstance(t, typeexpr.TSet):
        return r"\mathcal{P}(" + type_to_latex(t.elem) + ")"
    if isinstance(t, typeexpr.TSeq):
        return r"\mathrm{seq}(" + type_to_latex(t.elem) + ")"
    if isinstance(t, typeexpr.TTuple):
        return "(" + ", ".join(type_to_latex(e) for e in t.elems) + ")"
    raise TypeError(f"not an RCL type: {t!r}")


def _ctor(c: typeexpr.Constructor) -> str:
    if not c.args:
        return name_to_latex(c.name)
    return name_to_latex(c.name) + "(" + ", ".join(type_to_latex(a) for a in c.args) + ")"


# ---------------------------------------------------------------------------
# Expressions
# ---------------------------------------------------------------------------

def expr_to_latex(e: ast.Expr, explicit: bool = False) -> str:
    """Math-mode LaTeX of a formula or term (no surrounding ``$``).

    ``explicit=True`` also parenthesises an ``and``/``or`` operand of
    ``->``/``<=>``.  Raises ``TypeError`` for a value that is not an
    expression."""
    return _Tex(explicit).expr(e, 0, True)


class _Tex:
    def __init__(self, explicit: bool) -> None:
        self.explicit = explicit

    def expr(self, e: ast.Expr, min_level: int, open_right: bool, force: bool = False) -> str:
        """``open_right``: nothing follows ``e`` inside its enclosing
        delimiters, so a quantifier there needs no parentheses."""
        wrap = force or level(e) < min_level
        s = self.bare(e, True if wrap else open_right)
        return f"({s})" if wrap else s

    def items(self, items: tuple[ast.Expr, ...]) -> str:
        return ", ".join(self.expr(i, 0, True) for i in items)

    def bare(self, e: ast.Expr, open_right: bool) -> str:
        if isinstance(e, ast.Var):
            return _var(e)
        if isinstance(e, ast.BoolLit):
            return r"\mathit{TRUE}" if e.value else r"\mathit{FALSE}"
        if isinstance(e, ast.NumLit):
            return _number(e.text) + unit_to_latex(e.unit)
        if isinstance(e, ast.Apply):
            return f"{_var(e.func)}({self.items(e.args)})"
        if isinstance(e, ast.First):
            return rf"\mathit{{first}}({_var(e.arg)})"
        if isinstance(e, ast.Unary):
            if e.op == "not":
                return r"\lnot " + self.expr(e.operand, NOT_LEVEL, open_right)
            if e.op == "-":
                return "-" + self.expr(e.operand, MINUS_LEVEL, open_right)
            if e.op == "abs":
                return r"\lvert " + self.expr(e.operand, 0, False) + r" \rvert"
            if e.op == "sqrt" or e.op == "sin" or e.op == "cos":
                inner = self.expr(e.operand, 0, False)
                return rf"\sqrt{{{inner}}}" if e.op == "sqrt" else rf"\{e.op}\left({inner}\right)"
            ast.unhandled(e.op)
        if isinstance(e, ast.Binary) and e.op in FLAT_CHAINS:
            ops = chain_operands(e)
            lv = BINARY_LEVEL[e.op]
            return f" {_BINARY[e.op]} ".join(self.expr(o, lv + 1, open_right and k == len(ops) - 1)
                                             for k, o in enumerate(ops))
        if isinstance(e, ast.Binary):
            lmin, rmin = operand_levels(e)
            lf = self.explicit and clarifying_parens(e, e.left)
            rf = self.explicit and clarifying_parens(e, e.right)
            left = self.expr(e.left, lmin, False, lf)
            right = self.expr(e.right, rmin, open_right, rf)
            return f"{left} {_BINARY[e.op]} {right}"
        if isinstance(e, ast.Compare):
            last = len(e.operands) - 1
            parts = [self.expr(e.operands[0], SUM_LEVEL, False)]
            for k, (op, operand) in enumerate(zip(e.ops, e.operands[1:]), 1):
                parts += [_COMPARE[op], self.expr(operand, SUM_LEVEL, open_right and k == last)]
            return " ".join(parts)
        if isinstance(e, ast.Member):
            kw = r"\notin" if e.negated else r"\in"
            return (f"{self.expr(e.elem, SUM_LEVEL, False)} {kw} "
                    f"{self.expr(e.collection, SUM_LEVEL, open_right)}")
        if isinstance(e, ast.SetLit):
            return r"\{" + self.items(e.items) + r"\}" if e.items else r"\emptyset"
        if isinstance(e, ast.SeqLit):
            return r"\langle " + self.items(e.items) + r" \rangle"
        if isinstance(e, ast.TupleLit):
            return "(" + self.items(e.items) + ")"
        if isinstance(e, ast.Quant):
            binds = ", ".join(self.binding(b) for b in e.bindings)
            s = f"{_QUANT[e.kind]} {binds} \\bullet {self.expr(e.body, 0, True)}"
            return s if open_right else f"({s})"
        if isinstance(e, ast.StrLit):
            return r"\texttt{``" + _tex_escape(e.value) + "''}"
        if isinstance(e, ast.SeqRange):
            return (r"\langle " + self.expr(e.lo, SUM_LEVEL, False) + r" \ldots "
                    + self.expr(e.hi, SUM_LEVEL, False) + r" \rangle")
        if isinstance(e, ast.TupleQuant):
            d = e.domain
            dom = type_to_latex(d) if is_type(d) else self.expr(d, SUM_LEVEL, False)  # type: ignore[arg-type]
            names = ", ".join(name_to_latex(n) for n in e.names)
            s = f"{_QUANT[e.kind]} ({names}) \\in {dom} \\bullet {self.expr(e.body, 0, True)}"
            return s if open_right else f"({s})"
        raise TypeError(f"not an RCL expression: {e!r}")

    def binding(self, b: ast.Binding) -> str:
        d = b.domain
        dom = type_to_latex(d) if is_type(d) else self.expr(d, SUM_LEVEL, False)  # type: ignore[arg-type]
        return ", ".join(name_to_latex(n) for n in b.names) + r" \in " + dom


# ---------------------------------------------------------------------------
# Document
# ---------------------------------------------------------------------------

@lru_cache(maxsize=1)
def _env() -> jinja2.Environment:
    return jinja2.Environment(
        loader=jinja2.PackageLoader("rclverify.lang", "templates"),
        undefined=jinja2.StrictUndefined, autoescape=False, keep_trailing_newline=True,
        trim_blocks=True, lstrip_blocks=True,
        block_start_string="<%", block_end_string="%>",
        variable_start_string="<<", variable_end_string=">>",
        comment_start_string="<#", comment_end_string="#>",
    )


#: The file name of a text parsed without one (:class:`rclverify.lang.ast.Loc`).
_NO_FILE = "<string>"


def _source_name(file: str) -> str:
    """The file as the user gave it, or only its name when absolute (no
    machine paths inside generated artifacts); ``""`` for text parsed
    without a file name."""
    if file == _NO_FILE:
        return ""
    p = PurePath(file)
    return p.name if p.is_absolute() else p.as_posix()


def _where(loc: ast.Loc) -> str:
    """``file:line`` of a node for its LaTeX comment, ``line N`` without a file name."""
    source = _source_name(loc.file)
    return f"{source}:{loc.line}" if source else f"line {loc.line}"


def _io(vs: tuple[ast.IOVar, ...]) -> str:
    return "(" + ", ".join(f"{name_to_latex(v.name)} : {type_to_latex(v.type)}{unit_to_latex(v.unit, True)}"
                           for v in vs) + ")"


_UNIT_TOKEN = re.compile(r"\^([+-]?\d+)|(\w+)|([*/()%])")
_UNIT_SYMBOL = {"us": r"\mu\mathrm{s}", "Ohm": r"\Omega", "deg": r"{}^{\circ}", "degC": r"{}^{\circ}\mathrm{C}",
                "percent": r"\%"}


def unit_to_latex(u: ast.UnitAnn | None, brackets: bool = False) -> str:
    """A unit of measure in math mode after a thin space, upright as SI
    writes it: ``[m/s^2]`` -> ``\\,\\mathrm{m}/\\mathrm{s}^{2}``, ``[mm]`` ->
    ``\\,\\mathrm{mm}``, ``[us]`` -> ``\\,\\mu\\mathrm{s}``; ``""`` for none.
    With ``brackets`` (a declaration: ``d : \\mathbb{R}\\,[\\mathrm{m}]``)
    the unit is in square brackets, as RCL writes it."""
    if u is None:
        return ""
    out = []
    for m in _UNIT_TOKEN.finditer(u.text):
        exp, sym, op = m.groups()
        if exp is not None:
            out.append("^{" + exp.lstrip("+") + "}")
        elif sym is not None and sym[0] in "\u00b5\u03bc" and len(sym) > 1:  # the micro sign
            out.append(r"\mu\mathrm{" + escape(sym[1:]) + "}")
        elif sym is not None:
            out.append(_UNIT_SYMBOL.get(sym, r"\mathrm{" + escape(sym) + "}"))
        else:
            out.append({"*": r"\cdot ", "%": r"\%"}.get(op, op))
    body = "".join(out)
    return r"\,[" + body + "]" if brackets else r"\," + body


def _timing(c: ast.Clause) -> str:
    """`` triggered by $in.x$ within 200~ms while \\textsf{active}`` after a guarantee (empty when
    untimed and unscoped)."""
    s = r" triggered by $" + _var(c.trigger) + "$" if c.trigger is not None else ""
    if c.deadline is not None:
        s += " within " + escape(c.deadline.amount) + (r"~\textrm{" + escape(c.deadline.unit) + "}"
                                                        if c.deadline.unit else "")
    if c.scope is not None:
        s += " while " + " or ".join(r"\textsf{" + escape(st) + "}" for st in c.scope.states)
    return s


def _transition(t: ast.TransitionDeadline) -> str:
    r"""``ready within 200~ms of \textsf{activate}``: a lifecycle node's transition deadline."""
    d = t.deadline
    return ("ready within " + escape(d.amount) + (r"~\textrm{" + escape(d.unit) + "}" if d.unit else "")
            + r" of \textsf{" + escape(t.transition) + "}")


def _link(lk: ast.Link) -> str:
    parts = ", ".join("$" + _var(v) + "$" for v in lk.parts)
    return (lk.kind + r" \texttt{" + escape(lk.ros_type) + r"}~\texttt{" + escape(lk.name) + "} "
            + lk.role + "(" + parts + ")")


def _topic(t: ast.Topic) -> str:
    s = r"\texttt{" + escape(t.msg_type) + r"}~\texttt{" + escape(t.field) + "}"
    if t.match is not None:
        s += r" matches: $" + _var(t.match) + "$"
    return s


def _decl(d: Union[ast.TypeDecl, ast.ConstDecl], explicit: bool) -> dict[str, str]:
    if isinstance(d, ast.TypeDecl):
        return {"name": name_to_latex(d.name), "sep": ":", "body": type_to_latex(d.type), "line": str(d.loc.line)}
    typed = f" : {type_to_latex(d.type)}{unit_to_latex(d.unit, True)}" if d.type is not None else ""
    return {"name": name_to_latex(d.name) + typed, "sep": "=",
            "body": expr_to_latex(d.value, explicit), "line": str(d.loc.line)}


def to_latex(spec: ast.Spec, document: bool = True, explicit: bool = False, header: bool = True) -> str:
    """LaTeX of a parsed RCL file, paper style.

    ``document=True`` gives a complete ``article`` (packages amssymb and
    tabularx); ``False`` only the blocks, for inclusion in another document.
    ``explicit``: see :func:`expr_to_latex`.  With ``header`` the first line
    is a comment naming the source file (``file:1``, nothing for text parsed
    without a file name) and "generated by rclverify"; each node's block
    starts with a comment giving its ``file:line``.  The output holds no
    timestamps and no absolute paths."""
    source = _source_name(spec.file)
    contexts = [[_decl(d, explicit) for d in c.decls] for c in spec.contexts]
    nodes = [{
        "name": escape(n.name),
        "where": _where(n.loc),
        "inputs": _io(n.inputs),
        "outputs": _io(n.outputs),
        "topics": [_topic(t) for t in n.topics],
        "assumes": [expr_to_latex(c.formula, explicit) for c in n.assumes],
        "guarantees": [expr_to_latex(c.formula, explicit) for c in n.guarantees],
        "timing": [_timing(c) for c in n.guarantees],
        "links": [_link(lk) for lk in n.links],
        "initially": [expr_to_latex(c.formula, explicit) for c in n.initially],
        "progress": [escape(progress_to_rcl(p)) for p in n.progress],
        "periodic": ["$" + _var(p.output) + "$, " + escape(p.amount)
                     + (r"~\textrm{" + escape(p.unit) + "}" if p.unit else "") for p in n.periodic],
        "transitions": [_transition(t) for t in n.transitions],
    } for n in spec.nodes]
    return _env().get_template("contracts.tex.j2").render(
        source=source, document=document, header=header, contexts=contexts, nodes=nodes)


def node_latex(node: ast.Node, explicit: bool = False) -> str:
    """The LaTeX block of one node (``\\paragraph`` and its table, after a
    comment with the node's ``file:line``): no preamble and no file header,
    for a document that shows many nodes under one preamble
    (:func:`document_frame`)."""
    return to_latex(ast.Spec((), (node,), file=node.loc.file), document=False, explicit=explicit, header=False)


def document_frame(sources: Sequence[str] = ()) -> tuple[str, str]:
    """``(begin, end)``: the text before the contract blocks of a complete
    document -- the header comment naming ``sources`` (the contract files,
    as given; none: no names), the ``article`` preamble and
    ``\\begin{document}`` -- and the text after them (``\\end{document}``).
    ``begin + blocks + end`` of :func:`node_latex` blocks is a document like
    :func:`to_latex`'s."""
    frame = _env().get_template("document.tex.j2").module
    names = ", ".join(s for s in (_source_name(str(x)) for x in sources) if s)
    header, begin, end = (getattr(frame, m) for m in ("header", "begin", "end"))  # the template's macros
    return str(header(names)) + str(begin()), str(end())


_TEX_SPECIAL = {"\\": r"\textbackslash{}", "{": r"\{", "}": r"\}", "$": r"\$", "&": r"\&", "#": r"\#",
                "_": r"\_", "%": r"\%", "~": r"\textasciitilde{}", "^": r"\textasciicircum{}"}


def _tex_escape(text: str) -> str:
    """``text`` with LaTeX's special characters escaped (string literals)."""
    return "".join(_TEX_SPECIAL.get(ch, ch) for ch in text)
