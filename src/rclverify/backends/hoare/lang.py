"""The hoare backend's imperative language: immutable AST, parser and printer.

The paper models the Radiation Sensor node "as a simple program in a Hoare
Logic-style language" (shared/reference, lines 1477-1491) and proves its
guarantee by hand (appendix B, lines 1984-).  This module gives that language
a concrete, checkable form (grammar: ``imp.lark``):

* declarations: ``var x, y : T;`` where ``T`` is ``REAL``, ``INTEGER``,
  ``NATURAL``, ``BOOL`` or a type name of the RCL context (``RadStat``), and
  ``extern f : T1 x T2 --> T;`` for uninterpreted functions;
* statements: ``x := e``, ``if c then S [elif c then S]* [else S] end``, the
  paper's ``IF (c) THEN s [ELSE s]`` (one statement per branch),
  ``while c invariant I do S end`` and ``skip``; ``;`` between statements is
  optional;
* expressions: ``-> or and not``, comparisons (``=`` is ``==``),
  ``+ - * /``, unary ``-``, numbers, ``TRUE``/``FALSE``, names (variables and
  the context's enumeration values), calls ``f(e, ...)`` and ``old(x)`` (the
  value ``x`` had when the program started; meant for loop invariants).

Locations are excluded from equality, so ``parse_program(to_text(p)) == p``.

Public entry points
-------------------
``parse_program(text, file)`` / ``parse_program_file(path, display)`` -> :class:`Program`
``parse_expression(text, file, line, col)`` -> :data:`Expr`
``to_text(program)`` -> ``str``; ``expr_text(expr)`` -> ``str``; ``stmt_header(stmt)`` -> ``str``

Every parse error is an :class:`~rclverify.lang.errors.RclError` located in the
program file (``file:line:col``).  The printer is :mod:`.printer`'s,
re-exported here.
"""
from __future__ import annotations

from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import Any

from lark import Lark, Token, Transformer, v_args
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken, VisitError

from rclverify.lang import typeexpr
from rclverify.lang.ast import Loc, unhandled
from rclverify.lang.parser import describe_terminal, lark_cache_file
from rclverify.lang.errors import RclError, error

from rclverify.backends.hoare.nodes import (  # re-exported: the language's syntax, one namespace
    NOLOC, Num, BoolConst, Name, Old, Call, UnOp, BinOp, COMPARISONS, CONNECTIVES, Unary, Binary, Expr, Assign,
    If, While, Skip, Stmt, VarDecl, ExternDecl, Program)
from rclverify.lang.source import decode_text
from rclverify.backends.hoare.printer import expr_text, stmt_header, to_text  # re-exported: the language's printer


# --------------------------------------------------------------------------
# Parser
# --------------------------------------------------------------------------

_FRIENDLY = {"NAME": "a name", "NUMBER": "a number", "CMP_OP": "a comparison", "$END": "end of file"}


@lru_cache(maxsize=1)
def _lark() -> Lark:
    grammar = resources.files("rclverify.backends.hoare").joinpath("imp.lark").read_text(encoding="utf-8")
    # the analysed tables kept by lark as the RCL grammar's are (lang/parser.py: lark_cache_file):
    # building them cost 0.11 s in every process that reads a Hoare program or diagnoses its triples
    return Lark(grammar, parser="lalr", start=["start", "expr"], propagate_positions=True,
                maybe_placeholders=True, cache=lark_cache_file("hoare"))


def _describe(term: str) -> str:
    return describe_terminal(_lark(), term, _FRIENDLY)


def _block(stmts: Any) -> tuple[Stmt, ...]:
    if stmts is None:
        return ()
    if isinstance(stmts, tuple):
        return stmts
    return (stmts,)


