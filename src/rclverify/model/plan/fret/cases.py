"""A FRETish formula's ``ite`` and Lustre tables stated case by case, and the formula written as RCL.

RCL has no conditional term.  A formula (already resolved by
:meth:`.fretish.Writer.resolve`: every name placed, every ``pre`` a state
variable) that reads ``ite(c, a, b)`` (a Lustre ``if`` or ``->``, FRET's
``maxReal``) or a Lustre table of constants (:mod:`.lustre`) is stated
where a formula reads it (:func:`lift`), and written as fully bracketed RCL
text (:func:`text`).
"""
from __future__ import annotations

from decimal import Decimal
from typing import Callable

#: A parsed expression: ("num", text) | ("bool", "TRUE"/"FALSE") | ("var", name) | ("not", e) |
#: ("neg", e) | ("bin", op, a, b) | ("call", name, (args...)) | ("ite", c, a, b) | ("table", counter, (c0..cN))
#: | ("text", rcl) | ("paren", e) | ("and*", (items...)).
Expr = tuple[object, ...]
#: FRETish's binary operators as RCL's.
_RCL_OP = {"<=>": "<=>", "<->": "<=>", "=>": "->", "->": "->", "|": "or", "&": "and", "=": "==", "!=": "!=",
           "~=": "!=", "<": "<", "<=": "<=", ">": ">", ">=": ">=", "+": "+", "-": "-", "*": "*", "/": "/"}


#: FRETish's Boolean connectives: their operands are formulas, where an ``ite`` is stated as a case split.
_CONNECTIVES = ("&", "|", "=>", "->", "<=>", "<->", "xor")


def _split(e: Expr) -> tuple[Expr, Callable[[Expr], Expr]] | None:
    """The first ``ite`` or table inside term-level tree ``e`` and the function putting a tree in its place;
    ``None`` when it has none."""
    if e[0] in ("ite", "table"):
        return e, lambda x: x
    for i, a in enumerate(e):
        if i == 0 or not isinstance(a, tuple) or not a:
            continue
        if isinstance(a[0], str):
            got = _split(a)
            if got is not None:
                node, put = got
                return node, lambda x, i=i, put=put: e[:i] + (put(x),) + e[i + 1:]
        else:
            for j, b in enumerate(a):
                got = _split(b)
                if got is not None:
                    node, put = got
                    return node, (lambda x, i=i, j=j, put=put, a=a:
                                  e[:i] + (a[:j] + (put(x),) + a[j + 1:],) + e[i + 1:])
    return None


def lift(e: Expr) -> Expr:
    """Formula ``e`` (resolved) with each ``ite(c, a, b)`` and table stated where a formula reads it: an
    ``ite`` formula as ``(c & a) | (!c & b)``, a comparison (or other atom) ``A`` reading ``ite(c, a, b)``
    as ``(c => A[a]) & (!c => A[b])``, one reading tables of step counter ``v`` (``(v, c0..cN)``) as the
    conjunction of ``v = k => A[each table at k]`` for k < N and ``v >= N => A[each at N]``, N the longest
    table's last step and a shorter table's last constant standing from its end on (``("and*", items)``,
    written flat)."""
    kind = e[0]
    if kind in ("not", "paren"):
        return (kind, lift(e[1]))  # type: ignore[arg-type]
    if kind == "bin" and e[1] in _CONNECTIVES:
        return ("bin", e[1], lift(e[2]), lift(e[3]))  # type: ignore[arg-type]
    if kind == "ite":
        c = lift(e[1])  # type: ignore[arg-type]
        return ("bin", "|", ("bin", "&", c, lift(e[2])), ("bin", "&", ("not", c), lift(e[3])))  # type: ignore[arg-type]
    got = _split(e)
    if got is None:
        return e
    node, put = got
    if node[0] == "ite":
        c = lift(node[1])  # type: ignore[arg-type]
        return ("bin", "&", ("bin", "=>", c, lift(put(node[2]))),  # type: ignore[arg-type]
                ("bin", "=>", ("not", c), lift(put(node[3]))))  # type: ignore[arg-type]
    counter = str(node[1])
    last = _longest(e, counter) - 1
    return ("and*", tuple(("bin", "=>", ("bin", "=" if k < last else ">=", ("text", counter), ("num", str(k))),
                           lift(_fold(_at(e, counter, k)))) for k in range(last + 1)))


