"""FRETish conditions and responses read, and written as RCL formulas.

The Boolean and arithmetic expressions of a FRET requirement (its
``pre_condition``, ``post_condition``, ``stop_condition`` and mode; FRET's
field guide, "Condition": ``!``, ``&``, ``|``, ``=>``/``->``,
``<=>``/``<->``, ``xor``, comparisons ``= != < <= > >=``, ``+ - * /``,
numbers, ``TRUE``/``FALSE`` and function calls ``f(a, b)``) are parsed
here into a small tree (:func:`parse`) and written back as RCL
(:class:`Writer`), fully bracketed so that no precedence differs:

=====================  =====================================================
FRETish                RCL
=====================  =====================================================
``! a``, ``a & b``     ``not a``, ``a and b`` (``|``: ``or``)
``a => b``, ``a <=> b``  ``a -> b``, ``a <=> b``
``a xor b``            ``not (a <=> b)``
``if a then b``        ``a -> b``
``FTP``                the first step: a state variable true only there; on a node another
                       node feeds, ``(first(Node.in.x) or ...)`` over its fed inputs (translate.py)
``a = b``              ``a == b``
``absReal(e)``, ``absInt(e)``, ``abs(e)``  ``abs(e)``
``sqrt(e)``, ``sin(e)``, ``cos(e)``  the same (RCL's, radians)
``maxReal(a, b)``      ``ite(a >= b, a, b)`` (``maxInt`` the same; ``minReal``,
                       ``minInt`` with ``<=``), stated case by case where a
                       formula reads it (:func:`.cases.lift`)
``preBool(i, e)``, ``preReal(i, e)``, ``preInt(i, e)``  a state variable
                       holding ``e`` of the step before, ``i`` at the first
                       step (FRET's field guide, "builtin functions": Lustre's
                       ``i -> pre e``), made by the writer's ``pre`` callback
``persisted(n, p)``    ``(p and state.c >= n)``, ``c`` counting the steps in a
                       row before this one at which p held, up to n (FRET:
                       ``H[0,n] p & H[0,n-1] Y TRUE``)
``occurred(n, p)``     ``(p or state.d <= n)``, ``d`` the steps since p last
                       held before this one, n + 1 when not within n (FRET:
                       ``O[0,n] p``)
=====================  =====================================================

A function the plan defines (``fret: functions:``, :mod:`.declared`) is
its RCL term with the arguments in place.  Any other function, ``^`` and a
name the caller cannot place raise :class:`Refusal` with the reason and
what would make it importable.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable, Mapping, Union

from rclverify.model.plan.fret.cases import Expr as Expr, lift, text  # Expr: a parsed expression (its shapes there)
from rclverify.model.plan.fret.refusal import Refusal as Refusal  # the readers' refusal, named here too

if TYPE_CHECKING:
    from rclverify.model.plan.fret.declared import DeclaredFunction

_TOKEN = re.compile(r"\s*(?:(?P<num>\d+(?:\.\d*)?(?:[eE][-+]?\d+)?|\.\d+(?:[eE][-+]?\d+)?)"
                    r"|(?P<name>[A-Za-z_][A-Za-z0-9_]*)"
                    r"|(?P<op><=>|<->|=>|->|!=|~=|<=|>=|[!&|=<>+\-*/^(),]))")
#: Binary operators by precedence, loosest first (FRET's grammar; ``->`` and ``=>`` group to the right).
_LEVELS: tuple[tuple[str, ...], ...] = (("<=>", "<->"), ("=>", "->"), ("xor",), ("|",), ("&",))
_COMPARE = ("=", "!=", "~=", "<", "<=", ">", ">=")
ABS = ("absReal", "absInt", "abs")
#: FRET's sqrt, sin, cos of one real: RCL's own (docs/semantics.md, "Mathematical functions")
MATH = ("sqrt", "sin", "cos")
#: FRET's maxReal/maxInt and minReal/minInt (FRET's field guide, "builtin functions"): the comparison choosing a.
EXTREMA = {"maxReal": ">=", "maxInt": ">=", "minReal": "<=", "minInt": "<="}
PRE = {"preBool": "BOOL", "preReal": "REAL", "preInt": "INTEGER"}


def _tokens(text: str) -> list[str]:
    out: list[str] = []
    pos = 0
    text = text.rstrip()
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if m is None or m.end() == pos:
            raise Refusal(f"FRETish expression {text!r} has a character rclverify does not read at "
                          f"{text[pos:pos + 10].strip()!r}", "write the condition with FRETish operators")
        out.append(m.group(m.lastgroup or "op"))
        pos = m.end()
    return out


class _Parser:
    #: The binary levels read, loosest first (a subclass adds FRET's past-time ``S``).
    levels: tuple[tuple[str, ...], ...] = _LEVELS

    def __init__(self, text: str, toks: list[str] | None = None) -> None:
        self.text, self.toks, self.i = text, _tokens(text) if toks is None else toks, 0

    def peek(self) -> str | None:
        return self.toks[self.i] if self.i < len(self.toks) else None

    def take(self, want: str | None = None) -> str:
        t = self.peek()
        if t is None or (want is not None and t != want):
            raise Refusal(f"FRETish expression {self.text!r} does not parse (expected {want or 'more'} at "
                          f"{t or 'its end'})", "correct the requirement in FRET")
        self.i += 1
        return t

    def level(self, k: int) -> Expr:
        if k == len(self.levels):
            return self.unary()
        left = self.level(k + 1)
        while self.peek() in self.levels[k]:
            op = self.take()
            right = self.level(k) if op in ("=>", "->") else self.level(k + 1)
            left = ("bin", op, left, right)
            if op in ("=>", "->"):
                break
        return left

    def unary(self) -> Expr:
        if self.peek() == "!":
            self.take()
            return ("not", self.unary())
        return self.compare()

    def compare(self) -> Expr:
        left = self.sum()
        if self.peek() in _COMPARE:
            op = self.take()
            left = ("bin", op, left, self.sum())
        return left

    def sum(self) -> Expr:
        left = self.product()
        while self.peek() in ("+", "-"):
            op = self.take()
            left = ("bin", op, left, self.product())
        return left

    def product(self) -> Expr:
        left = self.atom()
        while self.peek() in ("*", "/", "^"):
            op = self.take()
            if op == "^":
                raise Refusal("FRETish '^' (a power) has no RCL counterpart", "write the power as a product")
            left = ("bin", op, left, self.atom())
        return left

    def atom(self) -> Expr:
        t = self.take()
        if t == "-":
            return ("neg", self.atom())
        if t == "(":
            e = self.level(0)
            self.take(")")
            return e
        if t[0].isdigit() or t[0] == ".":
            return ("num", t)
        if t in ("TRUE", "true", "FALSE", "false"):
            return ("bool", t.upper())
        if t == "if" and self.peek() != "(" or t == "if" and "then" in self.toks[self.i:]:
            cond = self.level(0)  # FRETish "if p then q": p => q
            self.take("then")
            return ("bin", "=>", cond, self.level(0))
        if not (t[0].isalpha() or t[0] == "_"):
            raise Refusal(f"FRETish expression {self.text!r} does not parse at {t!r}", "correct the requirement in FRET")
        if self.peek() == "(":
            self.take("(")
            args: list[Expr] = []
            while self.peek() != ")":
                args.append(self.level(0))
                if self.peek() == ",":
                    self.take(",")
                elif self.peek() != ")":
                    self.take(")")
            self.take(")")
            return ("call", t, tuple(args))
        return ("var", t)


def parse(text: str) -> Expr:
    """The tree of FRETish expression ``text``.  Raises :class:`Refusal`
    when it does not parse or uses ``^``."""
    p = _Parser(text)
    e = p.level(0)
    if p.peek() is not None:
        raise Refusal(f"FRETish expression {text!r} does not parse (unexpected {p.peek()!r})",
                      "correct the requirement in FRET")
    return e


def names(e: Expr) -> list[str]:
    """The variable names ``e`` reads, in order of first mention."""
    out: list[str] = []

    def walk(x: Expr) -> None:
        if x[0] == "var":
            out.append(str(x[1]))
        for a in x[1:]:
            if isinstance(a, tuple) and a and isinstance(a[0], str):
                walk(a)
            elif isinstance(a, tuple):
                for b in a:
                    walk(b)
    walk(e)
    return list(dict.fromkeys(out))


#: ``var(name, local)``: the RCL text of a variable (``Node.in.x``, or ``in.x`` when ``local``), or
#: the tree to write in its place (an Internal variable defined by a constant or a formula).
VarText = Callable[[str, bool], Union[str, Expr]]
#: ``pre(type, init, expr)``: the state variable's name holding ``expr`` (a tree) of the step before.
PreVar = Callable[[str, Expr, Expr], str]
#: ``count(kind, n, expr)``: the state variable's name counting, for ``persisted(n, expr)`` (``kind``
#: ``"persisted"``), the steps in a row before this one ``expr`` held (up to n), for ``occurred(n, expr)``
#: the steps since it last held before this one (n + 1: not within n).
CountVar = Callable[[str, int, Expr], str]
#: FRET's past-time predicates (FRET's field guide, "temporal conditions"): ``persisted(n, p)``, p held at
#: this step and the n before it; ``occurred(n, p)``, p held at this step or one of the n before it.
COUNTED = ("persisted", "occurred")


@dataclass
class Writer:
    """Writes trees as RCL: ``var`` places a name, ``pre`` makes the state
    variable of a ``pre*`` call, ``node`` is the component's node (for
    ``Node.state.v``)."""

    var: VarText
    pre: PreVar
    node: str
    count: CountVar | None = None
    #: ``temporal(e, local)``: the RCL text of a past-time node of FRET's formalisation (``("past", op, e)``,
    #: ``("bin", "S", a, b)``; :mod:`.pasttime`), ``None`` where the expression has none.
    temporal: Callable[[Expr, bool], str] | None = None

    #: ``table(length, local)``: the RCL text of the requirement's step counter (``state.v``, the steps
    #: since the first, at least ``length - 1`` once it stops) for a Lustre table (:mod:`.lustre`).
    table: Callable[[int, bool], str] | None = None
    #: the plan's ``fret: functions:`` by name (:mod:`.declared`)
    functions: "Mapping[str, DeclaredFunction] | None" = None

    def rcl(self, e: Expr, local: bool = False) -> str:
        """RCL text of formula ``e``: over ``Node.in.x``/``Node.out.y``/``Node.state.v``
        or, ``local``, over ``in.x``/``out.y``/``state.v`` (a state
        declaration's ``next``).  A Lustre ``ite`` or table inside a comparison
        is stated case by case there (:func:`.cases.lift`).  Raises :class:`Refusal`."""
        return text(lift(self.resolve(e, local)))

    def resolve(self, e: Expr, local: bool) -> Expr:
        """``e`` with every name placed (``("text", rcl)`` or the tree it stands for, resolved), every
        ``pre``, ``persisted``, ``occurred`` and past-time node replaced by the state variables' text."""
        kind = e[0]
        if kind in ("num", "bool", "text"):
            return e
        if kind == "var":
            got = self.var(str(e[1]), local)
            return ("text", got) if isinstance(got, str) else ("paren", self.resolve(got, local))
        if self.temporal is not None and (kind == "past" or kind == "bin" and e[1] == "S"):
            return ("text", self.temporal(e, local))
        if kind == "table":
            if self.table is None:
                raise Refusal("a Lustre table of constants is read only in a requirement", "define it in FRET")
            consts = e[1]
            assert isinstance(consts, tuple)
            return ("table", self.table(len(consts), local), consts)
        if kind != "call":
            return (kind,) + tuple(x if isinstance(x, str) else self.resolve(x, local) for x in e[1:])  # type: ignore[arg-type]
        name, args = str(e[1]), e[2]
        assert isinstance(args, tuple)
        if name in ABS and len(args) == 1:
            return ("call", "abs", (self.resolve(args[0], local),))
        if name in MATH and len(args) == 1:
            return ("call", name, (self.resolve(args[0], local),))
        if name in EXTREMA and len(args) == 2:  # FRET's maxReal(a, b): if a >= b then a else b
            a, b = (self.resolve(x, local) for x in args)
            return ("ite", ("bin", EXTREMA[name], a, b), a, b)
        if name in PRE and len(args) == 2:
            init = args[0]
            if not _constant(init):  # Lustre's i -> pre e: i at the first step, FRET's FTP
                default: Expr = ("bool", "FALSE") if PRE[name] == "BOOL" else ("num", "0.0" if PRE[name] ==
                                                                                     "REAL" else "0")
                return self.resolve(("ite", ("var", "FTP"), init, ("call", name, (default, args[1]))), local)
            body = args[1]
            if body[0] == "var" and not isinstance(got := self.var(str(body[1]), local), str):
                body = got
            if body[0] == "table":  # the pre of a table is the table a step later: no state variable
                consts = body[1]
                assert isinstance(consts, tuple)
                return self.resolve(("table", (init,) + consts), local)
            state = self.pre(PRE[name], init, args[1])
            return ("text", f"state.{state}" if local else f"{self.node}.state.{state}")
        if name in COUNTED and len(args) == 2 and self.count is not None:
            n = args[0]
            if n[0] != "num" or not str(n[1]).isdigit():
                raise Refusal(f"{name}'s first argument must be a number of steps", f"write {name}(N, p), N a number")
            state = self.count(name, int(str(n[1])), args[1])
            ref = ("text", f"state.{state}" if local else f"{self.node}.state.{state}")
            p = self.resolve(args[1], local)
            return ("bin", "&", p, ("bin", ">=", ref, n)) if name == "persisted" else ("bin", "|", p, ("bin", "<=", ref, n))
        if self.functions and name in self.functions:
            return ("text", self.functions[name].call([text(lift(self.resolve(a, local))) for a in args]))
        raise Refusal(f"it calls the FRET function {name}({', '.join('_' for _ in args)}), which has no RCL "
                      "counterpart", f"define {name} in the plan's fret: functions as an RCL term over its arguments,"
                                     " or write it as an RCL formula over the component's inputs and outputs"
                                     " (rclverify translates absReal, absInt, maxReal, maxInt, minReal, minInt, sqrt, sin,"
                                     " cos, preBool, preReal, preInt, persisted and occurred)")


def _constant(e: Expr) -> bool:
    return e[0] in ("num", "bool") or e[0] == "neg" and _constant(e[1])  # type: ignore[arg-type]
