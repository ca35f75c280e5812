"""How the RCL side of a mapping row matches a guarantee (:mod:`.mapping`'s docstring):
both in canonical form (:mod:`.canon`), a row's domain variables match
integer terms and take their values, its other variables match the
guarantee's quantified variables one to one, everything else matches only
itself; ``==``, ``+``, ``*``, the connectives and set literals match in any
order.  Structural matching of two atoms is a visitor over the row atom's
class (:mod:`rclverify.lang.visit`).
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass, replace
from typing import Any, Iterable, Iterator, Mapping, Sequence

from rclverify.lang import ast
from rclverify.lang.visit import Visitor
from rclverify.targets.ajpf.canon import FAnd, FConst, FLit, FOr, Form, FQuant, eval_int

@dataclass(frozen=True)
class State:
    """Bindings of one row application: domain variables to values, the row's
    other variables to the guarantee's variables (one-to-one)."""

    dom: tuple[tuple[str, int], ...] = ()
    bvar: tuple[tuple[str, str], ...] = ()

    @property
    def values(self) -> dict[str, int]:
        return dict(self.dom)

    @property
    def renaming(self) -> dict[str, str]:
        return dict(self.bvar)

    def bind_dom(self, name: str, value: int) -> "State | None":
        cur = self.values
        if name in cur:
            return self if cur[name] == value else None
        return replace(self, dom=tuple(sorted({**cur, name: value}.items())))

    def bind_var(self, name: str, target: str) -> "State | None":
        cur = self.renaming
        if name in cur:
            return self if cur[name] == target else None
        if target in cur.values():
            return None
        return replace(self, bvar=tuple(sorted({**cur, name: target}.items())))

    def unbind(self, names: Iterable[str]) -> "State":
        drop = set(names)
        return replace(self, bvar=tuple((k, v) for k, v in self.bvar if k not in drop))


@dataclass(frozen=True)
class MatchContext:
    """What a row's names mean while matching against one guarantee instance.

    ``dom_names``  domain variable names (``i``), pattern variables over values;
    ``fixed``      names that match only themselves (enumeration values,
                   constants, argument-less constructors);
    ``values``     the instance: domain variable -> value;
    ``targets``    the guarantee's variables a row variable may stand for.
    """

    dom_names: frozenset[str]
    fixed: frozenset[str]
    values: Mapping[str, int]
    targets: frozenset[str]

    def with_targets(self, extra: Iterable[str]) -> "MatchContext":
        return replace(self, targets=self.targets | frozenset(extra))


def match_expr(p: ast.Expr, t: ast.Expr, st: State, cx: MatchContext) -> Iterator[State]:
    """All ways the row term/atom ``p`` matches the guarantee term ``t``."""
    if isinstance(p, ast.Var) and p.prefix is None:
        if p.name in cx.dom_names:
            v = eval_int(t, cx.values)
            if v is not None:
                s = st.bind_dom(p.name, v)
                if s is not None:
                    yield s
            return
        if p.name in cx.fixed:
            if isinstance(t, ast.Var) and t.prefix is None and t.name == p.name:
                yield st
            return
        if isinstance(t, ast.Var) and t.prefix is None and t.name in cx.targets:
            s = st.bind_var(p.name, t.name)
            if s is not None:
                yield s
        return
    if isinstance(p, ast.Var):
        if isinstance(t, ast.Var) and t.prefix == p.prefix and t.name == p.name:
            yield st
        return
    if isinstance(p, (ast.NumLit, ast.Binary, ast.Unary)) and not _has_formula(p):
        found = False
        for s in _STRUCT.visit(p, t, st, cx):
            found = True
            yield s
        if not found:
            pv, tv = eval_int(p, st.values), eval_int(t, cx.values)
            if pv is not None and pv == tv:
                yield st
        return
    yield from _STRUCT.visit(p, t, st, cx)


def _has_formula(e: ast.Expr) -> bool:
    return isinstance(e, ast.Unary) and e.op == "not" or isinstance(e, ast.Binary) and e.op in (
        "and", "or", "->", "<=>")


def _match_seq(ps: Sequence[ast.Expr], ts: Sequence[ast.Expr], st: State, cx: MatchContext) -> Iterator[State]:
    if len(ps) != len(ts):
        return
    if not ps:
        yield st
        return
    for s in match_expr(ps[0], ts[0], st, cx):
        yield from _match_seq(ps[1:], ts[1:], s, cx)


_Match = Iterator[State]


