"""An RCL formula's space margin over whole columns of recorded values (the batch path's margins).

The column twin of :func:`rclverify.semantics.robustness.margin` in double
arithmetic (docs/semantics.md, "Margins"), for the formulas the batch path
compiles (:class:`rclverify.targets.columns.ColumnCompiler`: quantifier-free,
``REAL`` and enumeration values): a comparison of numbers that reads a value
of the run gives its distance (``b - a`` for ``a <= b``, ``-|a - b|`` for
``a == b`` on unequal sides and ``+inf`` on equal ones, ...), computed by numpy in float64 on the terms as the column
compiler computes them (the IEEE-754 operations of the double reading, in
the same order); every other comparison ``+inf`` or ``-inf`` by its truth;
``not`` negates, ``and``/``or`` are minimum and maximum, ``->`` and ``<=>``
as in the module above, ties kept on the left as there.  Each row also gets
the index of its deciding comparison in :attr:`MarginCompiler.atoms` (-1:
none).  tests/backends/test_margins_batch.py checks that the batch path's margins are
the streaming engine's, verdict by verdict.
"""
from __future__ import annotations

from typing import Any, Callable, Mapping

from rclverify.core.numeric import np

from rclverify.lang import ast
from rclverify.semantics.robustness import measures_the_run
from rclverify.targets.columns import ColumnCompiler, Unsupported

#: A compiled margin: columns (``in.r`` -> float64 or int array) -> (margins float64, deciding atom int array;
#: ``None`` from a compiler that does not track the atoms, :class:`MarginCompiler`).
ColumnMargin = Callable[[Mapping[str, np.ndarray]], tuple[np.ndarray, Any]]


class MarginCompiler:
    """Compiles the margins of formulas of the column compiler ``columns``'s node;
    ``atoms`` lists the deciding comparisons met, ``(comparison, link)``.  ``track``: each row's deciding
    atom too; without it the compiled margin gives ``None`` for the atoms and only the values (the same
    values, about half the work: :class:`RowAtoms` gives the atom of the few rows that need one)."""

    def __init__(self, columns: ColumnCompiler, track: bool = True) -> None:
        self.columns = columns
        self.track = track
        self.io = frozenset(columns.node.inputs) | frozenset(columns.node.outputs)
        self.atoms: list[tuple[ast.Compare, int]] = []

    def compile(self, formula: ast.Expr) -> ColumnMargin:
        """``formula``'s margin as a function of the columns (raises :class:`Unsupported`)."""
        return self._rob(formula)

    def _rob(self, e: Any) -> ColumnMargin:
        if isinstance(e, ast.Unary) and e.op == "not":
            f = self._rob(e.operand)
            return lambda c: _neg(f(c))
        if isinstance(e, ast.Binary) and e.op in ("and", "or", "->", "<=>"):
            a, b = self._rob(e.left), self._rob(e.right)
            if e.op == "and":
                return lambda c: _min(a(c), b(c))
            if e.op == "or":
                return lambda c: _max(a(c), b(c))
            if e.op == "->":
                return lambda c: _max(_neg(a(c)), b(c))
            return lambda c: _iff(a(c), b(c))
        if isinstance(e, ast.Compare):
            links = [self._link(e, i) for i in range(len(e.ops))]
            if len(links) == 1:
                return links[0]
            axes, track = self.columns.axes, self.track

            def chain(c: Mapping[str, np.ndarray]) -> tuple[np.ndarray, Any]:
                out = _truth(c, np.ones((_rows(c),) + axes, dtype=bool), axes, track)
                for link in links:
                    out = _min(out, link(c))
                return out
            return chain
        truth = self.columns.compile(e)  # a BOOL literal or constant: no distance
        axes, track = self.columns.axes, self.track
        return lambda c: _truth(c, truth(c)[0], axes, track)

    def _link(self, e: ast.Compare, i: int) -> ColumnMargin:
        op, x, y = e.ops[i], e.operands[i], e.operands[i + 1]
        cols = self.columns
        truth = cols._compare(op, x, y)
        axes, track = cols.axes, self.track
        if cols._enum(x) is not None or cols._enum(y) is not None or not self.measures((x, y)):
            return lambda c: _truth(c, truth(c)[0], axes, track)
        nx, ny = cols._num(x), cols._num(y)
        atom = len(self.atoms)
        self.atoms.append((e, i))

        def link(c: Mapping[str, np.ndarray]) -> tuple[np.ndarray, Any]:
            vx, vy = nx(c)[0], ny(c)[0]
            shape = (_rows(c),) + axes
            with np.errstate(all="ignore"):
                if op in ("<", "<="):
                    d = vy - vx
                elif op in (">", ">="):
                    d = vx - vy
                else:
                    d = np.abs(vx - vy)  # an equality holds without a distance: +inf (robustness.distance)
                    d = np.where(d == 0, np.inf, -d) if op == "==" else np.where(d == 0, -np.inf, d)
            if not track:  # (+ 0.0: a zero distance is +0.0, as the engine's; on d's own shape, broadcast as a view)
                return np.broadcast_to(np.asarray(d, dtype=np.float64) + 0.0, shape), None
            return np.broadcast_to(np.asarray(d, dtype=np.float64), shape) + 0.0, np.full(shape, atom, dtype=np.int32)
        return link

    def measures(self, terms: tuple[Any, Any]) -> bool:
        """Whether a comparison of ``terms`` reads a value of the run (else it has no distance)."""
        return measures_the_run(terms, self.io)


