"""Direct evaluation of an RCL formula on a node's concrete values (no solver).

Used by the offline trace checker (:mod:`rclverify.backends.monitors`) on
every event and by the property tests on every example
(:func:`rclverify.logic.decide.decide`), so it must be fast.  Values follow
:mod:`rclverify.values`; the environment is keyed by qualified names
(``"in.r"``, ``"out.radiationStatus"``), a bare name resolving inputs first,
like :meth:`CheckedNode.io_type`.  REAL arithmetic is exact (a float is the
rational it denotes), as in the Z3 encoding (shared/DESIGN.md).

Quantifiers are decided by enumeration:

* over ``BOOL``, an enumeration, a set literal or a finite set value: every
  element;
* over ``INTEGER``/``NATURAL`` bounded by literal guards (``k <= 12 -> ...``
  under ``forall``, ``k >= -2 and k <= 2 and ...`` under ``exists``): every
  value in the range (at most :data:`MAX_RANGE`);
* a variable (or a pair ``x, y``) fixed by an equality guard ``v == t`` or
  ``move(x, y) == t`` (``t`` free of it): only the value of ``t``;
* a variable (or a tuple ``x, y``) guarded by ``f(x, y) == t`` (``f`` a
  function value given as a finite table, ``t`` free of them) when ``t``'s
  value is not ``f``'s default: only the table's keys with that result (every
  other point gives the default, which fails the guard), whatever else the
  body does with the variables;
* over ``REAL``/``INTEGER``/``NATURAL`` otherwise: exactly, when the bound
  variable occurs only as an argument of a function or of a constructor, or
  as an operand of ``==``/``!=`` (possibly shifted by a literal, ``i + 1``)
  whose other side is a literal, an I/O value, a function's result or a
  variable bound outside; a constructor term holding it must itself be
  compared with an I/O value, a function's result or a literal term.  Then
  only the values the environment and the formula mention (shifted back by
  those literals) can make an atom true; every other value behaves like one
  fresh value, which is enumerated once.  For ``exists_unique`` a fresh
  value satisfying the body stands for infinitely many, so uniqueness fails.
  Any other use (``x < 3``, ``x * y``, ``x == in.r + 1``) makes the
  quantifier undecidable here and :func:`evaluate` answers ``None`` (the
  callers then ask Z3).

tests/test_one_evaluator.py checks on random formulas and values that
wherever this module and Z3 (:mod:`.concrete`) both decide, they agree.
"""
from __future__ import annotations

import dataclasses
import itertools
import math
from fractions import Fraction
from typing import Any, Callable, Iterable, Mapping, cast

from ..rcl import ast
from ..rcl import types as T
from ..rcl.types import Checked, CheckedNode
from ..values import FiniteFunction, Term, conforms


class Undecided(Exception):
    """The formula cannot be decided by direct evaluation (reason in ``str``)."""


_CMP: Mapping[str, Callable[[Any, Any], bool]] = {
    "==": lambda a, b: a == b, "!=": lambda a, b: a != b, "<": lambda a, b: a < b,
    "<=": lambda a, b: a <= b, ">": lambda a, b: a > b, ">=": lambda a, b: a >= b,
}
_INFINITE = ("REAL", "INTEGER", "NATURAL")
_LIT: dict[str, Any] = {}


def evaluate(formula: ast.Expr, checked: Checked, node: CheckedNode,
             values: Mapping[str, Any]) -> bool | None:
    """Truth value of ``formula`` for ``node`` on ``values``.

    ``values`` maps qualified names (``"in.r"``) to values in the
    :mod:`rclverify.values` convention.  Returns ``True``/``False``, or
    ``None`` when the formula cannot be decided directly (a quantifier over
    an infinite domain that does not reduce to finitely many candidates, or
    a value the formula needs is missing).  Never raises for such cases.
    """
    try:
        return bool(Evaluator(checked, node, values).eval(formula, {}))
    except (Undecided, TypeError, ZeroDivisionError):
        return None


def why_undecided(formula: ast.Expr, checked: Checked, node: CheckedNode, values: Mapping[str, Any]) -> str:
    """The reason :func:`evaluate` answers ``None`` ('' when it decides)."""
    try:
        Evaluator(checked, node, values).eval(formula, {})
        return ""
    except Undecided as exc:
        return str(exc)
    except (TypeError, ZeroDivisionError) as exc:
        return f"a value has the wrong form for the formula: {exc}"


