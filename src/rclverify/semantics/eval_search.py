"""The search plan of a ``forall``/``exists`` for direct evaluation: its
guards (the conjuncts left of ``->`` under ``forall``, the conjuncts under
``exists``) staged by the slot that binds their last variable, each slot's
pinning guard (``v == t``, ``move(x, y) == t``: only ``t``'s value is
tried) or preimage guard (``f(x, y) == t``: only the table's keys with that
result), and the joint slots of variables that occur only together.
Functions of the formula alone, memoised per AST node.

Part of the direct evaluator (:mod:`rclverify.semantics.evaluate`, whose module
docstring states the semantics).
"""
from __future__ import annotations

from typing import Any, Mapping, cast

from rclverify.lang import ast

from rclverify.lang import typeexpr
from rclverify.semantics.values import FiniteFunction, Term, Value
from rclverify.semantics.eval_shapes import _STATIC, _conjuncts, _ctor_uses, _free, _only_as, _tuple_apps
from rclverify.semantics.eval_values import _INFINITE, _fit


def _stage(guards: list[Any], slots: list[tuple[str, ...]]) -> list[list[Any]]:
    """Guards grouped by the slot at which their last bound variable is bound."""
    where = {n: k for k, names in enumerate(slots) for n in names}
    staged: list[list[Any]] = [[] for _ in slots]
    for g in guards:
        used: set[str] = set()
        _free(g, set(where), used)
        depth = max((where[n] for n in used), default=0)
        staged[depth].append(g)
    return staged


def _joint_groups(e: ast.Quant, bindings: Mapping[str, ast.Binding], ctors: Any,
                  io: frozenset[str]) -> list[tuple[tuple[str, ...], list[str], list[ast.Apply], frozenset[Any]]]:
    """The candidate joint slots of quantifier ``e`` in the order
    ``Evaluator._joint`` tries them: (variables, their base types, the
    applications using them, the literal argument tuples of constructor
    terms), those that pass the static checks (:func:`_only_as`,
    :func:`_ctor_uses`).  A function of the formula alone, memoised per AST
    node (the dynamic part, the function tables, is read per evaluation)."""
    key = (id(e), "", "joint")
    hit = _STATIC.get(key)
    if hit is not None and hit[0] is e:
        return cast("list[tuple[tuple[str, ...], list[str], list[ast.Apply], frozenset[Any]]]", hit[1])
    out = []
    apps: list[ast.Apply] = []
    _tuple_apps(e.body, set(e.variables), apps)
    for first in apps:
        group = tuple(a.name for a in first.args if isinstance(a, ast.Var))
        if len(group) < 2 or len(set(group)) != len(group):
            continue
        kinds: list[str] = []
        for n in group:
            dom = bindings[n].domain
            if not (isinstance(dom, typeexpr.TBase) and dom.name in _INFINITE):
                break
            kinds.append(dom.name)
        else:
            uses: list[ast.Apply] = []
            if not _only_as(e.body, group, uses):
                continue
            literal_keys = _ctor_uses(e.body, frozenset(group), ctors, io)
            if literal_keys is None:
                continue
            out.append((group, kinds, uses, literal_keys))
    _STATIC[key] = (e, out)
    return out


def _preimage_group(e: ast.Quant, bindings: Mapping[str, ast.Binding], ctors: Any) -> tuple[str, ...] | None:
    """Two or more variables of ``forall``/``exists`` ``e`` that a guard
    ``f(v1, ..., vk) == t`` names as the whole argument list of a function
    (not a constructor; ``t`` free of them; each over REAL, INTEGER or
    NATURAL): one slot, enumerated through that guard's preimage
    (:class:`_Preimage`).  Memoised per AST node."""
    key = (id(e), "", "preimage")
    hit = _STATIC.get(key)
    if hit is not None and hit[0] is e:
        return cast("tuple[str, ...] | None", hit[1])
    found: tuple[str, ...] | None = None
    for side, other in _equalities(_guards(e)):
        names = _function_args(side, ctors, bindings)
        if (names is None or len(names) < 2 or len(set(names)) != len(names)
                or not all(n in bindings and isinstance(bindings[n].domain, typeexpr.TBase)
                           and cast(typeexpr.TBase, bindings[n].domain).name in _INFINITE for n in names)):
            continue
        used: set[str] = set()
        _free(other, set(names), used)
        if not used:
            found = names
            break
    _STATIC[key] = (e, found)
    return found


def _plan(e: ast.Quant, slots: list[tuple[str, ...]], ctors: Any) -> tuple[list[list[Any]], list[Any]]:
    """The search plan of ``forall``/``exists`` ``e`` over ``slots``: its guards
    staged by slot (:func:`_stage`) and each slot's pinning guard
    (:func:`_pin`).  A function of the formula and the slots' layout only,
    memoised per (AST node, layout)."""
    key = (id(e), repr(slots), "plan")
    hit = _STATIC.get(key)
    if hit is not None and hit[0] is e:
        return cast("tuple[list[list[Any]], list[Any]]", hit[1])
    staged = _stage(_guards(e), slots)
    bindings = {n: bd for bd in e.bindings for n in bd.names}
    pins = [_pin(staged[k], names, bindings, ctors) for k, names in enumerate(slots)]
    _STATIC[key] = (e, (staged, pins))
    return staged, pins


