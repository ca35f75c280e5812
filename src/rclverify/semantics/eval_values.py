"""Values and domains of direct evaluation: what a number is, exact
arithmetic on RCL numbers, the numbers a set of values mentions, whether a
number fits a base type, the placeholders a quantifier's enumeration uses
(a fresh value, a slot without a domain).

Part of the direct evaluator (:mod:`rclverify.semantics.evaluate`, whose module
docstring states the semantics); values follow :mod:`rclverify.semantics.values`.
"""
from __future__ import annotations

from fractions import Fraction
from typing import Any, Callable, Mapping

from rclverify.semantics.operators import COMPARISONS, OPERATORS
from rclverify.semantics.operators import Undecided as Undecided  # re-exported: its home before the semantics table
from rclverify.semantics.values import FiniteFunction, Term


#: comparison symbol -> its exact meaning (the semantics table's entry)
_CMP: Mapping[str, Callable[[Any, Any], bool]] = {s: OPERATORS[s].exact for s in COMPARISONS}
_INFINITE = ("REAL", "INTEGER", "NATURAL")
_LIT: dict[str, int | Fraction] = {}


def _numbers(v: Any, out: set[Any]) -> None:
    if isinstance(v, bool) or v is None:
        return
    if isinstance(v, (int, float, Fraction)):
        out.add(v)
    elif isinstance(v, Term):
        for a in v.args:
            _numbers(a, out)
    elif isinstance(v, FiniteFunction):
        for key, res in v.table.items():
            for a in key:
                _numbers(a, out)
            _numbers(res, out)
        _numbers(v.default, out)
    elif isinstance(v, (tuple, frozenset)):
        for a in v:
            _numbers(a, out)


def arithmetic(op: str, x: Any, y: Any) -> Any:
    """``x op y`` for ``op`` in ``+ - * /`` on RCL numbers: the exact meaning of
    the semantics table (:data:`rclverify.semantics.operators.OPERATORS`: a
    float operand is the rational it denotes, no rounding, no overflow).
    Raises :class:`Undecided` for a division by zero (RCL leaves it unspecified)."""
    return OPERATORS[op].exact(x, y)


class _NoDomain:
    """A slot whose values cannot be enumerated (``reason``); usable only when pinned."""

    __slots__ = ("reason",)

    def __init__(self, reason: str) -> None:
        self.reason = reason


def _integral(v: Any) -> int | None:
    if isinstance(v, bool) or not isinstance(v, (int, float, Fraction)):
        return None
    if isinstance(v, int):
        return v
    if isinstance(v, float) and not v.is_integer():
        return None
    q = Fraction(v)
    return int(q) if q.denominator == 1 else None


def _fit(v: Any, kind: str) -> tuple[bool, Any]:
    """``(True, v')`` when number ``v`` is a value of ``kind`` (REAL/INTEGER/NATURAL), as ``v'``."""
    if kind == "REAL":
        ok = not isinstance(v, bool) and isinstance(v, (int, float, Fraction))
        return ok, v
    k = _integral(v)
    if k is None or (kind == "NATURAL" and k < 0):
        return False, None
    return True, k


def _fits(v: Any, kind: str) -> bool:
    if isinstance(v, bool) or not isinstance(v, (int, float, Fraction)):
        return False
    if kind == "REAL":
        return True
    return isinstance(v, int) and (kind == "INTEGER" or v >= 0)


class _Fresh:
    """A value no atom of the body can tell apart from infinitely many others."""

    __slots__ = ("value",)

    def __init__(self, value: Any) -> None:
        self.value = value
