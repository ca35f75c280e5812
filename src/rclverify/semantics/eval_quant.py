"""Quantifiers of direct evaluation: each variable's candidate values
(its finite domain, a literal integer range, the values the environment
and the formula mention plus one fresh value, a joint slot's table keys)
and the search over them with guards checked as soon as their variables
are bound (:class:`QuantifierEvaluation`, a base of
:class:`rclverify.semantics.evaluator.Evaluator`).

Part of the direct evaluator (:mod:`rclverify.semantics.evaluate`, whose module
docstring states which quantifiers are decided and how).
"""
from __future__ import annotations

import itertools
from fractions import Fraction
from typing import TYPE_CHECKING, Any, Mapping

from rclverify.lang import ast

from rclverify.lang import typeexpr
from rclverify.lang import types as T
from rclverify.semantics.values import FiniteFunction, Term, Value
from rclverify.semantics.eval_search import _Pin, _Preimage, _joint_groups, _plan, _preimage_group
from rclverify.semantics.eval_shapes import _children, _ctor_uses, _integer_range, _shift, _static_literals, _static_shifts, _unused
from rclverify.semantics.eval_values import _INFINITE, Undecided, _Fresh, _NoDomain, _fits


class QuantifierEvaluation:
    """The quantifier half of :class:`~rclverify.semantics.evaluator.Evaluator`
    (its attributes ``env``, ``node``, ``values``, ``io_names``, ``_slots``,
    ``uncacheable`` and its methods ``eval``, ``var``, ``io``, ``numbers``,
    ``collection`` are used here)."""

    env: Any
    node: Any
    values: Mapping[str, object]
    io_names: frozenset[str]
    uncacheable: bool
    _slots: dict[int, Any]

    if TYPE_CHECKING:  # provided by the evaluator
        def eval(self, e: ast.Expr, b: Mapping[str, Value]) -> Any: ...

        def var(self, v: ast.Var, bound: Mapping[str, Value]) -> Any: ...

        def io(self, v: ast.Var) -> Any: ...

        def numbers(self) -> set[Any]: ...

        def collection(self, e: Any, b: Mapping[str, Value]) -> Any: ...

    def domain(self, binding: ast.Binding, name: str, body: ast.Expr, b: Mapping[str, Value],
               kind: str = "forall", qvars: tuple[str, ...] = ()) -> list[Any]:
        dom = binding.domain
        if isinstance(dom, typeexpr.TBase):
            base = dom.name
            typ: Any = T.Scalar(base) if base in _INFINITE or base == "BOOL" else None
        elif isinstance(dom, typeexpr.TName):
            typ = self.env.types.get(dom.name)
        elif isinstance(dom, typeexpr.TEnum):
            return list(dom.values)
        elif isinstance(dom, typeexpr.TypeExpr.__args__):  # type: ignore[attr-defined]
            raise Undecided(f"quantifier over a {type(dom).__name__} domain")
        else:
            return list(self.collection(dom, b))
        if isinstance(typ, T.EnumT):
            return list(typ.values)
        if isinstance(typ, T.Scalar) and typ.name == "BOOL":
            return [False, True]
        if isinstance(typ, T.Scalar):
            bounded = _integer_range(body, name, typ.name, kind)
            if bounded is not None:
                return bounded
            return self.candidates(name, typ.name, body, b, qvars)
        raise Undecided(f"quantifier over {dom} is not finite")

    def candidates(self, name: str, scalar: str, body: ast.Expr, b: Mapping[str, Value],
                   qvars: tuple[str, ...] = ()) -> list[Any]:
        found_shifts = _static_shifts(body, name, frozenset(qvars))
        if found_shifts is not None and _ctor_uses(body, frozenset({name}), self.env.ctors, self.io_names) is None:
            raise Undecided(f"{name} is an argument of a constructor term compared with a term whose value is "
                            f"not an input or output value, a function's result or a literal term")
        if found_shifts is None:
            raise Undecided(f"{name} ranges over {scalar} and is used outside equalities (with a literal, an "
                            f"I/O value, a function's result or an outer variable) and arguments")
        shifts, refs = found_shifts
        shifts.add(Fraction(0))
        base: set[Any] = set(self.numbers()) | _static_literals(body)
        for r in refs:  # outer bound variables and named constants the variable is compared with
            if r in b:
                self.uncacheable = True
                v = b[r]
                base.add(v.value if isinstance(v, _Fresh) else v)
            elif r in self.env.constants:
                base.add(self.eval(self.env.constants[r][1], {}))
        base = {v for v in base if not isinstance(v, bool) and isinstance(v, (int, float, Fraction))}
        local: set[Any] = set()
        if self._positional(body, name, b, local):
            found = _static_literals(body)
            raw = {v for v in local if not isinstance(v, bool) and isinstance(v, (int, float, Fraction))}
            raw |= {v - k if k else v for v in found for k in shifts}
        else:
            raw = {v - k if k else v for v in base for k in shifts}
        cands: set[Any] = set()
        for c in raw:
            if scalar != "REAL":
                if isinstance(c, float):
                    if not c.is_integer():
                        continue
                elif not isinstance(c, int) and Fraction(c).denominator != 1:
                    continue
                c = int(c)
                if scalar == "NATURAL" and c < 0:
                    continue
            cands.add(c)
        top = max(base | cands, default=0)
        fresh_value: Any = int(top + 2 * max((abs(k) for k in shifts), default=0)) + 1
        return sorted(cands) + [_Fresh(fresh_value)]

    def _terms(self, ctor: str) -> list[Term]:
        out: list[Term] = []

        def walk(v: Any) -> None:
            if isinstance(v, Term):
                if v.name == ctor:
                    out.append(v)
                for a in v.args:
                    walk(a)
            elif isinstance(v, FiniteFunction):
                for res in v.table.values():
                    walk(res)
                walk(v.default)
            elif isinstance(v, (tuple, frozenset)):
                for a in v:
                    walk(a)
        for v in self.values.values():
            walk(v)
        return out

    def _results(self, e: Any, b: Mapping[str, Value]) -> set[Any] | None:
        """Every value ``e`` can take whatever the bound variables are, when known."""
        if isinstance(e, ast.NumLit):
            return {e.value}
        if isinstance(e, ast.Var) and (e.prefix is not None or e.name in self.node.inputs
                                       or e.name in self.node.outputs) and e.name not in b:
            v = self.io(e)
            return {v} if not isinstance(v, FiniteFunction) else None
        if isinstance(e, ast.Apply) and e.func.name not in self.env.ctors:
            f = self.var(e.func, b)
            if isinstance(f, FiniteFunction):
                return set(f.table.values()) | {f.default}
        return None

    def _positional(self, e: Any, name: str, b: Mapping[str, Value], vals: set[Any]) -> bool:
        """Collect the only values ``name`` can take to make an atom differ from a
        fresh value; False when some occurrence gives no such bound."""
        if isinstance(e, ast.Quant) and name in e.variables:
            return True
        if isinstance(e, ast.Apply):
            for p, a in enumerate(e.args):
                k = _shift(a, name)
                if k is None:
                    if not self._positional(a, name, b, vals):
                        return False
                    continue
                if e.func.prefix is None and e.func.name in self.env.ctors and e.func.name not in b:
                    vals.update((t.args[p] - k if k else t.args[p]) for t in self._terms(e.func.name)
                                if p < len(t.args) and isinstance(t.args[p], (int, float, Fraction)))
                    continue
                f = self.var(e.func, b)
                if not isinstance(f, FiniteFunction):
                    return False
                vals.update((key[p] - k if k else key[p]) for key in f.table if isinstance(key[p], (int, float, Fraction)))
            return True
        if isinstance(e, ast.Compare):
            for a, c in zip(e.operands, e.operands[1:]):
                for side, other in ((a, c), (c, a)):
                    k = _shift(side, name)
                    if k is None:
                        continue
                    res = self._results(other, b)
                    if res is None:
                        return False
                    vals.update((v - k if k else v) for v in res if isinstance(v, (int, float, Fraction)) and not isinstance(v, bool))
            return all(self._positional(o, name, b, vals) for o in e.operands if _shift(o, name) is None)
        return all(self._positional(c, name, b, vals) for c in _children(e))

    def quant(self, e: ast.Quant, b: Mapping[str, Value]) -> bool:
        cached = self._slots.get(id(e))
        if cached is None:
            self.uncacheable = False
            cached = self.slots(e, b)
            if not self.uncacheable and not any(isinstance(bd.domain, (ast.SetLit, ast.Var)) for bd in e.bindings):
                self._slots[id(e)] = cached
        slots, doms = cached
        if e.kind in ("forall", "exists"):
            staged, pins = _plan(e, slots, self.env.ctors)
            found = self._search(e, slots, doms, staged, 0, dict(b), pins)
            return (not found) if e.kind == "forall" else found
        for dom in doms:
            if isinstance(dom, _NoDomain):
                raise Undecided(dom.reason)
        count = 0
        for combo in itertools.product(*doms):
            cur = dict(b)
            fresh = False
            for names, values in zip(slots, combo):
                for n, v in zip(names, values):
                    fresh = fresh or isinstance(v, _Fresh)
                    cur[n] = v.value if isinstance(v, _Fresh) else v
            if self.eval(e.body, cur):
                if fresh:
                    return False
                count += 1
                if count > 1:
                    return False
        return count == 1

    def slots(self, e: ast.Quant, b: Mapping[str, Value]) -> tuple[list[tuple[str, ...]], list[list[tuple[Any, ...]]]]:
        """The quantifier's variables in enumeration slots and each slot's candidate tuples.

        Variables that occur only together, as the whole argument list of
        function applications and constructor terms (``at(x, y)``,
        ``move(x, y)``), form one slot whose candidates are the table keys and
        term arguments plus one fresh tuple; every other variable is a slot
        of its own (:meth:`domain`).
        """
        bindings = {n: bd for bd in e.bindings for n in bd.names}
        group = self._joint(e, b, bindings)
        if group is None and e.kind in ("forall", "exists"):
            names = _preimage_group(e, bindings, self.env.ctors)
            if names is not None:  # enumerable only through its guard's preimage (_search)
                group = (names, _NoDomain(f"{', '.join(names)} are used outside function arguments and "
                                          f"their guard's value is the function's default"))  # type: ignore[assignment]
        slots: list[tuple[str, ...]] = []
        for n in e.variables:
            if group and n in group[0]:
                if n == group[0][0]:
                    slots.append(group[0])
                continue
            slots.append((n,))
        # a single-variable slot pinned by an equality guard (``v == t``) takes
        # only t's value in _search, never its domain: the domain is not computed
        pins = _plan(e, slots, self.env.ctors)[1] if e.kind in ("forall", "exists") else [None] * len(slots)
        doms: list[list[tuple[Any, ...]]] = []
        for names, pin in zip(slots, pins):
            if group and names == group[0]:
                doms.append(group[1])
                continue
            n = names[0]
            if isinstance(pin, _Pin) and pin.ctor is None:
                doms.append(_NoDomain("pinned by an equality guard"))  # type: ignore[arg-type]
                continue
            if e.kind in ("forall", "exists") and _unused(e, n, bindings[n]):
                doms.append([(0,)])  # the body does not depend on it and the domain is not empty: one value
                continue
            try:
                doms.append([(v,) for v in self.domain(bindings[n], n, e.body, b, e.kind, tuple(e.variables))])
            except Undecided as exc:  # may still be pinned by an equality guard (see _search)
                doms.append(_NoDomain(str(exc)))  # type: ignore[arg-type]
        return slots, doms

    def _joint(self, e: ast.Quant, b: Mapping[str, Value],
               bindings: Mapping[str, ast.Binding]) -> tuple[tuple[str, ...], list[tuple[Any, ...]]] | None:
        for group, kinds, uses, literal_keys in _joint_groups(e, bindings, self.env.ctors, self.io_names):
            keys: set[tuple[Any, ...]] = set(literal_keys)
            for app in uses:
                if app.func.prefix is None and app.func.name in self.env.ctors and app.func.name not in b:
                    keys.update(tuple(t.args) for t in self._terms(app.func.name) if len(t.args) == len(group))
                    continue
                f = self.var(app.func, b)
                if not isinstance(f, FiniteFunction):
                    break
                keys.update(f.table)
            else:
                ok = [k for k in keys if all(_fits(v, kind) for v, kind in zip(k, kinds))]
                top: set[Any] = set(self.numbers()) | _static_literals(e.body)
                fresh = int(max((abs(v) for v in top), default=0)) + 1
                cands: list[tuple[Any, ...]] = sorted(ok, key=repr)
                cands.append(tuple(_Fresh(fresh) for _ in group))
                return group, cands
        return None

    def _search(self, e: ast.Quant, slots: list[tuple[str, ...]], doms: list[Any],
                staged: list[list[ast.Expr]], depth: int, cur: dict[str, Value],
                pins: list[Any] | None = None) -> bool:
        """True when some assignment is a counterexample (forall) or a witness (exists);
        guards whose variables are all bound are checked as soon as possible.  A slot
        pinned by a guard ``v == t`` (or ``move(x, y) == t``, ``t`` free of the slot's
        variables) takes only the value of ``t``: no other value passes that guard."""
        if depth == len(slots):
            v = bool(self.eval(e.body, cur))
            return (not v) if e.kind == "forall" else v
        names = slots[depth]
        pin = pins[depth] if pins is not None else None
        dom: Any = doms[depth]
        if isinstance(pin, _Preimage):
            keys = pin.keys(self, cur)
            if keys is not None:
                dom = keys
            elif isinstance(dom, _NoDomain):
                raise Undecided(dom.reason)
        elif pin is not None and not (pin.ctor is not None and pin.ctor in cur):
            dom = pin.values(self.eval(pin.term, cur))
        elif isinstance(dom, _NoDomain):
            raise Undecided(dom.reason)
        for values in dom:
            for n, value in zip(names, values):
                cur[n] = value.value if isinstance(value, _Fresh) else value
            if all(self.eval(g, cur) for g in staged[depth]):
                if self._search(e, slots, doms, staged, depth + 1, cur, pins):
                    return True
        for n in names:
            cur.pop(n, None)
        return False
