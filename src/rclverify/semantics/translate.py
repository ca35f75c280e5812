"""RCL formulas and terms translated into Z3 terms, node by node of the
AST (:class:`_Ctx`, one per formula encoded by
:class:`rclverify.semantics.encode.Encoder`): names (I/O symbols, bound
variables, constants, enumeration values), literals, applications,
connectives and comparisons, membership, set, sequence and tuple literals,
ranges and quantifiers (``exists_unique`` as existence and uniqueness of
the tuple; a quantifier over the empty type is TRUE for ``forall``, FALSE
otherwise; NATURAL bound variables guarded ``>= 0``).  Part of the Z3
encoding (:mod:`rclverify.semantics.encode`, whose module docstring states it).
"""
from __future__ import annotations

from typing import Any, Mapping, cast

import z3

from rclverify.lang import ast

from rclverify.lang import typeexpr
from rclverify.lang.printer import FLAT_CHAINS, chain_operands, is_type
from rclverify.lang.typecheck import domain_type
from rclverify.lang.visit import Visitor
from rclverify.lang.types import BOOL, NATURAL, CheckedNode, EmptyT, FuncT, Scalar, TupleT, Type, qualified_base
from rclverify.semantics.connectives import conj, disj
from rclverify.semantics.mathfacts import math_function
from rclverify.semantics.sorts import _join_sort, _tuple_fields, apply_operator, coerce, sort_of, tuple_sort, widen
from rclverify.semantics.symbols import EncodingError, smt_symbol


def _is_empty_literal(x: ast.Expr) -> bool:
    return isinstance(x, (ast.SetLit, ast.SeqLit)) and not x.items


def unary_z3(op: ast.UnaryOp, v: Any) -> Any:
    """The Z3 term of unary operator ``op`` applied to ``v`` (a ``z3`` Bool for
    ``not``, an arithmetic term otherwise): ``Not``, ``-v``, ``If(v >= 0, v, -v)``
    (docs/rcl-language.md; the one Z3 reading of a unary operator, the
    experiment criterion's too); ``sqrt``, ``sin``, ``cos`` the uninterpreted
    function of :func:`~rclverify.semantics.mathfacts.math_function` applied
    to ``v`` as a real (their facts: :mod:`rclverify.semantics.mathfacts`)."""
    if op == "not":
        return z3.Not(v)
    if op == "-":
        return -v
    if op == "abs":
        return z3.If(v >= 0, v, -v)
    if op == "sqrt" or op == "sin" or op == "cos":
        return math_function(op)(z3.ToReal(v) if z3.is_int(v) else v)
    ast.unhandled(op)


