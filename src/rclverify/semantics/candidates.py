"""Candidate points: a quantifier over ``REAL``/``INTEGER``/``NATURAL`` decided by finitely
many values of its variable, where that is exact (docs/values.md, "Quantifiers over numbers").

The double reading (:mod:`rclverify.semantics.floatsem`) enumerates finite domains only.  A
quantified variable ``v`` over an unbounded numeric type is still decided exactly when the
body's truth, as a function of ``v`` (every other variable fixed, the inputs concrete: a
function is a finite table and a default, :class:`rclverify.semantics.values.FiniteFunction`), is
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
same order (``targets/cpp/candidates.py``).  This module reads the body (:func:`analyse`);
:mod:`rclverify.semantics.candidate_points` makes the points and decides the quantifier.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from rclverify.lang import ast
from rclverify.lang.visit import Visitor

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
    sources: tuple[Source, ...] = result
    return sources


class _Scan(Visitor[None]):
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
        lit = _int_lit(e.left) if e.op == "+" else None
        if lit is not None:
            s = self.ident(e.right, inner)
            return None if s is None else s + lit
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
        """Check ``e`` is piecewise constant in ``v``, collecting breakpoint sources:
        the method ``visit_<Class>`` of ``e``'s class; any other construct that
        mentions ``v`` is outside the fragment (:meth:`generic_visit`)."""
        if self.mentions(e, inner):
            self.visit(e, inner)

    def generic_visit(self, e: Any, inner: frozenset[str]) -> None:
        raise NotInFragment(f"{self.v} in {type(e).__name__}")

    def visit_Apply(self, e: ast.Apply, inner: frozenset[str]) -> None:
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

    def visit_Compare(self, e: ast.Compare, inner: frozenset[str]) -> None:
        for k, op in enumerate(e.ops):
            self.pair(e.operands[k], op, e.operands[k + 1], inner)

    def visit_Unary(self, e: ast.Unary, inner: frozenset[str]) -> None:
        if self.ident(e.operand, inner) is not None:
            raise NotInFragment(f"{self.v} under unary {e.op}")
        self.pc(e.operand, inner)

    def visit_Binary(self, e: ast.Binary, inner: frozenset[str]) -> None:
        if self.ident(e, inner) is not None or self.ident(e.left, inner) is not None \
                or self.ident(e.right, inner) is not None:
            raise NotInFragment(f"{self.v} in arithmetic that is not compared directly")
        self.pc(e.left, inner)
        self.pc(e.right, inner)

    def visit_Member(self, e: ast.Member, inner: frozenset[str]) -> None:
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

    def visit_Quant(self, e: ast.Quant, inner: frozenset[str]) -> None:
        now = inner
        for bd in e.bindings:
            if self.mentions(bd.domain, now):
                raise NotInFragment(f"{self.v} in a quantifier's domain")
            now = now | frozenset(bd.names)
        self.pc(e.body, now)

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


__all__ = ["NotInFragment", "Source", "analyse"]
