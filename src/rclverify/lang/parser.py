"""RCL parser: Lark LALR(1) over ``rcl.lark``, building the AST as it reduces.

Public entry points
-------------------
``parse_text(text, file)``  -> :class:`~rclverify.lang.ast.Spec`
``parse_file(path)``        -> :class:`~rclverify.lang.ast.Spec`
``parse_files(paths)``      -> list of :class:`~rclverify.lang.ast.Spec`
``parse_formula(text, file, line, col)`` -> :data:`~rclverify.lang.ast.Expr`
  (a single formula, e.g. an environment fact in the plan; ``line``/``col``
  say where ``text`` starts in ``file`` so diagnostics point into it).

All raise :class:`~rclverify.lang.errors.RclError` with a located diagnostic
on malformed input: ``file:line:col: error: unexpected X; expected one of
A, B, ...`` (code ``E-syntax``), where the expected set is what the LALR
automaton would accept at that point, keywords included.  The grammar
follows the paper's EBNF table (shared/reference lines 499-555), its
listings (1131-1171) and appendix A (1890-1983); see ``rcl.lark`` for the
precedence table and the reserved words.

The AST is built by lark's inline transformer (no intermediate parse tree)
with the cyclic garbage collector paused, which keeps parsing linear in the
size of the system (bench/parse_scale.py).
"""
from __future__ import annotations

import dataclasses
from itertools import accumulate
import os
import re
import sys
import threading
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping, cast

import lark
from lark import Lark, Token, Transformer
from lark.parsers.lalr_analysis import Shift
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken

from rclverify.core.cache.heap import no_collection
from rclverify.lang import ast
from rclverify.lang.errors import Diagnostic, RclError, error

_FRIENDLY = {
    "NAME": "a name", "IO_NAME": "an in./out. name", "NUMBER": "a number", "ROS_TYPE": "a ROS type",
    "CMP_OP": "a comparison", "EXISTS_BANG": "'exists!'", "$END": "end of file",
    "BASE_TYPE": "REAL/INTEGER/NATURAL/BOOL/STRING",
    "QUALIFIED_BASE": "a qualified built-in such as REAL.REAL", "STRING_LIT": "a string", "LT": "'<'", "GT": "'>'",
    "UNIT": "a unit such as [m]",
}

# Terminals whose text is data; every other token (keywords, punctuation) is
# syntax, kept in the children only for its position.  "QUANT" is the
# quantifier-kind token the transformer itself makes.
_VALUE_TERMINALS = frozenset({"NAME", "IO_NAME", "NUMBER", "ROS_TYPE", "CMP_OP", "BASE_TYPE", "EXISTS_BANG",
                              "QUANT", "STRING_LIT", "QUALIFIED_BASE", "UNIT"})


def grammar_text() -> str:
    """The text of ``rcl.lark`` (for tools that build other lark parsers
    over the same grammar, e.g. the parse benchmark)."""
    return resources.files("rclverify.lang").joinpath("rcl.lark").read_text(encoding="utf-8")


