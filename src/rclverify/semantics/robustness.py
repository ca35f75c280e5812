"""The space margin of an RCL state formula on concrete values: how far the
values are from the formula's boundary, signed (docs/semantics.md, "Margins").

The quantitative semantics of Donzé and Maler ("Robust satisfaction of
temporal logic over real-valued signals", FORMATS 2010) and of Fainekos and
Pappas ("Robustness of temporal logic specifications for continuous-time
signals", TCS 2009), read through RCL's state formulas, on the values the
evaluator judges (:mod:`rclverify.semantics.evaluate`, the operators of
:mod:`rclverify.semantics.operators`):

* a comparison of two numbers: ``a <= b`` and ``a < b`` give ``b - a``,
  ``a >= b`` and ``a > b`` give ``a - b``; a chain ``a < b <= c`` is the
  ``and`` of its links;
* an exact relation of two numbers: ``a == b`` gives ``-|a - b|`` when the
  sides differ and, when they are equal, ``+inf``: it holds without a
  distance (any change of either side breaks an equality, so a distance to
  the boundary would be 0 on every correct answer, and a correct copy
  ``out.x == in.x`` would read as the nearest of near misses);
  ``a != b`` is its negation, ``|a - b|`` when they differ and ``-inf``
  when equal;
* ``not`` negates, ``and`` is the minimum, ``or`` the maximum, ``a -> b`` is
  ``not a or b``, ``a <=> b`` is ``(a -> b) and (b -> a)``;
* ``forall`` is the minimum and ``exists`` the maximum over the quantifier's
  domain (a sequence's or a set's elements, an enumeration, BOOL, an integer
  range bounded by literal guards: the values the guard admits); over the
  empty domain ``+inf`` and ``-inf``; ``exists_unique`` is
  ``min(r1, -r2)`` for the largest and second largest margins of the body
  (``r2 = -inf`` on one element): positive when exactly one element is
  clear of the boundary on the true side and every other on the false side;
* a number's membership in a finite collection of numbers (``x in {1, 2}``)
  is the ``or`` of its equalities, ``!in`` their ``and`` of disequalities;
* every other atom (a BOOL value, a comparison of enumeration values,
  constructor terms or truth values, membership in a type, a function's
  BOOL result) has no distance: ``+inf`` when true, ``-inf`` when false
  (the convention of Donzé and Maler for Boolean signals).

**Sign.**  ``margin > 0`` implies the formula holds and ``margin < 0``
implies it fails, on the same values in the same arithmetic (by induction:
min and max keep the implication).  ``margin == 0`` is the boundary, where
the Boolean verdict decides: ``a <= b`` holds there, ``a < b`` does not (an
equality is never at 0: it holds at ``+inf``).  tests/semantics/test_robustness.py checks this
against the evaluator on random formulas and values.

**Arithmetic.**  ``exact``: the terms in exact rational arithmetic (the
evaluator's), the distances exact, rounded once to a double at the end (a
non-zero distance too small for a double becomes the smallest double of its
sign, so the sign never changes).  ``double``: the terms and distances in
IEEE-754 binary64 (:mod:`rclverify.semantics.floatsem`), whose subtraction
is zero only between equal numbers.  A verdict decided within a declared
tolerance has no margin here (the tolerance is a relation, not a distance).

**Unit.**  The margin is a value of the comparison that decides it (the one
whose distance min and max select, :attr:`Margin.atom`); its unit is that
comparison's (docs/rcl-language.md, "Units of measure": both sides have one
unit; the type checker's :class:`rclverify.lang.unitcheck.UnitChecker`
gives it; :mod:`rclverify.semantics.margin_atoms` names the atom), ``""`` when neither side declares one.  Distances of different
units meet in min and max as numbers, as in the standard semantics; the
atom and its unit say which one a margin is.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Any, Callable, Mapping

from rclverify.lang import ast
from rclverify.lang.types import Checked, CheckedNode
from rclverify.semantics.eval_closures import _compile
from rclverify.semantics.margin_atoms import atom_words, measured_terms
from rclverify.semantics.margin_atoms import measures_the_run as measures_the_run
from rclverify.semantics.evaluator import Evaluator
from rclverify.semantics.floatsem import MAX_ENUMERATION, _Double, _finite_domain
from rclverify.semantics.operators import OPERATORS, Undecided
from rclverify.semantics.values import Value

INF = math.inf

#: The arithmetics a margin is computed in (those of semantics/floatsem.py that measure a distance).
ARITHMETICS = ("exact", "double")


@dataclass(frozen=True)
class Margin:
    """A formula's space margin on some values.

    ``value``: the signed distance to the boundary (float; ``inf``/``-inf``
    when only atoms without a distance decide), in ``unit`` (the deciding
    comparison's unit text, ``""`` when it has none); ``atom``: that
    comparison's RCL text (``""`` when none decides: a BOOL atom, an empty
    domain); ``arithmetic``: ``exact`` or ``double``."""

    value: float
    unit: str = ""
    atom: str = ""
    arithmetic: str = "exact"


class MarginUndefined(Exception):
    """No margin on these values (the reason in ``str``): a quantifier over
    an infinite domain, a value missing, a division by zero, a value of the
    wrong form."""


_R = tuple[Any, Any]  # (distance: int | Fraction | float, the deciding atom: (node, link, bound names) or None)


#: the domains that are terms (a set's or a sequence's elements), not types
_COLLECTIONS = (ast.Var, ast.SetLit, ast.SeqLit, ast.SeqRange, ast.Apply)


def _number(v: Any) -> bool:
    return not isinstance(v, bool) and isinstance(v, (int, float, Fraction))


class _Margins:
    """One computation: the evaluator ``ev`` gives the terms' values."""

    def __init__(self, ev: Evaluator, exact: bool) -> None:
        self.ev = ev
        self.exact = exact
        self._sub = OPERATORS["-"].exact if exact else OPERATORS["-"].double

    def diff(self, x: Any, y: Any) -> Any:
        """``x - y`` in the arithmetic (a difference of doubles is zero only when they are equal)."""
        return self._sub(x, y)

    def truth(self, e: ast.Expr, b: Mapping[str, Value], holds: bool) -> _R:
        """An atom without a distance: ``+inf`` when it holds, ``-inf`` when not."""
        return (INF if holds else -INF), None

    def rob(self, e: ast.Expr, b: Mapping[str, Value], idx: frozenset[str] = frozenset()) -> _R:
        """The margin of ``e`` under bound variables ``b``; ``idx``: the bound
        variables that range over a type (an index, not a value of the run)."""
        return self.compiled(e, frozenset(b), idx)(self, b)

    def compiled(self, e: ast.Expr, scope: frozenset[str], idx: frozenset[str]) -> Callable[..., _R]:
        """``e``'s margin as nested closures ``f(margins, bound)`` for the bound
        names ``scope`` (:func:`_build`), made once per formula, node and scope."""
        ev = self.ev
        node = ev.node
        key = (id(e), scope, idx, id(node), id(ev.env), ev.mode)
        hit = _CLOSURES.get(key)
        if hit is None or hit[0] is not e or hit[1] is not node:
            if len(_CLOSURES) >= 4096:
                _CLOSURES.clear()
            hit = _CLOSURES[key] = (e, node, _build(e, scope, idx, _Static(ev.io_names, ev.env, node, ev.mode)))
        return hit[2]

    def measured(self, terms: Any, b: Mapping[str, Value], idx: frozenset[str]) -> bool:
        """Whether ``terms`` read a value of the run (:func:`rclverify.semantics.margin_atoms.measured_terms`)."""
        return measured_terms(terms, b, idx, self.ev.io_names)

    def compare(self, e: ast.Compare, b: Mapping[str, Value], idx: frozenset[str]) -> _R:
        """A comparison chain: the ``and`` of its links."""
        vals = [self.ev.eval(o, b) for o in e.operands]
        out: _R = (INF, None)
        for i, op in enumerate(e.ops):
            x, y = vals[i], vals[i + 1]
            if _number(x) and _number(y) and self.measured(e.operands[i:i + 2], b, idx):
                r: _R = (self.distance(op, x, y), (e, i, frozenset(b)))
            else:
                r = self.truth(e, b, bool(self.ev.compare(e, b, op, x, y)))
            out = _min(out, r)
        return out

    def distance(self, op: str, x: Any, y: Any) -> Any:
        """The margin of ``x op y`` on two numbers (module docstring)."""
        if op in ("<", "<="):
            return self.diff(y, x)
        if op in (">", ">="):
            return self.diff(x, y)
        d = abs(self.diff(x, y))
        if d == 0:  # an exact relation at equality: no distance (module docstring)
            return INF if op == "==" else -INF
        return -d if op == "==" else d

    def member(self, e: ast.Member, b: Mapping[str, Value], idx: frozenset[str]) -> _R:
        """``x in S``: the ``or`` of ``x == s`` over a finite collection of numbers, else its truth."""
        x = self.ev.eval(e.elem, b)
        carrier = self.ev.carrier(e.collection, b)
        if carrier is not None or not _number(x) or not self.measured((e.elem, e.collection), b, idx):
            return self.truth(e, b, bool(self.ev.eval(e, b)))
        items = list(self.ev.collection(e.collection, b))
        if not all(_number(v) for v in items):
            return self.truth(e, b, bool(self.ev.eval(e, b)))
        at = (e, 0, frozenset(b))
        near: _R = (-INF, None)
        for v in items:  # x in S: the or of x == v
            near = _max(near, (self.distance("==", x, v), at))
        return _neg(near) if e.negated else near

    def quant(self, e: ast.Quant, b: Mapping[str, Value], idx: frozenset[str]) -> _R:
        """A quantifier over finite domains (:meth:`domain`), its variables indexes or values (:meth:`indexes`)."""
        names: list[str] = []
        doms: list[list[Any]] = []
        size = 1
        inner = set(idx)
        for bd in e.bindings:
            for n in bd.names:
                try:
                    dom = self.domain(e, bd, n, b)
                except Undecided as exc:
                    raise MarginUndefined(f"{n}: {exc}") from None
                names.append(n)
                doms.append(dom)
                if self.indexes(bd.domain, b):
                    inner.add(n)
                else:
                    inner.discard(n)
                size *= max(len(dom), 1)
                if size > MAX_ENUMERATION:
                    raise MarginUndefined(f"quantifier over more than {MAX_ENUMERATION} values")
        return self.over(e.kind, e.body, names, itertools.product(*doms), b, frozenset(inner))

    def indexes(self, dom: Any, b: Mapping[str, Value]) -> bool:
        """Whether a variable over ``dom`` is an index (a type, a literal integer range), not a value of the run."""
        if isinstance(dom, ast.SeqRange):
            return not self.measured((dom.lo, dom.hi), b, frozenset())
        return not isinstance(dom, _COLLECTIONS) or self.ev.carrier(dom, b) is not None

    def domain(self, e: ast.Quant, bd: ast.Binding, name: str, b: Mapping[str, Value]) -> list[Any]:
        """The values ``name`` takes: a collection's elements, a range's integers,
        else a finite type's values (:func:`rclverify.semantics.floatsem._finite_domain`)."""
        dom = bd.domain
        if isinstance(dom, ast.SeqRange):
            lo, hi = self.ev.eval(dom.lo, b), self.ev.eval(dom.hi, b)
            return list(range(int(lo), int(hi) + 1))
        if isinstance(dom, _COLLECTIONS) and self.ev.carrier(dom, b) is None:
            return list(self.ev.collection(dom, b))
        return _finite_domain(self.ev, e, bd, name, b)

    def tuple_quant(self, e: ast.TupleQuant, b: Mapping[str, Value], idx: frozenset[str]) -> _R:
        """A quantifier over a collection's tuples, destructured."""
        dom = e.domain
        if not isinstance(dom, _COLLECTIONS) or self.ev.carrier(dom, b) is not None:
            raise MarginUndefined("a tuple quantifier over a type is not finite")
        elems = list(self.ev.collection(dom, b))
        return self.over(e.kind, e.body, list(e.names), (tuple(t) for t in elems), b, idx - frozenset(e.names))

    def over(self, kind: str, body: ast.Expr, names: list[str], combos: Any, b: Mapping[str, Value],
             idx: frozenset[str]) -> _R:
        """``forall`` (min), ``exists`` (max) or ``exists_unique`` (``min(r1, -r2)``) of ``body``."""
        best: _R = (INF, None) if kind == "forall" else (-INF, None)
        second: _R = (-INF, None)
        f = self.compiled(body, frozenset(b) | frozenset(names), idx)
        for combo in combos:
            cur = dict(b)
            cur.update(zip(names, combo))
            r = f(self, cur)
            if kind == "forall":
                best = _min(best, r)
            elif r[0] > best[0]:
                best, second = r, best
            elif r[0] > second[0]:
                second = r
        if kind == "exists_unique":
            return _min(best, _neg(second))
        return best


