"""Static analysis of quantifier bodies for direct evaluation, memoised
per AST node: under which shifts a bound variable occurs (``i + 1``), which
literals and outer names it is compared with, literal integer bounds of a
guard (``k <= 12 -> ...``), constructor terms holding it, the variables
that occur only together as a whole argument list (``at(x, y)``), and
whether a body reads a variable at all.  A function of the formula alone:
the values are read per evaluation by :mod:`rclverify.semantics.eval_quant`.

Part of the direct evaluator (:mod:`rclverify.semantics.evaluate`, whose module
docstring states the semantics).
"""
from __future__ import annotations

import dataclasses
import math
from fractions import Fraction
from typing import Any, Iterable, cast

from rclverify.lang import ast

from rclverify.lang import typeexpr
from rclverify.semantics.eval_values import _INFINITE
from rclverify.semantics.operators import OPERATORS

#: the order comparisons (their converse is the semantics table's)
_ORDER = frozenset({"<", "<=", ">", ">="})


#: node class -> the subexpressions the shape analyses look into: an applied
#: function's arguments (not its name), a quantifier's body (not its domains)
_CHILDREN: dict[type, Any] = {
    ast.Apply: lambda e: e.args, ast.Unary: lambda e: (e.operand,), ast.Binary: lambda e: (e.left, e.right),
    ast.Compare: lambda e: e.operands, ast.Member: lambda e: (e.elem, e.collection),
    ast.SetLit: lambda e: e.items, ast.TupleLit: lambda e: e.items, ast.SeqLit: lambda e: e.items,
    ast.Quant: lambda e: (e.body,),
}


def _children(e: Any) -> Iterable[Any]:
    of = _CHILDREN.get(type(e))
    return () if of is None else cast(Iterable[Any], of(e))


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


def _literals(e: Any, out: set[Any]) -> None:
    if isinstance(e, ast.NumLit):
        out.add(e.value)
    if isinstance(e, ast.Unary) and e.op == "-" and isinstance(e.operand, ast.NumLit):
        out.add(-e.operand.value)
    for c in _children(e):
        _literals(c, out)


def _unused(e: ast.Quant, name: str, binding: ast.Binding) -> bool:
    """True when ``name`` ranges over REAL, INTEGER or NATURAL (never empty) and
    does not occur free in ``e``'s body: the body's value is the same for every
    value of it, so ``forall``/``exists`` over it need one value (not for
    ``exists_unique``, where a true body has infinitely many witnesses).
    Memoised per AST node."""
    dom = binding.domain
    if not (isinstance(dom, typeexpr.TBase) and dom.name in _INFINITE):
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
    rel: str = op
    if is_name(c) and lit(a) is not None and op in _ORDER:  # c op name: name (op's converse) c
        rel, a, c = str(OPERATORS[op].converse), c, a
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
