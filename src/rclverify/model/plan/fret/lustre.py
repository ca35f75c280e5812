"""An Internal variable's Lustre definition read as a FRETish tree with state variables.

FRET lets an ``Internal`` variable be defined by a Lustre expression (its
``assignment``; FRET's field guide, "Internal variables"): Lustre's
``a -> b`` (a at the first step, b after it), ``pre e`` (e at the step
before), ``if c then a else b``, ``and``/``or``/``not``/``xor``, ``<>``,
comparisons and arithmetic.  The tree read here is the tree of
:mod:`.fretish`, with Lustre's operators in FRETish terms:

=========================  ====================================================
Lustre                     tree
=========================  ====================================================
``a -> b``                 ``("ite", FTP, a, b)``: FRET's first time point
``pre e``                  ``preBool/preReal/preInt(d, e)`` by e's type, ``d``
                           (FALSE, 0.0, 0) never read: a ``pre`` must stand on
                           the right of an ``->`` whose left covers the first
                           step (Lustre's nil there is refused)
``if c then a else b``     ``("ite", c, a, b)``
``c0 -> pre(c1 -> pre(...  ``("table", (c0, ..., cN))``: the value at step k is
 -> pre(cN)))``            ``c_k``, ``cN`` from step N on (constants ``ck``)
=========================  ====================================================

A ``pre`` of the variable being defined (``psi0 = psi -> if up then psi else
pre psi0``) is the variable's own value at the step before: one state
variable (:func:`.translate._writer`).  The writer (:class:`.fretish.Writer`)
states ``ite`` and ``table`` at the comparison that reads them, case by case
(``x = ite(c, a, b)`` as ``(c -> x = a) and (not c -> x = b)``; a table as
one case per step of the requirement's step counter), so no RCL term other
than FRET's own is needed.  Lustre's ``when``, ``current`` and ``fby``
raise :class:`~.fretish.Refusal`.
"""
from __future__ import annotations

import re
from typing import Callable

from rclverify.model.plan.fret.fretish import _COMPARE, PRE, Expr, Refusal, _Parser, _tokens

#: Lustre's word operators, read as FRETish's.
_WORDS = {"and": "&", "or": "|", "not": "!", "<>": "!="}
_WORD = re.compile(r"\b(?:and|or|not)\b|<>")
_UNREAD = re.compile(r"\b(when|current|fby|merge)\b")
_NUM = r"-?\s*(?:\d+(?:\.\d*)?(?:[eE][-+]?\d+)?|\.\d+)"
_CHAIN = re.compile(rf"\s*\(?\s*({_NUM})\s*\)?\s*->\s*pre\s*\((.*)\)\s*$", re.S)
_LAST = re.compile(rf"\s*\(?\s*({_NUM})\s*\)?\s*$")
#: Lustre words in an assignment: one of them makes it a Lustre definition.
LUSTRE = re.compile(r"\b(pre|if|then|else|fby|when|current)\b|->")
#: A pre's value at the first step, never read (a guarded pre), by type.
_DEFAULT: dict[str, Expr] = {"BOOL": ("bool", "FALSE"), "REAL": ("num", "0.0"), "INTEGER": ("num", "0")}
_PRE_OF = {t: name for name, t in PRE.items()}
_BOOL_OPS = ("&", "|", "=>", "->", "<=>", "<->", "xor", "=", "!=", "~=", "<", "<=", ">", ">=")


class _Lustre(_Parser):
    """Lustre's precedence, loosest first: ``->`` (to the right), ``=>``, ``or``/``xor``, ``and``, the
    comparisons, ``not``, ``+``/``-``, ``*``/``/``; ``pre`` binds tightest; ``if c then a else b`` is an
    atom."""

    levels = (("->",), ("=>",), ("|", "xor"), ("&",))

    def level(self, k: int) -> Expr:
        if k == 0:
            left = self.level(1)
            if self.peek() == "->":
                self.take()
                return ("arrow", left, self.level(0))
            return left
        return super().level(k)

    def unary(self) -> Expr:
        return self.compare()

    def compare(self) -> Expr:  # Lustre's not binds tighter than a comparison: not a = b is (not a) = b
        left = self.negated()
        if self.peek() in _COMPARE:
            op = self.take()
            left = ("bin", op, left, self.negated())
        return left

    def negated(self) -> Expr:
        if self.peek() == "!":
            self.take()
            return ("not", self.negated())
        return self.sum()

    def atom(self) -> Expr:
        t = self.peek()
        if t == "pre":
            self.take()
            return ("lpre", self.atom())
        if t == "if":
            self.take()
            c = self.level(0)
            self.take("then")
            a = self.level(0)
            self.take("else")
            return ("ite", c, a, self.level(0))
        return super().atom()


def _number(text: str) -> Expr:
    t = re.sub(r"\s+", "", text)
    return ("neg", ("num", t[1:])) if t.startswith("-") else ("num", t)


