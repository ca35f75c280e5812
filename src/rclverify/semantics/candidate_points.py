"""Candidate points at run time: the breakpoints of a quantified variable under the current
bindings, the points between them, and the quantifier decided over them (the method and why it
is exact: :mod:`rclverify.semantics.candidates`, docs/values.md)."""
from __future__ import annotations

import math
from fractions import Fraction
from typing import Any, Iterator, Mapping

from rclverify.lang import ast

from rclverify.lang import typeexpr
from rclverify.semantics.values import FiniteFunction, Term, Value
from rclverify.semantics.candidates import NotInFragment, Source, analyse
from rclverify.semantics.eval_values import Undecided

#: The most body evaluations one quantifier with candidate variables makes.
MAX_CANDIDATE_STEPS = 100_000
#: ``many``: a gap holding two or more values of the domain
MANY = 2


def _is_number(x: Any) -> bool:
    return not isinstance(x, bool) and isinstance(x, (int, float, Fraction))


def breakpoints(ev: Any, sources: tuple[Source, ...], b: Mapping[str, Value], numeric: str) -> list[Any]:
    """The breakpoints of the sources under bindings ``b`` (evaluated by ``ev``, the double
    reading): numbers as the reading compares them.  Raises ``Undecided`` when a point at an
    exact-equality position of a ``REAL`` variable is no double."""
    out: list[Any] = []
    for s in sources:
        if s.kind == "keys":
            f = ev.eval(s.expr, b)
            if not isinstance(f, FiniteFunction):
                raise Undecided(f"{s.expr.qualified} is not a finite table")
            out.extend(_exact(k[s.pos], numeric) for k in f.table)
        elif s.kind == "elems":
            out.extend(_exact(x, numeric) for x in ev.collection(s.expr, b))
        else:
            for val in _values(ev, s, b):
                p = None
                if s.kind == "ctor":
                    if isinstance(val, Term) and val.name == s.ctor and s.pos < len(val.args):
                        p = _exact(val.args[s.pos], numeric)
                elif _is_number(val):  # compared: as the reading compares it
                    p = _exact(float(val) if type(val) is Fraction else val, numeric)
                if p is not None:
                    out.append(p - s.shift)
    return [x for x in out if x is not None]


def _values(ev: Any, s: Source, b: Mapping[str, Value]) -> list[Any]:
    """The values ``s.expr`` takes: its value, or a table's results and default."""
    if not s.table:
        return [ev.eval(s.expr, b)]
    f = ev.eval(s.expr.func, b)
    if not isinstance(f, FiniteFunction):
        raise Undecided(f"{s.expr.func.qualified} is not a finite table")
    return list(f.table.values()) + [f.default]


def _exact(x: Any, numeric: str) -> Any:
    """A point met by exact equality (a key, an element, a constructor argument)."""
    if not _is_number(x):
        return None
    if numeric == "REAL" and type(x) is not float:
        if Fraction(float(x)) != x:
            raise Undecided(f"the point {x} is no double: a REAL the node holds never equals it")
        return float(x)
    return x


def points(bps: list[Any], numeric: str, eq: bool = False) -> Iterator[tuple[Any, int]]:
    """The candidate points, ascending, each with how many values of the domain it stands
    for (1, or :data:`MANY` for two and more): the breakpoints and one point in each gap.
    ``eq`` (every source an equality): the breakpoints, then one point above them (below when
    there is no double above) standing for every other value (always many: the domain is
    infinite, the breakpoints finite), where the body is the same everywhere."""
    if eq:
        yield from _eq_points(bps, numeric)
        return
    if numeric == "REAL":
        ps = sorted({float(x) for x in bps})
        if any(not math.isfinite(p) for p in ps):
            raise Undecided("a breakpoint is not a finite number")
        if not ps:
            yield 0.0, MANY
            return
        lo = ps[0] - 1.0 if ps[0] - 1.0 < ps[0] else math.nextafter(ps[0], -math.inf)
        if math.isfinite(lo):
            yield lo, _between(-math.inf, ps[0])
        for k, p in enumerate(ps):
            yield p, 1
            if k + 1 < len(ps):
                q = ps[k + 1]
                m = p / 2 + q / 2
                if not p < m < q:
                    m = math.nextafter(p, math.inf)
                if p < m < q:
                    yield m, _between(p, q)
        hi = ps[-1] + 1.0 if ps[-1] + 1.0 > ps[-1] else math.nextafter(ps[-1], math.inf)
        if math.isfinite(hi):
            yield hi, _between(ps[-1], math.inf)
        return
    zs = _integers(bps, numeric)
    if not zs:
        yield 0, MANY
        return
    if numeric == "INTEGER":
        yield zs[0] - 1, MANY
    elif zs[0] > 0:
        yield zs[0] - 1, min(zs[0], MANY)
    for k, z in enumerate(zs):
        yield z, 1
        if k + 1 < len(zs) and zs[k + 1] - z >= 2:
            yield z + 1, min(zs[k + 1] - z - 1, MANY)
    yield zs[-1] + 1, MANY


