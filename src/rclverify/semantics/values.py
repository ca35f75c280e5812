"""Concrete RCL values as Python values: the one convention shared by every
part of rclverify that sees a node's actual inputs and outputs (property
tests of Python implementations, offline checking of recorded traces).

The convention (also documented in docs/values.md):

==================  =========================================================
RCL type            Python value
==================  =========================================================
``REAL``            a finite ``float`` or ``int`` or ``fractions.Fraction``
                    (compared exactly, as a rational)
``INTEGER``         ``int`` (``bool`` is rejected)
``NATURAL``         ``int`` >= 0
``BOOL``            ``bool``
enumeration         the value's name as ``str`` (``"red"``)
constructor set     :class:`Term` (``Term("move", (1.5, 2.0))``)
``A x B --> C``     :class:`FiniteFunction`: a finite table plus a default,
                    callable (``f(1.0, 2.0)``) and a read-only mapping
``set(T)``          ``frozenset``
``seq(T)``          ``tuple``
tuple type          ``tuple`` of the element values
``{}``              no value inhabits it
==================  =========================================================

:func:`conforms` checks a value against a resolved type and says what is
wrong in one sentence; :func:`render` prints a value in RCL syntax (for
counterexamples and verdicts).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any, Iterator, Mapping, TypeAlias, Union

from rclverify.lang import types as T


@dataclass(frozen=True)
class Term:
    """A constructor term of a constructor set, e.g. ``move(1.5, 2.0)``.

    ``name`` is the constructor's name, ``args`` its argument values (each a
    value of this module's convention).  Immutable and hashable.
    """

    name: str
    args: tuple[Any, ...] = ()

    def __repr__(self) -> str:
        return render(self)


@dataclass(frozen=True)
class FiniteFunction(Mapping[tuple[Any, ...], Any]):
    """A function-typed value backed by a finite table and a default.

    ``table`` maps argument tuples (always tuples, of the function's arity) to
    results; every argument not in the table gives ``default``.  Calling it
    (``f(x, y)``) and indexing it (``f[(x, y)]``, or ``f[x]`` for arity 1)
    both look the table up.  Iterating yields the table's keys only.

    Raises ``TypeError`` when called with the wrong number of arguments.
    """

    table: Mapping[tuple[Any, ...], Any]
    default: Any
    arity: int = 1
    _items: tuple[tuple[tuple[Any, ...], Any], ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        items = []
        for k, v in self.table.items():
            key = k if isinstance(k, tuple) and (self.arity != 1 or len(k) == 1) else (k,)
            if len(key) != self.arity:
                raise TypeError(f"table key {k!r} has {len(key)} argument(s); the function takes {self.arity}")
            items.append((key, v))
        object.__setattr__(self, "_items", tuple(items))
        object.__setattr__(self, "table", dict(items))

    def __call__(self, *args: Any) -> Any:
        if len(args) != self.arity:
            raise TypeError(f"function takes {self.arity} argument(s), {len(args)} given")
        return self.table.get(tuple(args), self.default)

    def __getitem__(self, key: Any) -> Any:
        args = key if isinstance(key, tuple) and (self.arity != 1 or len(key) == 1) else (key,)
        return self(*args)

    def __iter__(self) -> Iterator[tuple[Any, ...]]:
        return iter(self.table)

    def __len__(self) -> int:
        return len(self.table)

    def __hash__(self) -> int:
        h = self.__dict__.get("_hash")
        if h is None:  # immutable: hashed once (monitors hash the same table at every event)
            h = hash((frozenset(self._items), self.default, self.arity))
            object.__setattr__(self, "_hash", h)
        return int(h)

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, FiniteFunction) and self.arity == other.arity
                and self.default == other.default and dict(self._items) == dict(other._items))

    def __repr__(self) -> str:
        return render(self)


#: One RCL value in this module's convention (the table in the module
#: docstring): what an environment maps a name to (``Mapping[str, Value]``:
#: a node's I/O values by qualified name, or bound variables by name).
Value: TypeAlias = Union[bool, int, Fraction, float, str, frozenset["Value"], tuple["Value", ...], Term,
                         FiniteFunction]


def exact(x: Any) -> Fraction:
    """The exact rational value of a numeric value (``float`` converted exactly).

    Raises ``ValueError`` for a NaN or an infinity, ``TypeError`` for a non-number.
    """
    if isinstance(x, bool) or not isinstance(x, (int, float, Fraction)):
        raise TypeError(f"not a number: {x!r}")
    if isinstance(x, float) and not math.isfinite(x):
        raise ValueError(f"not a finite number: {x!r}")
    return Fraction(x)


def conforms(value: Any, typ: T.Type) -> str | None:
    """``None`` when ``value`` is a value of RCL type ``typ`` under the
    convention above; otherwise one sentence saying what is wrong
    (``"-1 is below 0, not a NATURAL"``).

    A :class:`FiniteFunction` is checked entry by entry and on its default.
    """
    if isinstance(typ, T.Scalar):
        if typ.name == "BOOL":
            return None if isinstance(value, bool) else f"{value!r} is not a BOOL (expected True or False)"
        if isinstance(value, bool):
            return f"{value!r} is a bool, not a {typ.name}"
        if typ.name == "REAL":
            if isinstance(value, float) and not math.isfinite(value):
                return f"{value!r} is not a finite REAL"
            return None if isinstance(value, (int, float, Fraction)) else f"{value!r} is not a REAL"
        if not isinstance(value, int):
            return f"{value!r} is not an integer, so not a {typ.name}"
        if typ.name == "NATURAL" and value < 0:
            return f"{value!r} is below 0, not a NATURAL"
        return None
    if isinstance(typ, T.EnumT):
        if isinstance(value, str) and value in typ.values:
            return None
        return f"{value!r} is not a value of {typ.name} (one of {', '.join(typ.values)})"
    if isinstance(typ, T.DataT):
        if not isinstance(value, Term):
            return f"{value!r} is not a constructor term of {typ.name}"
        args = typ.ctor(value.name)
        if args is None:
            return f"{value.name} is not a constructor of {typ.name} (one of {', '.join(n for n, _ in typ.ctors)})"
        if len(args) != len(value.args):
            return f"{value.name} takes {len(args)} argument(s), the term has {len(value.args)}"
        for k, (a, t) in enumerate(zip(value.args, args), 1):
            why = conforms(a, t)
            if why:
                return f"argument {k} of {value.name}: {why}"
        return None
    if isinstance(typ, T.FuncT):
        if not isinstance(value, FiniteFunction):
            return f"{value!r} is not a finite function ({typ})"
        if value.arity != len(typ.args):
            return f"the function takes {value.arity} argument(s), {typ} takes {len(typ.args)}"
        for key, res in value.table.items():
            for a, t in zip(key, typ.args):
                why = conforms(a, t)
                if why:
                    return f"argument of entry {render_key(key)}: {why}"
            why = conforms(res, typ.result)
            if why:
                return f"result at {render_key(key)}: {why}"
        why = conforms(value.default, typ.result)
        return f"default result: {why}" if why else None
    if isinstance(typ, T.EmptyT):
        return f"{value!r}: the empty type {{}} has no values"
    if isinstance(typ, T.SetT):
        if not isinstance(value, frozenset):
            return f"{value!r} is not a set (frozenset)"
        return next((f"element {render(v)}: {w}" for v in value if (w := conforms(v, typ.elem))), None)
    if isinstance(typ, T.SeqT):
        if not isinstance(value, tuple):
            return f"{value!r} is not a sequence (tuple)"
        return next((f"item {k}: {w}" for k, v in enumerate(value) if (w := conforms(v, typ.elem))), None)
    if isinstance(typ, T.TupleT):
        if not isinstance(value, tuple) or len(value) != len(typ.elems):
            return f"{value!r} is not a tuple of {len(typ.elems)} values"
        return next((f"component {k}: {w}" for k, (v, t) in enumerate(zip(value, typ.elems), 1)
                     if (w := conforms(v, t))), None)
    return f"values of type {typ} are not supported"


def decimal_text(fr: Fraction) -> str | None:
    """``fr`` as an exact decimal (``Fraction(1, 5)`` -> ``"0.2"``), or
    ``None`` when its denominator has a prime factor other than 2 and 5
    (``1/3`` has no finite decimal).  Counterexamples and models print a
    rational so where it is exact (docs/values.md)."""
    d = fr.denominator
    twos = fives = 0
    while d % 2 == 0:
        d //= 2
        twos += 1
    while d % 5 == 0:
        d //= 5
        fives += 1
    if d != 1:
        return None
    places = max(twos, fives)
    digits = str(abs(fr.numerator) * 10 ** places // fr.denominator).rjust(places + 1, "0")
    text = digits[:len(digits) - places] + ("." + digits[len(digits) - places:] if places else "")
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    return ("-" if fr.numerator < 0 else "") + text


def render_key(key: tuple[Any, ...]) -> str:
    """``(1.5, 2)`` for a function-table key (``1.5`` for arity 1)."""
    return render(key[0]) if len(key) == 1 else "(" + ", ".join(render(k) for k in key) + ")"


def render(value: Any) -> str:
    """``value`` in RCL syntax: ``TRUE``, ``1.5``, ``red``, ``move(1.5, 2)``,
    ``{1, 2}``, ``(1, 2)`` (a sequence prints like a tuple: both are
    Python tuples); a function as
    ``{(1, 2) |-> 3, ... ; else |-> 0}``.  Deterministic (sets and tables
    sorted by their rendering)."""
    if isinstance(value, bool):
        return "TRUE" if value else "FALSE"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, Fraction):
        if value.denominator == 1:
            return str(value.numerator)
        return decimal_text(value) or f"{value.numerator}/{value.denominator}"
    if isinstance(value, str):
        return value
    if isinstance(value, Term):
        return value.name + ("(" + ", ".join(render(a) for a in value.args) + ")" if value.args else "")
    if isinstance(value, FiniteFunction):
        rows = sorted(f"{render_key(k)} |-> {render(v)}" for k, v in value.table.items())
        return "{" + ", ".join(rows + [f"else |-> {render(value.default)}"]) + "}"
    if isinstance(value, frozenset):
        return "{" + ", ".join(sorted(render(v) for v in value)) + "}"
    if isinstance(value, tuple):
        return "(" + ", ".join(render(v) for v in value) + ")"
    return repr(value)
