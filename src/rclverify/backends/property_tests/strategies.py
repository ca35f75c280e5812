"""Hypothesis strategies for a node's inputs, derived from their RCL types and
constrained by the node's assumption (docs/property-tests.md, "Strategies").

* Bounds by construction (read by :mod:`.bounds`): every top-level conjunct of the assumption of the
  form ``c <= in.x``, ``in.x < c``, ``a <= in.x < b`` (numeric literals or
  named constants of the context) bounds
  a numeric input; ``in.e in {v1, v2}`` restricts an enumeration input.  The
  plan's ``bounds: {in.x: [lo, hi]}`` narrows further (either end may be null).
* Sequence items by construction: a top-level ``forall(q in in.s | body)``
  bounds every item of the sequence input ``s`` by ``body``'s top-level
  conjuncts of the forms above over ``q``, and the plan's ``bounds`` of
  ``in.s`` bound its items too; the items are drawn within those bounds
  (:meth:`InputSpace.item`), not filtered into them.  A top-level
  ``exists(q in in.s | ...)`` makes ``s`` drawn with at least one item.
* Bound ends: each end of an input's (or its items') bounds is drawn as a
  boundary value with its neighbour inside (a decimal end that is no double
  is met by the nearest double inside it, so a drawn value never breaks the
  bound as an exact rational).
* Boundary values: the numeric literals of the node's contract, the values
  of the context constants it names and the numbers its implementation
  compares with (:mod:`.constants`), each with its neighbours (one ulp
  either side for REAL, one either side for integers), are drawn alongside
  arbitrary values, so a threshold that is off by one is hit.  The
  thresholds the contract's comparisons put on an input, however written
  (``in.p / 2 <= 0.1``: 0.2; :mod:`.thresholds`), are drawn with their
  neighbours at each field width in a choice of their own
  (:attr:`InputSpace.thresholds`).
* Function-typed inputs are finite tables with a default
  (:class:`~rclverify.semantics.values.FiniteFunction`).  Their keys come from one pool
  of argument tuples per argument type, drawn once per example, so two
  functions over the same domain (the Agent's ``at`` and ``wayP``) share
  their points; values inside tables are small (NATURAL 0..5, INTEGER -5..5).
* Inputs whose field's IDL type the message definitions tell are drawn as
  the field carries them (:mod:`.at_width`, handed in as
  :attr:`InputSpace.carried`): integer ranges, bounded sequences.
* What the bounds do not capture is enforced by filtering with the whole
  assumption, checked by :func:`~rclverify.semantics.decide.decide` (direct evaluation, Z3 where
  it cannot decide).
"""
from __future__ import annotations

import math
from functools import partial
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any, Callable, Iterable, Mapping, cast

from rclverify.backends.property_tests.bounds import Bound, assumption_bounds, conjuncts
from rclverify.backends.property_tests.hypothesis_lib import st
from rclverify.lang import ast
from rclverify.lang.types import CheckedNode, DataT, EmptyT, EnumT, FuncT, Scalar, SeqT, SetT, TupleT, Type
from rclverify.semantics.values import FiniteFunction, Term

SMALL_NAT = 5
POOL_SIZE = 4
_POOL_COUNT = st.integers(min_value=1, max_value=POOL_SIZE)
MAX_EDITS = 3
_EDITS = st.integers(min_value=0, max_value=MAX_EDITS)


def _double_inside(v: Fraction, towards: float) -> float:
    """The double nearest ``v`` on the side of ``towards`` (``math.inf``: at or above ``v``)."""
    f = float(v)
    if (Fraction(f) < v) if towards > 0 else (Fraction(f) > v):
        f = math.nextafter(f, towards)
    return f


def _term(name: str, args: tuple[Any, ...]) -> Term:
    return Term(name, tuple(args))


