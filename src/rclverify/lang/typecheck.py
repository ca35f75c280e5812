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

from pathlib import Path
from typing import Iterable, Mapping, Sequence

from rclverify.lang import ast, lifecycle, liveness, timing

from rclverify.lang import typeexpr
from rclverify.lang.errors import RclError
from rclverify.lang.typecheck_expr import CheckFailed, ExprChecker
from rclverify.lang.types import BOOL, Checked, CheckedNode, Env, Type, assignable


class _Checker(ExprChecker):
    """Checks a system's declarations and nodes (expressions: :class:`ExprChecker`)."""

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
                self.type_decls[d.name] = ast.TypeDecl(d.name, typeexpr.TEnum(items, d.value.loc), d.loc)
        for d in decls:
            if isinstance(d, ast.TypeDecl) and self.type_decls.get(d.name) is d:
                try:
                    self.declare_type(d)
                except CheckFailed:
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
                except CheckFailed:
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
                except CheckFailed:
                    self.failed_io.add((prefix, v.name))
                    ok = False
        typed = {f"in.{k}": t for k, t in inputs.items()} | {f"out.{k}": t for k, t in outputs.items()}
        cn = CheckedNode(n, inputs, outputs, self.units.declare(n, typed))
        for where, name, at in ([("topic", t.field, t.name_loc if t.name_loc.line else t.loc) for t in n.topics]
                                + [(lk.kind, lk.name, lk.name_loc if lk.name_loc.line else lk.loc)
                                   for lk in n.links]):
            if name.startswith("~"):
                self.err(at, f"{where} {name}: a private name resolves against the running node's own name, "
                             f"which a contract does not give (the monitors could not find it); write the "
                             f"resolved name, e.g. /<node name>{name[1:]}, or a relative one, {name[2:]}",
                         "E-topic-name")
                ok = False
        for t in n.topics:
            if t.match is not None:
                try:
                    self.var(t.match, cn, {})
                except CheckFailed:
                    ok = False
        if n.links and not timing.check_links(n, self.err):
            ok = False
        for cl in n.guarantees:
            if (cl.trigger is not None or cl.deadline is not None) and not timing.check_clause(n, cl, self.err):
                ok = False
        if (n.transitions or any(cl.scope is not None for cl in n.guarantees)) and not lifecycle.check_node(
                n, self.err, timing.seconds):
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
            except CheckFailed:
                ok = False
        return cn if ok else None



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
        if isinstance(x, ast.TypeDecl) and isinstance(x.type, typeexpr.TEnum):
            declared.update(x.type.values)
        elif isinstance(x, ast.TypeDecl) and isinstance(x.type, typeexpr.TConstructors):
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
    from rclverify.lang.parser import parse_files  # deferred: start-up (loads lark; checking parsed contracts needs no parser)
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
    except CheckFailed:
        raise RclError(c.diags) from None


def domain_type(b: ast.Binding, node: CheckedNode | None, env: Env, bound: Mapping[str, Type] | None = None) -> Type:
    """Element type of the values a quantifier binding ranges over."""
    c = _Checker()
    c.types, c.constants = dict(env.types), dict(env.constants)
    c.enum_values, c.ctors = dict(env.enum_values), dict(env.ctors)
    try:
        return c.domain(b, node, bound or {})
    except CheckFailed:
        raise RclError(c.diags) from None
