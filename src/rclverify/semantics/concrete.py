"""Z3 check of an RCL formula on concrete values of a node's inputs and outputs.

The values follow :mod:`rclverify.semantics.values` (REAL a float/int/Fraction taken
exactly as a rational, enumeration values as their names, :class:`Term` for
constructor terms, :class:`FiniteFunction` for function-typed values ...),
keyed by qualified name (``"in.r"``, ``"out.radiationStatus"``).

Each value becomes a Z3 constant term; a function-typed value becomes its
finite interpretation, ``ite(args == k1, v1, ite(..., default))``,
substituted for the function symbol, so the formula left to Z3 has no free
symbol.  Quantifiers (also over infinite domains such as REAL or NATURAL)
stay in the formula and are left to Z3.  The formula holds iff its negation
is unsatisfiable.  Used by the property-test backend on every example and
by the trace checker as a fallback when direct evaluation cannot decide.
"""
from __future__ import annotations

from fractions import Fraction
from typing import Any, Mapping

import z3

from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.types import BOOL, Checked, CheckedNode, DataT, EnumT, FuncT, Scalar, SeqT, SetT, TupleT, Type
from rclverify.semantics.connectives import conj
from rclverify.semantics.definedness import conditions, defined
from rclverify.semantics.values import FiniteFunction, Term, exact
from rclverify.semantics.encode import Encoder, sort_of, widen
from rclverify.semantics import mathfacts, wallclock
from rclverify.semantics.retry import SAFETY_TIMEOUT_MS
from rclverify.semantics.world import on_fresh


class ConcreteValueError(ValueError):
    """A value that does not fit its declared RCL type (message names the variable)."""


def to_z3(value: Any, typ: Type, enc: Encoder) -> z3.ExprRef:
    """The Z3 term of a first-order value of RCL type ``typ``.

    Raises :class:`ConcreteValueError` for a value of the wrong shape and
    ``ValueError`` for a function type (see :func:`finite_interpretation`).
    """
    if isinstance(typ, Scalar):
        if typ.name == "BOOL":
            if not isinstance(value, bool):
                raise ConcreteValueError(f"{value!r} is not a BOOL")
            return z3.BoolVal(value)
        try:
            q = exact(value)
        except (TypeError, ValueError) as exc:  # None (unobserved), a string, NaN: not an RCL number
            raise ConcreteValueError(f"{value!r} is not a value of {typ.name}: {exc}") from None
        if typ.name == "REAL":
            return z3.RealVal(f"{q.numerator}/{q.denominator}")
        if q.denominator != 1:
            raise ConcreteValueError(f"{value!r} is not a value of {typ.name}")
        return z3.IntVal(int(q))
    if isinstance(typ, EnumT):
        return enc.enum_value(str(value))
    if isinstance(typ, DataT):
        if not isinstance(value, Term):
            raise ConcreteValueError(f"{value!r} is not a constructor term of {typ.name}")
        args = typ.ctor(value.name)
        if args is None:
            raise ConcreteValueError(f"{value.name} is not a constructor of {typ.name}")
        c = enc.ctor(value.name)
        return c(*[widen(to_z3(a, t, enc), c.domain(k)) for k, (a, t) in enumerate(zip(value.args, args))])
    if isinstance(typ, TupleT):
        s: Any = sort_of(typ)
        return s.constructor(0)(*[to_z3(v, t, enc) for v, t in zip(value, typ.elems)])
    if isinstance(typ, SetT):
        out = z3.EmptySet(sort_of(typ.elem))
        for v in sorted(value, key=repr):
            out = z3.SetAdd(out, to_z3(v, typ.elem, enc))
        return out
    if isinstance(typ, SeqT):
        if not value:
            return z3.Empty(sort_of(typ))
        parts = [z3.Unit(to_z3(v, typ.elem, enc)) for v in value]
        return parts[0] if len(parts) == 1 else z3.Concat(*parts)
    raise ValueError(f"{typ} has no first-order Z3 value")


def finite_interpretation(value: FiniteFunction, typ: FuncT, enc: Encoder) -> z3.ExprRef:
    """The body (over de Bruijn variables ``Var(0..n-1)``) of a finite function's
    interpretation: ``ite`` over its table, else its default."""
    xs = [z3.Var(k, sort_of(a)) for k, a in enumerate(typ.args)]
    body = to_z3(value.default, typ.result, enc)
    for key, res in sorted(value.table.items(), key=lambda kv: repr(kv[0]), reverse=True):
        cond = conj(*[x == to_z3(k, a, enc) for x, k, a in zip(xs, key, typ.args)])
        body = z3.If(cond, to_z3(res, typ.result, enc), body)
    return body