def lark_cache_file(name: str) -> str | bool:
    """Where lark keeps the analysed LALR tables of the grammar ``name``
    (lark's own ``cache`` option): ``$XDG_CACHE_HOME/rclverify`` or
    ``~/.cache/rclverify``; the RCL, Hoare and Gwendolen grammars use it.
    Building the RCL tables costs about 0.25 s, a
    tenth of a doit run that re-parses one edited contract; loading them
    costs 0.02 s (docs/scale.md).  lark stores the sha256 of the grammar and
    options in the file and rebuilds (and rewrites) the tables when they
    differ, and falls back to building them when the file cannot be read or
    written.  Returns ``False`` (no cache) when the directory cannot be made."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    folder = os.path.join(base, "rclverify")
    try:
        os.makedirs(folder, exist_ok=True)
    except OSError:
        return False
    return os.path.join(folder, f"{name}-lark{lark.__version__}-py{sys.version_info[0]}{sys.version_info[1]}.cache")


@lru_cache(maxsize=1)
def _lark() -> Lark:
    """The LALR(1) parser with the AST builder applied during parsing
    (no intermediate parse tree).  ``keep_all_tokens`` keeps keywords and
    punctuation in the children so every AST node spans its full text."""
    return Lark(grammar_text(), parser="lalr", start=["start", "expr"], keep_all_tokens=True,
                maybe_placeholders=True, transformer=_BUILDER, cache=lark_cache_file("rcl"))


def describe_terminal(parser: Lark, term: str, friendly: Mapping[str, str]) -> str:
    """How a syntax error names the terminal ``term`` of ``parser``: the
    ``friendly`` wording when there is one, the literal text of a keyword or
    punctuation terminal in quotes, else the terminal's name in lower case.
    Shared by every Lark grammar of the project (RCL, the Hoare language)."""
    if term in friendly:
        return friendly[term]
    try:
        pattern = parser.get_terminal(term).pattern
    except KeyError:
        return term
    return f"'{pattern.value}'" if pattern.type == "str" else term.lower()


def _describe(term: str) -> str:
    return describe_terminal(_lark(), term, _FRIENDLY)


class _Spanned:
    """An intermediate value with the location of the text it came from."""

    __slots__ = ("value", "loc")

    def __init__(self, value: Any, loc: ast.Loc) -> None:
        self.value, self.loc = value, loc


def _is_syntax(x: Any) -> bool:
    return isinstance(x, Token) and x.type not in _VALUE_TERMINALS


def _vals(c: list[Any]) -> list[Any]:
    """The data children of a rule (syntax tokens dropped, placeholders kept)."""
    return [x for x in c if not (isinstance(x, Token) and x.type not in _VALUE_TERMINALS)]  # _is_syntax, inlined


class _ToAst(Transformer[Token, Any]):
    """Builds the immutable AST while the LALR parser reduces.

    Children arrive with all tokens kept; a node's location runs from the
    start of its first child to the end of its last one.  ``file``, ``dline``
    and ``dcol`` (set by :func:`_parse` for each run) offset locations for a
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
        from rclverify.lang.units import normal_text
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
                        tuple(p for kind, p in rest if kind == "periodic"))

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
        return ast.Topic(str(v[0]), str(v[1]), match, self._span(c))

    def topic_match(self, c: list[Any]) -> _Spanned:
        return _Spanned(_vals(c)[0], self._span(c))

    def assume(self, c: list[Any]) -> tuple[str, ast.Clause]:
        return ("assume", ast.Clause(_vals(c)[0], self._span(c)))

    def guarantee(self, c: list[Any]) -> tuple[str, ast.Clause]:
        v = _vals(c)
        trigger = v[1].value if len(v) > 1 and v[1] is not None else None
        deadline = v[2] if len(v) > 2 else None
        return ("guarantee", ast.Clause(v[0], self._span([x for x in c if x is not None]), trigger, deadline))

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
        return ast.Link(kind, str(v[0]), str(v[1]), v[2], tuple(v[3:]), self._span(c))

    def service_link(self, c: list[Any]) -> ast.Link:
        return self._link("service", c)

    def action_link(self, c: list[Any]) -> ast.Link:
        return self._link("action", c)

    # -- types ---------------------------------------------------------------
    def base_name(self, c: list[Token]) -> Token:
        return c[0]  # the BASE_TYPE token: its text and its position

    def base_type(self, c: list[Any]) -> ast.TBase:
        return ast.TBase(str(c[0]), self._span(c))  # type: ignore[arg-type]

    def named_type(self, c: list[Any]) -> ast.TName:
        return ast.TName(str(c[0]), self._span(c))

    def empty_type(self, c: list[Any]) -> ast.TEmpty:
        return ast.TEmpty(self._span(c))

    def alt(self, c: list[Any]) -> ast.Constructor:
        v = _vals(c)
        return ast.Constructor(str(v[0]), tuple(t for t in v[1:] if t is not None), self._span(c))

    def alt_type(self, c: list[Any]) -> ast.TypeExpr:
        alts: list[ast.Constructor] = _vals(c)
        if all(not a.args for a in alts):
            return ast.TEnum(tuple(a.name for a in alts), self._span(c))
        return ast.TConstructors(tuple(alts), self._span(c))

    def func_type(self, c: list[Any]) -> ast.TFunc:
        arrow = next(k for k, x in enumerate(c) if isinstance(x, Token) and x.value == "-->")
        args, res = _vals(c[:arrow]), _vals(c[arrow + 1:])
        result = res[0] if len(res) == 1 else ast.TTuple(tuple(res), self._span(c[arrow + 1:]))
        return ast.TFunc(tuple(args), result, self._span(c))

    def set_type(self, c: list[Any]) -> ast.TSet:
        return ast.TSet(_vals(c)[0], self._span(c))

    def seq_type(self, c: list[Any]) -> ast.TSeq:
        return ast.TSeq(_vals(c)[0], self._span(c))

    def tuple_type(self, c: list[Any]) -> ast.TTuple:
        return ast.TTuple(tuple(_vals(c)), self._span(c))

    def type_atom(self, c: list[Any]) -> Any:
        t = c[1]  # "(" type ")": the type itself, spanning its parentheses for its parent
        self.wrapped[id(t)] = (t, self._span(c))
        return t

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
            domain = ast.TName(domain.name, domain.loc)
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
        return ast.StrLit(_unquote(str(c[0])), self._span(c))

    def tuple_binder(self, c: list[Any]) -> list[Token]:
        return [t for t in _vals(c)]

    def tuple_quant(self, c: list[Any]) -> ast.TupleQuant:
        v = _vals(c)
        kind, names, domain, body = v[0], v[1], v[2], v[3]
        if isinstance(domain, ast.Var) and domain.prefix is None:
            domain = ast.TName(domain.name, domain.loc)
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