def _children(e: Any) -> Iterable[Any]:
    if isinstance(e, ast.Apply):
        return e.args
    if isinstance(e, ast.Unary):
        return (e.operand,)
    if isinstance(e, ast.Binary):
        return (e.left, e.right)
    if isinstance(e, ast.Compare):
        return e.operands
    if isinstance(e, ast.Member):
        return (e.elem, e.collection)
    if isinstance(e, (ast.SetLit, ast.TupleLit, ast.SeqLit)):
        return e.items
    if isinstance(e, ast.Quant):
        return (e.body,)
    return ()


def _shift(e: Any, name: str) -> Fraction | None:
    """``k`` when ``e`` is ``name``, ``name + k`` or ``name - k`` (literal k); else None."""
    if isinstance(e, ast.Var) and e.prefix is None and e.name == name:
        return Fraction(0)
    if isinstance(e, ast.Binary) and e.op in ("+", "-"):
        if isinstance(e.right, ast.NumLit) and isinstance(e.left, ast.Var) and e.left.prefix is None \
                and e.left.name == name:
            return e.right.value if e.op == "+" else -e.right.value
        if e.op == "+" and isinstance(e.left, ast.NumLit) and isinstance(e.right, ast.Var) \
                and e.right.prefix is None and e.right.name == name:
            return e.left.value
    return None


def _closed(e: Any, local: frozenset[str], refs: set[str]) -> bool:
    """Does every value of ``e`` come from a finite, known set: a literal, an I/O
    variable's value, a function's result (its table's results or default), or
    a variable bound outside the quantifier (named in ``refs``)?  ``local``:
    the variables of the quantifier under analysis and of those inside it."""
    if isinstance(e, ast.NumLit):
        return True
    if isinstance(e, ast.Unary) and e.op == "-" and isinstance(e.operand, ast.NumLit):
        return True
    if isinstance(e, ast.Var):
        if e.prefix is None:
            if e.name in local:
                return False
            refs.add(e.name)
        return True
    return isinstance(e, ast.Apply)


def _offsets(e: Any, name: str, out: set[Fraction], local: frozenset[str] = frozenset(),
             refs: set[str] | None = None) -> bool:
    """Collect the shifts under which ``name`` occurs in ``e``; False on a use
    that is not an argument or an ``==``/``!=`` operand compared with a
    :func:`_closed` term (bare names on such other sides go to ``refs``)."""
    if refs is None:
        refs = set()
    if isinstance(e, ast.Quant):
        if name in e.variables:
            return True
        local = local | frozenset(e.variables)
    if isinstance(e, ast.Apply):
        for a in e.args:
            k = _shift(a, name)
            if k is not None:
                out.add(k)
            elif not _offsets(a, name, out, local, refs):
                return False
        return True
    if isinstance(e, ast.Compare):
        for op, (a, b) in zip(e.ops, zip(e.operands, e.operands[1:])):
            for side, other in ((a, b), (b, a)):
                k = _shift(side, name)
                if k is not None:
                    if op not in ("==", "!=") or not _closed(other, local | {name}, refs):
                        return False
                    out.add(k)
                elif not _offsets(side, name, out, local, refs):
                    return False
        return True
    if isinstance(e, ast.Var):
        return not (e.prefix is None and e.name == name)
    return all(_offsets(c, name, out, local, refs) for c in _children(e))


_STATIC: dict[tuple[int, str, str], tuple[Any, Any]] = {}


def _static_shifts(body: Any, name: str, local: frozenset[str] = frozenset()) -> tuple[set[Fraction], frozenset[str]] | None:
    """:func:`_offsets` of ``body`` for ``name`` plus 0, and the bare names it
    is compared with, memoised per AST node (the node is kept in the memo, so
    its id stays its own); None when ``name`` has a use that is not an argument
    or an equality with a closed term.  ``local``: the quantifier's variables."""
    key = (id(body), name, "shifts:" + ",".join(sorted(local)))
    hit = _STATIC.get(key)
    if hit is not None and hit[0] is body:
        return (set(hit[1][0]), hit[1][1]) if hit[1] is not None else None
    shifts: set[Fraction] = set()
    refs: set[str] = set()
    ok = _offsets(body, name, shifts, frozenset(local) | {name}, refs)
    result = (frozenset(shifts | {Fraction(0)}), frozenset(refs)) if ok else None
    _STATIC[key] = (body, result)
    return (set(result[0]), result[1]) if result is not None else None