class _ToAst(Transformer[Token, Any]):
    """Builds the immutable AST; ``dline``/``dcol`` shift locations."""

    def __init__(self, file: str, dline: int = 0, dcol: int = 0) -> None:
        super().__init__()
        self.file, self.dline, self.dcol = file, dline, dcol

    def _loc(self, m: Any) -> Loc:
        if getattr(m, "empty", True) and not isinstance(m, Token):
            return Loc(self.file)
        line, col, end_line, end_col = m.line, m.column, m.end_line, m.end_column
        if line == 1:
            col += self.dcol
        if end_line == 1:
            end_col += self.dcol
        return Loc(self.file, line + self.dline, col, end_line + self.dline, end_col)

    # -- declarations ----------------------------------------------------------
    def start(self, c: list[Any]) -> Program:
        decls, body = c[:-1], c[-1]
        vars_ = tuple(d for group in decls if group[0] == "var" for d in group[1])
        externs = tuple(d for group in decls if group[0] == "extern" for d in group[1])
        return Program(vars_, externs, body, self.file)

    def _names(self, c: list[Any]) -> list[Token]:
        return [t for t in c[:-1]]

    def var_decl(self, c: list[Any]) -> tuple[str, tuple[VarDecl, ...]]:
        return ("var", tuple(VarDecl(str(t), c[-1], self._loc(t)) for t in self._names(c)))

    def extern_decl(self, c: list[Any]) -> tuple[str, tuple[ExternDecl, ...]]:
        return ("extern", tuple(ExternDecl(str(t), c[-1], self._loc(t)) for t in self._names(c)))

    @v_args(meta=True)
    def real(self, meta: Any, c: list[Any]) -> typeexpr.TBase:
        return typeexpr.TBase("REAL", self._loc(meta))

    @v_args(meta=True)
    def integer(self, meta: Any, c: list[Any]) -> typeexpr.TBase:
        return typeexpr.TBase("INTEGER", self._loc(meta))

    @v_args(meta=True)
    def natural(self, meta: Any, c: list[Any]) -> typeexpr.TBase:
        return typeexpr.TBase("NATURAL", self._loc(meta))

    @v_args(meta=True)
    def bool(self, meta: Any, c: list[Any]) -> typeexpr.TBase:
        return typeexpr.TBase("BOOL", self._loc(meta))

    @v_args(meta=True)
    def named_type(self, meta: Any, c: list[Any]) -> typeexpr.TName:
        return typeexpr.TName(str(c[0]), self._loc(meta))

    @v_args(meta=True)
    def func_type(self, meta: Any, c: list[Any]) -> typeexpr.TFunc:
        return typeexpr.TFunc(tuple(c[:-1]), c[-1], self._loc(meta))

    # -- statements --------------------------------------------------------------
    def stmts(self, c: list[Any]) -> tuple[Stmt, ...]:
        return tuple(s for s in c if s is not None)

    @v_args(meta=True)
    def assign(self, meta: Any, c: list[Any]) -> Assign:
        return Assign(str(c[0]), c[1], self._loc(meta))

    @v_args(meta=True)
    def if_lower(self, meta: Any, c: list[Any]) -> If:
        cond, then_, *elifs, else_ = c
        tail: tuple[Stmt, ...] = _block(else_)
        for e_cond, e_body, e_loc in reversed(elifs):
            tail = (If(e_cond, e_body, tail, e_loc),)
        return If(cond, then_, tail, self._loc(meta))

    @v_args(meta=True)
    def elif_clause(self, meta: Any, c: list[Any]) -> tuple[Expr, tuple[Stmt, ...], Loc]:
        return (c[0], c[1], self._loc(meta))

    @v_args(meta=True)
    def if_upper(self, meta: Any, c: list[Any]) -> If:
        return If(c[0], _block(c[1]), _block(c[2]), self._loc(meta))

    @v_args(meta=True)
    def while_stmt(self, meta: Any, c: list[Any]) -> While:
        cond, *invs, body = c
        inv = invs[0]
        for more in invs[1:]:
            inv = Binary("and", inv, more, inv.loc)
        return While(cond, inv, body, self._loc(meta))

    def invariant(self, c: list[Any]) -> Expr:
        return c[0]  # type: ignore[no-any-return]

    @v_args(meta=True)
    def skip(self, meta: Any, c: list[Any]) -> Skip:
        return Skip(self._loc(meta))

    # -- expressions -----------------------------------------------------------------
    def _bin(self, op: BinOp, meta: Any, c: list[Any]) -> Binary:
        return Binary(op, c[0], c[-1], self._loc(meta))

    @v_args(meta=True)
    def implies(self, meta: Any, c: list[Any]) -> Binary:
        return self._bin("->", meta, c)

    @v_args(meta=True)
    def or_(self, meta: Any, c: list[Any]) -> Binary:
        return self._bin("or", meta, c)

    @v_args(meta=True)
    def and_(self, meta: Any, c: list[Any]) -> Binary:
        return self._bin("and", meta, c)

    @v_args(meta=True)
    def not_(self, meta: Any, c: list[Any]) -> Unary:
        return Unary("not", c[-1], self._loc(meta))

    @v_args(meta=True)
    def compare(self, meta: Any, c: list[Any]) -> Binary:
        op = str(c[1])
        return Binary("==" if op == "=" else op, c[0], c[2], self._loc(meta))  # type: ignore[arg-type]

    @v_args(meta=True)
    def add(self, meta: Any, c: list[Any]) -> Binary:
        return self._bin("+", meta, c)

    @v_args(meta=True)
    def sub(self, meta: Any, c: list[Any]) -> Binary:
        return self._bin("-", meta, c)

    @v_args(meta=True)
    def mul(self, meta: Any, c: list[Any]) -> Binary:
        return self._bin("*", meta, c)

    @v_args(meta=True)
    def div(self, meta: Any, c: list[Any]) -> Binary:
        return self._bin("/", meta, c)

    @v_args(meta=True)
    def minus(self, meta: Any, c: list[Any]) -> Unary:
        return Unary("-", c[0], self._loc(meta))

    @v_args(meta=True)
    def number(self, meta: Any, c: list[Any]) -> Num:
        return Num(str(c[0]), self._loc(meta))

    @v_args(meta=True)
    def true(self, meta: Any, c: list[Any]) -> BoolConst:
        return BoolConst(True, self._loc(meta))

    @v_args(meta=True)
    def false(self, meta: Any, c: list[Any]) -> BoolConst:
        return BoolConst(False, self._loc(meta))

    @v_args(meta=True)
    def name(self, meta: Any, c: list[Any]) -> Name:
        return Name(str(c[0]), self._loc(meta))

    @v_args(meta=True)
    def call(self, meta: Any, c: list[Any]) -> Call:
        return Call(str(c[0]), tuple(a for a in c[1:] if a is not None), self._loc(meta))

    @v_args(meta=True)
    def old(self, meta: Any, c: list[Any]) -> Old:
        return Old(str(c[0]), self._loc(meta))


