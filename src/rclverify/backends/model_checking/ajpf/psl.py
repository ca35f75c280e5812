"""AJPF's property specification language (PSL): AST, parser, printer.

AJPF checks linear temporal properties of BDI agents.  A property is built
from BDI propositions about one agent's mental state and LTL operators
(paper lines 1366-1394, where the Agent's guarantees become such properties):

======================  ===================================================
``B(ag, f)``            agent ``ag`` believes ``f``
``G(ag, f)``            ``ag`` has the goal ``f``
``D(ag, f)``            the last action ``ag`` performed was ``f``
``I(ag, f)``            ``ag`` has an intention ``f``
``ItD(ag, f)``          ``ag`` intends to do the action ``f``
``P(f)``                ``f`` is a percept of the environment
``T`` / ``F``           true / false
``~ p``                 negation (AJPF accepts it next to a proposition only)
``p & q``, ``p || q``   conjunction, disjunction
``p -> q``              implication (shorthand for ``~p || q``)
``[] p``, ``<> p``      always, eventually
``p U q``, ``p R q``    until, release
======================  ===================================================

``f`` is a ground first-order term: ``going(4)``, ``movebase_result(_, 3)``
(``_`` matches any value).

Operator binding in AJPF's own grammar, loosest first: ``U``, ``R``, ``->``,
``&``, ``||``, then the unary ``[]``, ``<>``, ``~`` -- note that ``||``
binds *tighter* than ``&`` there.  To keep a text's meaning obvious to its
reader, :func:`parse` rejects ``&`` mixed with ``||`` and chained ``->``
without parentheses; :func:`to_text` always writes the parentheses and puts
negations next to propositions, so its output means the same under AJPF's
grammar and under the usual reading.  The negation normal form and the
simplification are :mod:`.psl_normal`'s, re-exported here with the AST.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

from rclverify.backends.model_checking.ajpf.psl_ast import (  # re-exported: one namespace, psl.Term, psl.parse
    Sym, Num, Wild, Compound, Term, MODALITIES, Modal, Percept, Const, Not, And, Or, Implies, Always,
    Eventually, Until, Release, Formula, TRUE, FALSE, MAX_NESTING, depth, PslSyntaxError, propositions)
from rclverify.backends.model_checking.ajpf.psl_normal import (  # re-exported: psl.simplify, psl.negate
    ATOMS, constant_value, negate, nnf, simplify)


# ---------------------------------------------------------------------------
# Parser
# ---------------------------------------------------------------------------

_TOKEN = re.compile(r"\s*(?:(\[\])|(<>)|(->)|(\|\|)|([&~(),])|([A-Za-z_][A-Za-z0-9_]*)|(\d+(?:\.\d+)?))")


@dataclass(frozen=True)
class _Tok:
    kind: str  # "op", "name", "num", "end"
    text: str
    col: int


def _tokens(text: str) -> list[_Tok]:
    out: list[_Tok] = []
    pos = 0
    while True:
        while pos < len(text) and text[pos].isspace():
            pos += 1
        if pos >= len(text):
            out.append(_Tok("end", "", pos + 1))
            return out
        m = _TOKEN.match(text, pos)
        if m is None or m.end() == pos:
            raise PslSyntaxError(f"unexpected character {text[pos]!r}", pos + 1)
        col = m.start(m.lastindex or 0) + 1
        value = m.group(m.lastindex or 0)
        kind = "name" if m.lastindex == 6 else "num" if m.lastindex == 7 else "op"
        out.append(_Tok(kind, value, col))
        pos = m.end()


class _Parser:
    _BINARY = (("U", "until"), ("R", "release"), ("->", "implies"), ("&", "and"), ("||", "or"))

    def __init__(self, text: str) -> None:
        self.toks = _tokens(text)
        self.i = 0
        self.nesting = 0

    def deeper(self, col: int) -> None:
        self.nesting += 1
        if self.nesting > MAX_NESTING:
            raise PslSyntaxError(f"nested deeper than {MAX_NESTING} levels (the limit of properties and terms)", col)

    @property
    def tok(self) -> _Tok:
        return self.toks[self.i]

    def take(self, text: str | None = None) -> _Tok:
        t = self.tok
        if text is not None and t.text != text:
            shown = repr(t.text) if t.kind != "end" else "end of property"
            raise PslSyntaxError(f"expected {text!r}, found {shown}", t.col)
        self.i += 1
        return t

    def formula(self) -> Formula:
        f, _ = self.level(0)
        if self.tok.kind != "end":
            raise PslSyntaxError(f"unexpected {self.tok.text!r}", self.tok.col)
        if depth(f) > MAX_NESTING:  # chains of U and R nest without parentheses
            raise PslSyntaxError(f"nested deeper than {MAX_NESTING} levels (the limit of properties and terms)", 1)
        return f

    def level(self, k: int) -> tuple[Formula, str | None]:
        """Parse binary level ``k``; also return the operator it produced bare."""
        if k == len(self._BINARY):
            return self.unary(), None
        op, name = self._BINARY[k]
        left, left_bare = self.level(k + 1)
        if self.tok.text != op:
            return left, left_bare
        items = [left]
        bares = [left_bare]
        while self.tok.text == op:
            t = self.take()
            if name == "implies" and len(items) == 2:
                raise PslSyntaxError("chained '->' is ambiguous; add parentheses", t.col)
            right, right_bare = self.level(k + 1)
            items.append(right)
            bares.append(right_bare)
        if name in ("and", "or"):
            other = "||" if op == "&" else "&"
            if other in bares:
                raise PslSyntaxError("'&' and '||' mixed without parentheses (AJPF binds '||' tighter); "
                                     "add parentheses", self.tok.col)
        if name == "and":
            return And(tuple(items)), op
        if name == "or":
            return Or(tuple(items)), op
        f = items[0]
        for r in items[1:]:
            f = Implies(f, r) if name == "implies" else Until(f, r) if name == "until" else Release(f, r)
        return f, op

    def unary(self) -> Formula:
        self.deeper(self.tok.col)
        try:
            return self._unary()
        finally:
            self.nesting -= 1

    def _unary(self) -> Formula:
        t = self.tok
        if t.text == "[]":
            self.take()
            return Always(self.unary())
        if t.text == "<>":
            self.take()
            return Eventually(self.unary())
        if t.text == "~":
            self.take()
            return Not(self.unary())
        if t.text == "(":
            self.take()
            f, _ = self.level(0)
            self.take(")")
            return f
        if t.kind == "name":
            if t.text in ("T", "F"):
                self.take()
                return Const(t.text == "T")
            if t.text in MODALITIES:
                self.take()
                self.take("(")
                agent = self.take()
                if agent.kind != "name" or not agent.text[:1].islower():
                    raise PslSyntaxError("expected an agent name (lower-case)", agent.col)
                self.take(",")
                term = self.term()
                self.take(")")
                return Modal(t.text, agent.text, term)
            if t.text == "P":
                self.take()
                self.take("(")
                term = self.term()
                self.take(")")
                return Percept(term)
        shown = repr(t.text) if t.kind != "end" else "end of property"
        raise PslSyntaxError(f"expected a proposition (B, G, D, I, ItD, P, T, F), '(' or an operator; found {shown}",
                             t.col)

    def term(self) -> Term:
        t = self.take()
        if t.kind == "num":
            return Num(t.text)
        if t.kind != "name":
            shown = repr(t.text) if t.kind != "end" else "end of property"
            raise PslSyntaxError(f"expected a term, found {shown}", t.col)
        if t.text == "_":
            return Wild()
        if not (t.text[0].islower() or t.text[0].isdigit()):
            raise PslSyntaxError(f"{t.text!r} is a variable; AJPF properties are ground (use '_' for any value)",
                                 t.col)
        if self.tok.text != "(":
            return Sym(t.text)
        self.deeper(self.tok.col)
        self.take("(")
        args = [self.term()]
        while self.tok.text == ",":
            self.take()
            args.append(self.term())
        self.take(")")
        self.nesting -= 1
        return Compound(t.text, tuple(args))


def parse(text: str) -> Formula:
    """Parse one AJPF property text (without the ``<name>:`` label).

    Returns the formula as written (negations are not pushed inwards; see
    :func:`nnf`).  Raises :class:`PslSyntaxError` (with a 1-based column)
    on malformed input, on non-ground terms, on ``&``/``||`` mixed or
    ``->`` chained without parentheses, and on nesting deeper than
    :data:`MAX_NESTING`.
    """
    return _Parser(text).formula()


# ---------------------------------------------------------------------------
# Printer
# ---------------------------------------------------------------------------


def term_text(t: Term) -> str:
    """``going(4)``, ``movebase_result(_, 3)``, ``danger_red``."""
    if isinstance(t, Sym):
        return t.name
    if isinstance(t, Num):
        return t.text
    if isinstance(t, Wild):
        return "_"
    return f"{t.name}({', '.join(term_text(a) for a in t.args)})"


def _is_atom(f: Formula) -> bool:
    return isinstance(f, ATOMS)


def to_text(f: Formula) -> str:
    """Print ``f`` in AJPF's concrete syntax (one line).

    Binary operands that are themselves binary are parenthesised; the
    operand of ``~`` is a proposition or parenthesised, the operand of
    ``<>`` is a proposition or its negation, the operand of ``[]`` may
    also be ``<>`` of those -- the shapes AJPF's grammar accepts bare.
    """
    if isinstance(f, Const):
        return "T" if f.value else "F"
    if isinstance(f, Modal):
        return f"{f.op}({f.agent}, {term_text(f.term)})"
    if isinstance(f, Percept):
        return f"P({term_text(f.term)})"
    if isinstance(f, Not):
        return "~" + (to_text(f.operand) if _is_atom(f.operand) else f"({to_text(f.operand)})")
    if isinstance(f, Eventually):
        return "<> " + (to_text(f.operand) if _not_level(f.operand) else f"({to_text(f.operand)})")
    if isinstance(f, Always):
        op = f.operand
        bare = _not_level(op) or (isinstance(op, Eventually) and _not_level(op.operand))
        return "[] " + (to_text(op) if bare else f"({to_text(op)})")
    if isinstance(f, (And, Or)):
        sep = " & " if isinstance(f, And) else " || "
        return sep.join(_operand(p) for p in f.parts)
    if isinstance(f, Implies):
        return f"{_operand(f.left)} -> {_operand(f.right)}"
    if isinstance(f, Until):
        return f"{_operand(f.left)} U {_operand(f.right)}"
    if isinstance(f, Release):
        return f"{_operand(f.left)} R {_operand(f.right)}"
    raise TypeError(f"not a PSL formula: {f!r}")


def _not_level(f: Formula) -> bool:
    return _is_atom(f) or (isinstance(f, Not) and _is_atom(f.operand))


def _operand(f: Formula) -> str:
    text = to_text(f)
    return f"({text})" if isinstance(f, (And, Or, Implies, Until, Release)) else text


__all__ = ["And", "Always", "Compound", "Const", "Eventually", "FALSE", "Formula", "Implies", "MAX_NESTING",
           "MODALITIES", "Modal", "Not", "Num", "Or", "Percept", "PslSyntaxError", "Release", "Sym", "TRUE", "Term",
           "Until", "Wild", "constant_value", "depth", "negate", "nnf", "parse", "propositions", "simplify",
           "term_text", "to_text"]