def contract_constants(node: CheckedNode) -> list[Fraction]:
    """Every numeric literal of the node's contract (sorted, unique)."""
    found: set[Fraction] = set()

    def walk(x: Any) -> None:
        if isinstance(x, ast.NumLit):
            found.add(x.value)
        elif isinstance(x, tuple):
            for y in x:
                walk(y)
        elif hasattr(x, "__dataclass_fields__"):
            for f in x.__dataclass_fields__:
                if f != "loc":
                    walk(getattr(x, f))

    for clause in (*node.node.assumes, *node.node.guarantees):
        walk(clause.formula)
    return sorted(found)


@dataclass
class InputSpace:
    """How one node's inputs are drawn (see the module docstring)."""

    node: CheckedNode
    bounds: dict[str, Bound]
    constants: list[Fraction]
    pools: dict[tuple[Type, ...], list[tuple[Any, ...]]] = field(default_factory=dict)
    cache: dict[tuple[Type, int, bool], st.SearchStrategy[Any]] = field(default_factory=dict)
    seed: Mapping[str, object] | None = None  # a Z3 model of the assumption and facts (.seeding)
    point_cache: dict[tuple[Any, ...], st.SearchStrategy[tuple[Any, ...]]] = field(default_factory=dict)
    misc_cache: dict[tuple[Any, ...], Any] = field(default_factory=dict)
    #: input name -> its strategy as its field carries it (:mod:`.at_width`), used instead of its type's
    carried: dict[str, st.SearchStrategy[Any]] = field(default_factory=dict)
    #: the thresholds the contract's comparisons put on an input, however written (``in.p / 2 <= 0.1``:
    #: 0.2; :mod:`.thresholds`), at each field width with their neighbours: drawn by a REAL input in a
    #: choice of their own, beside the constants' edges and arbitrary values
    thresholds: list[Fraction] = field(default_factory=list)

    def real(self, bd: Bound | None, small: bool = False) -> st.SearchStrategy[Any]:
        """Finite doubles within ``bd`` (``small``: within +-1000 where ``bd`` leaves a side open),
        with the thresholds inside and each end ``bd`` gives and its neighbour inside as edges.  A
        bound that is no double (``3.14``) is met by the nearest double inside it, so that every
        drawn value satisfies it as an exact rational."""
        lo = _double_inside(bd.lo, math.inf) if bd and bd.lo is not None else (-1000.0 if small else None)
        hi = _double_inside(bd.hi, -math.inf) if bd and bd.hi is not None else (1000.0 if small else None)
        no_lo = bool(bd and bd.lo is not None and lo is not None and bd.lo_strict and Fraction(lo) == bd.lo)
        no_hi = bool(bd and bd.hi is not None and hi is not None and bd.hi_strict and Fraction(hi) == bd.hi)
        edges: set[float] = set()
        for c in self.constants:
            f = float(c)
            edges.update((f, math.nextafter(f, -math.inf), math.nextafter(f, math.inf)))
        if bd is not None and bd.lo is not None and lo is not None:
            edges.update((lo, math.nextafter(lo, math.inf)))
        if bd is not None and bd.hi is not None and hi is not None:
            edges.update((hi, math.nextafter(hi, -math.inf)))
        edges_in = sorted(e for e in edges if (lo is None or e > lo or (e == lo and not no_lo))
                          and (hi is None or e < hi or (e == hi and not no_hi)))
        floats = st.floats(min_value=lo, max_value=hi, allow_nan=False, allow_infinity=False,
                           exclude_min=no_lo, exclude_max=no_hi)
        solved = sorted({float(t) for t in self.thresholds if Fraction(float(t)) == t
                         and (lo is None or float(t) > lo or (float(t) == lo and not no_lo))
                         and (hi is None or float(t) < hi or (float(t) == hi and not no_hi))})
        branches = [st.sampled_from(xs) for xs in (edges_in, solved) if xs]
        return st.one_of(*branches, floats) if branches else floats

    def integer(self, bd: Bound | None, natural: bool, small: bool = False) -> st.SearchStrategy[int]:
        """Integers within ``bd`` (``natural``: from 0; ``small``: a few values near 0, no edges), with
        the integer thresholds' neighbours and the ends ``bd`` gives and their neighbours inside as edges."""
        lo = math.ceil(bd.lo) if bd and bd.lo is not None else None
        hi = math.floor(bd.hi) if bd and bd.hi is not None else None
        if lo is not None and bd is not None and bd.lo_strict and bd.lo == lo:
            lo += 1
        if hi is not None and bd is not None and bd.hi_strict and bd.hi == hi:
            hi -= 1
        ends = {v + d for v, d in ((lo, 0), (lo, 1), (hi, 0), (hi, -1)) if v is not None}
        if natural:
            lo = 0 if lo is None else max(lo, 0)
        if small:
            lo = -SMALL_NAT if lo is None else lo
            hi = lo + 2 * SMALL_NAT if hi is None else hi
            hi = min(hi, SMALL_NAT) if lo <= SMALL_NAT else hi
        edges = sorted(e for e in {*(int(c) + d for c in self.constants if c.denominator == 1 for d in (-1, 0, 1)),
                                   *ends}
                       if (lo is None or e >= lo) and (hi is None or e <= hi))
        ints = st.integers(min_value=lo, max_value=hi)
        return st.one_of(st.sampled_from(edges), ints) if edges and not small else ints

    def value(self, t: Type, bd: Bound | None = None, small: bool = False) -> st.SearchStrategy[Any]:
        """A strategy for values of RCL type ``t`` (``small``: inside a table or term).

        Built once per (type, bound, size) and reused: Hypothesis inspects a
        strategy's source when it is built, which would dominate the run time.
        """
        key = (t, id(bd), small)
        if key not in self.cache:
            self.cache[key] = self._value(t, bd, small)
        return self.cache[key]

    def _value(self, t: Type, bd: Bound | None, small: bool) -> st.SearchStrategy[Any]:
        if isinstance(t, Scalar):
            if t.name == "BOOL":
                return st.booleans()
            if t.name == "REAL":
                return self.real(bd, small)
            return self.integer(bd, t.name == "NATURAL", small)
        if isinstance(t, EnumT):
            allowed = [v for v in t.values if bd is None or bd.enum is None or v in bd.enum]
            return st.sampled_from(allowed or list(t.values))
        if isinstance(t, DataT):
            alts = [st.tuples(*[self.value(a, small=True) for a in args]).map(partial(_term, name))
                    for name, args in t.ctors]
            return st.one_of(*alts)
        if isinstance(t, TupleT):
            return st.tuples(*[self.value(e, small=True) for e in t.elems])
        if isinstance(t, SetT):
            return st.frozensets(self.value(t.elem, small=True), max_size=POOL_SIZE)
        if isinstance(t, SeqT):
            least = bd.min_len if bd is not None else 0
            return st.lists(self.item(t.elem, bd), min_size=least, max_size=max(POOL_SIZE, least)).map(tuple)
        if isinstance(t, FuncT):
            return self.function(t)
        if isinstance(t, EmptyT):
            return st.nothing()
        raise ValueError(f"no strategy for {t}")

    def item(self, t: Type, bd: Bound | None) -> st.SearchStrategy[Any]:
        """An item of type ``t`` of a sequence input whose items ``bd`` bounds: drawn within ``bd`` by
        construction, with the bounds' ends and the thresholds as edges, as a scalar input with that
        bound is; an item without a bound is drawn small (:meth:`value`)."""
        if bd is not None and isinstance(t, (Scalar, EnumT)):
            return self.value(t, bd)
        return self.value(t, small=True)

    def function(self, t: FuncT) -> st.SearchStrategy[FiniteFunction]:
        @st.composite
        def draw_fn(draw: Callable[..., Any]) -> FiniteFunction:
            return self.table(draw, t)
        return draw_fn()

    def table(self, draw: Callable[..., Any], t: FuncT) -> FiniteFunction:
        """A finite table over ``t``, drawn inside a composite strategy: which
        points of the example's pool it has (one choice, a bit mask), a small
        result for each, and a default."""
        pool = self.pool(draw, t.args)
        mask = draw(self._index(1 << len(pool)))
        result = self.value(t.result, small=True)
        table = {k: draw(result) for j, k in enumerate(pool) if mask >> j & 1}
        return FiniteFunction(table, draw(result), len(t.args))

    def pool(self, draw: Callable[..., Any], args: tuple[Type, ...]) -> list[tuple[Any, ...]]:
        """This example's pool of argument tuples over ``args`` (drawn at its
        first use in the example): 1 to :data:`POOL_SIZE` points, each a key
        of a seeded table over the same arguments (one choice: which) or a
        new small point, so functions over one domain (the Agent's ``at`` and
        ``wayP``) meet."""
        pool = self.pools.get(args)
        if pool is None:
            pool = []
            seeded = self.seeded_keys(args)
            pick = self._index(len(seeded) + 1)
            for _ in range(draw(_POOL_COUNT)):
                j = draw(pick) if seeded else len(seeded)
                p = seeded[j] if j < len(seeded) else draw(self.small_points(args))
                if p not in pool:
                    pool.append(p)
            self.pools[args] = pool
        return pool

    def seeded_keys(self, args: tuple[Type, ...]) -> list[tuple[Any, ...]]:
        """The keys of the seeded tables over ``args`` (sorted, worked out once)."""
        key = ("seeded",) + args
        if key not in self.misc_cache:
            self.misc_cache[key] = sorted({k for q, base in (self.seed or {}).items()
                                           if isinstance(base, FiniteFunction) and self._args_of(q) == args
                                           for k in base.table}, key=repr)
        return cast("list[tuple[Any, ...]]", self.misc_cache[key])

    def _args_of(self, q: str) -> tuple[Type, ...] | None:
        t = self.node.inputs.get(q.removeprefix("in."))
        return t.args if isinstance(t, FuncT) else None

    def small_points(self, args: tuple[Type, ...]) -> st.SearchStrategy[tuple[Any, ...]]:
        """Argument tuples of small values over ``args``, built once."""
        key = ("small",) + args
        if key not in self.point_cache:
            self.point_cache[key] = st.tuples(*[self.value(a, small=True) for a in args])
        return self.point_cache[key]

    def points(self, args: tuple[Type, ...]) -> st.SearchStrategy[tuple[Any, ...]]:
        """Argument tuples of a function over ``args`` (full-size values), built once."""
        if args not in self.point_cache:
            self.point_cache[args] = st.tuples(*[self.value(a) for a in args])
        return self.point_cache[args]

    def inputs(self) -> st.SearchStrategy[dict[str, object]]:
        """One example: qualified input name -> value.

        A function-typed input with a seeded table (a Z3 model of the
        assumption and facts, :mod:`.seeding`) is that table with a few edits
        (:meth:`vary`), drawn after the other inputs so that its edits may use
        their pool; every other input is drawn from its type (a function's
        table by :meth:`table`, without a composite strategy of its own)."""
        seeded = {q: base for q, base in (self.seed or {}).items()
                  if isinstance(base, FiniteFunction) and self._args_of(q) is not None}

        @st.composite
        def draw_inputs(draw: Callable[..., Any]) -> dict[str, object]:
            self.pools = {}
            drawn: dict[str, object] = {}
            for n, t in self.node.inputs.items():
                q = f"in.{n}"
                if q in seeded:
                    continue
                if n in self.carried:
                    drawn[q] = draw(self.carried[n])
                    continue
                drawn[q] = self.table(draw, t) if isinstance(t, FuncT) else draw(self.value(t, self.bounds.get(n)))
            for q, base in seeded.items():
                drawn[q] = self.vary(draw, base, cast(FuncT, self.node.inputs[q[3:]]))
            return {f"in.{n}": drawn[f"in.{n}"] for n in self.node.inputs}
        return draw_inputs()

    def vary(self, draw: Callable[..., Any], base: FiniteFunction, t: FuncT) -> FiniteFunction:
        """``base`` (a table from a Z3 model of the facts) with 0 to
        :data:`MAX_EDITS` edits drawn by Hypothesis.  An edit works on one
        slot, an entry of the table or "elsewhere" (the default), and which
        slot and which edit is one choice:

        * an entry: move it to a point of this example's pool (so other
          functions over the same domain meet it) or to a new point, swap
          its result with another entry's, or give it a new result;
        * elsewhere: add an entry at a pool point or a new point, swap the
          default with an entry's result, or take a new default.

        A new result is one of the model's results or a small value of the
        result type, so results the model does not use are tested too.  A
        move or an added entry onto a key the table already has is skipped.
        Moves and swaps keep every fact about which results exist and what
        bounds them; a new result may break one, and the harness's filter
        rejects that example.  Few choices keep an example cheap (each
        Hypothesis choice costs about 25 microseconds).  Shrinking removes
        edits, towards the model itself."""
        table = dict(base.table)
        default = base.default
        where = list(table)
        n = len(where)
        pick = self._index((n + 1) * 4)
        for _ in range(draw(_EDITS)):
            i, kind = divmod(draw(pick), 4)
            if kind == 3:  # a new result (of the entry, or the default)
                value = draw(self._result(base, t))
                if i < n:
                    table[where[i]] = value
                else:
                    default = value
                continue
            if kind == 2:  # swap with an entry's result
                if not n:
                    continue
                j = where[draw(self._index(n))]
                if i < n:
                    table[where[i]], table[j] = table[j], table[where[i]]
                else:
                    default, table[j] = table[j], default
                continue
            if kind == 0:
                pool = self.pool(draw, t.args)
                point = pool[draw(self._index(len(pool)))]
            else:
                point = draw(self.points(t.args))
            if point in table:
                continue
            if i < n:  # move the entry
                table[point] = table.pop(where[i])
                where[i] = point
            else:  # add one
                table[point] = draw(self._result(base, t))
        return FiniteFunction(table, default, base.arity)

    def _index(self, n: int) -> st.SearchStrategy[int]:
        """``0 .. n - 1`` (built once per ``n``)."""
        key = ("index", n)
        if key not in self.misc_cache:
            self.misc_cache[key] = st.integers(min_value=0, max_value=n - 1)
        return cast("st.SearchStrategy[int]", self.misc_cache[key])

    def _result(self, base: FiniteFunction, t: FuncT) -> st.SearchStrategy[Any]:
        """A new result for a seeded table: one of the model's results (and
        default), or a small value of the result type (built once per table)."""
        key = ("result", id(base))
        if key not in self.misc_cache:
            results = sorted({*base.table.values(), base.default}, key=repr)
            self.misc_cache[key] = st.one_of(st.sampled_from(results), self.value(t.result, small=True))
        return cast("st.SearchStrategy[Any]", self.misc_cache[key])