class _Structural(Visitor[_Match]):
    """The ways row atom ``p`` matches guarantee atom ``t`` of the same class,
    node for node (a class without a method here never matches)."""

    def visit(self, p: Any, *args: Any) -> _Match:
        if type(p) is not type(args[0]):
            return iter(())
        return super().visit(p, *args)

    def generic_visit(self, p: Any, t: Any, st: State, cx: MatchContext) -> _Match:
        return iter(())

    def visit_BoolLit(self, p: ast.BoolLit, t: ast.BoolLit, st: State, cx: MatchContext) -> _Match:
        if p.value == t.value:
            yield st

    def visit_NumLit(self, p: ast.NumLit, t: ast.NumLit, st: State, cx: MatchContext) -> _Match:
        if p.value == t.value:
            yield st

    def visit_Apply(self, p: ast.Apply, t: ast.Apply, st: State, cx: MatchContext) -> _Match:
        if p.func.qualified == t.func.qualified:
            yield from _match_seq(p.args, t.args, st, cx)

    def visit_Unary(self, p: ast.Unary, t: ast.Unary, st: State, cx: MatchContext) -> _Match:
        if p.op == t.op:
            yield from match_expr(p.operand, t.operand, st, cx)

    def visit_Binary(self, p: ast.Binary, t: ast.Binary, st: State, cx: MatchContext) -> _Match:
        if p.op == t.op:
            yield from _match_seq((p.left, p.right), (t.left, t.right), st, cx)
            if p.op in ("+", "*", "and", "or", "<=>"):
                yield from _match_seq((p.left, p.right), (t.right, t.left), st, cx)

    def visit_Compare(self, p: ast.Compare, t: ast.Compare, st: State, cx: MatchContext) -> _Match:
        if p.ops == t.ops:
            yield from _match_seq(p.operands, t.operands, st, cx)
            if p.ops in (("==",), ("!=",)):
                yield from _match_seq(p.operands, tuple(reversed(t.operands)), st, cx)

    def visit_Member(self, p: ast.Member, t: ast.Member, st: State, cx: MatchContext) -> _Match:
        if p.negated == t.negated:
            yield from _match_seq((p.elem, p.collection), (t.elem, t.collection), st, cx)

    def visit_SetLit(self, p: ast.SetLit, t: ast.SetLit, st: State, cx: MatchContext) -> _Match:
        if len(p.items) == len(t.items) and len(p.items) <= 6:
            for perm in itertools.permutations(t.items):
                yield from _match_seq(p.items, perm, st, cx)

    def visit_TupleLit(self, p: ast.TupleLit, t: ast.TupleLit, st: State, cx: MatchContext) -> _Match:
        yield from _match_seq(p.items, t.items, st, cx)

    def visit_SeqLit(self, p: ast.SeqLit, t: ast.SeqLit, st: State, cx: MatchContext) -> _Match:
        yield from _match_seq(p.items, t.items, st, cx)

    def visit_Quant(self, p: ast.Quant, t: ast.Quant, st: State, cx: MatchContext) -> _Match:
        pv, tv = p.variables, t.variables
        if p.kind == t.kind and len(pv) == len(tv) and _domains(p) == _domains(t):
            inner = cx.with_targets(tv)
            for s in match_expr(p.body, t.body, st, inner):
                ren = s.renaming
                if all(ren.get(n, None) in tv for n in pv if n in ren):
                    yield s.unbind(pv)


_STRUCT = _Structural()


def _domains(q: ast.Quant) -> tuple[Any, ...]:
    return tuple(b.domain for b in q.bindings for _ in b.names)


def match_form(p: Form, t: Form, st: State, cx: MatchContext) -> Iterator[State]:
    """All ways the row form ``p`` matches the guarantee form ``t``."""
    if isinstance(p, FConst):
        if p == t:
            yield st
    elif isinstance(p, FLit):
        if isinstance(t, FLit) and p.positive == t.positive:
            yield from match_expr(p.atom, t.atom, st, cx)
    elif isinstance(p, (FAnd, FOr)):
        if isinstance(t, (FAnd, FOr)) and type(p) is type(t) and len(p.parts) == len(t.parts) <= 6:
            for perm in itertools.permutations(t.parts):
                yield from _match_forms(p.parts, perm, st, cx)
    elif isinstance(p, FQuant):
        if (isinstance(t, FQuant) and p.kind == t.kind and len(p.names) == len(t.names)
                and sorted(map(repr, p.domains)) == sorted(map(repr, t.domains))):
            inner = cx.with_targets(t.names)
            for s in match_form(p.body, t.body, st, inner):
                ren = s.renaming
                if all(ren[n] in t.names for n in p.names if n in ren):
                    yield s.unbind(p.names)


def _match_forms(ps: Sequence[Form], ts: Sequence[Form], st: State, cx: MatchContext) -> Iterator[State]:
    if not ps:
        yield st
        return
    for s in match_form(ps[0], ts[0], st, cx):
        yield from _match_forms(ps[1:], ts[1:], s, cx)