#: Most digits a numeral may have (before and after its point) and largest
#: magnitude of its exponent.  A literal within both limits has an exact value
#: of at most 2,001 digits, so every stage (Fraction arithmetic, Z3, printing
#: the value in JSON or text: Python refuses to print integers above 4,300
#: digits) handles it; a longer one is a located ``E-number`` error at parse
#: time (docs/rcl-language.md, "Robustness limits").
NUMERAL_DIGITS_LIMIT = 1000
NUMERAL_EXPONENT_LIMIT = 1000


def numeral_problem(text: str) -> str | None:
    """Why the numeral ``text`` (the ``NUMBER`` terminal of ``rcl.lark``:
    digits, an optional fraction, an optional exponent) is refused, or
    ``None`` when it is within :data:`NUMERAL_DIGITS_LIMIT` digits and its
    exponent within :data:`NUMERAL_EXPONENT_LIMIT` in magnitude."""
    mantissa, _, exponent = text.lower().partition("e")
    digits = len(mantissa) - ("." in mantissa)
    if digits > NUMERAL_DIGITS_LIMIT:
        return f"numeral too long: {digits} digits (limit {NUMERAL_DIGITS_LIMIT})"
    exp_digits = exponent.lstrip("+-").lstrip("0")
    if len(exp_digits) > 4 or (exp_digits and int(exp_digits) > NUMERAL_EXPONENT_LIMIT):
        return f"numeral's exponent too large (limit {NUMERAL_EXPONENT_LIMIT} in magnitude)"
    return None


#: Deepest nesting of expressions and types the parser accepts (AST depth;
#: parentheses alone do not count, a balanced ``and``/``or`` chain of n
#: operands counts log2(n)).  Deeper input is a located ``E-depth`` error
#: instead of a ``RecursionError`` in a later stage (docs/rcl-language.md).
NESTING_LIMIT = 200


