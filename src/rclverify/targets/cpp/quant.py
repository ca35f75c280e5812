"""Bounded RCL quantifiers as C++17 loops in the generated check header (docs/generate.md).

The header makes rclverify's *double* reading of a clause (``semantics/floatsem.py``), and that
reading enumerates a quantifier over a finite domain only (floatsem's module docstring,
``_finite_domain``): ``BOOL``, an enumeration, a finite set, an ``INTEGER``/``NATURAL``
variable bounded by literal guards (``forall(i in NATURAL | i <= 12 -> ...)``, the range
``eval_shapes._integer_range`` reads, at most ``MAX_RANGE`` values), or a numeric variable the
body never mentions (``forall``/``exists`` only); at most ``MAX_ENUMERATION`` assignments in
all.  A ``REAL``/``INTEGER``/``NATURAL`` variable with no literal bound is decided, in the double
reading only, at its candidate points (``semantics/candidates.py``; the loops are
:mod:`.cpp_candidates`'s).  Any other quantifier (a variable in arithmetic, compared with a term
of inner variables, ...) is *undecided* there, and so here: its code throws
``rclverify_rt::Undecided`` with the reason, before the body (the body is not translated: the
reading never evaluates it).

Each translated quantifier is an immediately invoked lambda looping over the domains in
binding order (the first name outermost, as ``itertools.product``), with the double reading's
short cuts: ``forall`` stops at the first false body, ``exists`` at the first true one,
``exists_unique`` at the second true one; an undecided body (division by zero) makes the
whole clause undecided, as the Python reading's exception does.

Not translated (:class:`.cpp_common.Untranslatable`: the clause's check answers undecided):
a domain that is an input or output (sets and sequences are not held in the header), a set
whose items are not literals, a tuple binder.
"""
from __future__ import annotations

from fractions import Fraction
from typing import Any

from rclverify.semantics.candidates import NotInFragment, analyse
from rclverify.semantics.eval_shapes import MAX_RANGE, _integer_range, _unused
from rclverify.semantics.floatsem import MAX_ENUMERATION
from rclverify.lang import ast
from rclverify.lang import typeexpr
from rclverify.lang.types import EnumT, Scalar
from rclverify.targets.cpp.candidates import candidate_code
from rclverify.targets.names import cpp_local
from rclverify.targets.cpp.common import Untranslatable, enum_const


class _Undecided(Exception):
    """The double reading cannot enumerate this domain (the reason in ``str``)."""


def cpp_ident(name: str) -> str:
    """The C++ name of a bound variable: ``x'`` -> ``qp_x`` (:func:`.names.cpp_local`)."""
    return cpp_local(name)


def quantifier(tr: Any, e: ast.Quant) -> tuple[str, str]:
    """``(code, "bool")`` for quantifier ``e`` under translator ``tr`` (a
    :class:`.expr.CppTranslator`: its ``expr``, its bound variables in ``tr.bound``, its
    ``notes``); raises :class:`.cpp_common.Untranslatable`."""
    loops: list[tuple[str, str, Any]] = []  # (C++ name, kind, domain: ("values", [code]) | ("range", lo, hi))
    size = 1
    names = [n for bd in e.bindings for n in bd.names]
    k = 0
    try:
        for bd in e.bindings:
            for n in bd.names:
                k += 1
                try:
                    dom = _domain(tr, e, bd, n)
                except _Undecided as why:  # the double reading's candidate points, where they decide
                    loops.append((n, *_candidates(tr, e, bd, n, names[k:], why)))
                    continue
                if dom is None:  # unused: the body's value is the same for every value of it
                    continue
                kind, spec = dom
                size *= max(_count(spec), 1)
                if size > MAX_ENUMERATION:
                    raise _Undecided(f"quantifier over more than {MAX_ENUMERATION} values")
                loops.append((n, kind, spec))
    except _Undecided as why:
        tr.notes.append(str(why))
        return f"rclverify_rt::undecided({_c_string(str(why))})", "bool"
    if any(kind.startswith("cand:") for _, kind, _ in loops):
        return candidate_code(tr, e, loops, cpp_ident, _CTYPES)
    saved = dict(tr.bound)
    try:
        for n, kind, _ in loops:
            tr.bound[n] = (cpp_ident(n), kind)
        body, bkind = tr.expr(e.body)
    finally:
        tr.bound.clear()
        tr.bound.update(saved)
    if bkind != "bool":
        raise Untranslatable(f"a quantifier body of type {bkind}")
    if e.kind == "forall":
        step, end = "if (!(" + body + ")) { return false; }", "return true;"
    elif e.kind == "exists":
        step, end = "if (" + body + ") { return true; }", "return false;"
    else:
        step, end = "if ((" + body + ") && ++cand_count > 1) { return false; }", "return cand_count == 1;"
    code = step
    for n, kind, spec in reversed(loops):
        ctype = _CTYPES[kind.split(":")[0]]
        v = cpp_ident(n)
        if spec[0] == "range":
            code = f"for ({ctype} {v} = {spec[1]}; {v} <= {spec[2]}; ++{v}) {{ {code} }}"  # literal bounds
        elif spec[1]:
            code = f"for (const {ctype} {v} : {{{', '.join(spec[1])}}}) {{ static_cast<void>({v}); {code} }}"
        else:  # an empty domain: no assignment
            code = ""
    count = "int cand_count = 0; " if e.kind == "exists_unique" else ""
    return f"([&]() -> bool {{ {count}{code} {end} }}())", "bool"