def _syntax_error(exc: UnexpectedInput, file: str, text: str, dline: int, dcol: int) -> RclError:
    line = getattr(exc, "line", 0) or 0
    col = getattr(exc, "column", 0) or 0
    expected: Any
    if isinstance(exc, UnexpectedEOF) or (isinstance(exc, UnexpectedToken) and exc.token.type == "$END"):
        lines = text.splitlines() or [""]
        line, col = len(lines), len(lines[-1]) + 1
        msg = "unexpected end of program"
        expected = getattr(exc, "expected", None)
    elif isinstance(exc, UnexpectedToken):
        msg = f"unexpected {exc.token.value!r}"
        expected = exc.expected
    elif isinstance(exc, UnexpectedCharacters):
        msg = f"unexpected character {exc.char!r}"
        expected = exc.allowed
    else:  # pragma: no cover - lark has no other subclasses today
        msg, expected = str(exc).splitlines()[0], None
    if expected:
        names = sorted({_describe(t) for t in expected if not t.startswith("__")})
        if names:
            msg += "; expected " + (names[0] if len(names) == 1 else "one of " + ", ".join(names))
    if line == 1:
        col += dcol
    return RclError([error(Loc(file, line + dline, col), msg, "E-syntax")])


@lru_cache(maxsize=512)
def _tree(text: str, start: str) -> Any:
    # Memoised apart from the locations: the same binding text (``x``) is
    # written at a different place of the plan for every node, and lark's
    # parse is most of the cost; the transformer below does not change the tree.
    return _lark().parse(text, start=start)


@lru_cache(maxsize=512)
def _parse(text: str, file: str, start: str, dline: int, dcol: int) -> Any:
    # Memoised: the AST is immutable (frozen dataclasses and tuples), and one
    # process checks many triples over the same program file and bindings.
    try:
        tree = _tree(text, start)
    except UnexpectedInput as exc:
        raise _syntax_error(exc, file, text, dline, dcol) from None
    try:
        return _ToAst(file, dline, dcol).transform(tree)
    except VisitError as exc:  # pragma: no cover - transformer bugs are internal errors
        raise exc.orig_exc from exc


def parse_program(text: str, file: str = "<string>") -> Program:
    """Parse a program's text; ``file`` names it in locations and errors.

    Returns a :class:`Program`; raises :class:`RclError` (code ``E-syntax``)
    located at the offending token.
    """
    return _parse(text, file, "start", 0, 0)  # type: ignore[no-any-return]


def parse_program_file(path: str | Path, display: str | None = None) -> Program:
    """Read and parse a program file.

    ``display`` is the name used in locations (e.g. the workspace-relative
    path); defaults to ``str(path)``.  An unreadable file is an
    :class:`RclError` (code ``E-io``) located at line 1.
    """
    name = display if display is not None else str(path)
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise RclError([error(Loc(name, 1, 1), f"cannot read program: {exc.strerror or exc}", "E-io")]) from None
    return parse_program(decode_text(data, name), name)


def parse_expression(text: str, file: str = "<string>", line: int = 1, col: int = 1) -> Expr:
    """Parse one expression of the language (e.g. a plan binding ``radiation_at(i)``).

    ``line``/``col`` say where ``text`` starts in ``file``; raises
    :class:`RclError` located there.
    """
    return _parse(text, file, "expr", line - 1, col - 1)  # type: ignore[no-any-return]


__all__ = ["Assign", "BinOp", "Binary", "BoolConst", "COMPARISONS", "CONNECTIVES", "Call", "Expr", "ExternDecl", "If",
           "NOLOC", "Name", "Num", "Old", "Program", "Skip", "Stmt", "UnOp", "Unary", "VarDecl", "While",
           "expr_text", "parse_expression", "parse_program", "parse_program_file", "stmt_header", "to_text"]