class _Pin:
    """A guard ``slot == term`` that fixes a slot's values (see ``Evaluator._search``)."""

    __slots__ = ("term", "ctor", "kinds")

    def __init__(self, term: Any, ctor: str | None, kinds: tuple[str, ...]) -> None:
        self.term, self.ctor, self.kinds = term, ctor, kinds

    def values(self, v: Any) -> list[tuple[Any, ...]]:
        """The slot's only candidate tuple given the term's value ``v`` (or none)."""
        if self.ctor is None:
            args: tuple[Any, ...] = (v,)
        else:
            if not isinstance(v, Term) or v.name != self.ctor or len(v.args) != len(self.kinds):
                return []
            args = v.args
        out = []
        for a, kind in zip(args, self.kinds):
            ok, a2 = _fit(a, kind)
            if not ok:
                return []
            out.append(a2)
        return [tuple(out)]


def _pin(guards: list[Any], names: tuple[str, ...], bindings: Mapping[str, ast.Binding],
         ctors: Any) -> _Pin | _Preimage | None:
    """A guard among ``guards`` of the form ``n == t`` (one variable of REAL/INTEGER/NATURAL)
    or ``c(n1, ..., nk) == t`` (constructor ``c``, the slot's variables in order), ``t`` not
    mentioning them; failing that, ``f(n1, ..., nk) == t`` (``f`` a function value:
    :class:`_Preimage`)."""
    kinds = []
    for n in names:
        dom = bindings[n].domain
        if not (isinstance(dom, typeexpr.TBase) and dom.name in _INFINITE):
            return None
        kinds.append(dom.name)
    equalities = _equalities(guards)
    for side, other in equalities:
        ctor: str | None = None
        if len(names) == 1 and isinstance(side, ast.Var) and side.prefix is None and side.name == names[0]:
            pass
        elif (isinstance(side, ast.Apply) and side.func.prefix is None and side.func.name in ctors
              and len(side.args) == len(names)
              and all(isinstance(a, ast.Var) and a.prefix is None and a.name == n
                      for a, n in zip(side.args, names))):
            ctor = side.func.name
        else:
            continue
        used: set[str] = set()
        _free(other, set(names), used)
        if not used:
            return _Pin(other, ctor, tuple(kinds))
    for side, other in equalities:
        if _function_args(side, ctors, names) == names:
            used = set()
            _free(other, set(names), used)
            if not used:
                return _Preimage(cast(ast.Apply, side).func, other, tuple(kinds))
    return None


def _guards(e: ast.Quant) -> list[Any]:
    """The guards of ``forall``/``exists`` ``e``: the conjuncts left of ``->``
    under ``forall``, the conjuncts of the body under ``exists``; none else."""
    if e.kind == "forall" and isinstance(e.body, ast.Binary) and e.body.op == "->":
        return _conjuncts(e.body.left)
    return _conjuncts(e.body) if e.kind == "exists" else []


def _equalities(guards: list[Any]) -> list[tuple[Any, Any]]:
    """``(side, other)`` for each guard ``a == b``, both ways round."""
    out = []
    for g in guards:
        if isinstance(g, ast.Compare) and tuple(g.ops) == ("==",):
            left, right = g.operands
            out += [(left, right), (right, left)]
    return out


def _function_args(side: Any, ctors: Any, bound: Any) -> tuple[str, ...] | None:
    """The variable names of ``side`` when it applies a function value (not a
    constructor, not a name in ``bound``) to bare variables only, else None."""
    if not isinstance(side, ast.Apply) or (side.func.prefix is None and (side.func.name in ctors
                                                                         or side.func.name in bound)):
        return None
    if not all(isinstance(a, ast.Var) and a.prefix is None for a in side.args):
        return None
    return tuple(cast(ast.Var, a).name for a in side.args)


class _Preimage:
    """A guard ``f(n1, ..., nk) == t`` (``f`` a function value, the slot's
    variables in order, ``t`` free of them): when ``f`` is a finite table
    whose default differs from ``t``'s value, only the table's keys with that
    result pass the guard, so only they are enumerated (``Evaluator._search``);
    otherwise the slot's own candidates are."""

    __slots__ = ("func", "term", "kinds")

    def __init__(self, func: ast.Var, term: Any, kinds: tuple[str, ...]) -> None:
        self.func, self.term, self.kinds = func, term, kinds

    def keys(self, ev: Any, cur: Mapping[str, Value]) -> list[tuple[Any, ...]] | None:
        """The slot's candidate tuples under ``cur``, or None (use its domain)."""
        f = ev.var(self.func, cur)
        if not isinstance(f, FiniteFunction) or f.arity != len(self.kinds):
            return None
        v = ev.eval(self.term, cur)
        if f.default == v:
            return None
        out = []
        for key, r in f.table.items():
            if r != v:
                continue
            fitted = []
            for a, kind in zip(key, self.kinds):
                ok, a2 = _fit(a, kind)
                if not ok:
                    break
                fitted.append(a2)
            else:
                out.append(tuple(fitted))
        return out
