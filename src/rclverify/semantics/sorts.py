"""Z3 sorts of RCL types and the coercions between them (shared/DESIGN.md
"Semantics the tool commits to"): ``REAL`` -> Real, ``INTEGER``/``NATURAL``
-> Int, ``BOOL`` -> Bool, enumerations -> enumeration sorts, constructor
sets -> algebraic datatypes (accessor ``<ctor>_<k>``, recogniser
``is_<ctor>``), tuples -> one datatype per list of component sorts, sets and
sequences -> Z3's; Int widened to Real where one side is Real (NATURAL <:
INTEGER <: REAL), componentwise for tuples; RCL's binary operators applied
on such terms.

Sorts are cached per process (and made anew with a fresh Z3 context,
:mod:`rclverify.semantics.world`), so two encoders agree on the sort ``RadStat``.
Part of the Z3 encoding (:mod:`rclverify.semantics.encode`).
"""
from __future__ import annotations

from typing import Any, cast

import z3

from rclverify.lang.types import DataT, EmptyT, EnumT, Scalar, SeqT, SetT, TupleT, Type
from rclverify.semantics.operators import OPERATORS
from rclverify.semantics.world import on_fresh

_SORTS: dict[Type, Any] = {}
_SORT_NAMES: dict[str, Type] = {}


def _sort_name(t: Type, name: str) -> str:
    """A Z3 sort name for ``t``: its own name unless another type already took it
    (Z3's datatype names are global to the process)."""
    k, candidate = 1, name
    while candidate in _SORT_NAMES and _SORT_NAMES[candidate] != t:
        k += 1
        candidate = f"{name}_{k}"
    _SORT_NAMES[candidate] = t
    return candidate
_ENUM_CONSTS: dict[tuple[str, str], z3.ExprRef] = {}


def sort_of(t: Type) -> z3.SortRef:
    """Z3 sort of a resolved RCL type (cached per process).

    Raises :class:`ValueError` for the empty type and for function types,
    which are not first-class values (they become uninterpreted functions).
    """
    if t in _SORTS:
        return _SORTS[t]
    s: Any
    if isinstance(t, Scalar):
        s = {"REAL": z3.RealSort(), "INTEGER": z3.IntSort(), "NATURAL": z3.IntSort(), "BOOL": z3.BoolSort(),
             "STRING": z3.StringSort()}[t.name]
    elif isinstance(t, EnumT):
        s, consts = z3.EnumSort(_sort_name(t, t.name), list(t.values))
        for v, c in zip(t.values, consts):
            _ENUM_CONSTS[(t.name, v)] = c
    elif isinstance(t, DataT):
        dt = z3.Datatype(_sort_name(t, t.name))
        for cname, args in t.ctors:
            dt.declare(cname, *[(f"{cname}_{k}", sort_of(a)) for k, a in enumerate(args)])
        s = dt.create()
    elif isinstance(t, TupleT):
        s = tuple_sort([sort_of(e) for e in t.elems])
    elif isinstance(t, SetT):
        s = z3.SetSort(sort_of(t.elem))
    elif isinstance(t, SeqT):
        s = z3.SeqSort(sort_of(t.elem))
    elif isinstance(t, EmptyT):
        raise ValueError(f"the empty type {t} has no values")
    else:
        raise ValueError(f"function type {t} is not a first-class value")
    _SORTS[t] = s
    return s


def enum_const(t: EnumT, value: str) -> z3.ExprRef:
    """The Z3 constant for enumeration value ``value`` of ``t``."""
    sort_of(t)
    return _ENUM_CONSTS[(t.name, value)]


def _ctor(t: DataT, name: str) -> z3.FuncDeclRef:
    s: Any = sort_of(t)
    for k in range(s.num_constructors()):
        if s.constructor(k).name() == name:
            return s.constructor(k)
    raise KeyError(name)


def _recogniser(t: DataT, name: str) -> z3.FuncDeclRef:
    s: Any = sort_of(t)
    for k in range(s.num_constructors()):
        if s.constructor(k).name() == name:
            return s.recognizer(k)
    raise KeyError(name)


def tuple_sort(fields: list[z3.SortRef]) -> z3.SortRef:
    """The Z3 datatype for tuples whose components have sorts ``fields``.

    One sort per list of component sorts (named ``Tuple_<sorts>``, with the
    constructor ``mk_Tuple_<sorts>`` and accessors ``Tuple_<sorts>_<k>``), so
    a tuple literal ``(1, 2)`` and a variable of type ``(NATURAL, INTEGER)``
    share a sort (both components are Z3 ``Int``).
    """
    name = "Tuple_" + "_".join(str(f) for f in fields)
    if name not in _TUPLE_SORTS:
        dt = z3.Datatype(name)
        dt.declare("mk_" + name, *[(f"{name}_{k}", f) for k, f in enumerate(fields)])
        _TUPLE_SORTS[name] = dt.create()
    return _TUPLE_SORTS[name]


