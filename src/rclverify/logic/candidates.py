"""Candidate points: a quantifier over ``REAL``/``INTEGER``/``NATURAL`` decided by finitely
many values of its variable, where that is exact (docs/values.md, "Quantifiers over numbers").

The double reading (:mod:`rclverify.logic.floatsem`) enumerates finite domains only.  A
quantified variable ``v`` over an unbounded numeric type is still decided exactly when the
body's truth, as a function of ``v`` (every other variable fixed, the inputs concrete: a
function is a finite table and a default, :class:`rclverify.values.FiniteFunction`), is
*piecewise constant* with breakpoints in a finite set ``S`` computable at run time.  Then
the body takes, over the whole domain, exactly the truth values it takes at the points of
``S`` and at one point of each open gap between consecutive points and beyond both ends;
counting the values of each gap (one, or two and more) also decides ``exists_unique``.

The fragment (:func:`analyse`, a static reading of the body per variable; anything else
leaves the quantifier undecided with the reason): every occurrence of ``v`` is

* an argument of a table application ``f(.., v, ..)`` (``f`` an input or output function):
  the application changes value only at the table keys' coordinates at that position;
* an operand of a comparison ``v op t`` / ``t op v`` (also ``v + c``/``v - c``/``c + v`` for
  an ``INTEGER``/``NATURAL`` ``v`` and an integer literal ``c``: integer arithmetic is exact
  in both readings), where ``t`` does not mention ``v`` and either mentions no variable
  bound inside ``v``'s scope (its value is known when ``v``'s candidates are computed) or is
  a table application (its values are the table's results and its default): breakpoints the
  values of ``t`` (less ``c``);
* an argument of a constructor term compared ``==``/``!=`` with such a ``t``
  (``out.command == move(x, y)``): breakpoints ``t``'s arguments at that position;
* the element of ``v in t`` with ``t`` a known set: breakpoints its elements;

and what contains it is built from such atoms by ``not and or -> <=>``, comparisons and
arithmetic of piecewise-constant terms, table applications, and inner quantifiers whose
domains do not mention ``v`` (their own variables are inner: a ``t`` that reads them is
known only through a table's results).  Nested quantifiers compute each variable's
candidates once the variables before it are bound (the binding order).

In the double reading a ``REAL`` variable ranges over the finite doubles (the values a node
computing in doubles can hold), comparisons compare doubles (``t`` rounded as
:func:`floatsem._double` rounds it), lookups and constructor equality are exact: a table key
or constructor argument at a ``REAL`` position that is no double leaves the quantifier
undecided (the node could not hold it; exact arithmetic decides it).  Gap points are doubles
strictly inside the gap (the midpoint, else the next double; none when the two points are
adjacent doubles), below and above the ends ``s - 1``/``s + 1`` (the next double when that
rounds back).  ``INTEGER``/``NATURAL`` points are the floor and ceiling of each breakpoint
(``NATURAL`` >= 0) and ``s - 1``, ``s + 1``; an integer breakpoint ``s`` splits nothing
between ``floor(s)`` and ``ceil(s)``.  The generated C++ checks make the same points in the
same order (``generate/cpp_quant.py``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Any, Iterator, Mapping

from ..rcl import ast
from ..values import FiniteFunction, Term
from .eval_values import Undecided

#: The most body evaluations one quantifier with candidate variables makes.
MAX_CANDIDATE_STEPS = 100_000
#: ``many``: a gap holding two or more values of the domain
MANY = 2


class NotInFragment(Exception):
    """The body reads the variable in a way candidate points cannot decide (the reason)."""


@dataclass(frozen=True)
class Source:
    """Where breakpoints come from at run time.

    ``kind``: ``keys`` (``expr`` the function variable: its keys' coordinates at ``pos``),
    ``values`` (``expr`` a term: its value, or a table application's results and default),
    ``ctor`` (``expr`` a term: when a ``ctor`` term, its argument at ``pos``), ``elems``
    (``expr`` a set: its elements).  ``shift``: subtracted from each point (``v + c op t``)."""

    kind: str
    expr: Any
    pos: int = 0
    ctor: str = ""
    shift: int = 0
    #: ``expr`` reads variables bound inside the scope: a table application, its results count
    table: bool = False
    #: the variable meets these points by equality only (a key, ``==``/``!=``, a constructor
    #: argument, membership): off the points it is the same everywhere
    eq: bool = True


_PLANS: dict[tuple[int, str, frozenset[str]], tuple[Any, Any]] = {}


def analyse(body: ast.Expr, name: str, numeric: str, inner: frozenset[str], env: Any) -> tuple[Source, ...]:
    """The breakpoint sources of variable ``name`` (``numeric``: ``REAL``, ``INTEGER`` or
    ``NATURAL``) in ``body``; ``inner``: the names bound inside its scope (the quantifier's later
    names).  Raises :class:`NotInFragment` with the reason.  Memoised per body."""
    key = (id(body), name, inner)
    hit = _PLANS.get(key)
    if hit is not None and hit[0] is body:
        if isinstance(hit[1], NotInFragment):
            raise hit[1]
        return tuple(hit[1])
    out: list[Source] = []
    try:
        _Scan(name, numeric, env, out).pc(body, inner)
        result: Any = tuple(out)
    except NotInFragment as exc:
        result = exc
    if len(_PLANS) >= 10_000:
        _PLANS.clear()
    _PLANS[key] = (body, result)
    if isinstance(result, NotInFragment):
        raise result
    return result


class _Scan:
    """One variable's occurrences: ``pc(e)`` checks ``e`` is piecewise constant in it."""

    def __init__(self, name: str, numeric: str, env: Any, out: list[Source]) -> None:
        self.v, self.numeric, self.env, self.out = name, numeric, env, out

    def mentions(self, e: Any, inner: frozenset[str]) -> bool:
        return _free(e, self.v, inner - {self.v}) if self.v not in inner else False

    def known(self, e: Any, inner: frozenset[str]) -> bool:
        """``e`` reads no variable bound inside the scope (its value is known)."""
        return not any(_free(e, n, frozenset()) for n in inner)

    def ident(self, e: Any, inner: frozenset[str]) -> int | None:
        """``shift`` when ``e`` is ``v``, ``v + c``, ``c + v`` or ``v - c`` (integer ``v``), else None."""
        if isinstance(e, ast.Var) and e.prefix is None and e.name == self.v and self.v not in inner:
            return 0
        if self.numeric == "REAL" or not isinstance(e, ast.Binary) or e.op not in ("+", "-"):
            return None
        if e.op == "+" and _int_lit(e.left) is not None:
            s = self.ident(e.right, inner)
            return None if s is None else s + _int_lit(e.left)
        c = _int_lit(e.right)
        s = self.ident(e.left, inner)
        if c is None or s is None:
            return None
        return s + c if e.op == "+" else s - c

    def valued(self, t: Any, inner: frozenset[str], kind: str, pos: int = 0, ctor: str = "", shift: int = 0,
               eq: bool = True) -> None:
        """Breakpoints from the values of ``t`` (a term without ``v``)."""
        if self.mentions(t, inner):
            raise NotInFragment(f"{self.v} is compared with a term that reads it")
        if self.known(t, inner):
            self.out.append(Source(kind, t, pos, ctor, shift, eq=eq))
            return
        if kind != "elems" and isinstance(t, ast.Apply) and self._table(t) and self.known(t.func, inner):
            self.out.append(Source(kind, t, pos, ctor, shift, table=True, eq=eq))
            return
        raise NotInFragment(f"{self.v} is compared with a term of variables bound inside its scope")

    def _table(self, e: ast.Apply) -> bool:
        return not (e.func.prefix is None and e.func.name in self.env.ctors)

    def pc(self, e: Any, inner: frozenset[str]) -> None:
        """Check ``e`` is piecewise constant in ``v``, collecting breakpoint sources."""
        if not self.mentions(e, inner):
            return
        if isinstance(e, ast.Apply):
            if not self._table(e):
                raise NotInFragment(f"{self.v} in a constructor term not compared with == or !=")
            if not (isinstance(e.func, ast.Var) and (e.func.prefix is not None or e.func.name not in inner)):
                raise NotInFragment(f"{self.v} is an argument of a function bound inside its scope")
            for k, a in enumerate(e.args):
                if self.ident(a, inner) == 0:
                    self.out.append(Source("keys", e.func, k))
                elif self.ident(a, inner) is not None:
                    raise NotInFragment(f"{self.v} in arithmetic as a function argument")
                else:
                    self.pc(a, inner)
            return
        if isinstance(e, ast.Compare):
            for k, op in enumerate(e.ops):
                self.pair(e.operands[k], op, e.operands[k + 1], inner)
            return
        if isinstance(e, ast.Unary):
            if self.ident(e.operand, inner) is not None:
                raise NotInFragment(f"{self.v} under unary {e.op}")
            self.pc(e.operand, inner)
            return
        if isinstance(e, ast.Binary):
            if self.ident(e, inner) is not None or self.ident(e.left, inner) is not None \
                    or self.ident(e.right, inner) is not None:
                raise NotInFragment(f"{self.v} in arithmetic that is not compared directly")
            self.pc(e.left, inner)
            self.pc(e.right, inner)
            return
        if isinstance(e, ast.Member):
            if self.ident(e.elem, inner) == 0 and (isinstance(e.collection, ast.SetLit) or (
                    isinstance(e.collection, ast.Var) and e.collection.prefix is not None)):
                self.valued(e.collection, inner, "elems")
                return
            if self.ident(e.elem, inner) is not None:
                raise NotInFragment(f"{self.v} tested for membership")
            self.pc(e.elem, inner)
            if isinstance(e.collection, ast.SetLit):
                for item in e.collection.items:
                    if self.ident(item, inner) is not None:
                        raise NotInFragment(f"{self.v} as a set element")
                    self.pc(item, inner)
                return
            raise NotInFragment(f"{self.v} in a membership test")
        if isinstance(e, ast.Quant):
            now = inner
            for bd in e.bindings:
                if self.mentions(bd.domain, now):
                    raise NotInFragment(f"{self.v} in a quantifier's domain")
                now = now | frozenset(bd.names)
            self.pc(e.body, now)
            return
        raise NotInFragment(f"{self.v} in {type(e).__name__}")

    def pair(self, left: Any, op: str, right: Any, inner: frozenset[str]) -> None:
        for a, b in ((left, right), (right, left)):
            s = self.ident(a, inner)
            if s is not None:
                self.valued(b, inner, "values", shift=s, eq=op in ("==", "!="))
                return
            if isinstance(a, ast.Apply) and not self._table(a) and self.mentions(a, inner):
                if op not in ("==", "!="):
                    raise NotInFragment(f"a constructor term of {self.v} compared with {op}")
                for k, arg in enumerate(a.args):
                    s = self.ident(arg, inner)
                    if s is not None:
                        self.valued(b, inner, "ctor", k, a.func.name, s)
                    elif self.mentions(arg, inner):
                        raise NotInFragment(f"{self.v} inside a constructor argument")
                return
        self.pc(left, inner)
        self.pc(right, inner)


def _int_lit(e: Any) -> int | None:
    if isinstance(e, ast.NumLit) and e.value.denominator == 1:
        return int(e.value)
    return None


def _free(e: Any, name: str, bound: frozenset[str]) -> bool:
    """Does ``name`` occur free in ``e`` (not rebound by an inner quantifier)?"""
    if isinstance(e, ast.Var):
        return e.prefix is None and e.name == name
    if isinstance(e, ast.Quant):
        if any(_free(bd.domain, name, bound) for bd in e.bindings):
            return True
        return not any(name in bd.names for bd in e.bindings) and _free(e.body, name, bound)
    if isinstance(e, ast.TupleQuant):
        return _free(e.domain, name, bound) or (name not in e.names and _free(e.body, name, bound))
    if isinstance(e, tuple):
        return any(_free(x, name, bound) for x in e)
    if isinstance(e, ast.Loc) or not hasattr(e, "__dataclass_fields__"):
        return False
    return any(_free(getattr(e, f), name, bound) for f in e.__dataclass_fields__)


# -- run time: the points ----------------------------------------------------------------
def _is_number(x: Any) -> bool:
    return not isinstance(x, bool) and isinstance(x, (int, float, Fraction))


def breakpoints(ev: Any, sources: tuple[Source, ...], b: Mapping[str, Any], numeric: str) -> list[Any]:
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


def _values(ev: Any, s: Source, b: Mapping[str, Any]) -> list[Any]:
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
    ints: set[int] = set()
    for x in bps:
        ints.add(math.floor(x))
        ints.add(math.ceil(x))
    zs = sorted(z for z in ints if numeric == "INTEGER" or z >= 0)
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
    ints = {math.floor(x) for x in bps} | {math.ceil(x) for x in bps}
    zs = sorted(z for z in ints if numeric == "INTEGER" or z >= 0)
    yield from ((z, 1) for z in zs)
    yield (zs[-1] + 1 if zs else 0), MANY


def _between(a: float, b: float) -> int:
    """How many finite doubles lie strictly between ``a`` and ``b`` (1, or MANY)."""
    n = math.nextafter(a, math.inf) if math.isfinite(a) else -1.7976931348623157e308
    if not n < b:
        return 0
    m = math.nextafter(n, math.inf)
    return MANY if m < b and math.isfinite(m) else 1


def numeric_of(ev: Any, dom: Any) -> str | None:
    """``REAL``/``INTEGER``/``NATURAL`` when binding domain ``dom`` is that type, else None."""
    name = dom.name if isinstance(dom, ast.TBase) else None
    if isinstance(dom, ast.TName):
        t = ev.env.types.get(dom.name)
        name = getattr(t, "name", None) if type(t).__name__ == "Scalar" else None
    return name if name in ("REAL", "INTEGER", "NATURAL") else None


def quantify(ev: Any, e: ast.Quant, b: Mapping[str, Any], finite_domain: Any, max_product: int) -> bool | None:
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

    def level(j: int, cur: dict[str, Any]) -> int:
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


__all__ = ["MANY", "MAX_CANDIDATE_STEPS", "NotInFragment", "Source", "analyse", "breakpoints", "numeric_of", "points",
           "quantify"]
