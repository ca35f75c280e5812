"""RCL type checker: every name resolves, every formula is well typed.

Entry points
------------
``check(specs)``  -> :class:`~rclverify.lang.types.Checked`
``load(paths)``   -> parse every file, then :func:`check`
``infer(expr, node, env, bound)`` -> :data:`~rclverify.lang.types.Type`
``domain_type(binding, node, env, bound)`` -> element type of a quantifier binding

All errors are collected and raised together as one
:class:`~rclverify.lang.errors.RclError` whose diagnostics name the file,
line, column, the offending text and, where it helps, the candidates.

Rules (shared/DESIGN.md "RCL"; paper lines 499-555):

* ``in.x`` must name an input and ``out.x`` an output of the node; a bare
  name resolves to, in order: a bound variable (innermost first), an input,
  an output, a context constant, an enumeration value or argument-less
  constructor.  A bare name that is both an input and an output is ambiguous.
* ``f(a, ...)`` is either a function-typed variable applied to arguments of
  the declared domain types (numeric widening NATURAL <: INTEGER <: REAL
  allowed), or a constructor term of a constructor set.
* ``not``/``and``/``or``/``->``/``<=>`` take BOOL; ``< <= > >=`` take numbers;
  ``==``/``!=`` take comparable types; ``in``/``!in`` take an element and a
  set (literal, set-typed term or a context type name used as a set).
* A node has at least one guarantee (the EBNF's ``guarantee+``).
"""
from __future__ import annotations

import difflib
from pathlib import Path
from typing import Iterable, Mapping, Sequence

from rclverify.lang import ast, liveness, timing
from rclverify.lang.errors import Diagnostic, RclError, error
from rclverify.lang.parser import parse_files
from rclverify.lang.unitcheck import UnitChecker
from rclverify.lang.types import (BASE_NAMES, BOOL, INTEGER, NATURAL, REAL, STRING, Checked, qualified_base, CheckedNode, DataT, EmptyT, EnumT, Env, FuncT,
                    Scalar, SeqT, SetT, TupleT, Type, assignable, comparable, is_numeric, numeric_join)



class _Fail(Exception):
    """Internal: an expression could not be typed (a diagnostic was recorded)."""


def _candidates(name: str, pool: Iterable[str]) -> str:
    """``"; did you mean 'STRING'?"``: close names from ``pool``, a name that
    differs only in case first (``String`` -> ``STRING``); ``""`` if none."""
    names = sorted(set(pool))
    same = [c for c in names if c.lower() == name.lower() and c != name]
    lower = {c.lower(): c for c in names}
    close = same + [lower[c] for c in difflib.get_close_matches(name.lower(), sorted(lower), n=4, cutoff=0.5)
                    if lower[c] not in same]
    return f"; did you mean {', '.join(repr(c) for c in close[:4])}?" if close else ""