def _io_type(node: CheckedNode, qualified: str) -> Type:
    if qualified.startswith("first(in.") and qualified.endswith(")") and qualified[9:-1] in node.inputs:
        return BOOL  # whether the message on that input is the first published on it (docs/semantics.md)
    prefix, _, name = qualified.partition(".")
    table = node.inputs if prefix == "in" else node.outputs if prefix == "out" else None
    if table is None or name not in table:
        raise KeyError(f"{node.name} has no {qualified}")
    return table[name]


_ENCODED: dict[tuple[int, str], tuple[ast.Expr, z3.BoolRef, dict[str, z3.ExprRef | z3.FuncDeclRef], list[z3.BoolRef]]] = {}
on_fresh(_ENCODED.clear)  # its formulas belong to the Z3 context they were made in


def _encoded_typed(formula: ast.Expr, checked: Checked,
                   node: CheckedNode) -> tuple[z3.BoolRef, dict[str, z3.ExprRef | z3.FuncDeclRef], list[z3.BoolRef]]:
    """``formula`` encoded once over free I/O symbols (cached per formula object:
    encoding costs more than the check), with those symbols by qualified name
    and the encoder's typing axioms over them (``NATURAL >= 0``, ...)."""
    key = (id(formula), node.name)
    hit = _ENCODED.get(key)
    if hit is not None and hit[0] is formula:
        return hit[1], hit[2], hit[3]
    enc = Encoder(checked.env)
    phi = enc.formula(formula, node)
    free: dict[str, z3.ExprRef | z3.FuncDeclRef] = {}
    for sym in enc.symbols.values():
        q = sym.z3name.split(".", 1)[1]  # "<Node>.in.x" -> "in.x"
        free[q] = sym.decl
    axioms = list(enc.axioms())
    _ENCODED[key] = (formula, phi, free, axioms)
    return phi, free, axioms


#: formula id -> (formula, its well-definedness condition or None), kept as :data:`_ENCODED` keeps encodings
_DEFINED: dict[int, tuple[ast.Expr, ast.Expr | None]] = {}


def _definedness(formula: ast.Expr) -> ast.Expr | None:
    """``formula``'s well-definedness condition (:func:`~.definedness.defined`),
    ``None`` for a formula of total operators; one object per formula, so
    that its encoding is cached as the formula's is."""
    hit = _DEFINED.get(id(formula))
    if hit is not None and hit[0] is formula:
        return hit[1]
    cond = defined(formula)
    out = None if isinstance(cond, ast.BoolLit) and cond.value is True else cond
    _DEFINED[id(formula)] = (formula, out)
    return out


def _encoded(formula: ast.Expr, checked: Checked, node: CheckedNode) -> tuple[z3.BoolRef, dict[str, z3.ExprRef | z3.FuncDeclRef]]:
    """:func:`_encoded_typed` without the axioms."""
    phi, free, _ = _encoded_typed(formula, checked, node)
    return phi, free


#: Z3's resource budget per check (its ``rlimit``, counted in Z3's own
#: steps, about 2 s on an idle core): a budget of work, not of wall-clock
#: time, so a check gives the same answer on a loaded machine, in a parallel
#: run and on CI.
CHECK_RLIMIT = 8_000_000