def _static_literals(body: Any) -> set[Any]:
    """The numeric literals of ``body`` (memoised per AST node)."""
    key = (id(body), "", "literals")
    hit = _STATIC.get(key)
    if hit is not None and hit[0] is body:
        return set(hit[1])
    out: set[Any] = set()
    _literals(body, out)
    _STATIC[key] = (body, frozenset(out))
    return out


def _conjuncts(e: Any) -> list[Any]:
    if isinstance(e, ast.Binary) and e.op == "and":
        return _conjuncts(e.left) + _conjuncts(e.right)
    return [e]


def _free(e: Any, names: set[str], out: set[str]) -> None:
    if isinstance(e, ast.Var) and e.prefix is None and e.name in names:
        out.add(e.name)
    if isinstance(e, ast.Quant):
        inner = names - set(e.variables)
        for c in _children(e):
            _free(c, inner, out)
        return
    for c in _children(e):
        _free(c, names, out)


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


def _numbers(v: Any, out: set[Any]) -> None:
    if isinstance(v, bool) or v is None:
        return
    if isinstance(v, (int, float, Fraction)):
        out.add(v)
    elif isinstance(v, Term):
        for a in v.args:
            _numbers(a, out)
    elif isinstance(v, FiniteFunction):
        for key, res in v.table.items():
            for a in key:
                _numbers(a, out)
            _numbers(res, out)
        _numbers(v.default, out)
    elif isinstance(v, (tuple, frozenset)):
        for a in v:
            _numbers(a, out)


def _literals(e: Any, out: set[Any]) -> None:
    if isinstance(e, ast.NumLit):
        out.add(e.value)
    if isinstance(e, ast.Unary) and e.op == "-" and isinstance(e.operand, ast.NumLit):
        out.add(-e.operand.value)
    for c in _children(e):
        _literals(c, out)


def arithmetic(op: str, x: Any, y: Any) -> Any:
    """``x op y`` for ``op`` in ``+ - * /`` on RCL numbers.  REAL is exact
    (DESIGN.md: REAL -> Z3 Real): a float operand is taken as the rational
    it denotes, so no rounding and no overflow to inf.  Raises
    :class:`Undecided` for a division by zero (RCL leaves it unspecified)."""
    if type(x) is float:
        x = Fraction(x)
    if type(y) is float:
        y = Fraction(y)
    if op == "+":
        return x + y
    if op == "-":
        return x - y
    if op == "*":
        return x * y
    if y == 0:
        raise Undecided("division by zero")
    return Fraction(x) / Fraction(y)