class _Checker:
    def __init__(self) -> None:
        self.diags: list[Diagnostic] = []
        self.types: dict[str, Type] = {}
        self.type_decls: dict[str, ast.TypeDecl] = {}
        self.constants: dict[str, tuple[Type, ast.Expr]] = {}
        self.enum_values: dict[str, EnumT] = {}
        self.ctors: dict[str, DataT] = {}
        self._resolving: set[str] = set()
        #: nodes allowed without assumption and guarantee (:func:`check`'s ``interface_only``)
        self.interface_only: frozenset[str] = frozenset()
        # Names whose declaration already failed (an unknown type was
        # reported there): later uses fail silently instead of adding
        # knock-on messages.  ``unknown_types``: reported once per name.
        self.unknown_types: set[str] = set()
        self.failed_io: set[tuple[str, str]] = set()
        self.failed_consts: set[str] = set()
        # units of measure (docs/rcl-language.md, "Units of measure"): declarations and formulas,
        # checked only when some file of the system writes a unit (check() sets it)
        self.units = UnitChecker(self.err)
        self.with_units = True

    # -- diagnostics -------------------------------------------------------------
    def err(self, loc: ast.Loc, msg: str, code: str = "E-type") -> None:
        self.diags.append(error(loc, msg, code))

    @property
    def env(self) -> Env:
        return Env(self.types, self.constants, self.enum_values, self.ctors, self.units.constants)

    # -- types ----------------------------------------------------------------------
    def resolve(self, t: ast.TypeExpr, name: str) -> Type:
        """Resolve a type expression; ``name`` names enums/constructor sets."""
        if isinstance(t, ast.TBase):
            return Scalar(t.name)
        if isinstance(t, ast.TName):
            if t.name in self.types:
                return self.types[t.name]
            if t.name in self.type_decls:
                if t.name in self._resolving:
                    self.err(t.loc, f"type {t.name!r} is defined in terms of itself", "E-type-cycle")
                    raise _Fail
                return self.declare_type(self.type_decls[t.name])
            if t.name not in self.unknown_types:
                self.unknown_types.add(t.name)
                self.err(t.loc, f"unknown type {t.name!r}" + _candidates(t.name, list(self.type_decls) + list(BASE_NAMES)), "E-name")
            raise _Fail
        if isinstance(t, ast.TEnum):
            enum = EnumT(name, t.values)
            seen: set[str] = set()
            for v in t.values:
                if v in seen:
                    self.err(t.loc, f"enumeration value {v!r} appears twice in {name}", "E-duplicate")
                    continue
                seen.add(v)
                self._claim_value(v, t.loc)
                self.enum_values[v] = enum
            return enum
        if isinstance(t, ast.TConstructors):
            ctors = []
            for c in t.ctors:
                args = tuple(self.resolve(a, f"{name}_{c.name}") for a in c.args)
                ctors.append((c.name, args))
            data = DataT(name, tuple(ctors))
            for c in t.ctors:
                self._claim_value(c.name, c.loc)
                self.ctors[c.name] = data
            return data
        if isinstance(t, ast.TFunc):
            return FuncT(tuple(self.resolve(a, name + "_arg") for a in t.args), self.resolve(t.result, name + "_res"))
        if isinstance(t, ast.TEmpty):
            return EmptyT(name)
        if isinstance(t, ast.TSet):
            return SetT(self.resolve(t.elem, name + "_elem"))
        if isinstance(t, ast.TSeq):
            return SeqT(self.resolve(t.elem, name + "_elem"))
        if isinstance(t, ast.TTuple):
            return TupleT(tuple(self.resolve(e, f"{name}_{k}") for k, e in enumerate(t.elems)))
        raise AssertionError(t)  # pragma: no cover

    def _claim_value(self, v: str, loc: ast.Loc) -> None:
        if v in self.enum_values or v in self.ctors:
            self.err(loc, f"{v!r} is already a value of {(self.enum_values.get(v) or self.ctors[v]).name}", "E-duplicate")

    def declare_type(self, d: ast.TypeDecl) -> Type:
        if d.name in self.types:
            return self.types[d.name]
        self._resolving.add(d.name)
        try:
            t = self.resolve(d.type, d.name)
        finally:
            self._resolving.discard(d.name)
        self.types[d.name] = t
        return t

    # -- contexts -----------------------------------------------------------------
    def contexts(self, specs: Sequence[ast.Spec]) -> None:
        decls = [d for s in specs for c in s.contexts for d in c.decls]
        seen: dict[str, ast.Loc] = {}
        for d in decls:
            if d.name in seen:
                self.err(d.loc, f"{d.name!r} is already declared at {seen[d.name]}", "E-duplicate")
                continue
            seen[d.name] = d.loc
            if isinstance(d, ast.TypeDecl):
                self.type_decls[d.name] = d
            elif _is_enum_constant(d, decls):
                # `Wayp = {wayA, wayB, wayC} ;`: a set of fresh names declared
                # as a constant is an enumeration usable as a type (`w : Wayp`)
                # and as a set (`w in Wayp`), as in the original tool
                # (docs/rcl-language.md).
                items = tuple(i.name for i in d.value.items)  # type: ignore[union-attr]
                self.type_decls[d.name] = ast.TypeDecl(d.name, ast.TEnum(items, d.value.loc), d.loc)
        for d in decls:
            if isinstance(d, ast.TypeDecl) and self.type_decls.get(d.name) is d:
                try:
                    self.declare_type(d)
                except _Fail:
                    pass
        for d in decls:
            if isinstance(d, ast.ConstDecl) and d.name not in self.constants and d.name not in self.type_decls:
                try:
                    vt = self.infer(d.value, None, {})
                    if d.type is not None:
                        dt = self.resolve(d.type, d.name)
                        if not assignable(vt, dt):
                            self.err(d.value.loc, f"constant {d.name} is declared {dt} but its value has type {vt}")
                        vt = dt
                    self.constants[d.name] = (vt, d.value)
                except _Fail:
                    self.failed_consts.add(d.name)
                    continue
                if self.with_units:
                    self.units.constant(d, vt)

    # -- nodes --------------------------------------------------------------------------
    def node(self, n: ast.Node) -> CheckedNode | None:
        inputs: dict[str, Type] = {}
        outputs: dict[str, Type] = {}
        ok = True
        self.failed_io = set()
        for group, table, prefix in ((n.inputs, inputs, "in"), (n.outputs, outputs, "out")):
            for v in group:
                if v.name in table:
                    self.err(v.loc, f"{v.name!r} is declared twice in node {n.name}", "E-duplicate")
                    ok = False
                    continue
                try:
                    table[v.name] = self.resolve(v.type, f"{n.name}_{v.name}")
                except _Fail:
                    self.failed_io.add((prefix, v.name))
                    ok = False
        typed = {f"in.{k}": t for k, t in inputs.items()} | {f"out.{k}": t for k, t in outputs.items()}
        cn = CheckedNode(n, inputs, outputs, self.units.declare(n, typed))
        for t in n.topics:
            if t.match is not None:
                try:
                    self.var(t.match, cn, {})
                except _Fail:
                    ok = False
        if n.links and not timing.check_links(n, self.err):
            ok = False
        for cl in n.guarantees:
            if (cl.trigger is not None or cl.deadline is not None) and not timing.check_clause(n, cl, self.err):
                ok = False
        if (n.progress or n.periodic or n.initially) and not liveness.check_node(
                n, set(inputs), set(outputs), self.err):
            ok = False
        if not n.guarantees and not (n.name in self.interface_only and not n.assumes):
            self.err(n.loc, f"node {n.name} has no guarantee; a contract needs at least one guarantee(...) "
                            f"(for a node declared by its interface only, `rclverify quotient {n.name}` computes "
                            "the weakest contract its neighbours need)", "E-contract")
            ok = False
        for cl in n.assumes + n.guarantees + n.initially:
            try:
                ft = self.infer(cl.formula, cn, {})
                if ft != BOOL:
                    self.err(cl.formula.loc, f"a contract clause must be a formula (BOOL), found {ft}")
                    ok = False
                elif self.with_units:
                    self.units.clause(cl.formula, cn)
            except _Fail:
                ok = False
        return cn if ok else None

    # -- expressions ----------------------------------------------------------------
    def var(self, v: ast.Var, node: CheckedNode | None, bound: Mapping[str, Type]) -> Type:
        if (self.failed_io or self.failed_consts) and v.name not in bound and ((v.prefix, v.name) in self.failed_io or (
                v.prefix is None and (("in", v.name) in self.failed_io or ("out", v.name) in self.failed_io
                                      or v.name in self.failed_consts))):
            raise _Fail  # its declaration already has an error; no knock-on message
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
                raise _Fail
            self.err(v.loc, f"{where} has no {kind} named {v.name!r} (in {v.qualified})"
                     + (_candidates(v.name, pool) if _candidates(v.name, pool) else f"; its {kind}s are: {', '.join(pool) or 'none'}"), "E-name")
            raise _Fail
        if v.name in bound:
            return bound[v.name]
        if node is not None:
            i, o = node.inputs.get(v.name), node.outputs.get(v.name)
            if i is not None and o is not None:
                self.err(v.loc, f"{v.name!r} is both an input and an output of {node.name}; write in.{v.name} or out.{v.name}", "E-ambiguous")
                raise _Fail
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
                raise _Fail
            return data
        pool = list(bound) + list(self.constants) + list(self.enum_values) + list(self.ctors)
        if node is not None:
            pool += list(node.inputs) + list(node.outputs)
        self.err(v.loc, f"unknown name {v.name!r}" + _candidates(v.name, pool), "E-name")
        raise _Fail

    def infer(self, e: ast.Expr, node: CheckedNode | None, bound: Mapping[str, Type]) -> Type:
        if isinstance(e, ast.BoolLit):
            return BOOL
        if isinstance(e, ast.NumLit):
            return NATURAL if e.is_integral else REAL
        if isinstance(e, ast.Var):
            if e.prefix is None and e.name not in bound and e.name in self.types and not (
                    node and (e.name in node.inputs or e.name in node.outputs)):
                self.err(e.loc, f"{e.name!r} is a type, not a value", "E-type")
                raise _Fail
            return self.var(e, node, bound)
        if isinstance(e, ast.Apply):
            return self.apply(e, node, bound)
        if isinstance(e, ast.Unary):
            t = self.infer(e.operand, node, bound)
            if e.op == "not":
                self.expect_bool(e.operand, t, "not")
                return BOOL
            if not is_numeric(t):
                self.err(e.operand.loc, f"unary '-' needs a number, found {t}")
                raise _Fail
            return REAL if t == REAL else INTEGER
        if isinstance(e, ast.Binary):
            lt, rt = self.infer(e.left, node, bound), self.infer(e.right, node, bound)
            if e.op in ("<=>", "->", "or", "and"):
                self.expect_bool(e.left, lt, e.op)
                self.expect_bool(e.right, rt, e.op)
                return BOOL
            for side, t in ((e.left, lt), (e.right, rt)):
                if not is_numeric(t):
                    self.err(side.loc, f"'{e.op}' needs numbers, found {t}")
                    raise _Fail
            if e.op == "/":
                return REAL
            j = numeric_join(lt, rt)
            assert j is not None
            return INTEGER if (e.op == "-" and j == NATURAL) else j
        if isinstance(e, ast.Compare):
            ts = [self.infer(o, node, bound) for o in e.operands]
            for op, (a, ta), (b, tb) in zip(e.ops, zip(e.operands, ts), zip(e.operands[1:], ts[1:])):
                if op in ("==", "!="):
                    if not comparable(ta, tb):
                        self.err(b.loc, f"cannot compare {ta} with {tb} using '{op}'")
                        raise _Fail
                elif not (is_numeric(ta) and is_numeric(tb)):
                    bad, bt = (a, ta) if not is_numeric(ta) else (b, tb)
                    self.err(bad.loc, f"'{op}' needs numbers, found {bt}")
                    raise _Fail
            return BOOL
        if isinstance(e, ast.Member):
            et = self.infer(e.elem, node, bound)
            st = self.collection(e.collection, node, bound)
            if not (isinstance(st.elem, EmptyT) or comparable(et, st.elem)):
                self.err(e.collection.loc, f"membership of a {et} in a collection of {st.elem}")
                raise _Fail
            return BOOL
        if isinstance(e, (ast.SetLit, ast.SeqLit)):
            elem: Type = EmptyT("{}")
            for it in e.items:
                t = self.infer(it, node, bound)
                if isinstance(elem, EmptyT):
                    elem = t
                elif numeric_join(elem, t) is not None:
                    elem = numeric_join(elem, t)  # type: ignore[assignment]
                elif not comparable(elem, t):
                    self.err(it.loc, f"collection mixes {elem} and {t}")
                    raise _Fail
            return SetT(elem) if isinstance(e, ast.SetLit) else SeqT(elem)
        if isinstance(e, ast.TupleLit):
            return TupleT(tuple(self.infer(i, node, bound) for i in e.items))
        if isinstance(e, ast.StrLit):
            return STRING
        if isinstance(e, ast.SeqRange):
            ts = [self.infer(x, node, bound) for x in (e.lo, e.hi)]
            for x, t in zip((e.lo, e.hi), ts):
                if t not in (NATURAL, INTEGER):
                    self.err(x.loc, f"a bound of '<a upto b>' must be an integer (NATURAL or INTEGER), found {t}")
                    raise _Fail
            return SeqT(NATURAL if ts == [NATURAL, NATURAL] else INTEGER)
        if isinstance(e, ast.TupleQuant):
            et = self.domain(ast.Binding(e.names, e.domain, e.loc), node, bound)
            if not isinstance(et, TupleT) or len(et.elems) != len(e.names):
                self.err(e.domain.loc, f"({', '.join(e.names)}) takes apart tuples of {len(e.names)} components, "
                                       f"but the elements here have type {et}")
                raise _Fail
            inner = dict(bound)
            inner.update(zip(e.names, et.elems))
            self.expect_bool(e.body, self.infer(e.body, node, inner), e.kind)
            return BOOL
        if isinstance(e, ast.Quant):
            inner = dict(bound)
            for bd in e.bindings:
                dt = self.domain(bd, node, bound)
                for nm in bd.names:
                    inner[nm] = dt
            self.expect_bool(e.body, self.infer(e.body, node, inner), e.kind)
            return BOOL
        raise AssertionError(e)  # pragma: no cover

    def expect_bool(self, e: ast.Expr, t: Type, op: str) -> None:
        if t != BOOL:
            self.err(e.loc, f"'{op}' needs a formula (BOOL), found {t}")
            raise _Fail

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
        raise _Fail

    def domain(self, b: ast.Binding, node: CheckedNode | None, bound: Mapping[str, Type]) -> Type:
        d = b.domain
        if isinstance(d, ast.TName) and (product := qualified_base(d.name)) is not None:
            return product
        if isinstance(d, ast.TName) and d.name not in self.types and d.name not in self.type_decls:
            known = d.name in bound or d.name in self.constants or (
                node is not None and (d.name in node.inputs or d.name in node.outputs))
            if not known:
                # An unknown type is reported once, where it is first used
                # (`inputs(c : String)` then `forall(x in String | ...)`).
                if d.name not in self.unknown_types:
                    self.unknown_types.add(d.name)
                    self.err(d.loc, f"unknown type or set {d.name!r}"
                             + _candidates(d.name, list(self.types) + list(self.type_decls) + list(BASE_NAMES)),
                             "E-name")
                raise _Fail
            return self.collection(ast.Var(d.name, None, d.loc), node, bound).elem
        if isinstance(d, (ast.TBase, ast.TName, ast.TEnum, ast.TConstructors, ast.TFunc, ast.TEmpty,
                          ast.TSet, ast.TSeq, ast.TTuple)):
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
            raise _Fail
        self.args(e, ft.args, node, bound, f.qualified)
        return ft.result

    def args(self, e: ast.Apply, params: Sequence[Type], node: CheckedNode | None,
             bound: Mapping[str, Type], what: str) -> None:
        if len(e.args) != len(params):
            self.err(e.loc, f"{what} takes {len(params)} argument(s) ({', '.join(map(str, params))}), given {len(e.args)}", "E-arity")
            raise _Fail
        for a, p in zip(e.args, params):
            at = self.infer(a, node, bound)
            if not assignable(at, p):
                self.err(a.loc, f"argument of {what} must be {p}, found {at}")
                raise _Fail