@dataclass(frozen=True)
class _Static:
    """What a closure is built for: the node's I/O names ``io``, the contract's
    environment ``env``, the node and the evaluator's number ``mode``."""

    io: frozenset[str]
    env: Any
    node: CheckedNode
    mode: str | None


def _build(e: ast.Expr, scope: frozenset[str], idx: frozenset[str], st: _Static) -> Callable[..., _R]:  # long: one closure per formula class, a flat table
    """``e``'s margin as a closure ``f(margins, bound)`` doing what the
    :class:`_Margins` methods do, with what is static decided here: the
    connectives' shape, whether a comparison measures a value of the run, its
    atom, its operands as the evaluator's compiled closures
    (:func:`rclverify.semantics.eval_closures._compile`).  Members and
    quantifiers call their methods."""
    io = st.io
    if isinstance(e, ast.BoolLit):
        const: _R = (INF if e.value else -INF), None
        return lambda m, b: const
    if isinstance(e, ast.Unary) and e.op == "not":
        inner = _build(e.operand, scope, idx, st)
        return lambda m, b: _neg(inner(m, b))
    if isinstance(e, ast.Binary) and e.op in ("and", "or", "->", "<=>"):
        lf, rf = _build(e.left, scope, idx, st), _build(e.right, scope, idx, st)
        if e.op == "and":
            return lambda m, b: _min(lf(m, b), rf(m, b))
        if e.op == "or":
            return lambda m, b: _max(lf(m, b), rf(m, b))
        if e.op == "->":
            return lambda m, b: _max(_neg(lf(m, b)), rf(m, b))
        return lambda m, b: _iff(lf(m, b), rf(m, b))
    if isinstance(e, ast.Compare) and len(e.ops) == 1:
        cmp_ = e
        op, (o1, o2) = e.ops[0], e.operands
        atom = (e, 0, scope)
        f1, f2 = _compile(o1, st.env, st.node, st.mode), _compile(o2, st.env, st.node, st.mode)
        if not measured_terms(e.operands, scope, idx, io):
            return lambda m, b: (INF if m.ev.compare(cmp_, b, op, f1(m.ev, b), f2(m.ev, b)) else -INF, None)

        def compare(m: _Margins, b: Mapping[str, Value]) -> _R:
            ev = m.ev
            x, y = f1(ev, b), f2(ev, b)
            if _number(x) and _number(y):
                return m.distance(op, x, y), atom
            return (INF if ev.compare(cmp_, b, op, x, y) else -INF), None
        return compare
    if isinstance(e, ast.Compare):
        chain = e
        return lambda m, b: m.compare(chain, b, idx)
    if isinstance(e, ast.Member):
        mem = e
        return lambda m, b: m.member(mem, b, idx)
    if isinstance(e, ast.Quant):
        q = e
        return lambda m, b: m.quant(q, b, idx)
    if isinstance(e, ast.TupleQuant):
        tq = e
        return lambda m, b: m.tuple_quant(tq, b, idx)
    other = e
    return lambda m, b: m.truth(other, b, bool(m.ev.eval(other, b)))  # a BOOL value, a function's BOOL result


