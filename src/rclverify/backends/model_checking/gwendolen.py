"""Gwendolen agent programs: parser (``gwendolen.lark``) to an AST with source lines.

A program is ``GWENDOLEN``, ``:name: agent``, then the sections
``:Initial Beliefs:`` (ground terms), ``:Reasoning Rules:`` (Prolog-style
``head :- lit, ~lit;``), ``:Initial Goals:`` (``g [achieve]`` /
``g [perform]``) and ``:Plans:`` (``trigger : { guard } <- deed, ...;``).
Source of the language: Dennis and Farwer, "Gwendolen: A BDI Language for
Verifiable Agents" (2008), and the Gwendolen chapter of the MCAPL manual;
docs/model-checking.md lists the subset this interpreter runs.

Terms are :mod:`rclverify.backends.model_checking.ajpf.psl` terms (``Sym``, ``Num``,
``Compound``, ``Wild`` for ``_``) plus :class:`Var` for a variable; a string
``"text"`` is the symbol whose name is the quoted text.  A name with no
arguments and the same name with ``()`` are one term (``Sym``).

Every construct the interpreter does not run (messages ``.send``/
``.query``, ``+.received``, locks ``+.lock``, wait-for ``*b``, test goals
``?b``, comparisons in guards, a second agent) is refused by name with a
located :class:`GwendolenError` (``file:line:col: error: Gwendolen construct
... is not supported by rclverify's interpreter``), never skipped.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Union, cast

from lark import Lark, Token, Tree
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken

from rclverify.lang.ast import Loc
from rclverify.lang.errors import RclError, error
from rclverify.lang.parser import lark_cache_file
from rclverify.lang.source import read_text
from rclverify.backends.model_checking.ajpf import psl

GOAL_TYPES = ("achieve", "perform")
#: Deepest term the interpreter accepts in a program and builds while running
#: one (a deeper one cuts the exploration: docs/model-checking.md, "Bounds").
MAX_TERM_DEPTH = psl.MAX_NESTING
DEFAULT_GOAL_TYPE = "achieve"  # MCAPL: a goal written without a type is an achievement goal


class GwendolenError(RclError):
    """A user error in a Gwendolen program (or in running it): located diagnostics."""


def located(file: str, line: int, col: int, message: str, code: str = "E-gwendolen") -> GwendolenError:
    """A :class:`GwendolenError` with one diagnostic at ``file:line:col``."""
    return GwendolenError([error(Loc(file, line, col), message, code)])


def unsupported(file: str, line: int, col: int, what: str) -> GwendolenError:
    """The refusal of a construct the interpreter does not implement."""
    return located(file, line, col, f"Gwendolen construct {what} is not supported by rclverify's interpreter",
                   "E-gwendolen-unsupported")


@dataclass(frozen=True)
class Var:
    """A variable (``Location``); ``_`` is :class:`psl.Wild` (a fresh variable each time)."""

    name: str


Term = Union[psl.Sym, psl.Num, psl.Wild, "psl.Compound[Term]", Var]


@dataclass(frozen=True)
class GuardLit:
    """One guard literal: ``B t`` (``kind`` ``"B"``), ``G t`` (``"G"``) or ``True`` (``"T"``), maybe negated."""

    kind: str
    term: Term | None
    positive: bool = True


@dataclass(frozen=True)
class Rule:
    """``head :- body;``: ``body`` is a tuple of (positive, term); ``~`` is negation as failure."""

    head: Term
    body: tuple[tuple[bool, Term], ...]
    line: int


@dataclass(frozen=True)
class Trigger:
    """``+b`` / ``-b`` (``goal`` false) or ``+!g [type]`` / ``-!g [type]``."""

    sign: str
    term: Term
    goal: bool = False
    goal_type: str | None = None

    def text(self) -> str:
        kind = f"!{term_text(self.term)} [{self.goal_type}]" if self.goal else term_text(self.term)
        return f"{self.sign}{kind}"


@dataclass(frozen=True)
class Deed:
    """One deed of a plan body.

    ``kind``: ``"+b"``/``"-b"`` belief update, ``"+!"``/``"-!"`` adopt or
    drop a goal (``goal_type`` set), ``"act"`` an action (``print`` among
    them).  ``line``/``col`` where it is written.
    """

    kind: str
    term: Term
    line: int
    col: int
    goal_type: str | None = None

    def text(self) -> str:
        t = term_text(self.term)
        if self.kind in ("+!", "-!"):
            return f"{self.kind}{t} [{self.goal_type}]"
        return t if self.kind == "act" else f"{self.kind[0]}{t}"


@dataclass(frozen=True)
class Plan:
    """``trigger : { guard } <- body;`` at ``line`` (1-based); ``index`` its position in the program."""

    trigger: Trigger
    guard: tuple[GuardLit, ...]
    body: tuple[Deed, ...]
    line: int
    index: int


@dataclass(frozen=True)
class Program:
    """One agent: name, initial beliefs (ground), rules, initial goals ((term, type)), plans in program order."""

    name: str
    source: str
    beliefs: tuple[Term, ...]
    rules: tuple[Rule, ...]
    goals: tuple[tuple[Term, str], ...]
    plans: tuple[Plan, ...]


@lru_cache(maxsize=1)
def _parser() -> Lark:
    grammar = (Path(__file__).with_name("gwendolen.lark")).read_text(encoding="utf-8")
    return Lark(grammar, parser="lalr", propagate_positions=True, maybe_placeholders=False,
                cache=lark_cache_file("gwendolen"))  # the analysed tables kept by lark (lang/parser.py)


def parse_file(path: Path, source_name: str) -> Program:
    """Parse the Gwendolen file ``path``; diagnostics name it ``source_name``.

    Raises :class:`GwendolenError` on a syntax error, an unsupported
    construct, an unknown goal type, a non-ground initial belief or goal;
    :class:`~rclverify.lang.errors.RclError` when the file cannot be read or
    is not UTF-8.
    """
    return parse_text(read_text(path, source_name), source_name)


def parse_text(text: str, source_name: str = "<string>") -> Program:
    """Parse a Gwendolen program text (see :func:`parse_file`)."""
    if not text.strip():
        raise located(source_name, 1, 1, "empty program: a Gwendolen program starts with GWENDOLEN and :name:")
    try:
        tree = _parser().parse(text)
    except UnexpectedInput as exc:
        raise _syntax_error(exc, text, source_name) from None
    return _Builder(source_name).program(tree)


def _syntax_error(exc: UnexpectedInput, text: str, file: str) -> GwendolenError:
    line, col = getattr(exc, "line", 1) or 1, getattr(exc, "column", 1) or 1
    if isinstance(exc, UnexpectedToken) and exc.token.type == "$END" or isinstance(exc, UnexpectedEOF):
        lines = text.splitlines() or [""]
        return located(file, len(lines), len(lines[-1]) + 1, "unexpected end of the program")
    if isinstance(exc, UnexpectedCharacters):
        pos = cast(int, exc.pos_in_stream)  # the lexer's position: set for an unexpected character
        return located(file, line, col, f"unexpected character {text[pos]!r}")
    tok = exc.token if isinstance(exc, UnexpectedToken) else None
    shown = repr(str(tok)) if tok is not None else "input"
    expected = sorted({_terminal_text(name) for name in getattr(exc, "expected", ()) or ()})
    hint = f" (expected one of: {', '.join(expected[:12])})" if expected else ""
    return located(file, line, col, f"unexpected {shown}{hint}")


_TERMINAL_WORDS = {"NAME": "a name", "VAR": "a variable", "NUMBER": "a number", "STRING": "a string",
                   "SIGN": "'+' or '-'", "RULES_HDR": "':Reasoning Rules:'", "_END": "';'", "DOT_NAME": "'.name'", "CMP": "a comparison"}


def _terminal_text(name: str) -> str:
    """A terminal of the grammar as a reader knows it (``':'`` rather than ``COLON``)."""
    if name in _TERMINAL_WORDS:
        return _TERMINAL_WORDS[name]
    try:
        pattern = _parser().get_terminal(name).pattern
    except KeyError:  # pragma: no cover - every expected terminal is the grammar's
        return name
    return repr(pattern.value) if pattern.type == "str" else name


class _Builder:
    """Walk the lark tree into the AST; refuse unsupported constructs at their location."""

    def __init__(self, file: str) -> None:
        self.file = file

    def _err(self, node: Tree[Token] | Token, message: str) -> GwendolenError:
        line, col = _pos(node)
        return located(self.file, line, col, message)

    def _unsupported(self, node: Tree[Token] | Token, what: str) -> GwendolenError:
        line, col = _pos(node)
        return unsupported(self.file, line, col, what)

    def program(self, tree: Tree[Token]) -> Program:
        agents = [c for c in tree.children if isinstance(c, Tree)]
        if len(agents) > 1:
            raise self._unsupported(agents[1], "a second agent in one file (multi-agent systems)")
        agent = agents[0]
        name = str(_tree(agent.children[0]).children[0])
        beliefs: list[Term] = []
        rules: list[Rule] = []
        goals: list[tuple[Term, str]] = []
        plans: list[Plan] = []
        for sec in map(_tree, agent.children[1:]):
            items = [_tree(c) for c in sec.children if isinstance(c, Tree) or c.type not in (
                "BELIEFS_HDR", "RULES_HDR", "GOALS_HDR", "PLANS_HDR")]
            if sec.data == "beliefs":
                for node in items:
                    beliefs.append(self._ground(node, "an initial belief"))
            elif sec.data == "rules":
                rules.extend(self.rule(node) for node in items)
            elif sec.data == "goals":
                for node in items:
                    term = self._ground(_tree(node.children[0]), "an initial goal")
                    gtype = self.goal_type(_tree(node.children[1])) if len(node.children) > 1 else DEFAULT_GOAL_TYPE
                    goals.append((term, gtype))
            else:
                plans.extend(self.plan(node, len(plans) + i) for i, node in enumerate(items))
        return Program(name, self.file, tuple(beliefs), tuple(rules), tuple(goals), tuple(plans))

    def _ground(self, node: Tree[Token], what: str) -> Term:
        term = self.term(node)
        if not is_ground(term):
            raise self._err(node, f"{what} must be ground (no variables): {psl.term_text(_show(term))}")
        return term

    def goal_type(self, node: Tree[Token]) -> str:
        tok = node.children[0]
        if str(tok) not in GOAL_TYPES:
            raise self._err(tok, f"unknown goal type [{tok}] (Gwendolen's are [achieve] and [perform])")
        return str(tok)

    def rule(self, node: Tree[Token]) -> Rule:
        head = self.term(node.children[0])
        body = []
        for lit in map(_tree, node.children[1:]):
            positive = not (isinstance(lit.children[0], Token) and lit.children[0].type == "NEG")
            body.append((positive, self.term(lit.children[-1])))
        return Rule(head, tuple(body), _pos(node)[0])

    def plan(self, node: Tree[Token], index: int) -> Plan:
        trig_node = _tree(node.children[0])
        trigger = self.trigger(trig_node)
        guard: tuple[GuardLit, ...] = ()
        body: tuple[Deed, ...] = ()
        for part in map(_tree, node.children[1:]):
            if part.data == "guard":
                guard = tuple(self.guard_lit(_tree(g)) for g in part.children)
            else:
                body = tuple(self.deed(_tree(d)) for d in part.children)
        return Plan(trigger, guard, body, _pos(node)[0], index)

    def trigger(self, node: Tree[Token]) -> Trigger:
        kids = node.children
        if node.data == "unsupported_trigger":
            raise self._unsupported(node, f"{kids[0]}{kids[1]} (as a plan trigger)")
        sign = str(kids[0])
        if node.data == "goal_trigger":
            gtype = self.goal_type(_tree(kids[2])) if len(kids) > 2 else DEFAULT_GOAL_TYPE
            return Trigger(sign, self.term(kids[1]), True, gtype)
        return Trigger(sign, self.term(kids[1]))

    def guard_lit(self, node: Tree[Token]) -> GuardLit:
        kids = node.children
        positive = not (isinstance(kids[0], Token) and kids[0].type == "NEG")
        rest = kids if positive else kids[1:]
        if node.data == "true_lit":
            return GuardLit("T", None, positive)
        if node.data == "modal_lit":
            return GuardLit(str(rest[0]), self.term(rest[1]), positive)
        if node.data == "unsupported_lit":
            raise self._unsupported(rest[0], f"{rest[0]} (in a guard)")
        raise self._unsupported(kids[1], f"comparison '{kids[1]}' (in a guard)")

    def deed(self, node: Tree[Token]) -> Deed:
        kids = node.children
        line, col = _pos(node)
        if node.data == "unsupported_deed":
            shown = "".join(str(k) for k in kids if isinstance(k, Token))
            raise self._unsupported(node, f"{shown} (as a deed)")
        if node.data == "wait_deed":
            raise self._unsupported(node, "*b (wait for a belief)")
        if node.data == "query_deed":
            raise self._unsupported(node, "?b (test goal)")
        if node.data == "goal_deed":
            gtype = self.goal_type(_tree(kids[2])) if len(kids) > 2 else DEFAULT_GOAL_TYPE
            return Deed(f"{kids[0]}!", self.term(kids[1]), line, col, gtype)
        if node.data == "belief_deed":
            return Deed(f"{kids[0]}b", self.term(kids[1]), line, col)
        return Deed("act", self.term(kids[0]), line, col)

    def term(self, node: Tree[Token] | Token, depth: int = 1) -> Term:
        if isinstance(node, Token):  # pragma: no cover - every term is a tree
            raise self._err(node, f"unexpected {node!s}")
        if depth > MAX_TERM_DEPTH:
            raise self._err(node, f"term nested deeper than {MAX_TERM_DEPTH} levels (the interpreter's limit)")
        kind = node.data
        tok = node.children[0]
        if kind == "var":
            return Var(str(tok))
        if kind == "wild":
            return psl.Wild()
        if kind == "number":
            return psl.Num(str(tok))
        if kind == "string":
            return psl.Sym(str(tok))
        args = _tree(node.children[1]).children if len(node.children) > 1 else []
        if not args:
            return psl.Sym(str(tok))
        return psl.Compound(str(tok), tuple(self.term(a, depth + 1) for a in args))


def _tree(node: Tree[Token] | Token) -> Tree[Token]:
    """``node``, a child the grammar makes a rule's tree (a section, a
    term, a goal type, a plan's parts), never a token."""
    return cast("Tree[Token]", node)


def _pos(node: Tree[Token] | Token) -> tuple[int, int]:
    if isinstance(node, Token):
        return node.line or 1, node.column or 1
    meta = node.meta
    return (getattr(meta, "line", 1) or 1), (getattr(meta, "column", 1) or 1)


def is_ground(term: Term) -> bool:
    """No :class:`Var` and no ``_`` in ``term``."""
    if isinstance(term, (Var, psl.Wild)):
        return False
    if isinstance(term, psl.Compound):
        return all(is_ground(a) for a in term.args)
    return True


def as_psl(term: Term) -> psl.Term:
    """``term``, known to hold no :class:`Var`, as the psl term it then is."""
    return cast(psl.Term, term)


def _show(term: Term) -> psl.Term:
    """``term`` with variables shown by name (for messages)."""
    if isinstance(term, Var):
        return psl.Sym(term.name)
    if isinstance(term, psl.Compound):
        return psl.Compound(term.name, tuple(_show(a) for a in term.args))
    return term


def term_text(term: Term) -> str:
    """The term as Gwendolen writes it (variables by name)."""
    return psl.term_text(_show(term))