_CTYPES = {"int": "std::int64_t", "bool": "bool", "enum": "std::uint8_t", "double": "double"}


def _candidates(tr: Any, e: ast.Quant, bd: ast.Binding, name: str, later: list[str],
                why: _Undecided) -> tuple[str, Any]:
    """``("cand:<NUMERIC>", sources)`` of a variable over an unbounded numeric domain (double reading
    only: the tolerance reading enumerates finite domains only); raises :class:`_Undecided`."""
    numeric = _numeric(tr, bd.domain)
    if tr.mode != "double" or numeric is None or "without a literal bound" not in str(why):
        raise why
    try:
        return f"cand:{numeric}", analyse(e.body, name, numeric, frozenset(later), tr.env)
    except NotInFragment as nf:
        raise _Undecided(f"{why}, and not by candidate points: {nf}") from None


def _numeric(tr: Any, dom: Any) -> str | None:
    name = dom.name if isinstance(dom, typeexpr.TBase) else None
    if isinstance(dom, typeexpr.TName):
        t = tr.env.types.get(dom.name)
        name = t.name if isinstance(t, Scalar) else None
    return name if name in ("REAL", "INTEGER", "NATURAL") else None


def _count(spec: tuple[Any, ...]) -> int:
    return spec[2] - spec[1] + 1 if spec[0] == "range" else len(spec[1])


def _domain(tr: Any, e: ast.Quant, bd: ast.Binding, name: str) -> tuple[str, tuple[Any, ...]] | None:
    """``(kind, spec)`` of bound variable ``name``, ``None`` when the body does not read it
    (floatsem ``_finite_domain``'s cases, in its order); raises :class:`_Undecided`."""
    dom = bd.domain
    env = tr.env
    if isinstance(dom, typeexpr.TEnum):
        t = env.enum_values.get(dom.values[0]) if dom.values else None
        if t is None:
            raise Untranslatable("a quantifier over an enumeration the context does not declare")
        return f"enum:{t.name}", ("values", [enum_const(t, v) for v in dom.values])
    typ: Any = None
    if isinstance(dom, typeexpr.TBase):
        typ = Scalar(dom.name) if dom.name in ("REAL", "INTEGER", "NATURAL", "BOOL") else None
    elif isinstance(dom, typeexpr.TName):
        typ = env.types.get(dom.name)
    elif isinstance(dom, ast.SetLit):
        return _set_domain(tr, dom.items)
    elif isinstance(dom, ast.Var):
        if dom.prefix is None and dom.name in env.constants and isinstance(env.constants[dom.name][1], ast.SetLit):
            return _set_domain(tr, env.constants[dom.name][1].items)
        raise Untranslatable(f"a quantifier over {dom.qualified} (sets and sequences are not held here)")
    if isinstance(typ, EnumT):
        return f"enum:{typ.name}", ("values", [enum_const(typ, v) for v in typ.values])
    if isinstance(typ, Scalar):
        if typ.name == "BOOL":
            return "bool", ("values", ["false", "true"])
        if e.kind in ("forall", "exists") and _unused(e, name, bd):
            return None
        bounded = _integer_range(e.body, name, typ.name, e.kind)
        if bounded is not None and len(bounded) <= MAX_RANGE:
            if not bounded:
                return "int", ("values", [])
            return "int", ("range", bounded[0], bounded[-1])
        raise _Undecided(f"{name} ranges over {typ.name} without a literal bound: not enumerable "
                         f"outside exact arithmetic")
    raise _Undecided(f"quantifier over {type(dom).__name__} is not finite")


def _set_domain(tr: Any, items: tuple[Any, ...]) -> tuple[str, tuple[Any, ...]]:
    """A set literal's items as loop values, once each, in the order the Python reading's set
    iterates them (numbers; enumeration values in the order written)."""
    codes: list[tuple[Any, str]] = []
    kinds: set[str] = set()
    for item in items:
        code, kind = tr.expr(item)
        lit = _literal(item, tr)
        if lit is None:
            raise Untranslatable("a quantifier over a set whose items are not literals")
        kinds.add(kind.split(":")[0] if not kind.startswith("enum") else kind)
        codes.append((lit, code))
    if len(kinds) > 1:
        raise Untranslatable(f"a quantifier over a set of mixed kinds {sorted(kinds)}")
    kind = kinds.pop() if kinds else "int"
    order = {v: c for v, c in codes}  # once each (the Python reading's set); numbers in its set order
    values = list(set(order)) if kind in ("int", "double", "bool") else list(order)
    return kind, ("values", [order[v] for v in values])


def _literal(item: Any, tr: Any) -> Any:
    if isinstance(item, ast.NumLit):
        v = item.value
        return int(v) if v.denominator == 1 else float(Fraction(v))
    if isinstance(item, ast.Unary) and item.op == "-" and isinstance(item.operand, ast.NumLit):
        v = -item.operand.value
        return int(v) if v.denominator == 1 else float(Fraction(v))
    if isinstance(item, ast.BoolLit):
        return item.value
    if isinstance(item, ast.Var) and item.prefix is None and item.name in tr.env.enum_values:
        return item.name
    return None


def _c_string(s: str) -> str:
    return '"' + s.replace("\\", "\\\\").replace('"', '\\"') + '"'


__all__ = ["cpp_ident", "quantifier"]