def _rows(c: Mapping[str, np.ndarray]) -> int:
    return len(next(iter(c.values()))) if c else 0


def _truth(c: Mapping[str, np.ndarray], truth: Any, axes: tuple[int, ...] = (), track: bool = True
           ) -> tuple[np.ndarray, Any]:
    """``+inf`` where ``truth`` holds, ``-inf`` elsewhere; no deciding atom (``axes``: as ColumnCompiler.axes;
    ``track``: the atoms made, -1, else ``None``)."""
    shape = (_rows(c),) + axes
    return np.where(np.broadcast_to(truth, shape), np.inf, -np.inf), \
        (np.full(shape, -1, dtype=np.int32) if track else None)


def _neg(a: tuple[np.ndarray, Any]) -> tuple[np.ndarray, Any]:
    return -a[0], a[1]


def _min(a: tuple[np.ndarray, Any], b: tuple[np.ndarray, Any]) -> tuple[np.ndarray, Any]:
    """The smaller of each row, the left one on a tie (as robustness._min); the atoms where both track them."""
    right = b[0] < a[0]
    return np.where(right, b[0], a[0]), (None if a[1] is None or b[1] is None else np.where(right, b[1], a[1]))


def _max(a: tuple[np.ndarray, Any], b: tuple[np.ndarray, Any]) -> tuple[np.ndarray, Any]:
    """The larger of each row, the left one on a tie (as robustness._max); the atoms where both track them."""
    right = b[0] > a[0]
    return np.where(right, b[0], a[0]), (None if a[1] is None or b[1] is None else np.where(right, b[1], a[1]))


def _iff(a: tuple[np.ndarray, Any], b: tuple[np.ndarray, Any]) -> tuple[np.ndarray, Any]:
    return _min(_max(_neg(a), b), _max(_neg(b), a))


class RowAtoms:
    """The deciding atoms of some rows of a run's columns, each found when read: ``atoms[j]`` (an integer)
    runs the atom-tracking margin ``margin`` on row ``rows[j]`` of ``columns`` alone (every compiled margin
    reads a row by itself, so its atom there is the whole run's); a slice, a mask or an index array gives
    the atoms of those rows.  The batch path computes every row's margin without its atom
    (``MarginCompiler(track=False)``) and needs the atom of the smallest only."""

    __slots__ = ("margin", "columns", "rows")

    def __init__(self, margin: ColumnMargin, columns: Mapping[str, np.ndarray], rows: np.ndarray) -> None:
        self.margin, self.columns, self.rows = margin, columns, rows

    def __len__(self) -> int:
        return len(self.rows)

    def __getitem__(self, j: Any) -> Any:
        if isinstance(j, (int, np.integer)):
            r = int(self.rows[j])
            return int(self.margin({k: v[r:r + 1] for k, v in self.columns.items()})[1][0])
        return RowAtoms(self.margin, self.columns, self.rows[j])


__all__ = ["ColumnMargin", "MarginCompiler", "RowAtoms", "Unsupported"]