def check_concrete(formula: ast.Expr, checked: Checked, node: CheckedNode, values: Mapping[str, object], *,
                   timeout_ms: int = SAFETY_TIMEOUT_MS, rlimit: int = CHECK_RLIMIT) -> tuple[bool | None, str]:
    """Does ``formula`` (an RCL formula of ``node``) hold on these concrete values?

    ``values`` maps qualified names (``"in.r"``) to values of
    :mod:`rclverify.semantics.values`; every I/O variable the formula uses must be
    there.  Returns ``(True, "")`` when Z3 proves the formula holds,
    ``(False, "")`` when it is violated, ``(None, reason)`` when Z3 answers
    unknown (``reason`` is Z3's, e.g. ``"max. resource limit exceeded"``)
    within the resource budget ``rlimit`` (Z3 steps; ``timeout_ms``
    milliseconds of wall-clock time are only a safety net: when it fires,
    ``reason`` says "took longer than N s", :mod:`.wallclock`).  Raises ``KeyError`` for a name that is not an I/O
    variable of ``node``, :class:`ConcreteValueError` for a value of the
    wrong shape, :class:`~rclverify.semantics.encode.EncodingError` for a formula
    Z3 cannot express.

    Semantics: shared/DESIGN.md ("Semantics the tool commits to"); a node's
    contract is checked per input/output pair as in the paper, lines 462-495.
    """
    for q in values:
        _io_type(node, q)  # KeyError for a name that is not an I/O variable of the node
    cond = _definedness(formula)
    if cond is not None:  # a partial operator: the formula has a truth value only where it is defined
        ok, why = check_concrete(cond, checked, node, values, timeout_ms=timeout_ms, rlimit=rlimit)
        if ok is not True:
            failures = " or ".join(sorted({f"a {c.failure}" for c in conditions(formula)}))
            return None, (why if ok is None else
                          f"undefined on these values: {expr_to_rcl(cond)} does not hold ({failures})")
    phi, free = _encoded(formula, checked, node)
    consts: list[tuple[z3.ExprRef, z3.ExprRef]] = []
    funcs: list[tuple[z3.FuncDeclRef, z3.ExprRef]] = []
    enc = Encoder(checked.env)
    for q, decl in free.items():
        if q not in values:
            raise KeyError(f"no value given for {node.name}.{q}")
        t, v = _io_type(node, q), values[q]
        if isinstance(t, FuncT):
            if not isinstance(v, FiniteFunction):
                raise ConcreteValueError(f"{q}: {v!r} is not a finite function ({t})")
            funcs.append((decl, finite_interpretation(v, t, enc)))
        else:
            consts.append((decl, to_z3(v, t, enc)))
    if consts:
        phi = z3.substitute(phi, *consts)
    if funcs:
        phi = z3.substitute_funs(phi, *funcs)
    simple = z3.simplify(phi)
    if z3.is_true(simple):
        return True, ""
    if z3.is_false(simple):
        return False, ""
    s = z3.Solver()
    s.set("rlimit", int(rlimit))
    wallclock.note_limit(s, timeout_ms)  # a safety net: its firing is told apart
    s.add(z3.Not(phi), *mathfacts.facts([phi]))
    r, cut = wallclock.check_cut(s)
    if r == z3.unsat:
        return True, ""
    if r == z3.sat and mathfacts.transcendental([phi]):  # the model may give sin/cos a value no real one takes:
        # with every value given, the formula is decided when it keeps one truth value around Python's math values
        unsure = mathfacts.unconfirmed([z3.Not(phi)], s.model())
        if unsure is not None:
            return (True, "") if mathfacts.unconfirmed([phi], s.model()) is None else (None, unsure)
    if r == z3.sat:
        return False, ""
    return None, wallclock.why_unknown(s, cut) or "unknown"


def false_whatever_the_rest(formula: ast.Expr, checked: Checked, node: CheckedNode, values: Mapping[str, object], *,
                            timeout_ms: int = SAFETY_TIMEOUT_MS, rlimit: int = CHECK_RLIMIT) -> bool:
    """Is ``formula`` false for these values of some of ``node``'s inputs and
    outputs whatever values the others take (within their types)?  ``values``
    as for :func:`check_concrete`, but the I/O variables it leaves out are
    free.  ``True`` only when Z3 shows the formula unsatisfiable with them
    (a monitor may then call an answer missing an output false: no value of
    that output could have made it hold); ``False`` when it is satisfiable or
    Z3 cannot say.  Raises as :func:`check_concrete`."""
    for q in values:
        _io_type(node, q)
    phi, free, axioms = _encoded_typed(formula, checked, node)  # encoded once per formula (a monitor asks often)
    enc = Encoder(checked.env)
    consts: list[tuple[z3.ExprRef, z3.ExprRef]] = []
    funcs: list[tuple[z3.FuncDeclRef, z3.ExprRef]] = []
    for q, decl in free.items():
        if q not in values:
            continue
        t, v = _io_type(node, q), values[q]
        if isinstance(t, FuncT):
            if not isinstance(v, FiniteFunction):
                raise ConcreteValueError(f"{q}: {v!r} is not a finite function ({t})")
            funcs.append((decl, finite_interpretation(v, t, enc)))
        else:
            consts.append((decl, to_z3(v, t, enc)))
    body = z3.And(phi, *axioms)  # the free outputs range over their types (NATURAL >= 0, ...)
    if consts:
        body = z3.substitute(body, *consts)
    if funcs:
        body = z3.substitute_funs(body, *funcs)
    s = z3.Solver()
    s.set("rlimit", int(rlimit))
    wallclock.note_limit(s, timeout_ms)
    s.add(body)
    return bool(wallclock.check(s) == z3.unsat)


__all__ = ["ConcreteValueError", "check_concrete", "false_whatever_the_rest", "finite_interpretation", "to_z3"]
