"""The AST builder of the RCL parser: a lark transformer that makes the
immutable AST (:mod:`rclverify.lang.ast`) while the LALR(1) automaton of
``rcl.lark`` reduces, so no parse tree is ever built.

A literal is checked as it is read (:mod:`rclverify.lang.literals`,
``E-number``) and an ``and``/``or`` chain becomes a balanced tree
(:mod:`rclverify.lang.chains`, shared with the printer).  :mod:`rclverify.lang.parser` drives it; the grammar follows the
paper's EBNF table and appendix A (see ``rcl.lark``).
"""
from __future__ import annotations

import dataclasses
from typing import Any, cast

from lark import Token, Transformer

from rclverify.lang import ast

from rclverify.lang import typeexpr
from rclverify.lang.builder_types import TypeRules
from rclverify.lang.chains import balanced
from rclverify.lang.errors import RclError, error
from rclverify.lang.lark_children import _Spanned, _vals
from rclverify.lang.literals import numeral_problem, unquote

class ToAst(TypeRules, Transformer[Token, Any]):
    """Builds the immutable AST while the LALR parser reduces.

    Children arrive with all tokens kept; a node's location runs from the
    start of its first child to the end of its last one.  ``file``, ``dline``
    and ``dcol`` (set by the parser for each run) offset locations for a
    formula embedded in another file (first line shifted by ``dcol``)."""

    def __init__(self) -> None:
        super().__init__()
        self.reset("<string>", 0, 0)

    def reset(self, file: str, dline: int, dcol: int) -> None:
        """Prepare for one parse of ``file`` (offsets as in :func:`parse_formula`)."""
        self.file, self.dline, self.dcol = file, dline, dcol
        self.units_seen = False  # a UNIT token was read (Spec.has_units)
        # id(node) -> (node, span with the parentheses) for parenthesised
        # expressions: a parent spans its operand's parentheses, while the
        # operand's own location is the text inside them.  The node is held
        # so that its id stays unique for the whole parse.
        self.wrapped: dict[int, tuple[Any, ast.Loc]] = {}

    # -- locations -------------------------------------------------------
    def _start(self, x: Any) -> tuple[int, int]:
        if isinstance(x, Token):
            line = x.line or 0
            return line + self.dline, (x.column or 0) + (self.dcol if line == 1 else 0)
        loc = self.wrapped[id(x)][1] if id(x) in self.wrapped else x.loc
        return loc.line, loc.col

    def _end(self, x: Any) -> tuple[int, int]:
        if isinstance(x, Token):
            end_line = x.end_line or 0
            return end_line + self.dline, (x.end_column or 0) + (self.dcol if end_line == 1 else 0)
        loc = self.wrapped[id(x)][1] if id(x) in self.wrapped else x.loc
        return loc.end_line, loc.end_col

    def _span(self, c: list[Any]) -> ast.Loc:
        first, last = c[0], c[-1]  # usually positioned; else skip placeholders
        if first is None or not (isinstance(first, Token) or hasattr(first, "loc")):
            first = next((x for x in c if isinstance(x, Token) or hasattr(x, "loc")), None)
            if first is None:
                return ast.Loc(self.file)
        if last is None or not (isinstance(last, Token) or hasattr(last, "loc")):
            last = next(x for x in reversed(c) if isinstance(x, Token) or hasattr(x, "loc"))
        # _start/_end inlined: this runs once per AST node (hot in parsing).
        wrapped = self.wrapped
        if isinstance(first, Token):
            sl = first.line or 0
            sc = (first.column or 0) + (self.dcol if sl == 1 else 0)
            sl += self.dline
        else:
            w = wrapped.get(id(first)) if wrapped else None
            loc = w[1] if w is not None else first.loc
            sl, sc = loc.line, loc.col
        if isinstance(last, Token):
            el = last.end_line or 0
            ec = (last.end_column or 0) + (self.dcol if el == 1 else 0)
            el += self.dline
        else:
            w = wrapped.get(id(last)) if wrapped else None
            loc = w[1] if w is not None else last.loc
            el, ec = loc.end_line, loc.end_col
        return ast.Loc(self.file, sl, sc, el, ec)

    # -- top level -----------------------------------------------------------
    def start(self, c: list[Any]) -> ast.Spec:
        ctx = tuple(i for i in c if isinstance(i, ast.Context))
        nodes = tuple(i for i in c if isinstance(i, ast.Node))
        return ast.Spec(ctx, nodes, file=self.file, has_units=self.units_seen)

    def context_clause(self, c: list[Any]) -> ast.Context:
        return ast.Context(tuple(_vals(c)), self._span(c))

    def type_decl(self, c: list[Any]) -> ast.TypeDecl:
        v = _vals(c)
        return ast.TypeDecl(str(v[0]), v[1], self._span(c))

    def const_decl(self, c: list[Any]) -> ast.ConstDecl:
        v = _vals(c)
        if len(v) == 4:  # NAME type [UNIT] expr
            return ast.ConstDecl(str(v[0]), v[3], v[1], self._span(c), self._unit(v[2]))
        return ast.ConstDecl(str(v[0]), v[1], None, self._span(c))

    def _unit(self, tok: Token | None) -> ast.UnitAnn | None:
        """The :class:`~rclverify.lang.ast.UnitAnn` of a ``UNIT`` token
        (``None`` for an absent one): its text without the brackets, as
        :func:`~rclverify.lang.units.normal_text` writes it (a blank between
        two symbols is a product, ``[m s]`` is ``m*s``, never ``ms``),
        located at the opening bracket."""
        if tok is None:
            return None
        self.units_seen = True
        from rclverify.lang.units import normal_text  # deferred: start-up (loads rclverify.lang.units, difflib only when called)
        return ast.UnitAnn(normal_text(str(tok)[1:-1]), self._span([tok]))

    def node_clause(self, c: list[Any]) -> ast.Node:
        v = _vals(c)
        name, inputs, outputs = str(v[0]), v[1], v[2]
        rest = v[3:]
        topics: tuple[ast.Topic, ...] = ()
        if rest and rest[0][0] == "topics":
            topics = rest[0][1]
            rest = rest[1:]
        links = tuple(lk for kind, group in rest if kind == "links" for lk in group)
        assumes = tuple(cl for kind, cl in rest if kind == "assume")
        guarantees = tuple(cl for kind, cl in rest if kind == "guarantee")
        return ast.Node(name, inputs, outputs, topics, assumes, guarantees, self._span(c), links,
                        tuple(cl for kind, cl in rest if kind == "initially"),
                        tuple(p for kind, p in rest if kind == "progress"),
                        tuple(p for kind, p in rest if kind == "periodic"),
                        tuple(t for kind, t in rest if kind == "transition"))

    def inputs(self, c: list[Any]) -> tuple[ast.IOVar, ...]:
        return tuple(x for x in _vals(c) if x is not None)

    outputs = inputs

    def io_var(self, c: list[Any]) -> ast.IOVar:
        v = _vals(c)
        return ast.IOVar(str(v[0]), v[1], self._span(c), self._unit(v[2]))

    def topics(self, c: list[Any]) -> tuple[str, tuple[ast.Topic, ...]]:
        return ("topics", tuple(x for x in _vals(c) if x is not None))

    def topic(self, c: list[Any]) -> ast.Topic:
        v = _vals(c)
        match = v[2].value if v[2] is not None else None
        return ast.Topic(str(v[0]), str(v[1]), match, self._span(c), self._span([v[1]]))

    def topic_match(self, c: list[Any]) -> _Spanned:
        return _Spanned(_vals(c)[0], self._span(c))

    def assume(self, c: list[Any]) -> tuple[str, ast.Clause]:
        return ("assume", ast.Clause(_vals(c)[0], self._span(c)))

    def guarantee(self, c: list[Any]) -> tuple[str, ast.Clause]:
        v = _vals(c)
        trigger = v[1].value if len(v) > 1 and v[1] is not None else None
        deadline = v[2] if len(v) > 2 else None
        scope = v[3] if len(v) > 3 else None
        return ("guarantee", ast.Clause(v[0], self._span([x for x in c if x is not None]), trigger, deadline, scope))

    def scope(self, c: list[Any]) -> ast.Scope:
        return ast.Scope(tuple(str(x) for x in _vals(c)), self._span(c))

    def transition_deadline(self, c: list[Any]) -> tuple[str, ast.TransitionDeadline]:
        v = _vals(c)
        return ("transition", ast.TransitionDeadline(str(v[1]), v[0], self._span(c)))

    def initially(self, c: list[Any]) -> tuple[str, ast.Clause]:
        return ("initially", ast.Clause(_vals(c)[0], self._span(c)))

    def progress(self, c: list[Any]) -> tuple[str, ast.Progress]:
        kind = _vals(c)[0]
        return ("progress", ast.Progress(kind[0], kind[1], self._span(c)))

    def progress_eventually(self, c: list[Any]) -> tuple[str | None, str | None]:
        return (None, None)

    def progress_within(self, c: list[Any]) -> tuple[str | None, str | None]:
        v = _vals(c)
        return (str(v[0]), str(v[1]) if v[1] is not None else None)

    def periodic(self, c: list[Any]) -> tuple[str, ast.Periodic]:
        v = _vals(c)
        return ("periodic", ast.Periodic(v[0], str(v[1]), str(v[2]) if v[2] is not None else None,
                                         self._span(c)))

    def trigger(self, c: list[Any]) -> _Spanned:
        return _Spanned(_vals(c)[0], self._span(c))

    def deadline(self, c: list[Any]) -> ast.Deadline:
        v = _vals(c)
        unit = str(v[1]) if v[1] is not None else None
        return ast.Deadline(str(v[0]), unit, self._span([x for x in c if x is not None]))

    def services(self, c: list[Any]) -> tuple[str, tuple[ast.Link, ...]]:
        return ("links", tuple(x for x in _vals(c) if x is not None))

    actions = services

    def serves(self, c: list[Any]) -> str:
        return "serves"

    def calls(self, c: list[Any]) -> str:
        return "calls"

    def _link(self, kind: str, c: list[Any]) -> ast.Link:
        v = _vals(c)
        return ast.Link(kind, str(v[0]), str(v[1]), v[2], tuple(v[3:]), self._span(c), self._span([v[1]]))

    def service_link(self, c: list[Any]) -> ast.Link:
        return self._link("service", c)

    def action_link(self, c: list[Any]) -> ast.Link:
        return self._link("action", c)

    # -- expressions -----------------------------------------------------------
    def _bin(self, op: ast.BinaryOp, c: list[Any]) -> ast.Binary:
        return ast.Binary(op, c[0], c[2], self._span(c))

    def iff(self, c: list[Any]) -> ast.Binary:
        return self._bin("<=>", c)

    def implies(self, c: list[Any]) -> ast.Binary:
        return self._bin("->", c)

    def disj(self, c: list[Any]) -> ast.Binary:
        return self._chain("or", c)

    def conj(self, c: list[Any]) -> ast.Binary:
        return self._chain("and", c)

    def _chain(self, op: ast.BinaryOp, c: list[Any]) -> ast.Binary:
        """A flat ``a op b op c ...`` chain as a balanced tree (see
        :func:`balanced`): depth log2(n), so every recursive consumer copes
        with chains of any length."""
        if len(c) == 3:
            return ast.Binary(op, c[0], c[2], self._span(c))
        return balanced(op, c[0::2], lambda a, b: self._span([a, b]))  # type: ignore[no-any-return]

    def add(self, c: list[Any]) -> ast.Binary:
        return self._bin("+", c)

    def sub(self, c: list[Any]) -> ast.Binary:
        return self._bin("-", c)

    def mul(self, c: list[Any]) -> ast.Binary:
        return self._bin("*", c)

    def div(self, c: list[Any]) -> ast.Binary:
        return self._bin("/", c)

    def neg(self, c: list[Any]) -> ast.Unary:
        return ast.Unary("not", c[1], self._span(c))

    def minus(self, c: list[Any]) -> ast.Unary:
        return ast.Unary("-", c[1], self._span(c))

    def first_value(self, c: list[Any]) -> ast.First:
        return ast.First(c[2], self._span(c))

    def abs_value(self, c: list[Any]) -> ast.Unary:
        return ast.Unary("abs", c[2], self._span(c))

    def sqrt_value(self, c: list[Any]) -> ast.Unary:
        return ast.Unary("sqrt", c[2], self._span(c))

    def sin_value(self, c: list[Any]) -> ast.Unary:
        return ast.Unary("sin", c[2], self._span(c))

    def cos_value(self, c: list[Any]) -> ast.Unary:
        return ast.Unary("cos", c[2], self._span(c))

    def compare(self, c: list[Any]) -> ast.Compare:
        ops = cast("tuple[ast.CompareOp, ...]", tuple(str(t) for t in c[1::2]))
        return ast.Compare(ops, tuple(c[0::2]), self._span(c))

    def member(self, c: list[Any]) -> ast.Member:
        return ast.Member(c[0], c[2], False, self._span(c))

    def not_member(self, c: list[Any]) -> ast.Member:
        return ast.Member(c[0], c[2], True, self._span(c))

    def number(self, c: list[Any]) -> ast.NumLit:
        text, loc = str(c[0]), self._span([c[0]])
        problem = numeral_problem(text)
        if problem:
            raise RclError([error(loc, problem, "E-number")])
        unit = c[1] if len(c) > 1 else None
        if unit is not None:
            return ast.NumLit(text, self._span(c), self._unit(unit))
        return ast.NumLit(text, loc)

    def true(self, c: list[Any]) -> ast.BoolLit:
        return ast.BoolLit(True, self._span(c))

    def false(self, c: list[Any]) -> ast.BoolLit:
        return ast.BoolLit(False, self._span(c))

    def io_name(self, c: list[Any]) -> ast.Var:
        prefix, name = str(c[0]).split(".", 1)
        return ast.Var(name, prefix, self._span(c))  # type: ignore[arg-type]

    def plain_name(self, c: list[Any]) -> ast.Var:
        return ast.Var(str(c[0]), None, self._span(c))

    base_type_name = plain_name
    qualified_base = plain_name

    def apply(self, c: list[Any]) -> ast.Apply:
        v = _vals(c)
        return ast.Apply(v[0], tuple(a for a in v[1:] if a is not None), self._span(c))

    def _kind(self, kind: str, c: list[Token]) -> Token:
        return Token.new_borrow_pos("QUANT", kind, c[0])

    def forall(self, c: list[Token]) -> Token:
        return self._kind("forall", c)

    def exists(self, c: list[Token]) -> Token:
        return self._kind("exists", c)

    def exists_unique(self, c: list[Token]) -> Token:
        return self._kind("exists_unique", c)

    def quant(self, c: list[Any]) -> ast.Quant:
        v = _vals(c)
        return ast.Quant(str(v[0]), v[1], v[2], self._span(c))  # type: ignore[arg-type]

    def bindings(self, c: list[Any]) -> tuple[ast.Binding, ...]:
        return tuple(_vals(c))

    def binding(self, c: list[Any]) -> ast.Binding:
        v = _vals(c)
        names = tuple(str(n) for n in v[:-1])
        locs = tuple(self._span([n]) for n in v[:-1])
        domain = v[-1]
        if isinstance(domain, ast.Var) and domain.prefix is None:
            domain = typeexpr.TName(domain.name, domain.loc)
        return ast.Binding(names, domain, self._span(c), locs)

    def bound_name(self, c: list[Token]) -> Token:
        return c[0]  # the NAME token: its text and its position

    def set_lit(self, c: list[Any]) -> ast.SetLit:
        return ast.SetLit(tuple(x for x in _vals(c) if x is not None), self._span(c))

    def seq_lit(self, c: list[Any]) -> ast.SeqLit:
        return ast.SeqLit(tuple(x for x in _vals(c) if x is not None), self._span(c))

    def seq_range(self, c: list[Any]) -> ast.SeqRange:
        v = _vals(c)
        return ast.SeqRange(v[0], v[1], self._span(c))

    def string(self, c: list[Any]) -> ast.StrLit:
        return ast.StrLit(unquote(str(c[0])), self._span(c))

    def tuple_binder(self, c: list[Any]) -> list[Token]:
        return [t for t in _vals(c)]

    def tuple_quant(self, c: list[Any]) -> ast.TupleQuant:
        v = _vals(c)
        kind, names, domain, body = v[0], v[1], v[2], v[3]
        if isinstance(domain, ast.Var) and domain.prefix is None:
            domain = typeexpr.TName(domain.name, domain.loc)
        return ast.TupleQuant(str(kind), tuple(str(n) for n in names), domain, body,  # type: ignore[arg-type]
                              self._span(c), tuple(self._span([n]) for n in names))

    def tuple_lit(self, c: list[Any]) -> ast.TupleLit:
        return ast.TupleLit(tuple(_vals(c)), self._span(c))

    def paren(self, c: list[Any]) -> Any:
        e = c[1]
        if isinstance(e, ast.Binary):
            e = dataclasses.replace(e, parenthesised=True)
        self.wrapped[id(e)] = (e, self._span(c))
        return e