_TUPLE_SORTS: dict[str, z3.SortRef] = {}


@on_fresh
def _forget_sorts() -> None:
    """A new Z3 context (:func:`rclverify.semantics.world.fresh`) makes every kept sort and constant anew."""
    for cache in (_SORTS, _SORT_NAMES, _ENUM_CONSTS, _TUPLE_SORTS):
        cache.clear()


def _tuple_fields(s: z3.SortRef) -> list[z3.SortRef] | None:
    """The component sorts of a tuple sort made by :func:`tuple_sort`, else ``None``."""
    if s.kind() != z3.Z3_DATATYPE_SORT or not s.name().startswith("Tuple_"):
        return None
    c = cast(z3.DatatypeSortRef, s).constructor(0)
    return [c.domain(k) for k in range(c.arity())]


def _join_sort(a: z3.SortRef, b: z3.SortRef) -> z3.SortRef:
    """The sort both ``a`` and ``b`` widen to: Real over Int, componentwise
    for tuples of equal length; ``a`` when there is none (Z3 then reports the
    mismatch, which the type checker has already ruled out)."""
    if a == b:
        return a
    if {a, b} == {z3.IntSort(), z3.RealSort()}:
        return z3.RealSort()
    fa, fb = _tuple_fields(a), _tuple_fields(b)
    if fa is not None and fb is not None and len(fa) == len(fb):
        return tuple_sort([_join_sort(x, y) for x, y in zip(fa, fb)])
    return a


def coerce(a: z3.ExprRef, b: z3.ExprRef) -> tuple[z3.ExprRef, z3.ExprRef]:
    """Widen Int to Real when one side is Real (NATURAL <: INTEGER <: REAL),
    componentwise for tuples (``(1, 2) == p`` with ``p : (REAL, REAL)``).
    Sort kinds are compared first: this runs for every comparison encoded."""
    sa, sb = a.sort(), b.sort()
    ka, kb = sa.kind(), sb.kind()
    if ka == z3.Z3_INT_SORT and kb == z3.Z3_REAL_SORT:
        return z3.ToReal(a), b
    if ka == z3.Z3_REAL_SORT and kb == z3.Z3_INT_SORT:
        return a, z3.ToReal(b)
    if ka == kb == z3.Z3_DATATYPE_SORT and not sa.eq(sb):
        s = _join_sort(sa, sb)
        return widen(a, s), widen(b, s)
    return a, b


def widen(x: z3.ExprRef, s: z3.SortRef) -> z3.ExprRef:
    """``x`` as a value of sort ``s`` (an Int widened to Real when ``s`` is
    Real; a tuple rebuilt component by component when ``s`` is a wider tuple
    sort); ``x`` itself otherwise."""
    ks = s.kind()
    if ks == z3.Z3_REAL_SORT:
        return z3.ToReal(x) if x.sort().kind() == z3.Z3_INT_SORT else x
    if ks != z3.Z3_DATATYPE_SORT or x.sort().eq(s):
        return x
    fs, fx = _tuple_fields(s), _tuple_fields(x.sort())
    if fs is not None and fx is not None and len(fs) == len(fx):
        xs = cast(z3.DatatypeSortRef, x.sort())
        return cast(z3.DatatypeSortRef, s).constructor(0)(
            *[widen(xs.accessor(0, k)(x), f) for k, f in enumerate(fs)])
    return x


def apply_operator(op: str, a: Any, b: Any) -> Any:
    """``a op b`` in Z3 for a binary connective, comparison or arithmetic operator
    of RCL (or the Hoare language): ``and or -> <=> == != < <= > >= + - * /``.

    Numeric operands are widened as :func:`coerce` does; ``/`` is real
    division.  The left operand's method is called explicitly so that
    ``k >= 0`` stays ``k >= 0`` (Python would otherwise prefer the numeral's
    reflected method and build ``0 <= k``).  The Z3 function or method is
    the operator's entry in the semantics table
    (:data:`rclverify.semantics.operators.OPERATORS`).  Raises ``KeyError``
    for an unknown operator.
    """
    entry = OPERATORS[op]
    if entry.kind == "connective" and entry.decisive is not None:  # and, or, ->
        return getattr(z3, cast(str, entry.z3))(a, b)
    if op == "/":
        a, b = widen(a, z3.RealSort()), widen(b, z3.RealSort())
    else:
        a, b = coerce(a, b)
    if entry.z3 in ("__eq__", "__ne__"):  # also <=> on truth values
        return getattr(z3.ExprRef, entry.z3)(a, b)
    return getattr(z3.ArithRef, cast(str, entry.z3))(a, b)