def _is_enum_constant(d: ast.TypeDecl | ast.ConstDecl, decls: Sequence[ast.TypeDecl | ast.ConstDecl]) -> bool:
    """Whether ``d`` is ``Name = {a, b, c} ;`` (no declared type) whose items
    are all bare names not declared anywhere in the contexts: then the names
    are new enumeration values and ``Name`` is their type."""
    if not (isinstance(d, ast.ConstDecl) and d.type is None and isinstance(d.value, ast.SetLit) and d.value.items):
        return False
    if not all(isinstance(i, ast.Var) and i.prefix is None for i in d.value.items):
        return False
    declared = {x.name for x in decls}
    for x in decls:
        if isinstance(x, ast.TypeDecl) and isinstance(x.type, ast.TEnum):
            declared.update(x.type.values)
        elif isinstance(x, ast.TypeDecl) and isinstance(x.type, ast.TConstructors):
            declared.update(c.name for c in x.type.ctors)
    return not any(i.name in declared for i in d.value.items)  # type: ignore[union-attr]


def check(specs: Sequence[ast.Spec], interface_only: Iterable[str] = ()) -> Checked:
    """Type-check parsed RCL files together (contexts are shared by all files).

    ``interface_only`` names nodes that may be declared with their inputs,
    outputs and topics alone (no assumption, no guarantee): the node whose
    contract ``rclverify quotient`` computes (docs/calculus.md).  Everywhere
    else a node needs a guarantee.
    Returns the :class:`Checked` system; raises :class:`RclError` listing
    every error found (sorted by file, line, column).
    """
    c = _Checker()
    c.with_units = any(getattr(s, "has_units", True) for s in specs)
    c.interface_only = frozenset(interface_only)
    c.contexts(specs)
    nodes: dict[str, CheckedNode] = {}
    seen: dict[str, ast.Loc] = {}
    for s in specs:
        for n in s.nodes:
            if n.name in seen:
                c.err(n.loc, f"node {n.name!r} is already defined at {seen[n.name]}", "E-duplicate")
                continue
            seen[n.name] = n.loc
            cn = c.node(n)
            if cn is not None:
                nodes[n.name] = cn
    if c.diags:
        unique = list(dict.fromkeys(c.diags))
        raise RclError(sorted(unique, key=lambda d: (d.loc.file, d.loc.line, d.loc.col)))
    return Checked(c.env, nodes, tuple(specs))


