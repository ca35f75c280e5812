"""Quantifiers in Dafny: ``forall``/``exists``/``exists_unique`` over types,
set and sequence terms and tuples, and the finite expansion of quantifiers over
literal collections.

:class:`QuantifierTranslation` is the part of
:class:`rclverify.targets.dafny.translate.Translator` that binds variables:

* ``forall(x', y' in REAL, i in NATURAL | P)`` ->
  ``(forall x': real, y': real, i: nat :: P)``; a binding over a set term adds
  ``x in S`` as guard (``==>`` under ``forall``, ``&&`` under ``exists``);
* a quantifier all of whose bindings range over set or sequence literals is
  expanded into the conjunction/disjunction of its instances (at most
  :data:`EXPANSION_LIMIT`);
* ``exists_unique(xs | P)`` -> ``(exists xs :: P && (forall ys :: P[ys] ==>
  ys == xs))``; a binding over the empty type ``{}`` makes ``forall`` true and
  ``exists`` false (as in the Z3 encoding, :mod:`rclverify.semantics.encode`);
* a bound variable gets a Dafny-safe name that captures no parameter, constant
  or datatype value (:func:`.types.dafny_ident`).

Quantifying over functions raises a located
:class:`~rclverify.model.plan.errors.PlanError`.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any, Mapping, cast

from rclverify.lang import ast
from rclverify.lang import typeexpr
from rclverify.lang.errors import error
from rclverify.lang.printer import is_type
from rclverify.lang.typecheck import domain_type
from rclverify.lang.types import CheckedNode, EmptyT, Env, FuncT, TupleT, Type
from rclverify.model.plan.errors import PlanError
from rclverify.targets.dafny.text import wrap
from rclverify.targets.dafny.types import dafny_ident, dafny_type

#: Largest number of instances a quantifier over literal collections is expanded into.
EXPANSION_LIMIT = 64


@dataclass
class Bound:
    """A bound variable in scope: its Dafny text (a name, or ``u_v.0`` for a
    tuple's part) and its RCL type."""

    dafny: str
    type: Type


class QuantifierTranslation(ABC):
    """The quantifier half of the translator, mixed into
    :class:`~rclverify.targets.dafny.translate.Translator`, which supplies the
    attributes and the methods declared here (the term translation
    :meth:`tr`, set membership :meth:`member`, the numeric join :meth:`_join`
    and the names already in scope)."""

    env: Env
    node: CheckedNode
    used_types: list[Type]

    @staticmethod
    def _err(loc: ast.Loc, msg: str) -> PlanError:
        return PlanError([error(loc, msg, "E-dafny")])

    @abstractmethod
    def tr(self, e: ast.Expr, scope: Mapping[str, Bound]) -> tuple[str, Type]:
        """``(text, type)`` of ``e``: the host's term translation."""

    @abstractmethod
    def member(self, elem: tuple[str, Type], coll: ast.Expr, scope: Mapping[str, Bound]) -> str:
        """Dafny text of ``elem in coll``: the host's membership translation."""

    @abstractmethod
    def _join(self, items: list[tuple[str, Type]]) -> tuple[list[str], Type]:
        """The items' texts joined at one numeric type, and that type: the host's."""

    @abstractmethod
    def _names_in_scope(self, scope: Mapping[str, Bound]) -> set[str]:
        """The Dafny names the bound variables of ``scope`` take: the host's."""

    @abstractmethod
    def _value_names(self) -> set[str]:
        """The parameters', constants' and datatype values' names: the host's."""

    def tuple_quant(self, e: ast.TupleQuant, scope: Mapping[str, Bound]) -> str:
        """``Q((u, v) in S | body)``: one Dafny variable ``u_v`` of the tuple
        type, ``u`` and ``v`` read as ``u_v.0`` and ``u_v.1``, guarded by
        ``u_v in S`` unless ``S`` is a tuple type."""
        rcl_bound = {k: b.type for k, b in scope.items()}
        t = domain_type(ast.Binding(("_tuple",), e.domain, e.loc), self.node, self.env, rcl_bound)
        if isinstance(t, EmptyT):
            return "true" if e.kind == "forall" else "false"
        if not isinstance(t, TupleT) or len(t.elems) != len(e.names):
            raise self._err(e.loc, f"{len(e.names)} names cannot take apart an element of type {t}")
        dt = dafny_type(t, e.loc, f"the domain of ({', '.join(e.names)})")
        if t not in self.used_types:
            self.used_types.append(t)
        coll = self._domain_collection(e.domain)
        taken = self._names_in_scope(scope) | self._value_names()

        def parts(var: str) -> tuple[str, str]:
            inner = dict(scope)
            inner.update({nm: Bound(f"{var}.{k}", ct) for k, (nm, ct) in enumerate(zip(e.names, t.elems))})
            guard = self.member((var, t), coll, scope) if coll is not None else ""
            body = self.tr(e.body, inner)[0]
            return guard, body

        d = dafny_ident("_".join(e.names), taken)
        guard, body = parts(d)
        if e.kind == "forall":
            return f"(forall {d}: {dt} :: {guard} ==> {body})" if guard else f"(forall {d}: {dt} :: {body})"
        core = f"{guard} && {body}" if guard else body
        if e.kind == "exists":
            return f"(exists {d}: {dt} :: {core})"
        y = dafny_ident(f"{d}_u", taken | {d})
        yguard, ybody = parts(y)
        ycore = f"{yguard} && {ybody}" if yguard else ybody
        return f"(exists {d}: {dt} :: {core} && (forall {y}: {dt} :: ({ycore}) ==> ({y} == {d})))"

    def _domain_collection(self, domain: Any) -> ast.Expr | None:
        """The collection a quantifier domain stands for, or ``None`` for a type."""
        if not is_type(domain):
            return cast(ast.Expr, domain)
        if isinstance(domain, typeexpr.TName) and domain.name not in self.env.types:
            return ast.Var(domain.name, None, domain.loc)
        return None


    def _expand_literal(self, e: ast.Quant, scope: Mapping[str, Bound]) -> str | None:
        """``forall``/``exists`` whose every binding ranges over a set or sequence
        literal, as a finite conjunction/disjunction of instances (at most
        :data:`EXPANSION_LIMIT`).  Equivalent to the guarded quantifier, and
        gives Dafny nothing to trigger on to get wrong.  ``None`` otherwise."""
        if e.kind == "exists_unique" or not all(isinstance(b.domain, (ast.SetLit, ast.SeqLit)) for b in e.bindings):
            return None
        choices: list[list[tuple[str, str, Type]]] = []  # per bound name: (rcl name, text, type) options
        for bd in e.bindings:
            coll = bd.domain
            assert isinstance(coll, (ast.SetLit, ast.SeqLit))
            texts, t = self._join([self.tr(i, scope) for i in coll.items])
            for nm in bd.names:
                choices.append([(nm, wrap(x), t) for x in texts])
        total = 1
        for c in choices:
            total *= len(c)
        if total > EXPANSION_LIMIT:
            return None
        if total == 0:
            return "true" if e.kind == "forall" else "false"
        instances: list[str] = []

        def walk(k: int, sc: dict[str, Bound]) -> None:
            if k == len(choices):
                instances.append(self.tr(e.body, sc)[0])
                return
            for nm, text, t in choices[k]:
                walk(k + 1, {**sc, nm: Bound(text, t)})

        walk(0, dict(scope))
        joiner = " && " if e.kind == "forall" else " || "
        return "(" + joiner.join(instances) + ")"

    def quant(self, e: ast.Quant, scope: Mapping[str, Bound]) -> str:
        expanded = self._expand_literal(e, scope)
        if expanded is not None:
            return expanded
        inner = dict(scope)
        decls: list[str] = []
        guards: list[str] = []
        news: list[tuple[str, str, Type, str]] = []  # (rcl name, dafny name, type, dafny type)
        rcl_bound = {k: b.type for k, b in scope.items()}
        for bd in e.bindings:
            t = domain_type(bd, self.node, self.env, rcl_bound)
            if isinstance(t, EmptyT):
                return "true" if e.kind == "forall" else "false"
            if isinstance(t, FuncT):
                raise self._err(bd.loc, f"quantifying over functions ({', '.join(bd.names)} in {t}) cannot be "
                                        "expressed in the Dafny contract stub")
            dt = dafny_type(t, bd.loc, f"the domain of {', '.join(bd.names)}")
            if t not in self.used_types:
                self.used_types.append(t)
            coll = self._domain_collection(bd.domain)
            for nm in bd.names:
                taken = self._names_in_scope(inner) | self._value_names()
                d = dafny_ident(nm, taken)
                decls.append(f"{d}: {dt}")
                news.append((nm, d, t, dt))
                inner[nm] = Bound(d, t)
                if coll is not None:
                    guards.append(self.member((d, t), coll, scope))
                rcl_bound[nm] = t
        body, bt = self.tr(e.body, inner)
        guard = " && ".join(guards)
        binders = ", ".join(decls)
        if e.kind == "forall":
            return f"(forall {binders} :: {guard} ==> {body})" if guard else f"(forall {binders} :: {body})"
        core = f"{guard} && {body}" if guard else body
        if e.kind == "exists":
            return f"(exists {binders} :: {core})"
        # exists_unique: the tuple of bound values is unique
        again = dict(scope)
        ydecls, yguards, eqs = [], [], []
        taken = self._names_in_scope(inner) | self._value_names()
        for nm, d, t, dt in news:
            y = dafny_ident(f"{d}_u", taken)
            taken.add(y)
            again[nm] = Bound(y, t)
            ydecls.append(f"{y}: {dt}")
            eqs.append(f"({y} == {d})")
        for bd in e.bindings:
            coll = self._domain_collection(bd.domain)
            if coll is not None:
                for nm in bd.names:
                    yguards.append(self.member((again[nm].dafny, again[nm].type), coll, scope))
        ybody, _ = self.tr(e.body, again)
        ycore = " && ".join(yguards + [ybody])
        unique = f"(forall {', '.join(ydecls)} :: ({ycore}) ==> ({' && '.join(eqs)}))"
        return f"(exists {binders} :: {core} && {unique})"