def balanced(op: ast.BinaryOp, operands: list[Any], span: Callable[[Any, Any], ast.Loc]) -> Any:
    """The balanced tree of ``op`` over ``operands`` (n >= 1): the first
    ceil(n/2) operands form the left subtree, the rest the right one, so two
    and three operands give the left-nested tree a left-associative grammar
    gives.  ``span(first, last)`` is the location of a subtree.  Also used by
    the printer's round-trip check (printer.py); iterative (no recursion)."""
    if len(operands) == 1:
        return operands[0]
    # Build bottom-up over (lo, hi) ranges with an explicit post-order stack.
    result: dict[tuple[int, int], Any] = {}
    stack: list[tuple[int, int, bool]] = [(0, len(operands), False)]
    while stack:
        lo, hi, ready = stack.pop()
        if hi - lo == 1:
            result[(lo, hi)] = operands[lo]
            continue
        mid = lo + (hi - lo + 1) // 2
        if not ready:
            stack += [(lo, hi, True), (mid, hi, False), (lo, mid, False)]
            continue
        left, right = result.pop((lo, mid)), result.pop((mid, hi))
        result[(lo, hi)] = ast.Binary(op, left, right, span(operands[lo], operands[hi - 1]))
    return result[(0, len(operands))]


def _unquote(text: str) -> str:
    """The value of a ``STRING_LIT`` token: quotes removed, ``\\x`` -> ``x``."""
    return re.sub(r"\\(.)", r"\1", text[1:-1])


_BUILDER = _ToAst()
_LOCK = threading.Lock()


def _accepts(state: Any) -> set[str] | None:
    """Terminals the LALR automaton accepts in parser state ``state``.

    The expected set lark attaches to an error is either the contextual
    lexer's terminal set (which omits keywords the NAME pattern absorbs, and
    may include follow tokens of merged states) or the raw action-table row.
    Simulating the reductions for each candidate terminal, without touching the
    value stack, gives exactly the tokens that would let the parse continue.
    Returns ``None`` when ``state`` is not a lark ``ParserState``.
    """
    try:
        states = state.parse_conf.states
        end_state = state.parse_conf.end_state
        base_stack = list(state.state_stack)
    except AttributeError:
        return None
    accepted: set[str] = set()
    for term in states[base_stack[-1]]:
        if not term.isupper():
            continue
        stack = list(base_stack)
        while True:
            entry = states[stack[-1]].get(term)
            if entry is None:
                break
            action, arg = entry
            if action is Shift:
                accepted.add(term)
                break
            size = len(arg.expansion)
            if size:
                del stack[-size:]
            stack.append(states[stack[-1]][arg.origin.name][1])
            if term == "$END" and stack[-1] == end_state:
                accepted.add(term)
                break
    return accepted


def _unterminated_comment(text: str) -> int | None:
    """Offset of a ``/*`` that is never closed, or ``None``."""
    for m in _COMMENT_SCAN.finditer(text):
        if m.group(0) == "/*":
            return m.start()
    return None


_COMMENT_SCAN = re.compile(r"//[^\n]*|/\*.*?\*/|/\*", re.S)


def _line_col(text: str, offset: int) -> tuple[int, int]:
    line = text.count("\n", 0, offset) + 1
    return line, offset - (text.rfind("\n", 0, offset) + 1) + 1


def _syntax_error(exc: UnexpectedInput, file: str, text: str, dline: int, dcol: int) -> RclError:
    """Turn a lark exception into a located ``E-syntax`` diagnostic:
    ``unexpected X; expected one of A, B, ...`` at the offending token."""
    line = getattr(exc, "line", 0) or 0
    col = getattr(exc, "column", 0) or 0
    expected: Iterable[str] | None = _accepts(getattr(exc, "state", None))
    if expected is None:
        expected = getattr(exc, "expected", None) or getattr(exc, "allowed", None)
    hint = ""
    open_comment = _unterminated_comment(text)
    pos = getattr(exc, "pos_in_stream", None)
    if open_comment is not None and (pos is None or pos >= open_comment):
        line, col = _line_col(text, open_comment)
        msg, expected = "unterminated /* comment (no closing */)", None
    elif isinstance(exc, UnexpectedEOF) or (isinstance(exc, UnexpectedToken) and exc.token.type == "$END"):
        line, col = _line_col(text, len(text.rstrip()))
        msg = "unexpected end of input"
    elif isinstance(exc, UnexpectedToken):
        msg = f"unexpected {exc.token.value!r}"
        if exc.token.value == "=" and expected and "CMP_OP" in expected:
            hint = " (equality is written '==')"
    elif isinstance(exc, UnexpectedCharacters):
        msg = f"unexpected character {exc.char!r}"
    else:  # pragma: no cover - lark has no other subclasses today
        msg, expected = str(exc).splitlines()[0], None
    if expected:
        names = sorted({_describe(t) for t in expected})
        if names:
            msg += "; expected " + (names[0] if len(names) == 1 else "one of " + ", ".join(names))
    msg += hint
    if line == 1:
        col += dcol
    return RclError([error(ast.Loc(file, line + dline, col), msg, "E-syntax")])