def check_node_again(specs: Sequence[ast.Spec], n: ast.Node) -> CheckedNode:
    """Type-check the one node ``n`` as :func:`check` would check it among
    ``specs`` (the files of a checked system, ``n`` in place of the node of
    the same name): ``specs``' contexts are resolved again (they do not
    depend on nodes), then ``n`` alone.  For an edit inside one node's
    clauses (the diagnosis's repair checks), whose other nodes the caller
    already holds checked: the cost is that of the contexts and one node,
    not of the system.  Raises :class:`RclError` as :func:`check`
    does for ``n``'s errors."""
    c = _Checker()
    c.with_units = any(getattr(s, "has_units", True) for s in specs)
    c.contexts(specs)
    cn = c.node(n)
    if c.diags or cn is None:
        unique = list(dict.fromkeys(c.diags))
        raise RclError(sorted(unique, key=lambda d: (d.loc.file, d.loc.line, d.loc.col)))
    return cn


def load(paths: Iterable[str | Path]) -> Checked:
    """Parse and type-check RCL files.  Raises :class:`RclError`."""
    return check(parse_files(paths))


def infer(expr: ast.Expr, node: CheckedNode | None, env: Env, bound: Mapping[str, Type] | None = None) -> Type:
    """Type of ``expr`` in ``node``'s scope (plus ``bound`` variables).

    Raises :class:`RclError` when ``expr`` is ill-typed (for formulas that
    did not go through :func:`check`, e.g. plan environment facts).
    """
    c = _Checker()
    c.types, c.constants = dict(env.types), dict(env.constants)
    c.enum_values, c.ctors = dict(env.enum_values), dict(env.ctors)
    try:
        return c.infer(expr, node, bound or {})
    except _Fail:
        raise RclError(c.diags) from None


def domain_type(b: ast.Binding, node: CheckedNode | None, env: Env, bound: Mapping[str, Type] | None = None) -> Type:
    """Element type of the values a quantifier binding ranges over."""
    c = _Checker()
    c.types, c.constants = dict(env.types), dict(env.constants)
    c.enum_values, c.ctors = dict(env.enum_values), dict(env.ctors)
    try:
        return c.domain(b, node, bound or {})
    except _Fail:
        raise RclError(c.diags) from None