def _value(e: Expr) -> Decimal | None:
    """The number a constant tree (a numeral, its negation) stands for; ``None`` for another tree."""
    if e[0] == "num":
        return Decimal(str(e[1]))
    if e[0] in ("neg", "paren"):
        v = _value(e[1])  # type: ignore[arg-type]
        return None if v is None else -v if e[0] == "neg" else v
    return None


def _fold(e: Expr) -> Expr:
    """``e`` with each sum, difference and product of two numerals written as one (exactly: numerals are
    decimals), so that a divisor that a table makes constant is a numeral."""
    if e[0] == "bin" and e[1] in ("+", "-", "*"):
        a, b = _fold(e[2]), _fold(e[3])  # type: ignore[arg-type]
        va, vb = _value(a), _value(b)
        if va is None or vb is None:
            return ("bin", e[1], a, b)
        v = va + vb if e[1] == "+" else va - vb if e[1] == "-" else va * vb
        text = format(abs(v), "f")
        return ("neg", ("num", text)) if v < 0 else ("num", text)
    return tuple(a if i == 0 or not isinstance(a, tuple) or not a else
                 _fold(a) if isinstance(a[0], str) else tuple(_fold(b) for b in a) for i, a in enumerate(e))


def _longest(e: Expr, counter: str) -> int:
    """The length of the longest table of ``counter`` inside ``e``."""
    if e[0] == "table":
        consts = e[2]
        assert isinstance(consts, tuple)
        return len(consts) if e[1] == counter else 0
    return max([_longest(a, counter) for a in _children(e)], default=0)


def _at(e: Expr, counter: str, k: int) -> Expr:
    """``e`` with every table of ``counter`` as its value at step ``k`` (its last from its end on)."""
    if e[0] == "table" and e[1] == counter:
        consts = e[2]
        assert isinstance(consts, tuple)
        return consts[min(k, len(consts) - 1)]  # type: ignore[no-any-return]
    return tuple(a if i == 0 or not isinstance(a, tuple) or not a else
                 _at(a, counter, k) if isinstance(a[0], str) else tuple(_at(b, counter, k) for b in a)
                 for i, a in enumerate(e))


def _children(e: Expr) -> list[Expr]:
    out: list[Expr] = []
    for a in e[1:]:
        if isinstance(a, tuple) and a:
            out.extend([a] if isinstance(a[0], str) else a)
    return out


def text(e: Expr) -> str:
    """RCL text of a resolved, lifted tree (:meth:`Writer.rcl`), fully bracketed."""
    kind = e[0]
    if kind == "num":
        t = str(e[1])
        return "0" + t if t.startswith(".") else t
    if kind in ("bool", "text"):
        return str(e[1])
    if kind == "not":
        return f"(not {text(e[1])})"  # type: ignore[arg-type]
    if kind == "neg":
        return f"(-{text(e[1])})"  # type: ignore[arg-type]
    if kind == "paren":
        return f"({text(e[1])})"  # type: ignore[arg-type]
    if kind == "and*":
        items = e[1]
        assert isinstance(items, tuple)
        return "(" + " and ".join(text(x) for x in items) + ")"
    if kind == "call":
        return f"{e[1]}({text(e[2][0])})"  # type: ignore[index]
    op, la, lb = e[1], text(e[2]), text(e[3])  # type: ignore[arg-type]
    if op == "xor":
        return f"(not ({la} <=> {lb}))"
    return f"({la} {_RCL_OP[str(op)]} {lb})"