def _eq_points(bps: list[Any], numeric: str) -> Iterator[tuple[Any, int]]:
    if numeric == "REAL":
        ps = sorted({float(x) for x in bps})
        if any(not math.isfinite(p) for p in ps):
            raise Undecided("a breakpoint is not a finite number")
        yield from ((p, 1) for p in ps)
        if not ps:
            yield 0.0, MANY
            return
        hi = ps[-1] + 1.0 if ps[-1] + 1.0 > ps[-1] else math.nextafter(ps[-1], math.inf)
        lo = ps[0] - 1.0 if ps[0] - 1.0 < ps[0] else math.nextafter(ps[0], -math.inf)
        yield (hi if math.isfinite(hi) else lo), MANY
        return
    zs = _integers(bps, numeric)
    yield from ((z, 1) for z in zs)
    yield (zs[-1] + 1 if zs else 0), MANY


#: integer breakpoints beyond this are left undecided (the C++ checks hold 64-bit integers)
INT_LIMIT = 2 ** 62


def _integers(bps: list[Any], numeric: str) -> list[int]:
    """The floor and ceiling of each breakpoint, ascending (``NATURAL``: from 0)."""
    ints: set[int] = set()
    for x in bps:
        if not (math.isfinite(x) and -INT_LIMIT < x < INT_LIMIT):
            raise Undecided(f"the breakpoint {x} is beyond 2**62")
        ints.add(math.floor(x))
        ints.add(math.ceil(x))
    return sorted(z for z in ints if numeric == "INTEGER" or z >= 0)


def _between(a: float, b: float) -> int:
    """How many finite doubles lie strictly between ``a`` and ``b`` (1, or MANY)."""
    n = math.nextafter(a, math.inf) if math.isfinite(a) else -1.7976931348623157e308
    if not n < b:
        return 0
    m = math.nextafter(n, math.inf)
    return MANY if m < b and math.isfinite(m) else 1


def numeric_of(ev: Any, dom: Any) -> str | None:
    """``REAL``/``INTEGER``/``NATURAL`` when binding domain ``dom`` is that type, else None."""
    name = dom.name if isinstance(dom, typeexpr.TBase) else None
    if isinstance(dom, typeexpr.TName):
        t = ev.env.types.get(dom.name)
        name = getattr(t, "name", None) if type(t).__name__ == "Scalar" else None
    return name if name in ("REAL", "INTEGER", "NATURAL") else None


def quantify(ev: Any, e: ast.Quant, b: Mapping[str, Value], finite_domain: Any, max_product: int) -> bool | None:
    """Quantifier ``e`` under bindings ``b`` in the reading of evaluator ``ev``: each variable
    over its finite domain (``finite_domain(ev, e, binding, name, b)``, raising ``Undecided``)
    or, where that finds an unbounded numeric domain, over its candidate points.  ``None``
    when no variable needs candidate points (the caller enumerates as before).  Raises
    ``Undecided`` with the reason outside the fragment or beyond
    :data:`MAX_CANDIDATE_STEPS` body evaluations."""
    names = [n for bd in e.bindings for n in bd.names]
    slots: list[tuple[str, Any, Any]] = []
    size, k = 1, 0
    for bd in e.bindings:
        for n in bd.names:
            k += 1
            try:
                dom = finite_domain(ev, e, bd, n, b)
            except Undecided as why:
                numeric = numeric_of(ev, bd.domain)
                if numeric is None or "without a literal bound" not in str(why):
                    raise
                try:
                    sources = analyse(e.body, n, numeric, frozenset(names[k:]), ev.env)
                except NotInFragment as nf:
                    raise Undecided(f"{why}, and not by candidate points: {nf}") from None
                slots.append((n, None, (numeric, sources)))
                continue
            size *= max(len(dom), 1)
            if size > max_product:
                raise Undecided(f"quantifier over more than {max_product} values")
            slots.append((n, dom, None))
    if all(s[1] is not None for s in slots):
        return None
    steps = [0]
    unique = e.kind == "exists_unique"

    def level(j: int, cur: dict[str, Value]) -> int:
        """forall: 1 when the body holds everywhere; exists: 1 when somewhere; unique: how
        many times (capped at MANY)."""
        if j == len(slots):
            steps[0] += 1
            if steps[0] > MAX_CANDIDATE_STEPS:
                raise Undecided(f"quantifier needs more than {MAX_CANDIDATE_STEPS} candidate evaluations")
            return 1 if ev.eval(e.body, cur) else 0
        name, dom, cand = slots[j]
        items: Any = ((x, 1) for x in dom) if dom is not None else \
            points(breakpoints(ev, cand[1], cur, cand[0]), cand[0], all(s.eq for s in cand[1]))
        count = 0
        for x, mult in items:
            nxt = dict(cur)
            nxt[name] = x
            c = level(j + 1, nxt)
            if e.kind == "forall" and not c:
                return 0
            if e.kind == "exists" and c:
                return 1
            if unique:
                count = min(count + c * mult, MANY)
                if count >= MANY:
                    return MANY
        return 1 if e.kind == "forall" else count
    got = level(0, dict(b))
    return got == 1


__all__ = ["MANY", "MAX_CANDIDATE_STEPS", "breakpoints", "numeric_of", "points", "quantify"]