def input_space(node: CheckedNode, plan_bounds: Mapping[str, tuple[Fraction | None, Fraction | None]],
                seed: Mapping[str, object] | None = None, constants: Iterable[Fraction] = (),
                named: Mapping[str, Fraction] | None = None) -> InputSpace:
    """The :class:`InputSpace` of ``node``; ``plan_bounds`` maps input names
    (without ``in.``) to the plan's ``[lo, hi]`` (closed); ``seed`` maps
    qualified input names to a Z3 model's values (function-typed ones are
    varied per example, see :meth:`InputSpace.vary`); ``constants`` the
    thresholds drawn beside the contract's literals, each with its
    neighbours (the named constants and the code's, :mod:`.constants`);
    ``named`` the context constants' values, which bound an input as literals do.  A plan bound of
    a sequence input bounds its items."""
    bounds = assumption_bounds(node, named)
    for name, (lo, hi) in plan_bounds.items():
        bd = bounds.setdefault(name, Bound())
        if lo is not None:
            bd.lower(lo, False)
        if hi is not None:
            bd.upper(hi, False)
    return InputSpace(node, bounds, sorted({*contract_constants(node), *constants}), seed=seed)


# the bounds' reading lives in .bounds; its names stay importable from here (the harness, coverage, the tests)
__all__ = ["Bound", "InputSpace", "POOL_SIZE", "assumption_bounds", "conjuncts", "contract_constants", "input_space"]