class Evaluator:
    """One evaluation context: the node, its values and the candidate numbers.

    ``compiled`` (class attribute, True): evaluate through the compiled
    closures; False walks the tree (:meth:`interpret`) everywhere, the
    reference the tests compare the closures with."""

    compiled = True
    #: ``None``: exact arithmetic (the compiled closures of this class); a
    #: subclass with other number semantics names them here (its expressions
    #: are compiled apart, calling :meth:`literal`, :meth:`arith` and
    #: :meth:`compare`)
    mode: str | None = None

    def __init__(self, checked: Checked, node: CheckedNode, values: Mapping[str, Any]) -> None:
        self.env = checked.env
        self.node = node
        self.values = values
        self._numbers: set[Any] | None = None
        self._slots: dict[int, tuple[list[tuple[str, ...]], list[list[tuple[Any, ...]]]]] = {}
        self.uncacheable = False  # set when a quantifier's candidates depend on outer bound values
        self.io_names = frozenset(node.inputs) | frozenset(node.outputs)

    def numbers(self) -> set[Any]:
        if self._numbers is None:
            found: set[Any] = set()
            for v in self.values.values():
                _numbers(v, found)
            self._numbers = found
        return self._numbers

    # -- names ---------------------------------------------------------------
    def io(self, v: ast.Var) -> Any:
        if v.prefix is not None:
            key = v.qualified
        elif v.name in self.node.inputs:
            key = "in." + v.name
        else:
            key = "out." + v.name
        value = self.values.get(key)
        if value is None:  # absent, or not observed yet: nothing to evaluate on
            raise Undecided(f"no value for {key}")
        return value

    def var(self, v: ast.Var, bound: Mapping[str, Any]) -> Any:
        if v.prefix is None and v.name in bound:
            return bound[v.name]
        if v.prefix is None and v.name in self.env.enum_values:
            return v.name
        if v.prefix is None and v.name in self.env.constants:
            return self.eval(self.env.constants[v.name][1], {})
        if v.prefix is None and v.name in self.env.ctors:
            return Term(v.name, ())
        return self.io(v)

    # -- expressions -----------------------------------------------------------
    def eval(self, e: ast.Expr, b: Mapping[str, Any]) -> Any:
        """The value of ``e`` under bound variables ``b``: the expression is
        compiled once (per AST node and I/O node) into nested closures that
        do what :meth:`interpret` does, node for node (:func:`_compile`)."""
        if not self.compiled:
            return self.interpret(e, b)
        mode = self.mode
        key: tuple[Any, ...] = (id(e), id(self.node), id(self.env)) if mode is None else \
            (id(e), id(self.node), id(self.env), mode)
        hit = _COMPILED.get(key)
        if hit is None or hit[0] is not e or hit[1] is not self.node or hit[2] is not self.env:
            if len(_COMPILED) >= COMPILED_SIZE:
                _COMPILED.clear()
            hit = _COMPILED[key] = (e, self.node, self.env, _compile(e, self.env, self.node, mode))
        return hit[3](self, b)

    def interpret(self, e: ast.Expr, b: Mapping[str, Any]) -> Any:
        """The value of ``e`` under ``b`` by walking the tree (the reference the
        compiled closures follow; what they delegate membership, set and
        tuple literals and quantifiers to)."""
        if isinstance(e, ast.BoolLit):
            return e.value
        if isinstance(e, ast.NumLit):
            return self.literal(e)
        if isinstance(e, ast.Var):
            return self.var(e, b)
        if isinstance(e, ast.Apply):
            args = tuple(self.eval(a, b) for a in e.args)
            if e.func.prefix is None and e.func.name in self.env.ctors and e.func.name not in b:
                return Term(e.func.name, args)
            f = self.var(e.func, b)
            if not callable(f):
                raise Undecided(f"{e.func.qualified} is not a function value")
            return f(*args)
        if isinstance(e, ast.Unary):
            x = self.eval(e.operand, b)
            return (not x) if e.op == "not" else -x
        if isinstance(e, ast.Binary):
            return self.binary(e, b)
        if isinstance(e, ast.Compare):
            vals = [self.eval(o, b) for o in e.operands]
            return all(self.compare(e, b, op, x, y) for op, x, y in zip(e.ops, vals, vals[1:]))
        if isinstance(e, ast.Member):
            x = self.eval(e.elem, b)
            carrier = self.carrier(e.collection, b)
            if carrier is not None:  # `x in NATURAL`, `(x, y) in REAL.REAL`
                inside = conforms(x, carrier) is None
                return (not inside) if e.negated else inside
            coll = self.collection(e.collection, b)
            return (x not in coll) if e.negated else (x in coll)
        if isinstance(e, ast.SetLit):
            return frozenset(self.eval(i, b) for i in e.items)
        if isinstance(e, (ast.TupleLit, ast.SeqLit)):
            return tuple(self.eval(i, b) for i in e.items)
        if isinstance(e, ast.Quant):
            return self.quant(e, b)
        raise Undecided(f"cannot evaluate {type(e).__name__}")

    def carrier(self, e: Any, b: Mapping[str, Any]) -> T.Type | None:
        """The type a built-in term on the right of ``in`` stands for
        (``NATURAL``, or the product ``REAL.REAL``), else ``None``."""
        if not isinstance(e, ast.Var) or e.prefix is not None or e.name in b:
            return None
        if e.name in T.BASE_NAMES:
            return T.Scalar(e.name)
        return T.qualified_base(e.name)

    def collection(self, e: Any, b: Mapping[str, Any]) -> Any:
        if isinstance(e, ast.SetLit):
            return {self.eval(i, b) for i in e.items}
        v = self.eval(e, b)
        if isinstance(v, (frozenset, tuple, set)):
            return v
        raise Undecided("membership in a value that is not a set")

    def binary(self, e: ast.Binary, b: Mapping[str, Any]) -> Any:
        op = e.op
        if op == "and":
            return bool(self.eval(e.left, b)) and bool(self.eval(e.right, b))
        if op == "or":
            return bool(self.eval(e.left, b)) or bool(self.eval(e.right, b))
        if op == "->":
            return (not self.eval(e.left, b)) or bool(self.eval(e.right, b))
        if op == "<=>":
            return bool(self.eval(e.left, b)) == bool(self.eval(e.right, b))
        return self.arith(op, self.eval(e.left, b), self.eval(e.right, b))

    # -- the semantics of numbers: exact here (REAL as rationals); the
    # float-faithful semantics of recorded runs (logic/floatsem.py) override
    # these three and set ``mode``, under which expressions are compiled apart
    def literal(self, e: ast.NumLit) -> Any:
        """The value of a numeric literal: its exact rational (an ``int`` when whole)."""
        lit = _LIT.get(e.text)
        if lit is None:
            v = e.value
            lit = _LIT[e.text] = int(v) if v.denominator == 1 else v
        return lit

    def arith(self, op: str, x: Any, y: Any) -> Any:
        """``x op y`` (:func:`arithmetic`: exact)."""
        return arithmetic(op, x, y)

    def compare(self, e: ast.Compare, b: Mapping[str, Any], op: str, x: Any, y: Any) -> bool:
        """One comparison ``x op y`` of ``e`` under bound variables ``b`` (exact)."""
        return _CMP[op](x, y)

    # -- quantifiers -------------------------------------------------------------
    def domain(self, binding: ast.Binding, name: str, body: ast.Expr, b: Mapping[str, Any],
               kind: str = "forall", qvars: tuple[str, ...] = ()) -> list[Any]:
        dom = binding.domain
        if isinstance(dom, ast.TBase):
            base = dom.name
            typ: Any = T.Scalar(base) if base in _INFINITE or base == "BOOL" else None
        elif isinstance(dom, ast.TName):
            typ = self.env.types.get(dom.name)
        elif isinstance(dom, ast.TEnum):
            return list(dom.values)
        elif isinstance(dom, ast.TypeExpr.__args__):  # type: ignore[attr-defined]
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

    def candidates(self, name: str, scalar: str, body: ast.Expr, b: Mapping[str, Any],
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

    def _results(self, e: Any, b: Mapping[str, Any]) -> set[Any] | None:
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

    def _positional(self, e: Any, name: str, b: Mapping[str, Any], vals: set[Any]) -> bool:
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

    def quant(self, e: ast.Quant, b: Mapping[str, Any]) -> bool:
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

    def slots(self, e: ast.Quant, b: Mapping[str, Any]) -> tuple[list[tuple[str, ...]], list[list[tuple[Any, ...]]]]:
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

    def _joint(self, e: ast.Quant, b: Mapping[str, Any],
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
                staged: list[list[ast.Expr]], depth: int, cur: dict[str, Any],
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
            if not (isinstance(dom, ast.TBase) and dom.name in _INFINITE):
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
                or not all(n in bindings and isinstance(bindings[n].domain, ast.TBase)
                           and cast(ast.TBase, bindings[n].domain).name in _INFINITE for n in names)):
            continue
        used: set[str] = set()
        _free(other, set(names), used)
        if not used:
            found = names
            break
    _STATIC[key] = (e, found)
    return found


def _unused(e: ast.Quant, name: str, binding: ast.Binding) -> bool:
    """True when ``name`` ranges over REAL, INTEGER or NATURAL (never empty) and
    does not occur free in ``e``'s body: the body's value is the same for every
    value of it, so ``forall``/``exists`` over it need one value (not for
    ``exists_unique``, where a true body has infinitely many witnesses).
    Memoised per AST node."""
    dom = binding.domain
    if not (isinstance(dom, ast.TBase) and dom.name in _INFINITE):
        return False
    key = (id(e), name, "unused")
    hit = _STATIC.get(key)
    if hit is not None and hit[0] is e:
        return bool(hit[1])
    unused = not _mentions(e.body, name)
    _STATIC[key] = (e, unused)
    return unused


def _mentions(e: Any, name: str) -> bool:
    """Does ``name`` occur as a bare variable anywhere in ``e`` (quantifier
    domains included, shadowing ignored: a conservative answer)?"""
    if isinstance(e, ast.Var):
        return e.prefix is None and e.name == name
    if isinstance(e, tuple):
        return any(_mentions(x, name) for x in e)
    if dataclasses.is_dataclass(e) and not isinstance(e, (type, ast.Loc)):
        return any(_mentions(getattr(e, f.name), name) for f in dataclasses.fields(e))
    return False


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


class _NoDomain:
    """A slot whose values cannot be enumerated (``reason``); usable only when pinned."""

    __slots__ = ("reason",)

    def __init__(self, reason: str) -> None:
        self.reason = reason


def _integral(v: Any) -> int | None:
    if isinstance(v, bool) or not isinstance(v, (int, float, Fraction)):
        return None
    if isinstance(v, int):
        return v
    if isinstance(v, float) and not v.is_integer():
        return None
    q = Fraction(v)
    return int(q) if q.denominator == 1 else None


def _fit(v: Any, kind: str) -> tuple[bool, Any]:
    """``(True, v')`` when number ``v`` is a value of ``kind`` (REAL/INTEGER/NATURAL), as ``v'``."""
    if kind == "REAL":
        ok = not isinstance(v, bool) and isinstance(v, (int, float, Fraction))
        return ok, v
    k = _integral(v)
    if k is None or (kind == "NATURAL" and k < 0):
        return False, None
    return True, k


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
        if not (isinstance(dom, ast.TBase) and dom.name in _INFINITE):
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

    def keys(self, ev: "Evaluator", cur: Mapping[str, Any]) -> list[tuple[Any, ...]] | None:
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


#: Compiled expressions kept (per AST node and I/O node); cleared when full.
COMPILED_SIZE = 10_000
_Fn = Callable[["Evaluator", Mapping[str, Any]], Any]
_COMPILED: dict[tuple[int, int, int], tuple[Any, Any, Any, _Fn]] = {}


def _compile(e: Any, env: Any, node: CheckedNode, mode: str | None = None) -> _Fn:
    """``e`` as a closure ``fn(evaluator, bound) -> value`` doing exactly what
    :meth:`Evaluator.interpret` does for it (same order of evaluation, same
    values, same exceptions), with the tree walk and the name resolution
    that does not depend on the bound variables done once.  Membership,
    set/tuple literals and quantifiers are handed to the evaluator.  With a
    ``mode`` (an evaluator of other number semantics) literals, arithmetic
    and comparisons call the evaluator's :meth:`~Evaluator.literal`,
    :meth:`~Evaluator.arith` and :meth:`~Evaluator.compare`."""
    if isinstance(e, ast.Var):
        return _compile_var(e, env, node, mode)
    if mode is not None:
        if isinstance(e, ast.NumLit):
            return lambda ev, b: ev.literal(e)
        if isinstance(e, ast.Compare):
            parts = tuple(_compile(o, env, node, mode) for o in e.operands)
            ops = e.ops

            def compare_in_mode(ev: Evaluator, b: Mapping[str, Any]) -> Any:
                vals = [o(ev, b) for o in parts]
                return all(ev.compare(e, b, op, x, y) for op, x, y in zip(ops, vals, vals[1:]))
            return compare_in_mode
    if isinstance(e, ast.NumLit):
        lit = _LIT.get(e.text)
        if lit is None:
            v = e.value
            lit = _LIT[e.text] = int(v) if v.denominator == 1 else v
        value = lit
        return lambda ev, b: value
    if isinstance(e, ast.BoolLit):
        truth = e.value
        return lambda ev, b: truth
    if isinstance(e, ast.Apply):
        args = tuple(_compile(a, env, node, mode) for a in e.args)
        func = e.func
        fname, qualified = func.name, func.qualified
        ctor = func.prefix is None and fname in env.ctors
        fvar = _compile_var(func, env, node, mode)

        def apply(ev: Evaluator, b: Mapping[str, Any]) -> Any:
            vals = tuple([a(ev, b) for a in args])
            if ctor and fname not in b:
                return Term(fname, vals)
            f = fvar(ev, b)
            if not callable(f):
                raise Undecided(f"{qualified} is not a function value")
            return f(*vals)
        return apply
    if isinstance(e, ast.Unary):
        operand = _compile(e.operand, env, node, mode)
        if e.op == "not":
            return lambda ev, b: not operand(ev, b)
        return lambda ev, b: -operand(ev, b)
    if isinstance(e, ast.Binary):
        return _compile_binary(e, env, node, mode)
    if isinstance(e, ast.Compare):
        operands = tuple(_compile(o, env, node) for o in e.operands)
        cmps = tuple(_CMP[op] for op in e.ops)
        if len(cmps) == 1:
            first, second = operands
            cmp = cmps[0]
            return lambda ev, b: bool(cmp(first(ev, b), second(ev, b)))  # all() of one comparison

        def compare(ev: Evaluator, b: Mapping[str, Any]) -> Any:
            vals = [o(ev, b) for o in operands]
            return all(c(x, y) for c, x, y in zip(cmps, vals, vals[1:]))
        return compare
    return lambda ev, b: ev.interpret(e, b)


def _compile_var(v: ast.Var, env: Any, node: CheckedNode, mode: str | None = None) -> _Fn:
    """:meth:`Evaluator.var` for ``v``: a bound variable first, then (fixed by
    the context) an enumeration value, a constant, a constructor, else the
    I/O value (:meth:`Evaluator.io`)."""
    if v.prefix is not None:
        key = v.qualified
    else:
        key = ("in." + v.name) if v.name in node.inputs else ("out." + v.name)

    def io(ev: Evaluator, b: Mapping[str, Any]) -> Any:
        value = ev.values.get(key)
        if value is None:
            raise Undecided(f"no value for {key}")
        return value
    if v.prefix is not None:
        return io
    name = v.name
    if name in env.enum_values:
        return lambda ev, b: b.get(name, name)
    if name in env.constants:
        const = _compile(env.constants[name][1], env, node, mode)
        return lambda ev, b: b[name] if name in b else const(ev, {})
    if name in env.ctors:
        return lambda ev, b: b[name] if name in b else Term(name, ())
    return lambda ev, b: b[name] if name in b else io(ev, b)


def _compile_binary(e: ast.Binary, env: Any, node: CheckedNode, mode: str | None = None) -> _Fn:
    """:meth:`Evaluator.binary` for ``e``."""
    op = e.op
    left, right = _compile(e.left, env, node, mode), _compile(e.right, env, node, mode)
    if op == "and":
        return lambda ev, b: bool(left(ev, b)) and bool(right(ev, b))
    if op == "or":
        return lambda ev, b: bool(left(ev, b)) or bool(right(ev, b))
    if op == "->":
        return lambda ev, b: (not left(ev, b)) or bool(right(ev, b))
    if op == "<=>":
        return lambda ev, b: bool(left(ev, b)) == bool(right(ev, b))
    if mode is not None:
        return lambda ev, b: ev.arith(op, left(ev, b), right(ev, b))
    return lambda ev, b: arithmetic(op, left(ev, b), right(ev, b))


#: The most values a guard-bounded INTEGER/NATURAL quantifier is enumerated over.
MAX_RANGE = 4096
_RANGES: dict[tuple[int, str, str, str], tuple[Any, Any]] = {}


def _bound_of(e: Any, name: str) -> tuple[str, Fraction] | None:
    """``("hi"|"lo", c)`` when guard ``e`` is ``name <= c``, ``name < c``,
    ``c >= name``, ... with a numeric literal ``c`` (integer-rounded)."""
    if not isinstance(e, ast.Compare) or len(e.ops) != 1:
        return None
    op, (a, c) = e.ops[0], e.operands

    def lit(x: Any) -> Fraction | None:
        if isinstance(x, ast.NumLit):
            return Fraction(x.value)
        if isinstance(x, ast.Unary) and x.op == "-" and isinstance(x.operand, ast.NumLit):
            return -Fraction(x.operand.value)
        return None

    def is_name(x: Any) -> bool:
        return isinstance(x, ast.Var) and x.prefix is None and x.name == name
    flip = {"<": ">", "<=": ">=", ">": "<", ">=": "<="}
    rel: str = op
    if is_name(c) and lit(a) is not None and op in flip:
        rel, a, c = flip[op], c, a
    k = lit(c)
    if not is_name(a) or k is None:
        return None
    if rel == "<=":
        return "hi", Fraction(math.floor(k))
    if rel == "<":
        return "hi", Fraction(math.ceil(k) - 1)
    if rel == ">=":
        return "lo", Fraction(math.ceil(k))
    if rel == ">":
        return "lo", Fraction(math.floor(k) + 1)
    return None


def _integer_range(body: Any, name: str, scalar: str, kind: str) -> list[int] | None:
    """Every value of an INTEGER/NATURAL variable ``name`` that can make the
    quantifier's body differ from its value outside a literal bound: the
    bound comes from the guard (the conjuncts left of ``->`` under
    ``forall``, the conjuncts of the body under ``exists``/``exists_unique``),
    and outside it the body is TRUE (forall) or FALSE (exists), so only the
    values inside matter.  ``None`` when there is no such finite range (or it
    has more than :data:`MAX_RANGE` values)."""
    if scalar not in ("INTEGER", "NATURAL"):
        return None
    key = (id(body), name, scalar, kind)
    hit = _RANGES.get(key)
    if hit is not None and hit[0] is body:
        return cast("list[int] | None", hit[1])
    if kind == "forall":
        guards = _conjuncts(body.left) if isinstance(body, ast.Binary) and body.op == "->" else []
    else:
        guards = _conjuncts(body)
    lo: Fraction | None = Fraction(0) if scalar == "NATURAL" else None
    hi: Fraction | None = None
    for g in guards:
        found = _bound_of(g, name)
        if found is None:
            continue
        side, k = found
        if side == "hi":
            hi = k if hi is None else min(hi, k)
        else:
            lo = k if lo is None else max(lo, k)
    result = None
    if lo is not None and hi is not None and hi - lo < MAX_RANGE:
        result = list(range(int(lo), int(hi) + 1))
    _RANGES[key] = (body, result)
    return result


def _literal_number(e: Any) -> Any:
    if isinstance(e, ast.NumLit):
        v = e.value
    elif isinstance(e, ast.Unary) and e.op == "-" and isinstance(e.operand, ast.NumLit):
        v = -e.operand.value
    else:
        return None
    return int(v) if v.denominator == 1 else v


def _ctor_uses(body: Any, names: frozenset[str], ctors: Any, io: frozenset[str]) -> frozenset[tuple[Any, ...]] | None:
    """Check that every constructor term with one of ``names`` (possibly shifted)
    as an argument is an operand of ``==``/``!=`` whose other side takes only
    values the candidates know: an I/O variable (its value), a function's
    result (its table's results or default), or a term of the same
    constructor with literal arguments.  Returns those literal argument
    tuples (the candidates must include them), or None when some use is
    otherwise (the variable cannot be decided by candidates).  Memoised."""
    key = (id(body), ",".join(sorted(names)), "ctor-uses")
    hit = _STATIC.get(key)
    if hit is not None and hit[0] is body:
        return cast("frozenset[tuple[Any, ...]] | None", hit[1])
    literal: set[tuple[Any, ...]] = set()
    cleared: set[int] = set()

    def mentions(app: Any, live: frozenset[str]) -> bool:
        return (isinstance(app, ast.Apply) and app.func.prefix is None and app.func.name in ctors
                and any(_shift(a, n) is not None for a in app.args for n in live))

    def closed(other: Any, ctor: str) -> bool:
        if isinstance(other, ast.Var):
            return other.prefix is not None or other.name in io
        if isinstance(other, ast.Apply) and not (other.func.prefix is None and other.func.name in ctors):
            return True  # a function's result
        if isinstance(other, ast.Apply) and other.func.name == ctor:
            nums = tuple(_literal_number(a) for a in other.args)
            if all(n is not None for n in nums):
                literal.add(nums)
                return True
        return False

    def walk(e: Any, live: frozenset[str]) -> bool:
        if isinstance(e, ast.Quant):
            live = live - frozenset(e.variables)
            if not live:
                return True
        if isinstance(e, ast.Compare):
            for op, (a, b) in zip(e.ops, zip(e.operands, e.operands[1:])):
                for side, other in ((a, b), (b, a)):
                    if op in ("==", "!=") and isinstance(side, ast.Apply) and mentions(side, live):
                        if not closed(other, side.func.name):
                            return False
                        cleared.add(id(side))
        if mentions(e, live) and id(e) not in cleared:
            return False
        return all(walk(c, live) for c in _children(e))

    result = frozenset(literal) if walk(body, names) else None
    _STATIC[key] = (body, result)
    return result


def _fits(v: Any, kind: str) -> bool:
    if isinstance(v, bool) or not isinstance(v, (int, float, Fraction)):
        return False
    if kind == "REAL":
        return True
    return isinstance(v, int) and (kind == "INTEGER" or v >= 0)


def _tuple_apps(e: Any, names: set[str], out: list[ast.Apply]) -> None:
    """Applications whose arguments are all variables of ``names``."""
    if isinstance(e, ast.Quant):
        names = names - set(e.variables)
    if isinstance(e, ast.Apply) and e.args and all(
            isinstance(a, ast.Var) and a.prefix is None and a.name in names for a in e.args):
        out.append(e)
    for c in _children(e):
        _tuple_apps(c, names, out)


def _only_as(e: Any, group: tuple[str, ...], uses: list[ast.Apply]) -> bool:
    """True when every occurrence of a ``group`` variable in ``e`` is inside an
    application whose whole argument list is ``group`` (collected in ``uses``)."""
    if isinstance(e, ast.Quant) and set(group) & set(e.variables):
        return False  # a nested binder shadows a group variable: no joint slot
    if isinstance(e, ast.Apply) and len(e.args) == len(group) and all(
            isinstance(a, ast.Var) and a.prefix is None and a.name == g for a, g in zip(e.args, group)):
        uses.append(e)
        return True
    if isinstance(e, ast.Var):
        return not (e.prefix is None and e.name in group)
    return all(_only_as(c, group, uses) for c in _children(e))


class _Fresh:
    """A value no atom of the body can tell apart from infinitely many others."""

    __slots__ = ("value",)

    def __init__(self, value: Any) -> None:
        self.value = value
