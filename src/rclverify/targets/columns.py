"""An RCL formula evaluated over whole columns of recorded values, with a certificate per row.

The offline batch path (:mod:`.batch`) asks, for each row (one question and
its answer), whether a quantifier-free formula holds **in exact
arithmetic** (the first semantics of :func:`rclverify.semantics.floatsem.judge`,
whose answer "true in exact arithmetic" is ``Judgement(True, "exact")``).
It evaluates the formula in float64 with numpy and carries, for every
numeric term, an upper bound of its distance to the exact rational value
(running error analysis, Higham, *Accuracy and Stability of Numerical
Algorithms*, ch. 3: a ``+ - *`` of doubles is within ``2**-53`` relative of
the exact result; the bound used is ``2**-52``, twice that):

* a recorded ``REAL`` value is exact (a double is the rational it denotes);
  a literal is exact when its decimal is a double (``120``, ``0.5``), else
  within ``|v| * 2**-52`` (``119.99999999999999``, ``0.1``);
* a comparison is **sure** when both sides are exact (the double comparison
  is the exact one) or when the two sides are further apart than twice the
  sum of their bounds (plus a relative and an absolute slack): its double
  truth is then its exact truth;
* ``not``, ``and``, ``or``, ``->``, ``<=>`` combine (truth, sure) as
  three-valued logic does: ``a and b`` is surely false when one side is
  surely false, surely true when both are surely true;
* enumeration values are compared by name (codes), exactly.

A row whose every formula is surely true is decided; every other row
(surely false, or not sure) is left to the streaming engine, whose judge
decides it (exact, double, tolerance).  :func:`field_values`, :func:`column` and :func:`seed` read the recorded
values into columns as the engine's one-field mapper reads them (a finite
``float`` for ``REAL``, a ``str`` of the enumeration for one; anything else
is marked, and left to the engine).  What is not compiled (division,
functions, sets, quantifiers, integers, booleans as values) raises
:class:`Unsupported`: the batch path then declines the whole node.
"""
from __future__ import annotations

from fractions import Fraction
from itertools import repeat
from operator import is_, itemgetter
from typing import Any, Callable, Mapping, TypeVar

from rclverify.core.numeric import np

from rclverify.lang import ast
from rclverify.lang import types as T
from rclverify.lang.types import Checked, CheckedNode
from rclverify.semantics.operators import COMPARISONS, OPERATORS

_REL = 2.0 ** -52  # relative bound of one rounding (twice the unit roundoff)
_SLACK_REL = 2.0 ** -48
_SLACK_ABS = 2.0 ** -1000
#: Each comparison's numpy ufunc, as the one operator table names it (semantics/operators.py).
_CMP: Mapping[str, Callable[[Any, Any], Any]] = {s: getattr(np, str(OPERATORS[s].numpy)) for s in sorted(COMPARISONS)}


_R = TypeVar("_R")  # what a constant's definition compiles to (a formula or a term)


class Unsupported(Exception):
    """A construct the column evaluator does not compile (its name in ``str``)."""


#: A compiled formula: columns (``in.r`` -> float64 or int array) -> (truth, sure), bool arrays.
Compiled = Callable[[Mapping[str, np.ndarray]], tuple[np.ndarray, np.ndarray]]


def io_kind(typ: Any) -> str | None:
    """``"real"`` for ``REAL``, ``"enum"`` for an enumeration, ``None`` for a type not compiled."""
    if isinstance(typ, T.Scalar) and typ.name == "REAL":
        return "real"
    if isinstance(typ, T.EnumT):
        return "enum"
    return None


