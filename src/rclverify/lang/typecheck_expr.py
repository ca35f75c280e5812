"""The typing of RCL names and expressions: on the state of a type check and
its resolution of type expressions (:mod:`rclverify.lang.type_resolution`),
the rules that give each expression its type (shared/DESIGN.md "RCL"; paper lines
499-555; the rules are listed in :mod:`rclverify.lang.typecheck`).

An expression that cannot be typed records one diagnostic and raises
:class:`CheckFailed`; :mod:`rclverify.lang.typecheck` collects the
diagnostics of a whole system and raises them as one ``RclError``.
"""
from __future__ import annotations

from typing import Any, Callable, Mapping, Sequence

from rclverify.lang import ast

from rclverify.lang import typeexpr
from rclverify.lang.type_resolution import CheckFailed as CheckFailed, TypeResolver, candidates
from rclverify.lang.types import (BASE_NAMES, BOOL, INTEGER, NATURAL, REAL, STRING, qualified_base, CheckedNode,
                                  EmptyT, FuncT, Scalar, SeqT, SetT, TupleT, Type, assignable, comparable,
                                  is_numeric, numeric_join)


class ExprChecker(TypeResolver):
    """Types the names, type expressions and expressions of one system: the
    state and the type resolution of :class:`~rclverify.lang.type_resolution.TypeResolver`,
    and the rules that give each expression its type.

    A failure to type raises :class:`CheckFailed` after recording its
    diagnostic.  The subclass in :mod:`rclverify.lang.typecheck` adds the
    declarations and nodes."""

    # -- contexts -----------------------------------------------------------------

    # -- expressions ----------------------------------------------------------------
    def var(self, v: ast.Var, node: CheckedNode | None, bound: Mapping[str, Type]) -> Type:
        if (self.failed_io or self.failed_consts) and v.name not in bound and ((v.prefix, v.name) in self.failed_io or (
                v.prefix is None and (("in", v.name) in self.failed_io or ("out", v.name) in self.failed_io
                                      or v.name in self.failed_consts))):
            raise CheckFailed  # its declaration already has an error; no knock-on message
        if v.prefix is not None:
            table = (node.inputs if v.prefix == "in" else node.outputs) if node else {}
            if v.name in table:
                return table[v.name]
            kind = "input" if v.prefix == "in" else "output"
            where = f"node {node.name}" if node else "a context constant"
            pool = list(table)
            other = "out" if v.prefix == "in" else "in"
            if node is not None and v.name in (node.outputs if v.prefix == "in" else node.inputs):
                self.err(v.loc, f"{where} has no {kind} named {v.name!r}, but it has an "
                                f"{'output' if other == 'out' else 'input'} of that name; did you mean {other}.{v.name}? "
                                f"(its {kind}s are: {', '.join(pool) or 'none'})", "E-name")
                raise CheckFailed
            self.err(v.loc, f"{where} has no {kind} named {v.name!r} (in {v.qualified})"
                     + (candidates(v.name, pool) if candidates(v.name, pool) else f"; its {kind}s are: {', '.join(pool) or 'none'}"), "E-name")
            raise CheckFailed
        if v.name in bound:
            return bound[v.name]
        if node is not None:
            i, o = node.inputs.get(v.name), node.outputs.get(v.name)
            if i is not None and o is not None:
                self.err(v.loc, f"{v.name!r} is both an input and an output of {node.name}; write in.{v.name} or out.{v.name}", "E-ambiguous")
                raise CheckFailed
            if i is not None or o is not None:
                return i or o  # type: ignore[return-value]
        if v.name in self.constants:
            return self.constants[v.name][0]
        if v.name in self.enum_values:
            return self.enum_values[v.name]
        if v.name in self.ctors:
            data = self.ctors[v.name]
            if data.ctor(v.name):
                self.err(v.loc, f"constructor {v.name} takes {len(data.ctor(v.name) or ())} argument(s); write {v.name}(...)", "E-arity")
                raise CheckFailed
            return data
        pool = list(bound) + list(self.constants) + list(self.enum_values) + list(self.ctors)
        if node is not None:
            pool += list(node.inputs) + list(node.outputs)
        self.err(v.loc, f"unknown name {v.name!r}" + candidates(v.name, pool), "E-name")
        raise CheckFailed

    def infer(self, e: ast.Expr, node: CheckedNode | None, bound: Mapping[str, Type]) -> Type:
        """The type of ``e`` in ``node``'s scope plus the ``bound`` variables
        (one rule per kind of expression, :data:`_RULES`)."""
        rule = _RULES.get(type(e))
        if rule is None:
            raise AssertionError(e)  # pragma: no cover
        return rule(self, e, node, bound)

    def _var(self, e: ast.Var, node: CheckedNode | None, bound: Mapping[str, Type]) -> Type:
        if e.prefix is None and e.name not in bound and e.name in self.types and not (
                node and (e.name in node.inputs or e.name in node.outputs)):
            self.err(e.loc, f"{e.name!r} is a type, not a value", "E-type")
            raise CheckFailed
        return self.var(e, node, bound)

    def _first(self, e: ast.First, node: CheckedNode | None, bound: Mapping[str, Type]) -> Type:
        """``first(in.x)`` is a formula (BOOL) whose argument is an input of
        the node (in a requirement, ``Node.in.x``); anything else is an
        ``E-type`` error at the argument naming what it is (docs/semantics.md,
        "The first published value")."""
        v = e.arg
        usage = "first(...) takes an input of the node: first(in.x) in a contract, first(Node.in.x) in a requirement"
        if v.prefix is None and v.name in bound:
            why = f"{v.name} is a bound variable, not an input"
        elif node is not None and ".state." in v.name and v.name in node.inputs:
            why = f"{v.name} is a state variable, which no node publishes"
        elif node is not None and (v.prefix == "out" or (v.prefix is None and v.name in node.outputs
                                                         and v.name not in node.inputs)):
            why = f"{v.qualified} is an output; first(...) speaks of the messages a node receives"
        elif node is not None and v.prefix != "out" and v.name in node.inputs:
            self.var(v, node, bound)  # an input whose declaration failed reports nothing more
            return BOOL
        else:
            self.var(v, node, bound)  # an unknown name: its own E-name error
            why = f"{v.qualified} is not an input" if node is not None else "a context has no inputs"
        self.err(v.loc, f"{usage}; {why}")
        raise CheckFailed

    def _unary(self, e: ast.Unary, node: CheckedNode | None, bound: Mapping[str, Type]) -> Type:
        t = self.infer(e.operand, node, bound)
        if e.op == "not":
            self.expect_bool(e.operand, t, "not")
            return BOOL
        if e.op == "-" or e.op == "abs":
            if not is_numeric(t):
                self.err(e.operand.loc, f"{'unary -' if e.op == '-' else 'abs'} needs a number, found {t}")
                raise CheckFailed
            return REAL if t == REAL else INTEGER
        # a real argument, a real value (docs/semantics.md, "Mathematical functions")
        if e.op == "sqrt" or e.op == "sin" or e.op == "cos":
            if not is_numeric(t):
                self.err(e.operand.loc, f"{e.op} needs a number, found {t}")
                raise CheckFailed
            return REAL
        ast.unhandled(e.op)

    def _binary(self, e: ast.Binary, node: CheckedNode | None, bound: Mapping[str, Type]) -> Type:
        lt, rt = self.infer(e.left, node, bound), self.infer(e.right, node, bound)
        if e.op in ("<=>", "->", "or", "and"):
            self.expect_bool(e.left, lt, e.op)
            self.expect_bool(e.right, rt, e.op)
            return BOOL
        for side, t in ((e.left, lt), (e.right, rt)):
            if not is_numeric(t):
                self.err(side.loc, f"'{e.op}' needs numbers, found {t}")
                raise CheckFailed
        if e.op == "/":
            return REAL
        j = numeric_join(lt, rt)
        assert j is not None
        return INTEGER if (e.op == "-" and j == NATURAL) else j

    def _compare(self, e: ast.Compare, node: CheckedNode | None, bound: Mapping[str, Type]) -> Type:
        ts = [self.infer(o, node, bound) for o in e.operands]
        for op, (a, ta), (b, tb) in zip(e.ops, zip(e.operands, ts), zip(e.operands[1:], ts[1:])):
            if op in ("==", "!="):
                if not comparable(ta, tb):
                    self.err(b.loc, f"cannot compare {ta} with {tb} using '{op}'")
                    raise CheckFailed
            elif not (is_numeric(ta) and is_numeric(tb)):
                bad, bt = (a, ta) if not is_numeric(ta) else (b, tb)
                self.err(bad.loc, f"'{op}' needs numbers, found {bt}")
                raise CheckFailed
        return BOOL

    def _member(self, e: ast.Member, node: CheckedNode | None, bound: Mapping[str, Type]) -> Type:
        et = self.infer(e.elem, node, bound)
        st = self.collection(e.collection, node, bound)
        if not (isinstance(st.elem, EmptyT) or comparable(et, st.elem)):
            self.err(e.collection.loc, f"membership of a {et} in a collection of {st.elem}")
            raise CheckFailed
        return BOOL

    def _collection_lit(self, e: ast.SetLit | ast.SeqLit, node: CheckedNode | None,
                        bound: Mapping[str, Type]) -> Type:
        elem: Type = EmptyT("{}")
        for it in e.items:
            t = self.infer(it, node, bound)
            if isinstance(elem, EmptyT):
                elem = t
            elif numeric_join(elem, t) is not None:
                elem = numeric_join(elem, t)  # type: ignore[assignment]
            elif not comparable(elem, t):
                self.err(it.loc, f"collection mixes {elem} and {t}")
                raise CheckFailed
        return SetT(elem) if isinstance(e, ast.SetLit) else SeqT(elem)

    def _tuple_lit(self, e: ast.TupleLit, node: CheckedNode | None, bound: Mapping[str, Type]) -> Type:
        return TupleT(tuple(self.infer(i, node, bound) for i in e.items))

    def _seq_range(self, e: ast.SeqRange, node: CheckedNode | None, bound: Mapping[str, Type]) -> Type:
        ts = [self.infer(x, node, bound) for x in (e.lo, e.hi)]
        for x, t in zip((e.lo, e.hi), ts):
            if t not in (NATURAL, INTEGER):
                self.err(x.loc, f"a bound of '<a upto b>' must be an integer (NATURAL or INTEGER), found {t}")
                raise CheckFailed
        return SeqT(NATURAL if ts == [NATURAL, NATURAL] else INTEGER)

    def _tuple_quant(self, e: ast.TupleQuant, node: CheckedNode | None, bound: Mapping[str, Type]) -> Type:
        et = self.domain(ast.Binding(e.names, e.domain, e.loc), node, bound)
        if not isinstance(et, TupleT) or len(et.elems) != len(e.names):
            self.err(e.domain.loc, f"({', '.join(e.names)}) takes apart tuples of {len(e.names)} components, "
                                   f"but the elements here have type {et}")
            raise CheckFailed
        inner = dict(bound)
        inner.update(zip(e.names, et.elems))
        self.expect_bool(e.body, self.infer(e.body, node, inner), e.kind)
        return BOOL

    def _quant(self, e: ast.Quant, node: CheckedNode | None, bound: Mapping[str, Type]) -> Type:
        inner = dict(bound)
        for bd in e.bindings:
            dt = self.domain(bd, node, bound)
            for nm in bd.names:
                inner[nm] = dt
        self.expect_bool(e.body, self.infer(e.body, node, inner), e.kind)
        return BOOL

    def expect_bool(self, e: ast.Expr, t: Type, op: str) -> None:
        if t != BOOL:
            self.err(e.loc, f"'{op}' needs a formula (BOOL), found {t}")
            raise CheckFailed

    def collection(self, c: ast.Expr, node: CheckedNode | None, bound: Mapping[str, Type]) -> SetT:
        if isinstance(c, ast.Var) and c.prefix is None and c.name in BASE_NAMES and c.name not in bound:
            return SetT(Scalar(c.name))
        if isinstance(c, ast.Var) and c.prefix is None and (product := qualified_base(c.name)) is not None:
            return SetT(product)
        if isinstance(c, ast.Var) and c.prefix is None and c.name not in bound and c.name in self.types and not (
                node and (c.name in node.inputs or c.name in node.outputs)):
            return SetT(self.types[c.name])
        t = self.infer(c, node, bound)
        if isinstance(t, (SetT, SeqT)):
            return SetT(t.elem)
        self.err(c.loc, f"'in' needs a set, a sequence or a type on its right, found {t}")
        raise CheckFailed

    def domain(self, b: ast.Binding, node: CheckedNode | None, bound: Mapping[str, Type]) -> Type:
        d = b.domain
        if isinstance(d, typeexpr.TName) and (product := qualified_base(d.name)) is not None:
            return product
        if isinstance(d, typeexpr.TName) and d.name not in self.types and d.name not in self.type_decls:
            known = d.name in bound or d.name in self.constants or (
                node is not None and (d.name in node.inputs or d.name in node.outputs))
            if not known:
                # An unknown type is reported once, where it is first used
                # (`inputs(c : String)` then `forall(x in String | ...)`).
                if d.name not in self.unknown_types:
                    self.unknown_types.add(d.name)
                    self.err(d.loc, f"unknown type or set {d.name!r}"
                             + candidates(d.name, list(self.types) + list(self.type_decls) + list(BASE_NAMES)),
                             "E-name")
                raise CheckFailed
            return self.collection(ast.Var(d.name, None, d.loc), node, bound).elem
        if isinstance(d, (typeexpr.TBase, typeexpr.TName, typeexpr.TEnum, typeexpr.TConstructors, typeexpr.TFunc, typeexpr.TEmpty,
                          typeexpr.TSet, typeexpr.TSeq, typeexpr.TTuple)):
            return self.resolve(d, "_".join(b.names) + "_dom")
        return self.collection(d, node, bound).elem

    def apply(self, e: ast.Apply, node: CheckedNode | None, bound: Mapping[str, Type]) -> Type:
        f = e.func
        is_var = f.prefix is not None or f.name in bound or (
            node is not None and (f.name in node.inputs or f.name in node.outputs)) or f.name in self.constants
        if not is_var and f.name in self.ctors:
            data = self.ctors[f.name]
            params = data.ctor(f.name) or ()
            self.args(e, params, node, bound, f"constructor {f.name}")
            return data
        ft = self.var(f, node, bound)
        if not isinstance(ft, FuncT):
            self.err(f.loc, f"{f.qualified} has type {ft} and cannot be applied to arguments", "E-type")
            raise CheckFailed
        self.args(e, ft.args, node, bound, f.qualified)
        return ft.result

    def args(self, e: ast.Apply, params: Sequence[Type], node: CheckedNode | None,
             bound: Mapping[str, Type], what: str) -> None:
        if len(e.args) != len(params):
            self.err(e.loc, f"{what} takes {len(params)} argument(s) ({', '.join(map(str, params))}), given {len(e.args)}", "E-arity")
            raise CheckFailed
        for a, p in zip(e.args, params):
            at = self.infer(a, node, bound)
            if not assignable(at, p):
                self.err(a.loc, f"argument of {what} must be {p}, found {at}")
                raise CheckFailed


_Rule = Callable[[ExprChecker, Any, "CheckedNode | None", Mapping[str, Type]], Type]

#: The typing rule of each kind of expression (kinds of the RCL AST, lang/ast.py).
_RULES: dict[type, _Rule] = {
    ast.BoolLit: lambda c, e, node, bound: BOOL,
    ast.NumLit: lambda c, e, node, bound: NATURAL if e.is_integral else REAL,
    ast.StrLit: lambda c, e, node, bound: STRING,
    ast.Var: ExprChecker._var, ast.Apply: ExprChecker.apply, ast.Unary: ExprChecker._unary,
    ast.Binary: ExprChecker._binary, ast.Compare: ExprChecker._compare, ast.Member: ExprChecker._member,
    ast.SetLit: ExprChecker._collection_lit, ast.SeqLit: ExprChecker._collection_lit,
    ast.TupleLit: ExprChecker._tuple_lit, ast.SeqRange: ExprChecker._seq_range,
    ast.TupleQuant: ExprChecker._tuple_quant, ast.Quant: ExprChecker._quant,
    ast.First: ExprChecker._first,
}