def parse_text(text: str, file: str = "<string>") -> ast.Spec:
    """Parse a whole RCL file's text.  Raises :class:`RclError` on a syntax error.
    A UTF-8 byte-order mark left at the start of ``text`` is ignored
    (:mod:`rclverify.lang.source`)."""
    if text.startswith("\ufeff"):
        text = text[1:]
    return _parse(text, file, "start", 0, 0)  # type: ignore[no-any-return]


def parse_formula(text: str, file: str = "<string>", line: int = 1, col: int = 1) -> ast.Expr:
    """Parse one RCL formula (or term) starting at ``file:line:col``."""
    return _parse(text, file, "expr", line - 1, col - 1)  # type: ignore[no-any-return]


def _parse(text: str, file: str, start: str, dline: int, dcol: int) -> Any:
    parser = _lark()
    # parse trees and AST nodes hold no reference cycles; without the pause the collector
    # scans the growing heap again and again (about 2x slower at a thousand nodes, bench/parse_scale.py)
    with _LOCK, no_collection():
        _BUILDER.reset(file, dline, dcol)
        try:
            result = parser.parse(text, start=start)
        except UnexpectedInput as exc:
            raise _syntax_error(exc, file, text, dline, dcol) from None
        finally:
            _BUILDER.reset("<string>", 0, 0)
    check_nesting(result, text, dline)
    return result


#: Fields that hold subtrees, per AST class (leaves are absent).
_CHILD_FIELDS: dict[type, tuple[str, ...]] = {
    ast.Binary: ("left", "right"), ast.Unary: ("operand",), ast.Compare: ("operands",),
    ast.Member: ("elem", "collection"), ast.Apply: ("args",), ast.SetLit: ("items",), ast.SeqLit: ("items",),
    ast.TupleLit: ("items",), ast.Quant: ("bindings", "body"), ast.Binding: ("domain",),
    ast.TupleQuant: ("domain", "body"), ast.SeqRange: ("lo", "hi"), ast.ConstDecl: ("value", "type"),
    ast.TypeDecl: ("type",), ast.IOVar: ("type",), ast.TFunc: ("args", "result"), ast.TSet: ("elem",),
    ast.TSeq: ("elem",), ast.TTuple: ("elems",), ast.TConstructors: ("ctors",), ast.Constructor: ("args",),
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


def ast_from_tree(tree: Any, file: str = "<string>") -> Any:
    """The AST of a lark parse tree of ``rcl.lark`` built by another lark
    parser with ``keep_all_tokens=True`` and ``maybe_placeholders=True``
    (e.g. an Earley parser over the same grammar, in the parse benchmark)."""
    with _LOCK:
        _BUILDER.reset(file, 0, 0)
        try:
            return _BUILDER.transform(tree)
        finally:
            _BUILDER.reset("<string>", 0, 0)


def parse_file(path: str | Path) -> ast.Spec:
    """Read and parse an RCL file.  A missing/unreadable file is an RclError."""
    from rclverify.lang.source import decode_text
    p = Path(path)
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise RclError([error(ast.Loc(str(path), 1, 1), f"cannot read RCL file: {exc.strerror or exc}", "E-io")]) from None
    return parse_text(decode_text(data, str(path)), str(path))


def parse_files(paths: Iterable[str | Path]) -> list[ast.Spec]:
    """Parse several files; collects the syntax errors of all of them."""
    specs: list[ast.Spec] = []
    diags: list[Diagnostic] = []
    for p in paths:
        try:
            specs.append(parse_file(p))
        except RclError as e:
            diags.extend(e.diagnostics)
    if diags:
        raise RclError(diags)
    return specs
