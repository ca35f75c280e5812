"""The abstract syntax of AJPF's property specification language (PSL):
terms, BDI propositions and LTL formulas (:mod:`.psl` states the language,
parses and prints it; its names are re-exported there).  These classes are
PSL's own, not copies of RCL's: docs/semantics.md, "One formula core".
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Generic, Iterator, TypeVar, Union

# ---------------------------------------------------------------------------
# Terms
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class Sym:
    """An atom: a lower-case name (``danger_red``, ``jackal``)."""

    name: str


@dataclass(frozen=True)
class Num:
    """A number, kept as written (``3``, ``0.5``)."""

    text: str


@dataclass(frozen=True)
class Wild:
    """``_``: matches any value."""


_A = TypeVar("_A", covariant=True)  # the type of a compound's arguments


@dataclass(frozen=True)
class Compound(Generic[_A]):
    """``name(arg, ...)`` with at least one argument.  A PSL term's arguments
    are PSL terms (``Compound[Term]``); the Gwendolen interpreter's terms
    also hold its variables (:mod:`rclverify.backends.model_checking.gwendolen`)."""

    name: str
    args: tuple[_A, ...]


Term = Union[Sym, Num, Wild, "Compound[Term]"]

# ---------------------------------------------------------------------------
# Formulas
# ---------------------------------------------------------------------------

MODALITIES = ("B", "G", "D", "I", "ItD")


@dataclass(frozen=True)
class Modal:
    """``B(agent, term)`` and its siblings; ``op`` is one of :data:`MODALITIES`."""

    op: str
    agent: str
    term: Term


@dataclass(frozen=True)
class Percept:
    """``P(term)``."""

    term: Term


@dataclass(frozen=True)
class Const:
    """``T`` (``value`` true) or ``F``."""

    value: bool


@dataclass(frozen=True)
class Not:
    operand: "Formula"


@dataclass(frozen=True)
class And:
    parts: tuple["Formula", ...]


@dataclass(frozen=True)
class Or:
    parts: tuple["Formula", ...]


@dataclass(frozen=True)
class Implies:
    left: "Formula"
    right: "Formula"


@dataclass(frozen=True)
class Always:
    operand: "Formula"


@dataclass(frozen=True)
class Eventually:
    operand: "Formula"


@dataclass(frozen=True)
class Until:
    left: "Formula"
    right: "Formula"


@dataclass(frozen=True)
class Release:
    left: "Formula"
    right: "Formula"


Formula = Union[Modal, Percept, Const, Not, And, Or, Implies, Always, Eventually, Until, Release]
TRUE = Const(True)
FALSE = Const(False)


#: Deepest nesting of a formula or term (operators, parentheses, compound
#: terms): deeper input is refused with a located error, so that no
#: recursive function over formulas and terms meets Python's recursion limit.
MAX_NESTING = 64


def depth(x: "Formula | Term") -> int:
    """The nesting depth of a formula or term (an atom's term counts inside
    it), computed without recursion: 1 for ``T``, ``danger_red``."""
    best = 0
    stack: list[tuple[object, int]] = [(x, 1)]
    while stack:
        node, d = stack.pop()
        best = max(best, d)
        if isinstance(node, (Not, Always, Eventually)):
            stack.append((node.operand, d + 1))
        elif isinstance(node, (And, Or)):
            stack.extend((p, d + 1) for p in node.parts)
        elif isinstance(node, (Implies, Until, Release)):
            stack.extend(((node.left, d + 1), (node.right, d + 1)))
        elif isinstance(node, (Modal, Percept)):
            stack.append((node.term, d + 1))
        elif isinstance(node, Compound):
            stack.extend((a, d + 1) for a in node.args)
    return best


class PslSyntaxError(ValueError):
    """A malformed property text; ``col`` is the 1-based column of the problem."""

    def __init__(self, message: str, col: int) -> None:
        super().__init__(f"column {col}: {message}")
        self.message = message
        self.col = col


# ---------------------------------------------------------------------------
# Traversal
# ---------------------------------------------------------------------------


def propositions(f: Formula) -> Iterator[Formula]:
    """Every proposition (``Modal``, ``Percept``) in ``f``, left to right."""
    if isinstance(f, (Modal, Percept)):
        yield f
    elif isinstance(f, Const):
        return
    elif isinstance(f, (Not, Always, Eventually)):
        yield from propositions(f.operand)
    elif isinstance(f, (And, Or)):
        for p in f.parts:
            yield from propositions(p)
    else:
        yield from propositions(f.left)
        yield from propositions(f.right)