class _Ctx(Visitor[Any]):
    def __init__(self, enc: Any, node: CheckedNode, symbols: dict[str, z3.ExprRef | z3.FuncDeclRef]) -> None:
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
        """The Z3 term of ``x`` under the bound variables ``bound``: the method
        ``visit_<Class>`` of ``x``'s class (:class:`rclverify.lang.visit.Visitor`)."""
        return self.visit(x, bound)

    def visit_BoolLit(self, x: ast.BoolLit, b: Mapping[str, z3.ExprRef]) -> Any:
        return z3.BoolVal(x.value)

    def visit_NumLit(self, x: ast.NumLit, b: Mapping[str, z3.ExprRef]) -> Any:
        v = x.value
        if x.is_integral:
            return z3.IntVal(int(v))
        return z3.RealVal(f"{v.numerator}/{v.denominator}")

    def visit_Var(self, x: ast.Var, b: Mapping[str, z3.ExprRef]) -> Any:
        r = self.var(x, b)
        if isinstance(r, z3.FuncDeclRef) and r.arity() > 0:
            raise EncodingError(x.loc, f"{x.qualified} is a function; comparing whole functions is not supported, apply it")
        return r() if isinstance(r, z3.FuncDeclRef) else r

    def visit_Apply(self, x: ast.Apply, b: Mapping[str, z3.ExprRef]) -> Any:
        f = x.func
        args = [self.enc(a, b) for a in x.args]
        is_value = f.prefix is not None or f.name in b or f.name in self.node.inputs or f.name in self.node.outputs
        if not is_value and f.name in self.e.env.ctors:
            c = self.e.ctor(f.name)
            return c(*[widen(a, c.domain(k)) for k, a in enumerate(args)])
        fn = self.var(f, b)
        if isinstance(fn, z3.FuncDeclRef):
            return fn(*[widen(a, fn.domain(k)) for k, a in enumerate(args)])
        if z3.is_array(fn):  # a function-typed variable given as an array (a step of calculus/requirements/transition.py)
            return z3.Select(fn, *[widen(a, fn.sort().domain_n(k)) for k, a in enumerate(args)])
        raise EncodingError(x.loc, f"{f.qualified} cannot be applied")

    def visit_First(self, x: ast.First, b: Mapping[str, z3.ExprRef]) -> Any:
        """``first(in.x)``: the term the caller gives as ``first(in.x)`` (a state's flag in the requirements'
        transition system), else the query's free Boolean of that input (:meth:`Encoder.first_symbol`)."""
        key = f"first(in.{x.arg.name})"
        given = self.symbols.get(key)
        return given if given is not None else self.e.first_symbol(self.node, x.arg.name)

    def visit_Unary(self, x: ast.Unary, b: Mapping[str, z3.ExprRef]) -> Any:
        return unary_z3(x.op, self.enc(x.operand, b))

    def visit_Binary(self, x: ast.Binary, b: Mapping[str, z3.ExprRef]) -> Any:
        if x.op in FLAT_CHAINS:
            # One n-ary And/Or over the whole chain, opened iteratively, so a
            # chain of any length or shape (also one built by a program,
            # left-nested) encodes without deep recursion.
            parts = [self.enc(o, b) for o in chain_operands(x)]
            return conj(*parts) if x.op == "and" else disj(*parts)
        return apply_operator(x.op, self.enc(x.left, b), self.enc(x.right, b))

    def visit_StrLit(self, x: ast.StrLit, b: Mapping[str, z3.ExprRef]) -> Any:
        return z3.StringVal(x.value)

    def visit_SeqRange(self, x: ast.SeqRange, b: Mapping[str, z3.ExprRef]) -> Any:
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

    def visit_TupleQuant(self, x: ast.TupleQuant, b: Mapping[str, z3.ExprRef]) -> Any:
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

    def _bind(self, name: str, t: Type, inner: dict[str, z3.ExprRef], xs: list[z3.ExprRef], guards: list[Any]) -> z3.ExprRef:
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
        if is_type(d) and not (isinstance(d, typeexpr.TName) and d.name not in self.e.env.types):
            return None
        return ast.Var(d.name, None, d.loc) if isinstance(d, typeexpr.TName) else cast(ast.Expr, d)

    def visit_Compare(self, x: ast.Compare, b: Mapping[str, z3.ExprRef]) -> Any:
        vals = [None if _is_empty_literal(o) else self.enc(o, b) for o in x.operands]
        for k, o in enumerate(x.operands):
            if vals[k] is None:
                # `out.route == <>`: the empty literal takes its neighbour's sort.
                near = [v for v in vals[max(k - 1, 0):k + 2] if v is not None]
                vals[k] = self.empty_literal(cast(ast.SetLit | ast.SeqLit, o), near[0].sort() if near else None)
        parts = [apply_operator(op, l, r) for op, l, r in zip(x.ops, vals, vals[1:])]
        return parts[0] if len(parts) == 1 else conj(*parts)

    def member(self, elem: Any, coll: ast.Expr, b: Mapping[str, z3.ExprRef]) -> Any:
        env = self.e.env
        if isinstance(coll, ast.SeqRange):
            lo, hi = self.enc(coll.lo, b), self.enc(coll.hi, b)
            integral = z3.IsInt(elem) if z3.is_real(elem) else z3.BoolVal(True)
            return z3.And(integral, lo <= elem, elem <= hi)
        if isinstance(coll, ast.SetLit) or isinstance(coll, ast.SeqLit):
            items = [self.enc(i, b) for i in coll.items]
            eqs = [(lambda p: p[0] == p[1])(coerce(elem, i)) for i in items]
            return disj(*eqs) if eqs else z3.BoolVal(False)
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
        return conj(*[self.in_base(acc(0, k)(elem), cast(Scalar, t).name) for k, t in enumerate(product.elems)])

    @staticmethod
    def in_base(elem: Any, base: str) -> Any:
        """``elem in NATURAL`` and friends: integrality and sign constraints."""
        if base in ("NATURAL", "INTEGER"):
            integral = z3.IsInt(elem) if z3.is_real(elem) else z3.BoolVal(True)
            return z3.And(integral, elem >= 0) if base == "NATURAL" else integral
        return z3.BoolVal(True)

    def visit_Member(self, x: ast.Member, b: Mapping[str, z3.ExprRef]) -> Any:
        r = self.member(self.enc(x.elem, b), x.collection, b)
        return z3.Not(r) if x.negated else r

    def _items(self, x: ast.SetLit | ast.SeqLit, b: Mapping[str, z3.ExprRef], what: str) -> list[Any]:
        """The items of a set or sequence literal, widened to one sort."""
        if not x.items:
            raise EncodingError(x.loc, f"an empty {what} literal is only supported where its element type is "
                                       f"known (compared with a {what}, or on the right of 'in')")
        items = [self.enc(i, b) for i in x.items]
        elem = items[0].sort()
        for i in items[1:]:
            elem = _join_sort(elem, i.sort())
        return [widen(i, elem) for i in items]

    def visit_SetLit(self, x: ast.SetLit, b: Mapping[str, z3.ExprRef]) -> Any:
        items = self._items(x, b, "set")
        s = z3.EmptySet(items[0].sort())
        for i in items:
            s = z3.SetAdd(s, i)
        return s

    def visit_SeqLit(self, x: ast.SeqLit, b: Mapping[str, z3.ExprRef]) -> Any:
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

    def visit_TupleLit(self, x: ast.TupleLit, b: Mapping[str, z3.ExprRef]) -> Any:
        items = [self.enc(i, b) for i in x.items]
        return cast(z3.DatatypeSortRef, tuple_sort([i.sort() for i in items])).constructor(0)(*items)

    def visit_Quant(self, x: ast.Quant, b: Mapping[str, z3.ExprRef]) -> Any:
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
        guard = conj(*guards) if guards else None
        if kind == "forall":
            return z3.ForAll(xs, z3.Implies(guard, body) if guard is not None else body)
        core = z3.And(guard, body) if guard is not None else body
        if kind == "exists":
            return z3.Exists(xs, core)
        ys = [z3.Const(str(v) + "_u", v.sort()) for v in xs]
        body_y = z3.substitute(core, *zip(xs, ys))
        unique = z3.ForAll(ys, z3.Implies(body_y, conj(*[y == v for y, v in zip(ys, xs)])))
        return z3.Exists(xs, z3.And(core, unique))

    def _bound_types(self, b: Mapping[str, z3.ExprRef]) -> dict[str, Type]:
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