def _iff(left: _R, right: _R) -> _R:
    """``(a -> b) and (b -> a)``."""
    return _min(_max(_neg(left), right), _max(_neg(right), left))


#: (formula id, bound names, index names, node id) -> (the formula, the node, its closure)
_CLOSURES: dict[tuple[Any, ...], tuple[Any, Any, Callable[..., _R]]] = {}


def _min(x: _R, y: _R) -> _R:
    return y if y[0] < x[0] else x


def _max(x: _R, y: _R) -> _R:
    return y if y[0] > x[0] else x


def _neg(x: _R) -> _R:
    return -x[0], x[1]


def _to_float(v: Any) -> float:
    """``v`` as a double, never changing its sign (a non-zero rational too small
    for a double becomes the smallest double of its sign)."""
    f = float(v) + 0.0  # -0.0 is 0
    if f == 0 and v != 0:
        return math.nextafter(0.0, 1.0 if v > 0 else -1.0)
    return f



def margin(formula: ast.Expr, checked: Checked, node: CheckedNode, values: Mapping[str, object],
           arithmetic: str = "exact") -> Margin:
    """The space margin of ``formula`` (a state formula of ``node``) on
    ``values`` (qualified names ``in.r``/``out.d`` -> values of
    :mod:`rclverify.semantics.values`, as :func:`rclverify.semantics.evaluate.evaluate`
    takes them), in ``arithmetic`` (``exact`` or ``double``, :data:`ARITHMETICS`).
    Returns a :class:`Margin` (module docstring for the rules and the sign).
    Raises :class:`MarginUndefined` when there is none (a quantifier over an
    infinite domain, a missing value, a division by zero, a value of the
    wrong form) and ``ValueError`` for an unknown ``arithmetic``."""
    if arithmetic not in ARITHMETICS:
        raise ValueError(f"no margin in {arithmetic!r} arithmetic (one of {', '.join(ARITHMETICS)})")
    ev = Evaluator(checked, node, values) if arithmetic == "exact" else _Double(checked, node, values)
    try:
        value, at = _Margins(ev, arithmetic == "exact").rob(formula, {})
    except Undecided as exc:
        raise MarginUndefined(str(exc)) from None
    except (TypeError, ZeroDivisionError, OverflowError, ValueError) as exc:
        raise MarginUndefined(f"a value has the wrong form for the formula: {exc}") from None
    if at is None:
        return Margin(float(value), "", "", arithmetic)
    atom, i, bound = at
    text, unit = atom_words(checked, node, atom, i, bound)
    return Margin(_to_float(value), unit, text, arithmetic)


__all__ = ["ARITHMETICS", "INF", "Margin", "MarginUndefined", "atom_words", "margin", "measures_the_run"]