def _table(text: str) -> Expr | None:
    """``c0 -> pre(c1 -> pre(... -> pre(cN)))`` over constants as a table, read without recursion (the
    case studies' chains run to 200 steps); ``None`` for another expression."""
    consts: list[Expr] = []
    rest = text
    while (m := _CHAIN.match(rest)) is not None:
        consts.append(_number(m.group(1)))
        rest = m.group(2)
    last = _LAST.match(rest)
    if not consts or last is None:
        return None
    return ("table", tuple(consts) + (_number(last.group(1)),))


def parse_lustre(name: str, text: str) -> Expr:
    """The tree of Internal variable ``name``'s Lustre definition ``text``, Lustre's operators still its own
    (``arrow``, ``lpre``, ``ite``, ``table``).  Raises :class:`~.fretish.Refusal`."""
    if (m := _UNREAD.search(text)) is not None:
        raise Refusal(f"{name} is defined with Lustre's {m.group(1)}, which rclverify does not read",
                      f"define {name} with ->, pre and if-then-else")
    got = _table(text)
    if got is not None:
        return got
    p = _Lustre(text, _tokens(_WORD.sub(lambda m: _WORDS[m.group(0)], text)))
    e = p.level(0)
    if p.peek() is not None:
        raise Refusal(f"{name}'s Lustre definition {text!r} does not parse (unexpected {p.peek()!r})",
                      "correct the definition in FRET")
    return e


def kind(e: Expr, var_type: Callable[[str], str]) -> str:
    """``BOOL``, ``REAL`` or ``INTEGER``: the type of ``e``, ``var_type(name)`` a variable's."""
    k = e[0]
    if k in ("bool", "not") or k == "bin" and e[1] in _BOOL_OPS:
        return "BOOL"
    if k == "num":
        return "REAL" if re.search(r"[.eE]", str(e[1])) else "INTEGER"
    if k == "var":
        return var_type(str(e[1]))
    if k in ("neg", "lpre"):
        return kind(e[1], var_type)  # type: ignore[arg-type]
    if k in ("ite", "arrow"):
        return kind(e[-1], var_type)  # type: ignore[arg-type]
    if k == "table":
        consts = e[1]
        assert isinstance(consts, tuple)
        return "REAL" if any(kind(c, var_type) == "REAL" for c in consts) else "INTEGER"
    if k == "call":
        name, args = str(e[1]), e[2]
        assert isinstance(args, tuple)
        return PRE.get(name) or (kind(args[0], var_type) if args else "REAL")
    parts = [kind(x, var_type) for x in e[2:]]  # type: ignore[arg-type]
    return "REAL" if "REAL" in parts else "INTEGER"


def fretish(name: str, e: Expr, var_type: Callable[[str], str], guarded: bool = False) -> Expr:
    """Lustre tree ``e`` (of :func:`parse_lustre`) as a FRETish one (module table); ``guarded`` when ``e``
    is read only after the first step.  Raises :class:`~.fretish.Refusal` for a ``pre`` read at the first
    step."""
    k = e[0]
    if k == "arrow":
        return ("ite", ("var", "FTP"), fretish(name, e[1], var_type, guarded),  # type: ignore[arg-type]
                fretish(name, e[2], var_type, True))  # type: ignore[arg-type]
    if k == "lpre":
        if not guarded:
            raise Refusal(f"{name}'s definition reads pre at the first step, where Lustre leaves it undefined",
                          "give the pre an initial value in FRET (i -> pre e)")
        t = kind(e[1], var_type)  # type: ignore[arg-type]
        return ("call", _PRE_OF[t], (_DEFAULT[t], fretish(name, e[1], var_type, False)))  # type: ignore[arg-type]
    if k in ("num", "bool", "var", "table"):
        return e
    if k == "bin":
        return ("bin", e[1], fretish(name, e[2], var_type, guarded), fretish(name, e[3], var_type, guarded))  # type: ignore[arg-type]
    if k == "call":
        args = e[2]
        assert isinstance(args, tuple)
        return ("call", e[1], tuple(fretish(name, a, var_type, guarded) for a in args))
    return (k,) + tuple(fretish(name, x, var_type, guarded) for x in e[1:])  # type: ignore[arg-type]


def self_reads(e: Expr) -> tuple[list[str], list[str]]:
    """The names ``e`` reads outside any ``pre`` and those it reads only under one (a variable may read
    its own value of the step before, never its value now)."""
    now: list[str] = []
    before: list[str] = []

    def walk(x: Expr, under: bool) -> None:
        if x[0] == "var":
            (before if under else now).append(str(x[1]))
            return
        if x[0] == "call" and str(x[1]) in PRE:
            args = x[2]
            assert isinstance(args, tuple)
            walk(args[0], under)
            walk(args[1], True)
            return
        for a in x[1:]:
            if isinstance(a, tuple) and a and isinstance(a[0], str):
                walk(a, under)
            elif isinstance(a, tuple):
                for b in a:
                    walk(b, under)
    walk(e, False)
    return list(dict.fromkeys(now)), list(dict.fromkeys(before))