class ColumnCompiler:
    """Compiles formulas of ``node`` (in ``checked``'s context); ``codes`` maps
    each enumeration value's name to the integer that stands for it in a column."""

    def __init__(self, checked: Checked, node: CheckedNode) -> None:
        self.env, self.node = checked.env, node
        self.codes = {name: k for k, name in enumerate(sorted(self.env.enum_values))}
        self._expanding: set[str] = set()
        #: the lengths of the bound offsets' axes in scope (a window's quantifiers, :mod:`.column_windows`):
        #: a term compiled inside them is an array of shape ``(rows,) + axes``; empty outside every quantifier
        self.axes: tuple[int, ...] = ()

    def compile(self, formula: ast.Expr) -> Compiled:
        """``formula`` as a function of the columns (raises :class:`Unsupported`)."""
        return self._bool(formula)

    # -- booleans ------------------------------------------------------------------------
    def _bool(self, e: Any) -> Compiled:
        if isinstance(e, ast.BoolLit):
            v, axes = bool(e.value), self.axes
            return lambda c: (_full(c, v, axes), _full(c, True, axes))
        if isinstance(e, ast.Unary) and e.op == "not":
            f = self._bool(e.operand)
            return lambda c: _not(f(c))
        if isinstance(e, ast.Binary) and e.op in ("and", "or", "->", "<=>"):
            a, b = self._bool(e.left), self._bool(e.right)
            if e.op == "and":
                return lambda c: _and(a(c), b(c))
            if e.op == "or":
                return lambda c: _or(a(c), b(c))
            if e.op == "->":
                return lambda c: _or(_not(a(c)), b(c))
            return lambda c: _iff(a(c), b(c))
        if isinstance(e, ast.Compare):
            parts = [self._compare(op, x, y) for op, x, y in zip(e.ops, e.operands, e.operands[1:])]
            if len(parts) == 1:
                return parts[0]

            def chain(c: Mapping[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
                out = parts[0](c)
                for p in parts[1:]:
                    out = _and(out, p(c))
                return out
            return chain
        if isinstance(e, ast.Var) and e.prefix is None and e.name in self.env.constants:
            return self._constant(e.name, self._bool)
        raise Unsupported(f"a {type(e).__name__} as a formula")

    def _compare(self, op: str, x: Any, y: Any) -> Compiled:
        ex, ey = self._enum(x), self._enum(y)
        if ex is not None or ey is not None:
            if ex is None or ey is None or op not in ("==", "!="):
                raise Unsupported("an enumeration compared with a number or ordered")
            cmp, axes = _CMP[op], self.axes
            return lambda c: (cmp(ex(c), ey(c)), _full(c, True, axes))
        nx, ny = self._num(x), self._num(y)
        cmp = _CMP[op]

        def compare(c: Mapping[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
            (vx, bx), (vy, by) = nx(c), ny(c)
            with np.errstate(all="ignore"):
                truth = cmp(vx, vy)
                bound = bx + by
                if type(bound) is float and bound == 0:  # both sides exact everywhere: sure wherever both are finite
                    return truth, np.isfinite(vx) & np.isfinite(vy)
                gap = np.abs(vx - vy)
                sure = (bound == 0) | (gap > 2 * bound + _SLACK_REL * (np.abs(vx) + np.abs(vy)) + _SLACK_ABS)
                sure &= np.isfinite(vx) & np.isfinite(vy)
            return truth, sure
        return compare

    # -- terms ---------------------------------------------------------------------------
    def _enum(self, e: Any) -> Callable[[Mapping[str, np.ndarray]], Any] | None:
        """An enumeration-valued term (a literal or an I/O variable), else ``None``."""
        if isinstance(e, ast.Var):
            if e.prefix is None and e.name in self.env.enum_values:
                code = self.codes[e.name]
                return lambda c: code
            key = self._key(e)
            if key is not None and io_kind(self.node.io_type(e)) == "enum":
                return _io(key, self.axes)
        return None

    def _key(self, v: ast.Var) -> str | None:
        if v.prefix is not None:
            return v.qualified if v.prefix in ("in", "out") else None
        if v.name in self.env.enum_values or v.name in self.env.constants or v.name in self.env.ctors:
            return None
        return ("in." + v.name) if v.name in self.node.inputs else ("out." + v.name)

    def _num(self, e: Any) -> Callable[[Mapping[str, np.ndarray]], tuple[Any, Any]]:
        """A numeric term: columns -> (float64 value, bound of its distance to the exact value)."""
        if isinstance(e, ast.NumLit):
            exact = e.value
            v = float(exact)
            bound = 0.0 if Fraction(v) == exact else abs(v) * _REL + _SLACK_ABS
            return lambda c: (v, bound)
        if isinstance(e, ast.Var):
            if e.prefix is None and e.name in self.env.constants:
                return self._constant(e.name, self._num)
            key = self._key(e)
            if key is None or io_kind(self.node.io_type(e)) != "real":
                raise Unsupported(f"the term {e.qualified}")
            value = _io(key, self.axes)
            return lambda c: (value(c), 0.0)
        if isinstance(e, ast.Unary) and e.op == "-":
            f = self._num(e.operand)
            return lambda c: _neg(f(c))
        if isinstance(e, ast.Unary) and e.op == "abs":  # | |a| - |b| | <= |a - b|: the error bound is kept
            g = self._num(e.operand)
            return lambda c: _abs(g(c))
        if isinstance(e, ast.Unary) and e.op in ("sqrt", "sin", "cos"):
            raise Unsupported(f"{e.op}(...): the columns keep no error bound through it (the engine judges it)")
        if isinstance(e, ast.Binary) and e.op in ("+", "-", "*"):
            a, b = self._num(e.left), self._num(e.right)
            return {"+": lambda c: _add(a(c), b(c)), "-": lambda c: _add(a(c), _neg(b(c))),
                    "*": lambda c: _mul(a(c), b(c))}[e.op]
        raise Unsupported(f"a {type(e).__name__} {getattr(e, 'op', '')} as a term")

    def _constant(self, name: str, how: Callable[[Any], _R]) -> _R:
        if name in self._expanding:
            raise Unsupported(f"the constant {name} defined through itself")
        self._expanding.add(name)
        try:
            return how(self.env.constants[name][1])
        finally:
            self._expanding.discard(name)


def _full(c: Mapping[str, np.ndarray], v: bool, axes: tuple[int, ...] = ()) -> np.ndarray:
    n = len(next(iter(c.values()))) if c else 0
    return np.full((n,) + axes, v, dtype=bool)


def _io(key: str, axes: tuple[int, ...]) -> Callable[[Mapping[str, np.ndarray]], np.ndarray]:
    """The column of ``key``, one value a row; inside quantifiers (``axes``) shaped to broadcast over them."""
    if not axes:
        return lambda c: c[key]
    ones = (1,) * len(axes)
    return lambda c: c[key].reshape((-1,) + ones)


def _not(a: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    return ~a[0], a[1]


def _and(a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    (ta, sa), (tb, sb) = a, b
    return ta & tb, (sa & sb) | (sa & ~ta) | (sb & ~tb)


def _or(a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    (ta, sa), (tb, sb) = a, b
    return ta | tb, (sa & sb) | (sa & ta) | (sb & tb)


def _iff(a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    return a[0] == b[0], a[1] & b[1]


def _neg(a: tuple[Any, Any]) -> tuple[Any, Any]:
    return -a[0], a[1]


def _abs(a: tuple[Any, Any]) -> tuple[Any, Any]:
    return np.abs(a[0]), a[1]


def _add(a: tuple[Any, Any], b: tuple[Any, Any]) -> tuple[Any, Any]:
    with np.errstate(all="ignore"):
        v = a[0] + b[0]
        return v, a[1] + b[1] + np.abs(v) * _REL + _SLACK_ABS


def _mul(a: tuple[Any, Any], b: tuple[Any, Any]) -> tuple[Any, Any]:
    (va, ba), (vb, bb) = a, b
    with np.errstate(all="ignore"):
        v = va * vb
        return v, np.abs(va) * bb + np.abs(vb) * ba + ba * bb + np.abs(v) * _REL + _SLACK_ABS


def seed(value: Any, codes: Mapping[str, int] | None) -> Any:
    """A value the engine holds as a column entry: a finite float, or the code of an
    enumeration value; ``None`` for anything else."""
    if codes is not None:
        return codes.get(value) if type(value) is str else None
    return value if type(value) is float and np.isfinite(value) else None


def field_values(fields: list[Any], rows: np.ndarray, name: str) -> list[Any]:
    """Field ``name`` of the messages at ``rows`` (``None`` where a message has none)."""
    if not len(rows):
        return []
    first, step = int(rows[0]), int(rows[1] - rows[0]) if len(rows) > 1 else 1
    if step > 0 and int(rows[-1]) == first + step * (len(rows) - 1) and bool((np.diff(rows) == step).all()):
        # evenly spaced (topics taking turns): a slice
        picked = fields[first:int(rows[-1]) + 1:step]
    else:
        picked = itemgetter(*rows.tolist())(fields)
    try:
        return list(map(itemgetter(name), picked))
    except (KeyError, TypeError, IndexError):
        out = []
        for f in picked:
            try:
                out.append(f[name])
            except (KeyError, TypeError, IndexError):
                out.append(None)
        return out


def column(vals: list[Any], kind: str, codes: Mapping[str, int]) -> tuple[np.ndarray, np.ndarray]:
    """(mapped as the engine's one-field rule maps, the column): a finite ``float``
    for ``REAL``, a ``str`` of the enumeration for one."""
    n = len(vals)
    want = float if kind == "real" else str
    every = list(map(type, vals)).count(want) == n  # each value's type, counted (none: every one)
    if every:
        good = np.ones(n, dtype=bool)
    else:
        good = np.fromiter(map(is_, map(type, vals), repeat(want)), bool, n)
    if kind == "real":
        if every and n:
            col = np.fromiter(vals, np.float64, n)
        else:
            col = np.array([v if g else np.nan for v, g in zip(vals, good.tolist())], dtype=np.float64)
        good &= np.isfinite(col)
        return good, col
    get = codes.get  # only a value of the variable's own enumeration has a code
    if good.all():
        col = np.fromiter(map(get, vals, repeat(-1)), np.int64, n)
    else:
        col = np.fromiter((get(v, -1) if g else -1 for v, g in zip(vals, good.tolist())), np.int64, n)
    return good & (col >= 0), col


def block_column(block: Any, rows: np.ndarray, name: str, kind: str, codes: Mapping[str, int]
                 ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`column` of field ``name`` at ``rows`` of a log block (``traces/jsonl_blocks.LogBlock``: its
    ``values`` and ``kept``): :func:`column` maps each row alone, so the column of every row of the block
    is made once for the field, kind and codes and kept with the block (the deadline judge and the
    untimed check's batch path read the same fields of the same block), and each request takes its rows
    of it (copies, so a caller may write into what it gets)."""
    good, col = block.kept(("column", name, kind, tuple(codes.items())),
                           lambda: column(block.values(np.arange(len(block)), name), kind, codes))
    return good[rows], col[rows]


__all__ = ["ColumnCompiler", "Compiled", "Unsupported", "block_column", "column", "field_values", "io_kind", "seed"]
