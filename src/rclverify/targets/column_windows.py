"""Windowed formulas over whole columns: ``forall`` and ``exists`` over ``<lo upto hi>`` of a sampled window.

A time window is a value a message carries (docs/semantics.md, "Against
the peers"): a variable of type ``NATURAL --> REAL`` mapped from an array
field (traces/mapping.py, the window rule), ``in.x(k)`` the sample at offset
``k``; STL's bounded ``G`` and ``F`` are ``forall`` and ``exists`` over
``<0 upto h>``, until a nesting of the two.  The batch path (:mod:`rclverify.backends.monitors.batch`)
holds such a variable as a float64 column of shape ``(rows, width)``, one
row a message's window (``width``: the offsets the formulas read,
:attr:`WindowCompiler.widths`; a message whose window has another length
is left to the engine).

:class:`WindowCompiler` extends :class:`~.columns.ColumnCompiler` (same
certificate: a row is judged in batch only when surely decided in exact
arithmetic) with:

* a quantifier ``forall``/``exists`` binding one name over a ``<lo upto
  hi>`` of integer literals (``lo <= hi``): its body is compiled with one
  more axis of length ``hi - lo + 1`` (every term inside it an array of
  shape ``(rows,) + axes``, numpy broadcasting the rest); ``forall`` is
  true where the body is true on the whole axis, surely so where it is
  surely true on the whole axis, surely false where it is surely false at
  one offset (``exists`` the dual): three-valued logic, as ``and`` and
  ``or`` over the offsets;
* an **index term**: a bound offset, an integer literal, ``+ - *`` of
  them: known when the formula is compiled, an integer array over the axes
  in scope; a comparison of index terms (``i < j``) is exact (sure);
* an application ``in.x(t)`` of a window variable to an index term: the
  column's entries at those offsets (every offset ``>= 0``; the width read
  is the largest plus one).

:class:`WindowMargins` extends :class:`~.column_margins.MarginCompiler`:
``forall`` is the minimum and ``exists`` the maximum over the axis, the
first offset kept on a tie (as :mod:`rclverify.semantics.robustness` folds
the range in order, ties on the left), its deciding comparison with it; a
comparison of index terms reads no value of the run: ``+inf`` or ``-inf``
by its truth.  ``tests/backends/test_window_batch.py`` checks both against
the streaming engine and a brute-force enumeration of the window.
"""
from __future__ import annotations

from fractions import Fraction
from typing import Any, Callable, Mapping

from rclverify.core.numeric import np

from rclverify.lang import ast
from rclverify.lang import types as T
from rclverify.lang.types import Checked, CheckedNode
from rclverify.semantics.operators import COMPARISONS, OPERATORS
from rclverify.targets.column_margins import ColumnMargin, MarginCompiler
from rclverify.targets.columns import Compiled, ColumnCompiler, Unsupported

_CMP: Mapping[str, Callable[[Any, Any], Any]] = {s: getattr(np, str(OPERATORS[s].numpy)) for s in sorted(COMPARISONS)}
_INT_OPS: Mapping[str, Callable[[Any, Any], Any]] = {"+": np.add, "-": np.subtract, "*": np.multiply}
#: the most offsets one formula's axes span together (the arrays are rows x this)
MAX_CELLS = 4096


def is_window(typ: Any) -> bool:
    """Whether ``typ`` is a window type: ``NATURAL --> REAL`` or ``INTEGER --> REAL``."""
    return isinstance(typ, T.FuncT) and len(typ.args) == 1 and isinstance(typ.args[0], T.Scalar) and \
        typ.args[0].name in ("NATURAL", "INTEGER") and isinstance(typ.result, T.Scalar) and typ.result.name == "REAL"


