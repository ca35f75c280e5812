"""RCL formulas -> Z3 (shared/DESIGN.md "Semantics the tool commits to").

Encoding
--------
* ``REAL`` -> Real, ``INTEGER`` -> Int, ``NATURAL`` -> Int with ``>= 0``
  guards on every bound variable (``forall``: guard ``->`` body, ``exists``:
  guard ``and`` body) and an axiom for every free symbol (:meth:`Encoder.axioms`),
  ``BOOL`` -> Bool.
* Enumerations -> Z3 enumeration sorts, constructor sets -> algebraic
  datatypes (accessor ``<ctor>_<k>``, recogniser ``is_<ctor>``), both named
  after their context type; function types -> uninterpreted functions;
  ``set(T)`` -> Z3 sets, ``seq(T)`` -> Z3 sequences, tuples -> datatypes.
* ``exists_unique(x, y in D | P)`` -> ``exists x, y. P and forall x2, y2.
  P[x2, y2] -> x2 == x and y2 == y`` (uniqueness of the tuple).
* Quantifying over the empty type ``{}``: ``forall`` is TRUE, ``exists``
  FALSE; a formula that needs a value of the empty type is rejected.
* Free I/O variables become symbols named ``<Node>.<in|out>.<name>``;
  ``alias`` (the system model's connections) renames a consumer's input to
  the producer's output symbol, so that "an output variable and the input
  variable it feeds are the same symbol in the composed query".

Sorts are cached per process, so two encoders (e.g. a contract's and a Hoare
program's) agree on the sort ``RadStat``.
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Any, Callable, Mapping, Sequence, cast

import z3

from ..rcl import ast
from .world import on_fresh
from ..rcl.types import (BOOL, NATURAL, CheckedNode, DataT, EmptyT, EnumT, Env, FuncT, Scalar, SeqT,
                         SetT, TupleT, Type, qualified_base)
from ..rcl.printer import FLAT_CHAINS, chain_operands, is_type
from ..rcl.typecheck import domain_type
from ..values import decimal_text

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


class EncodingError(Exception):
    """A well-typed formula that the Z3 encoding does not support (located)."""

    def __init__(self, loc: ast.Loc, message: str) -> None:
        self.loc = loc
        super().__init__(f"{loc}: error: {message}")


def smt_symbol(name: str) -> str:
    """A Z3/SMT-LIB2 symbol for an RCL name: primes (``x'``), which SMT-LIB
    simple symbols do not allow, become ``_prime`` (``x_prime``), so that the
    written queries can be re-checked by a second solver."""
    return name.replace("'", "_prime")


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


@dataclass(frozen=True)
class Symbol:
    """A free symbol created by the encoder: its Z3 name, RCL display name and type."""

    z3name: str
    display: str
    type: Type
    decl: Any  # z3.ExprRef for constants, z3.FuncDeclRef for functions


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
    """A new Z3 context (:func:`rclverify.logic.world.fresh`) makes every kept sort and constant anew."""
    for cache in (_SORTS, _SORT_NAMES, _ENUM_CONSTS, _TUPLE_SORTS):
        cache.clear()


def _tuple_fields(s: z3.SortRef) -> list[z3.SortRef] | None:
    """The component sorts of a tuple sort made by :func:`tuple_sort`, else ``None``."""
    if s.kind() != z3.Z3_DATATYPE_SORT or not s.name().startswith("Tuple_"):
        return None
    c = cast(z3.DatatypeSortRef, s).constructor(0)
    return [c.domain(k) for k in range(c.arity())]


def _is_empty_literal(x: ast.Expr) -> bool:
    return isinstance(x, (ast.SetLit, ast.SeqLit)) and not x.items


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


_ARITH = {"<": "__lt__", "<=": "__le__", ">": "__gt__", ">=": "__ge__", "+": "__add__", "-": "__sub__",
          "*": "__mul__"}


def apply_operator(op: str, a: Any, b: Any) -> Any:
    """``a op b`` in Z3 for a binary connective, comparison or arithmetic operator
    of RCL (or the Hoare language): ``and or -> <=> == != < <= > >= + - * /``.

    Numeric operands are widened as :func:`coerce` does; ``/`` is real
    division.  The left operand's method is called explicitly so that
    ``k >= 0`` stays ``k >= 0`` (Python would otherwise prefer the numeral's
    reflected method and build ``0 <= k``).  Raises ``KeyError`` for an
    unknown operator.
    """
    if op == "and":
        return z3.And(a, b)
    if op == "or":
        return z3.Or(a, b)
    if op == "->":
        return z3.Implies(a, b)
    if op == "/":
        return widen(a, z3.RealSort()) / widen(b, z3.RealSort())
    if op in ("<=>", "=="):
        a, b = coerce(a, b)
        return z3.ExprRef.__eq__(a, b)
    a, b = coerce(a, b)
    if op == "!=":
        return z3.ExprRef.__ne__(a, b)
    return getattr(z3.ArithRef, _ARITH[op])(a, b)


class Encoder:
    """Encodes RCL formulas of one system into Z3.

    ``env``    the checked environment (context types, constants, values);
    ``alias``  maps ``(node, "in"|"out", var)`` to the canonical symbol name
               another I/O variable uses (consumer input -> producer output).
    """

    def __init__(self, env: Env, alias: Mapping[tuple[str, str, str], str] | None = None) -> None:
        self.env = env
        self.alias: Mapping[tuple[str, str, str], str] = alias if alias is not None else {}
        self.symbols: dict[str, Symbol] = {}

    # -- sorts and values ------------------------------------------------------------
    def sort(self, t: Type) -> z3.SortRef:
        """See :func:`sort_of`."""
        return sort_of(t)

    def enum_value(self, name: str) -> z3.ExprRef:
        """Z3 constant of an enumeration value (or argument-less constructor)."""
        if name in self.env.enum_values:
            return enum_const(self.env.enum_values[name], name)
        return _ctor(self.env.ctors[name], name)()

    def ctor(self, name: str) -> z3.FuncDeclRef:
        """Z3 constructor of constructor-set alternative ``name``."""
        return _ctor(self.env.ctors[name], name)

    # -- symbols --------------------------------------------------------------------------
    def symbol_name(self, node: str, prefix: str, var: str) -> str:
        return self.alias.get((node, prefix, var), f"{node}.{prefix}.{var}")

    def io_symbol(self, node: CheckedNode, prefix: str, var: str) -> Any:
        """The Z3 constant (or function declaration) of ``node``'s ``prefix.var``."""
        t = node.inputs[var] if prefix == "in" else node.outputs[var]
        name = self.symbol_name(node.name, prefix, var)
        if name in self.symbols:
            return self.symbols[name].decl
        display = name if name.count(".") >= 2 else f"{node.name}.{prefix}.{var}"
        if isinstance(t, FuncT):
            decl: Any = z3.Function(name, *[sort_of(a) for a in t.args], sort_of(t.result))
        else:
            decl = z3.Const(name, sort_of(t))
        self.symbols[name] = Symbol(name, display, t, decl)
        return decl

    def fresh(self, z3name: str, display: str, t: Type) -> z3.ExprRef:
        """A new free constant (e.g. a Skolem witness) shown as ``display`` in models."""
        z3name = smt_symbol(z3name)
        decl = z3.Const(z3name, sort_of(t))
        self.symbols[z3name] = Symbol(z3name, display, t, decl)
        return decl

    def axioms(self) -> list[z3.BoolRef]:
        """Typing side constraints of every free symbol created so far.

        NATURAL constants are ``>= 0``; functions with a NATURAL result are
        ``>= 0`` everywhere; constructor-set constants have NATURAL fields
        ``>= 0``.
        """
        out: list[z3.BoolRef] = []
        for sym in self.symbols.values():
            t = sym.type
            if t == NATURAL:
                out.append(sym.decl >= 0)
            elif isinstance(t, FuncT) and t.result == NATURAL:
                xs = [z3.Const(f"_a{k}", sort_of(a)) for k, a in enumerate(t.args)]
                out.append(z3.ForAll(xs, sym.decl(*xs) >= 0) if xs else sym.decl() >= 0)
            elif isinstance(t, DataT):
                for cname, args in t.ctors:
                    for k, a in enumerate(args):
                        if a == NATURAL:
                            acc = getattr(sort_of(t), f"{cname}_{k}")
                            out.append(z3.Implies(_recogniser(t, cname)(sym.decl), acc(sym.decl) >= 0))
        return out

    # -- formulas ----------------------------------------------------------------------------
    def formula(self, e: ast.Expr, node: CheckedNode, symbols: Mapping[str, Any] | None = None,
                bound: Mapping[str, z3.ExprRef] | None = None) -> z3.BoolRef:
        """Encode a (type-checked) formula of ``node``.

        ``symbols`` maps qualified I/O names (``"in.r"``, ``"out.x"``) to Z3
        terms (or function declarations) used instead of the node's symbols;
        ``bound`` gives Z3 terms for variables bound outside ``e`` (used to
        instantiate a quantifier's body).  Raises :class:`EncodingError` for
        unsupported constructs.
        """
        r = _Ctx(self, node, dict(symbols or {})).enc(e, dict(bound or {}))
        if not z3.is_bool(r):
            raise EncodingError(e.loc, "expected a formula")
        return r

    def term(self, e: ast.Expr, node: CheckedNode, symbols: Mapping[str, Any] | None = None) -> z3.ExprRef:
        """Encode a term (e.g. the left-hand side of a binding) of ``node``."""
        return _Ctx(self, node, dict(symbols or {})).enc(e, {})


class _Ctx:
    def __init__(self, enc: Encoder, node: CheckedNode, symbols: dict[str, Any]) -> None:
        self.e, self.node, self.symbols = enc, node, symbols
        self.var_types: dict[int, Type] = {}  # RCL type of each bound variable made here, by Z3 id

    # -- names -------------------------------------------------------------------------
    def io(self, v: ast.Var) -> Any:
        prefix = v.prefix or ("in" if v.name in self.node.inputs else "out")
        q = f"{prefix}.{v.name}"
        if q in self.symbols:
            return self.symbols[q]
        if v.prefix is None and v.name in self.symbols:
            return self.symbols[v.name]
        t = self.node.inputs.get(v.name) if prefix == "in" else self.node.outputs.get(v.name)
        if isinstance(t, EmptyT):
            raise EncodingError(v.loc, f"{q} has the empty type {t}; no formula can use its value")
        return self.e.io_symbol(self.node, prefix, v.name)

    def var(self, v: ast.Var, bound: Mapping[str, z3.ExprRef]) -> Any:
        if v.prefix is not None:
            return self.io(v)
        if v.name in bound:
            return bound[v.name]
        if v.name in self.node.inputs or v.name in self.node.outputs:
            return self.io(v)
        env = self.e.env
        if v.name in env.constants:
            return self.enc(env.constants[v.name][1], {})
        if v.name in env.enum_values or v.name in env.ctors:
            return self.e.enum_value(v.name)
        raise EncodingError(v.loc, f"unknown name {v.name!r}")

    # -- expressions ---------------------------------------------------------------------
    def enc(self, x: ast.Expr, bound: Mapping[str, z3.ExprRef]) -> Any:
        m: Callable[..., Any] = getattr(self, "e_" + type(x).__name__)
        return m(x, bound)

    def e_BoolLit(self, x: ast.BoolLit, b: Mapping[str, Any]) -> Any:
        return z3.BoolVal(x.value)

    def e_NumLit(self, x: ast.NumLit, b: Mapping[str, Any]) -> Any:
        v = x.value
        if x.is_integral:
            return z3.IntVal(int(v))
        return z3.RealVal(f"{v.numerator}/{v.denominator}")

    def e_Var(self, x: ast.Var, b: Mapping[str, Any]) -> Any:
        r = self.var(x, b)
        if isinstance(r, z3.FuncDeclRef) and r.arity() > 0:
            raise EncodingError(x.loc, f"{x.qualified} is a function; comparing whole functions is not supported, apply it")
        return r() if isinstance(r, z3.FuncDeclRef) else r

    def e_Apply(self, x: ast.Apply, b: Mapping[str, Any]) -> Any:
        f = x.func
        args = [self.enc(a, b) for a in x.args]
        is_value = f.prefix is not None or f.name in b or f.name in self.node.inputs or f.name in self.node.outputs
        if not is_value and f.name in self.e.env.ctors:
            c = self.e.ctor(f.name)
            return c(*[widen(a, c.domain(k)) for k, a in enumerate(args)])
        fn = self.var(f, b)
        if isinstance(fn, z3.FuncDeclRef):
            return fn(*[widen(a, fn.domain(k)) for k, a in enumerate(args)])
        if z3.is_array(fn):  # a function-typed variable given as an array (a step of requirements/transition.py)
            return z3.Select(fn, *[widen(a, fn.sort().domain_n(k)) for k, a in enumerate(args)])
        raise EncodingError(x.loc, f"{f.qualified} cannot be applied")

    def e_Unary(self, x: ast.Unary, b: Mapping[str, Any]) -> Any:
        v = self.enc(x.operand, b)
        return z3.Not(v) if x.op == "not" else -v

    def e_Binary(self, x: ast.Binary, b: Mapping[str, Any]) -> Any:
        if x.op in FLAT_CHAINS:
            # One n-ary And/Or over the whole chain, opened iteratively, so a
            # chain of any length or shape (also one built by a program,
            # left-nested) encodes without deep recursion.
            parts = [self.enc(o, b) for o in chain_operands(x)]
            return z3.And(*parts) if x.op == "and" else z3.Or(*parts)
        return apply_operator(x.op, self.enc(x.left, b), self.enc(x.right, b))

    def e_StrLit(self, x: ast.StrLit, b: Mapping[str, Any]) -> Any:
        return z3.StringVal(x.value)

    def e_SeqRange(self, x: ast.SeqRange, b: Mapping[str, Any]) -> Any:
        lo, hi = x.lo, x.hi
        if isinstance(lo, ast.NumLit) and isinstance(hi, ast.NumLit) and lo.is_integral and hi.is_integral:
            a, z = int(lo.value), int(hi.value)
            if z - a + 1 > MAX_RANGE_ITEMS:
                raise EncodingError(x.loc, f"a range of {z - a + 1} items is above the Z3 encoding's limit of "
                                           f"{MAX_RANGE_ITEMS}; not supported by backend z3")
            if z < a:
                return z3.Empty(z3.SeqSort(z3.IntSort()))
            units = [z3.Unit(z3.IntVal(k)) for k in range(a, z + 1)]
            return units[0] if len(units) == 1 else z3.Concat(*units)
        raise EncodingError(x.loc, "a range with non-literal bounds is only supported on the right of 'in' "
                                   "by backend z3")

    def e_TupleQuant(self, x: ast.TupleQuant, b: Mapping[str, Any]) -> Any:
        """``Q((u, v) in S | body)``: one bound variable per component, and
        the tuple they form must be an element of ``S`` (no guard when ``S``
        is a tuple type)."""
        probe = ast.Binding(("_tuple",), x.domain, x.loc)
        t = domain_type(probe, self.node, self.e.env, self._bound_types(b))
        if not isinstance(t, TupleT) or len(t.elems) != len(x.names):
            raise EncodingError(x.loc, f"{len(x.names)} names cannot take apart an element of type {t}")
        inner = dict(b)
        xs: list[z3.ExprRef] = []
        guards: list[Any] = []
        for nm, ct in zip(x.names, t.elems):
            if isinstance(ct, (FuncT, EmptyT)):
                raise EncodingError(x.loc, f"quantifying over {ct} is not supported by backend z3")
            self._bind(nm, ct, inner, xs, guards)
        coll = self._domain_collection(x.domain)
        if coll is not None:
            tup = cast(z3.DatatypeSortRef, sort_of(t)).constructor(0)(*xs)
            guards.append(self.member(tup, coll, b))
        return self._close(x.kind, xs, guards, self.enc(x.body, inner))

    def _bind(self, name: str, t: Type, inner: dict[str, Any], xs: list[z3.ExprRef], guards: list[Any]) -> z3.ExprRef:
        """A bound variable ``name`` of type ``t``: put in scope (``inner``) and in
        the quantifier's variables (``xs``), with ``>= 0`` for a NATURAL (``guards``)."""
        v = z3.Const(smt_symbol(name), sort_of(t))
        self.var_types[v.get_id()] = t
        inner[name] = v
        xs.append(v)
        if t == NATURAL:
            guards.append(v >= 0)
        return v

    def _domain_collection(self, d: Any) -> ast.Expr | None:
        """The collection a quantifier domain stands for (a term, or a name
        that is not a declared type), else ``None``: a type needs no guard."""
        if is_type(d) and not (isinstance(d, ast.TName) and d.name not in self.e.env.types):
            return None
        return ast.Var(d.name, None, d.loc) if isinstance(d, ast.TName) else cast(ast.Expr, d)

    def e_Compare(self, x: ast.Compare, b: Mapping[str, Any]) -> Any:
        vals = [None if _is_empty_literal(o) else self.enc(o, b) for o in x.operands]
        for k, o in enumerate(x.operands):
            if vals[k] is None:
                # `out.route == <>`: the empty literal takes its neighbour's sort.
                near = [v for v in vals[max(k - 1, 0):k + 2] if v is not None]
                vals[k] = self.empty_literal(cast(ast.SetLit | ast.SeqLit, o), near[0].sort() if near else None)
        parts = [apply_operator(op, l, r) for op, l, r in zip(x.ops, vals, vals[1:])]
        return parts[0] if len(parts) == 1 else z3.And(*parts)

    def member(self, elem: Any, coll: ast.Expr, b: Mapping[str, Any]) -> Any:
        env = self.e.env
        if isinstance(coll, ast.SeqRange):
            lo, hi = self.enc(coll.lo, b), self.enc(coll.hi, b)
            integral = z3.IsInt(elem) if z3.is_real(elem) else z3.BoolVal(True)
            return z3.And(integral, lo <= elem, elem <= hi)
        if isinstance(coll, ast.SetLit) or isinstance(coll, ast.SeqLit):
            items = [self.enc(i, b) for i in coll.items]
            eqs = [(lambda p: p[0] == p[1])(coerce(elem, i)) for i in items]
            return z3.Or(*eqs) if eqs else z3.BoolVal(False)
        if isinstance(coll, ast.Var) and coll.prefix is None and coll.name not in b and coll.name in ("REAL", "INTEGER", "NATURAL", "BOOL"):
            return self.in_base(elem, coll.name)
        if isinstance(coll, ast.Var) and coll.prefix is None and coll.name not in b and coll.name in env.types \
                and coll.name not in self.node.inputs and coll.name not in self.node.outputs:
            t = env.types[coll.name]
            return elem >= 0 if t == NATURAL else z3.BoolVal(True)
        if isinstance(coll, ast.Var) and coll.prefix is None and coll.name not in b \
                and (product := qualified_base(coll.name)) is not None:
            return self.in_product(elem, product, coll.loc)
        s = self.enc(coll, b)
        if z3.is_seq(s):
            return z3.Contains(s, z3.Unit(widen(elem, cast(z3.SeqSortRef, s.sort()).basis())))
        return z3.IsMember(widen(elem, cast(z3.ArraySortRef, s.sort()).domain()), s)

    def in_product(self, elem: Any, product: TupleT, loc: ast.Loc) -> Any:
        """``(x, y) in REAL.REAL``: each component in its base type."""
        fields = _tuple_fields(elem.sort())
        if fields is None or len(fields) != len(product.elems):
            raise EncodingError(loc, f"membership in {product} needs a tuple of {len(product.elems)} components")
        acc = cast(z3.DatatypeSortRef, elem.sort()).accessor
        return z3.And(*[self.in_base(acc(0, k)(elem), cast(Scalar, t).name) for k, t in enumerate(product.elems)])

    @staticmethod
    def in_base(elem: Any, base: str) -> Any:
        """``elem in NATURAL`` and friends: integrality and sign constraints."""
        if base in ("NATURAL", "INTEGER"):
            integral = z3.IsInt(elem) if z3.is_real(elem) else z3.BoolVal(True)
            return z3.And(integral, elem >= 0) if base == "NATURAL" else integral
        return z3.BoolVal(True)

    def e_Member(self, x: ast.Member, b: Mapping[str, Any]) -> Any:
        r = self.member(self.enc(x.elem, b), x.collection, b)
        return z3.Not(r) if x.negated else r

    def _items(self, x: ast.SetLit | ast.SeqLit, b: Mapping[str, Any], what: str) -> list[Any]:
        """The items of a set or sequence literal, widened to one sort."""
        if not x.items:
            raise EncodingError(x.loc, f"an empty {what} literal is only supported where its element type is "
                                       f"known (compared with a {what}, or on the right of 'in')")
        items = [self.enc(i, b) for i in x.items]
        elem = items[0].sort()
        for i in items[1:]:
            elem = _join_sort(elem, i.sort())
        return [widen(i, elem) for i in items]

    def e_SetLit(self, x: ast.SetLit, b: Mapping[str, Any]) -> Any:
        items = self._items(x, b, "set")
        s = z3.EmptySet(items[0].sort())
        for i in items:
            s = z3.SetAdd(s, i)
        return s

    def e_SeqLit(self, x: ast.SeqLit, b: Mapping[str, Any]) -> Any:
        units = [z3.Unit(i) for i in self._items(x, b, "sequence")]
        return units[0] if len(units) == 1 else z3.Concat(*units)

    def empty_literal(self, x: ast.SetLit | ast.SeqLit, like: z3.SortRef | None) -> Any:
        """``{}`` or ``<>`` as a value of sort ``like`` (the other side of a
        comparison); of integers when both sides are empty literals, where
        the element type does not matter.  Raises :class:`EncodingError`
        when ``like`` is not a set (sequence) sort."""
        if isinstance(x, ast.SeqLit):
            if like is None:
                return z3.Empty(z3.SeqSort(z3.IntSort()))
            if isinstance(like, z3.SeqSortRef):
                return z3.Empty(like)
        else:
            if like is None:
                return z3.EmptySet(z3.IntSort())
            if isinstance(like, z3.ArraySortRef) and like.range() == z3.BoolSort():
                return z3.EmptySet(like.domain())
        raise EncodingError(x.loc, f"an empty literal compared with a value of Z3 sort {like}")

    def e_TupleLit(self, x: ast.TupleLit, b: Mapping[str, Any]) -> Any:
        items = [self.enc(i, b) for i in x.items]
        return cast(z3.DatatypeSortRef, tuple_sort([i.sort() for i in items])).constructor(0)(*items)

    def e_Quant(self, x: ast.Quant, b: Mapping[str, Any]) -> Any:
        inner = dict(b)
        xs: list[z3.ExprRef] = []
        guards: list[Any] = []
        for bd in x.bindings:
            t = domain_type(bd, self.node, self.e.env, self._bound_types(b))
            if isinstance(t, EmptyT):
                return z3.BoolVal(x.kind == "forall")
            if isinstance(t, FuncT):
                raise EncodingError(bd.loc, "quantifying over functions is not supported")
            coll = self._domain_collection(bd.domain)
            for nm in bd.names:
                v = self._bind(nm, t, inner, xs, guards)
                if coll is not None:
                    guards.append(self.member(v, coll, b))
        return self._close(x.kind, xs, guards, self.enc(x.body, inner))

    @staticmethod
    def _close(kind: str, xs: list[z3.ExprRef], guards: list[Any], body: Any) -> Any:
        """The Z3 quantifier ``kind`` over ``xs`` with ``guards`` on them."""
        guard = z3.And(*guards) if guards else None
        if kind == "forall":
            return z3.ForAll(xs, z3.Implies(guard, body) if guard is not None else body)
        core = z3.And(guard, body) if guard is not None else body
        if kind == "exists":
            return z3.Exists(xs, core)
        ys = [z3.Const(str(v) + "_u", v.sort()) for v in xs]
        body_y = z3.substitute(core, *zip(xs, ys))
        unique = z3.ForAll(ys, z3.Implies(body_y, z3.And(*[y == v for y, v in zip(ys, xs)])))
        return z3.Exists(xs, z3.And(core, unique))

    def _bound_types(self, b: Mapping[str, Any]) -> dict[str, Type]:
        """RCL types of the bound names in scope: recorded for variables this
        encoder bound; read off the sort for scalars bound by the caller."""
        scalars = {z3.RealSort(): Scalar("REAL"), z3.IntSort(): Scalar("INTEGER"), z3.BoolSort(): BOOL}
        out: dict[str, Type] = {}
        for nm, v in b.items():
            t = self.var_types.get(v.get_id()) or scalars.get(v.sort())
            if t is not None:
                out[nm] = t
        return out


#: Largest ``<a upto b>`` with literal bounds the Z3 encoding spells out.
MAX_RANGE_ITEMS = 10_000


#: How a term is rendered: its text (a leaf), or its children and what joins their texts.
_Parts = tuple[str | None, Sequence[z3.ExprRef], Callable[[list[str]], str] | None]


def _render(root: z3.ExprRef, parts: Callable[[z3.ExprRef], _Parts]) -> str:
    """Render ``root`` bottom-up with an explicit stack: Z3 models can hold
    terms thousands of levels deep (a function table's ``else`` branch as a
    chain of ``if``s), deeper than Python's recursion limit."""
    todo: list[tuple[z3.ExprRef, tuple[int, Callable[[list[str]], str]] | None]] = [(root, None)]
    done: list[str] = []
    while todo:
        e, pending = todo.pop()
        if pending is not None:  # its children are rendered: the last n texts
            n, combine = pending
            texts = done[len(done) - n:]
            del done[len(done) - n:]
            done.append(combine(texts))
            continue
        leaf, kids, join = parts(e)
        if leaf is not None or join is None:
            done.append(leaf if leaf is not None else str(e))
            continue
        todo.append((e, (len(kids), join)))
        todo.extend((k, None) for k in reversed(kids))  # the first child is rendered first
    return done[0]


def _value_parts(v: z3.ExprRef) -> _Parts:
    if z3.is_int_value(v):
        return str(v.as_long()), (), None
    if z3.is_rational_value(v):
        fr = Fraction(v.numerator_as_long(), v.denominator_as_long())
        if fr.denominator == 1:
            return str(fr.numerator), (), None
        dec = float(fr)
        if Fraction(dec) == fr:
            return repr(dec), (), None
        exact = decimal_text(fr)  # 0.2, not 1/5 (docs/values.md)
        return (exact or f"{fr.numerator}/{fr.denominator}"), (), None
    if z3.is_algebraic_value(v):
        return str(v.as_decimal(6)), (), None
    if z3.is_true(v):
        return "TRUE", (), None
    if z3.is_false(v):
        return "FALSE", (), None
    if z3.is_app(v) and v.num_args() > 0:
        name = v.decl().name()
        return None, v.children(), lambda xs: f"{name}(" + ", ".join(xs) + ")"
    if z3.is_app(v):
        return str(v.decl().name()), (), None
    return str(v), (), None


def value_to_rcl(v: z3.ExprRef) -> str:
    """Render a Z3 model value in RCL notation (``move(1.5, 0)``, ``green``, ``7/3``)."""
    return _render(v, _value_parts)


_OPS = {z3.Z3_OP_AND: " and ", z3.Z3_OP_OR: " or ", z3.Z3_OP_EQ: " == ", z3.Z3_OP_LE: " <= ", z3.Z3_OP_LT: " < ",
        z3.Z3_OP_GE: " >= ", z3.Z3_OP_GT: " > ", z3.Z3_OP_ADD: " + ", z3.Z3_OP_SUB: " - ", z3.Z3_OP_MUL: " * ",
        z3.Z3_OP_IMPLIES: " -> ", z3.Z3_OP_DIV: " / "}


def _term_parts(e: z3.ExprRef) -> _Parts:
    if z3.is_int_value(e) or z3.is_rational_value(e) or z3.is_true(e) or z3.is_false(e):
        return value_to_rcl(e), (), None
    if not z3.is_app(e):
        return str(e), (), None
    k = e.decl().kind()
    kids = e.children()
    if k in _OPS and kids:
        op = _OPS[k]
        return None, kids, lambda xs: "(" + op.join(xs) + ")"
    if k == z3.Z3_OP_NOT:
        return None, kids[:1], lambda xs: f"not {xs[0]}"
    if k == z3.Z3_OP_ITE:
        return None, kids, lambda xs: f"(if {xs[0]} then {xs[1]} else {xs[2]})"
    if k == z3.Z3_OP_DISTINCT:
        return None, kids, lambda xs: "(" + " != ".join(xs) + ")"
    if k == z3.Z3_OP_TO_REAL and kids:
        return None, kids[:1], lambda xs: xs[0]
    if kids:
        name = e.decl().name()
        return None, kids, lambda xs: f"{name}(" + ", ".join(xs) + ")"
    return value_to_rcl(e), (), None


def term_to_rcl(e: z3.ExprRef) -> str:
    """Render a Z3 term from a model in RCL notation, e.g. a function
    table's symbolic ``else`` branch: ``p1 == 2 and p2 == 3``.  Terms of any
    depth (an explicit stack).

    The text is :func:`_render` with :func:`_term_parts` (what
    :func:`_term_to_rcl_reference` does), computed once per distinct
    subterm: a model's ``else`` branch is a DAG whose chain of ``if``s
    shares its conditions, and walking it as a tree through the Python Z3
    wrappers cost some 9 CPU seconds of the case study's cold run (health
    models of 270,000-430,000 characters).  Inner nodes are read with Z3's
    low-level API (``z3.Z3_get_app_arg`` ...) on the raw terms (no wrapper object per node); leaves (values,
    constants, bound variables) are rendered by :func:`_term_parts` as
    before."""
    ctx = e.ctx
    c = ctx.ref()
    ast_id, ast_kind, n_args, arg = z3.Z3_get_ast_id, z3.Z3_get_ast_kind, z3.Z3_get_app_num_args, z3.Z3_get_app_arg
    app_decl, decl_kind = z3.Z3_get_app_decl, z3.Z3_get_decl_kind
    app_kind = z3.Z3_APP_AST
    memo: dict[int, str] = {}
    names: dict[int, str] = {}
    root = e.as_ast()
    todo: list[tuple[Any, bool]] = [(root, False)]
    while todo:
        a, ready = todo.pop()
        aid = ast_id(c, a)
        if not ready:
            if aid in memo:
                continue
            n = n_args(c, a) if ast_kind(c, a) == app_kind else 0
            if n == 0:
                memo[aid] = _render(z3.z3._to_expr_ref(a, ctx), _term_parts)
                continue
            todo.append((a, True))
            todo.extend((arg(c, a, i), False) for i in range(n - 1, -1, -1))
            continue
        n = n_args(c, a)
        xs = [memo[ast_id(c, arg(c, a, i))] for i in range(n)]
        d = app_decl(c, a)
        k = decl_kind(c, d)
        if k in _OPS:
            memo[aid] = "(" + _OPS[k].join(xs) + ")"
        elif k == z3.Z3_OP_NOT:
            memo[aid] = f"not {xs[0]}"
        elif k == z3.Z3_OP_ITE:
            memo[aid] = f"(if {xs[0]} then {xs[1]} else {xs[2]})"
        elif k == z3.Z3_OP_DISTINCT:
            memo[aid] = "(" + " != ".join(xs) + ")"
        elif k == z3.Z3_OP_TO_REAL:
            memo[aid] = xs[0]
        else:
            did = ast_id(c, d)
            if did not in names:
                names[did] = z3.FuncDeclRef(d, ctx).name()
            memo[aid] = f"{names[did]}(" + ", ".join(xs) + ")"
    return memo[ast_id(c, root)]


def _term_to_rcl_reference(e: z3.ExprRef) -> str:
    """:func:`term_to_rcl` as a walk of the whole tree through the Python
    wrappers: the definition the fast version must agree with (tests)."""
    return _render(e, _term_parts)