class WindowCompiler(ColumnCompiler):
    """:class:`~.columns.ColumnCompiler` with window quantifiers and applications (module docstring);
    ``widths``: each window variable's key -> the offsets its column holds (the largest read plus one)."""

    def __init__(self, checked: Checked, node: CheckedNode) -> None:
        super().__init__(checked, node)
        self.widths: dict[str, int] = {}
        #: the bound offsets in scope, outermost first: (name, its values)
        self.scope: list[tuple[str, np.ndarray]] = []

    def _bool(self, e: Any) -> Compiled:
        if isinstance(e, ast.Quant):
            name, values = self.binding(e)
            body = self.within(name, values, lambda: self._bool(e.body))
            axis, shape = len(self.scope) + 1, self.axes + (len(values),)
            forall = e.kind == "forall"

            def quant(c: Mapping[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
                t, s = body(c)
                full = (len(next(iter(c.values()))),) + shape
                t, s = np.broadcast_to(t, full), np.broadcast_to(s, full)
                if forall:
                    return np.asarray(t.all(axis)), np.asarray(s.all(axis) | (s & ~t).any(axis))
                return np.asarray(t.any(axis)), np.asarray(s.all(axis) | (s & t).any(axis))
            return quant
        if isinstance(e, ast.Compare) and self.scope:
            static = self.index_compare(e)
            if static is not None:
                truth = static[None]
                return lambda c: (truth, np.ones_like(truth))
        return super()._bool(e)

    def binding(self, e: ast.Quant) -> tuple[str, np.ndarray]:
        """The one name ``e`` binds and its offsets (a ``<lo upto hi>`` of integer literals), or :class:`Unsupported`."""
        if e.kind not in ("forall", "exists") or len(e.bindings) != 1 or len(e.bindings[0].names) != 1:
            raise Unsupported(f"a quantifier {e.kind} other than over one offset")
        (bd,) = e.bindings
        dom, name = bd.domain, bd.names[0]
        if not isinstance(dom, ast.SeqRange):
            raise Unsupported("a quantifier over another domain than <lo upto hi>")
        lo, hi = _integer(dom.lo), _integer(dom.hi)
        if lo is None or hi is None or hi < lo:
            raise Unsupported("a <lo upto hi> whose bounds are not integer literals, or empty")
        if name in self.node.inputs or name in self.node.outputs or name in self.env.constants or \
                name in self.env.enum_values:
            raise Unsupported(f"an offset named as another name ({name})")
        values = np.arange(lo, hi + 1, dtype=np.int64)
        if int(np.prod(self.axes + (len(values),))) > MAX_CELLS:
            raise Unsupported("quantifiers spanning too many offsets")
        return name, values

    def within(self, name: str, values: np.ndarray, build: Callable[[], Any]) -> Any:
        """``build()`` with ``name`` bound to ``values`` on one more axis."""
        self.scope.append((name, values))
        outer = self.axes
        self.axes = outer + (len(values),)
        try:
            return build()
        finally:
            self.scope.pop()
            self.axes = outer

    def static(self, e: Any) -> np.ndarray | None:
        """An index term's integer values over the axes in scope (shape: ``axes``, 1 where it does not vary),
        or ``None`` when ``e`` is no index term."""
        depth = len(self.scope)
        if isinstance(e, ast.NumLit):
            v = e.value
            if isinstance(v, Fraction) and v.denominator != 1:
                return None
            return np.full((1,) * depth, int(v), dtype=np.int64)
        if isinstance(e, ast.Var) and e.prefix is None:
            for a in range(depth - 1, -1, -1):
                name, values = self.scope[a]
                if name == e.name:
                    shape = [1] * depth
                    shape[a] = len(values)
                    return values.reshape(shape)
            return None
        if isinstance(e, ast.Unary) and e.op == "-":
            inner = self.static(e.operand)
            return None if inner is None else -inner
        if isinstance(e, ast.Binary) and e.op in _INT_OPS:
            left, right = self.static(e.left), self.static(e.right)
            return None if left is None or right is None else np.asarray(_INT_OPS[e.op](left, right))
        return None

    def index_compare(self, e: ast.Compare) -> np.ndarray | None:
        """A comparison of index terms only: its truth over the axes in scope, else ``None``."""
        vals = [self.static(o) for o in e.operands]
        if any(v is None for v in vals):
            return None
        truth = np.ones((1,) * len(self.scope), dtype=bool)
        for op, x, y in zip(e.ops, vals, vals[1:]):
            truth = truth & _CMP[op](x, y)
        return truth

    def _num(self, e: Any) -> Callable[[Mapping[str, np.ndarray]], tuple[Any, Any]]:
        if self.scope:
            idx = self.static(e)
            if idx is not None:  # an offset as a number: exact
                value = idx.astype(np.float64)[None]
                return lambda c: (value, 0.0)
        if isinstance(e, ast.Apply) and len(e.args) == 1:
            key = self._key(e.func)
            if key is None or not is_window(self.node.io_type(e.func)):
                raise Unsupported(f"the application {e.func.qualified}(...)")
            at = self.static(e.args[0])
            if at is None or int(at.min()) < 0:
                raise Unsupported("a window read at an offset that is not an index term >= 0")
            self.widths[key] = max(self.widths.get(key, 0), int(at.max()) + 1)
            if at.ndim == 0:
                k = int(at)
                return lambda c: (c[key][:, k], 0.0)
            return lambda c: (c[key][:, at], 0.0)
        return super()._num(e)


def _integer(e: Any) -> int | None:
    """An integer literal's value (``-3`` too), else ``None``."""
    if isinstance(e, ast.Unary) and e.op == "-":
        v = _integer(e.operand)
        return None if v is None else -v
    if isinstance(e, ast.NumLit) and (not isinstance(e.value, Fraction) or e.value.denominator == 1):
        return int(e.value)
    return None


class WindowMargins(MarginCompiler):
    """:class:`~.column_margins.MarginCompiler` over a :class:`WindowCompiler`: ``forall`` the minimum and
    ``exists`` the maximum over an offset's axis, the first on a tie, with its deciding comparison."""

    columns: WindowCompiler

    def __init__(self, columns: WindowCompiler, track: bool = True) -> None:
        super().__init__(columns, track)

    def _rob(self, e: Any) -> ColumnMargin:
        cols = self.columns
        if isinstance(e, ast.Quant):
            name, values = cols.binding(e)
            body = cols.within(name, values, lambda: self._rob(e.body))
            axis, shape = len(cols.scope) + 1, cols.axes + (len(values),)
            pick = np.argmin if e.kind == "forall" else np.argmax
            forall = e.kind == "forall"

            def quant(c: Mapping[str, np.ndarray]) -> tuple[np.ndarray, Any]:
                v, a = body(c)
                full = (len(next(iter(c.values()))),) + shape
                v = np.broadcast_to(v, full)
                if a is None:  # the values alone: the extreme itself (NaN where one is, as argmin/argmax pick it)
                    return (v.min(axis) if forall else v.max(axis)), None
                a = np.broadcast_to(a, full)
                j = np.expand_dims(pick(v, axis=axis), axis)  # the first extreme: ties kept on the left
                return np.take_along_axis(v, j, axis).squeeze(axis), np.take_along_axis(a, j, axis).squeeze(axis)
            return quant
        if isinstance(e, ast.Compare) and cols.scope:
            static = cols.index_compare(e)
            if static is not None:  # offsets only: no distance
                value = np.where(static, np.inf, -np.inf)[None]
                none = np.full(value.shape, -1, dtype=np.int32) if self.track else None
                return lambda c: (value, none)
        return super()._rob(e)


__all__ = ["MAX_CELLS", "WindowCompiler", "WindowMargins", "is_window"]
