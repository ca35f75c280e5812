"""Canonical forms of RCL formulas for the AJPF mapping table (:mod:`.mapping`).

Both sides of a mapping row and the guarantee are put in the same canonical
form before rows are matched (the rules are in :mod:`.mapping`'s docstring):
negation normal form over :class:`FLit` atoms, :class:`FAnd`/:class:`FOr`
and :class:`FQuant`, bare input/output names qualified, quantified names
renamed apart, quantifiers narrowed to the conjuncts that use them
(:func:`miniscope`), and the disjunctive normal form (:func:`dnf`).  The
integer terms of domain variables, placeholders and ``when`` conditions are
evaluated by :func:`eval_int`/:func:`eval_bool`, with the operators' meaning
from the semantics table (:mod:`rclverify.semantics.operators`).

The traversals are visitors over the RCL syntax (:mod:`rclverify.lang.visit`).
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, Iterable, Iterator, Mapping, Union, cast

from rclverify.lang import ast
from rclverify.lang.printer import is_type
from rclverify.lang.visit import Transformer, Visitor
from rclverify.lang.walk import free_names
from rclverify.semantics.operators import OPERATORS, Undecided

@dataclass(frozen=True)
class FConst:
    value: bool


@dataclass(frozen=True)
class FLit:
    """An atom with a polarity.  ``atom`` is canonical; ``source`` is the RCL
    text it came from (for reports; excluded from equality)."""

    atom: ast.Expr
    positive: bool
    source: ast.Expr | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True)
class FAnd:
    parts: tuple["Form", ...]


@dataclass(frozen=True)
class FOr:
    parts: tuple["Form", ...]


@dataclass(frozen=True)
class FQuant:
    """``exists``/``forall`` over ``names`` (with their ``domains``)."""

    kind: str
    names: tuple[str, ...]
    domains: tuple[Any, ...]
    body: "Form"
    source: ast.Expr | None = field(default=None, compare=False, repr=False)


Form = Union[FConst, FLit, FAnd, FOr, FQuant]
#: What a conjunct of a disjunctive normal form is made of.
Item = Union[FLit, FQuant]


def expr_vars(e: Any) -> set[str]:
    """Names of the unprefixed variables occurring free in an RCL expression
    (applied function and constructor names and type-named domains excluded)."""
    return free_names(e, heads=False, type_names=False)


def form_vars(f: Form) -> set[str]:
    """Free unprefixed variable names of a canonical form."""
    if isinstance(f, FConst):
        return set()
    if isinstance(f, FLit):
        return expr_vars(f.atom)
    if isinstance(f, (FAnd, FOr)):
        out: set[str] = set()
        for p in f.parts:
            out |= form_vars(p)
        return out
    return form_vars(f.body) - set(f.names)




class _Subst(Transformer):
    """Free unprefixed variables replaced by ``m[name]`` (shadowing respected);
    an applied function's name, ranges and tuple quantifiers left as they are."""

    def visit_Var(self, e: ast.Var, m: Mapping[str, ast.Expr]) -> ast.Expr:
        return m.get(e.name, e) if e.prefix is None else e

    def visit_Apply(self, e: ast.Apply, m: Mapping[str, ast.Expr]) -> ast.Expr:
        return replace(e, args=tuple(self.visit(a, m) for a in e.args))

    def visit_Quant(self, e: ast.Quant, m: Mapping[str, ast.Expr]) -> ast.Expr:
        inner = {k: v for k, v in m.items() if k not in e.variables}
        bindings = tuple(b if is_type(b.domain) else replace(b, domain=self.visit(b.domain, m))
                         for b in e.bindings)
        return replace(e, bindings=bindings, body=self.visit(e.body, inner))

    def visit_SeqRange(self, e: ast.SeqRange, m: Mapping[str, ast.Expr]) -> ast.Expr:
        return e

    def visit_TupleQuant(self, e: ast.TupleQuant, m: Mapping[str, ast.Expr]) -> ast.Expr:
        return e


def subst(e: ast.Expr, m: Mapping[str, ast.Expr]) -> ast.Expr:
    """Replace free unprefixed variables of ``e`` by ``m[name]`` (respects shadowing)."""
    return cast(ast.Expr, _Subst().visit(e, m)) if m else e


class _Qualify(Transformer):
    """Bare I/O names qualified (``at`` -> ``in.at``) outside the names ``bound``;
    an applied function's name, quantifier domains, ranges and tuple
    quantifiers left as they are (locations kept)."""

    def __init__(self, io: Mapping[str, str]) -> None:
        self.io = io

    def visit_Var(self, e: ast.Var, bound: frozenset[str]) -> ast.Expr:
        if e.prefix is None and e.name not in bound and e.name in self.io:
            return ast.Var(e.name, self.io[e.name], e.loc)  # type: ignore[arg-type]
        return e

    def visit_Apply(self, e: ast.Apply, bound: frozenset[str]) -> ast.Expr:
        return replace(e, args=tuple(self.visit(a, bound) for a in e.args))

    def visit_Quant(self, e: ast.Quant, bound: frozenset[str]) -> ast.Expr:
        return replace(e, body=self.visit(e.body, bound | frozenset(e.variables)))

    def visit_SeqRange(self, e: ast.SeqRange, bound: frozenset[str]) -> ast.Expr:
        return e

    def visit_TupleQuant(self, e: ast.TupleQuant, bound: frozenset[str]) -> ast.Expr:
        return e


class Canon:
    """Puts RCL formulas in canonical form (see the module docstring).

    ``io`` maps a bare input/output name to its prefix (``"in"``/``"out"``),
    inputs first as the type checker resolves them.  ``used`` collects every
    quantified name met so far; a quantifier re-using one is renamed apart
    (``x`` -> ``x_2``), so that eliminating existential variables of two
    different quantifiers can never confuse them.
    """

    def __init__(self, io: Mapping[str, str] | None = None, used: Iterable[str] = ()) -> None:
        self.io = dict(io or {})
        self.used = set(used)

    def fresh(self, name: str) -> str:
        k = 2
        while f"{name}_{k}" in self.used:
            k += 1
        return f"{name}_{k}"

    # -- terms -------------------------------------------------------------
    def term(self, e: ast.Expr, bound: frozenset[str]) -> ast.Expr:
        """Qualify bare I/O names; everything else unchanged (locations kept)."""
        return cast(ast.Expr, _Qualify(self.io).visit(e, bound))

    # -- formulas ----------------------------------------------------------
    def form(self, e: ast.Expr, positive: bool = True, bound: frozenset[str] = frozenset()) -> Form:
        """Canonical form of ``e`` (negated when ``positive`` is false)."""
        return _Former(self).visit(e, positive, bound)

    def _pair(self, a: ast.Expr, op: str, b: ast.Expr, positive: bool, bound: frozenset[str],
              source: ast.Expr) -> Form:
        for lit, other in ((b, a), (a, b)):
            if isinstance(lit, ast.BoolLit) and op in ("==", "!="):
                truth = lit.value if op == "==" else not lit.value
                inner = self.form(other, positive == truth, bound)
                if isinstance(inner, FLit):
                    return replace(inner, source=source)
                return inner
        ta, tb = self.term(a, bound), self.term(b, bound)
        if op == "!=":
            return FLit(ast.Compare(("==",), (ta, tb), source.loc), not positive, source)
        return FLit(ast.Compare((op,), (ta, tb), source.loc), positive, source)  # type: ignore[arg-type]

    def _quant(self, e: ast.Quant, positive: bool, bound: frozenset[str]) -> Form:
        names: list[str] = []
        domains: list[Any] = []
        renaming: dict[str, ast.Expr] = {}
        for b in e.bindings:
            for n in b.names:
                new = self.fresh(n) if n in self.used else n
                self.used.add(new)
                if new != n:
                    renaming[n] = ast.Var(new, None)
                names.append(new)
                domains.append(b.domain)
        body_expr = subst(e.body, renaming)
        inner = bound | frozenset(names)
        # forall <-> exists under negation
        kind = e.kind if positive else ("exists" if e.kind == "forall" else "forall")
        body = self.form(body_expr, positive, inner)
        return miniscope(FQuant(kind, tuple(names), tuple(domains), body, e))


class _Former(Visitor[Form]):
    """The canonical form of one formula for :meth:`Canon.form`: connectives
    pushed into negation normal form, comparisons split, every other
    expression an atom (:meth:`generic_visit`)."""

    def __init__(self, canon: Canon) -> None:
        self.c = canon

    def generic_visit(self, e: Any, positive: bool, bound: frozenset[str]) -> Form:
        return FLit(self.c.term(e, bound), positive, e)

    def visit_BoolLit(self, e: ast.BoolLit, positive: bool, bound: frozenset[str]) -> Form:
        return FConst(e.value == positive)

    def visit_Unary(self, e: ast.Unary, positive: bool, bound: frozenset[str]) -> Form:
        if e.op == "not":
            return self.visit(e.operand, not positive, bound)
        return self.generic_visit(e, positive, bound)

    def visit_Binary(self, e: ast.Binary, positive: bool, bound: frozenset[str]) -> Form:
        form = self.c.form
        if e.op in ("and", "or"):
            left, right = form(e.left, positive, bound), form(e.right, positive, bound)
            return FAnd((left, right)) if (e.op == "and") == positive else FOr((left, right))
        if e.op == "->":
            if positive:
                return FOr((form(e.left, False, bound), form(e.right, True, bound)))
            return FAnd((form(e.left, True, bound), form(e.right, False, bound)))
        if e.op == "<=>":
            a, na = form(e.left, True, bound), form(e.left, False, bound)
            b, nb = form(e.right, True, bound), form(e.right, False, bound)
            if positive:
                return FOr((FAnd((a, b)), FAnd((na, nb))))
            return FOr((FAnd((a, nb)), FAnd((na, b))))
        return self.generic_visit(e, positive, bound)

    def visit_Compare(self, e: ast.Compare, positive: bool, bound: frozenset[str]) -> Form:
        pairs = [self.c._pair(e.operands[k], e.ops[k], e.operands[k + 1], positive, bound, e)
                 for k in range(len(e.ops))]
        if len(pairs) == 1:
            return pairs[0]
        return FAnd(tuple(pairs)) if positive else FOr(tuple(pairs))

    def visit_Member(self, e: ast.Member, positive: bool, bound: frozenset[str]) -> Form:
        atom = ast.Member(self.c.term(e.elem, bound), self.c.term(e.collection, bound), False, e.loc)
        return FLit(atom, positive != e.negated, e)

    def visit_Quant(self, e: ast.Quant, positive: bool, bound: frozenset[str]) -> Form:
        if e.kind in ("forall", "exists"):
            return self.c._quant(e, positive, bound)
        return self.generic_visit(e, positive, bound)


def miniscope(q: FQuant) -> Form:
    """Narrow a quantifier to the conjuncts that mention its variables.

    ``forall v (A and B)`` with ``v`` not in ``B`` is ``(forall v A) and B``
    (and likewise for ``exists``) when ``v`` ranges over a type, whose values
    exist; variables not used in the body are dropped.  Finite-set domains
    (which may be empty) are left as they are.
    """
    if not all(is_type(d) for d in q.domains):
        return q
    used = form_vars(q.body)
    keep = [(n, d) for n, d in zip(q.names, q.domains) if n in used]
    if not keep:
        return q.body
    names = tuple(n for n, _ in keep)
    domains = tuple(d for _, d in keep)
    if isinstance(q.body, FAnd):
        inside = tuple(p for p in q.body.parts if form_vars(p) & set(names))
        outside = tuple(p for p in q.body.parts if not form_vars(p) & set(names))
        if outside:
            body = inside[0] if len(inside) == 1 else FAnd(inside)
            return FAnd(outside + (FQuant(q.kind, names, domains, body, q.source),))
    return FQuant(q.kind, names, domains, q.body, q.source)


# ---------------------------------------------------------------------------
# Integer evaluation (domain variables, placeholders, `when`)
# ---------------------------------------------------------------------------


class _Int(Visitor["int | None"]):
    """An integer term's value (:func:`eval_int`); ``None`` for anything else."""

    def generic_visit(self, e: Any, values: Mapping[str, int]) -> int | None:
        return None

    def visit_NumLit(self, e: ast.NumLit, values: Mapping[str, int]) -> int | None:
        return int(e.value) if e.value.denominator == 1 else None

    def visit_Var(self, e: ast.Var, values: Mapping[str, int]) -> int | None:
        return values.get(e.name) if e.prefix is None else None

    def visit_Unary(self, e: ast.Unary, values: Mapping[str, int]) -> int | None:
        v = self.visit(e.operand, values) if e.op == "-" else None
        return None if v is None else -v

    def visit_Binary(self, e: ast.Binary, values: Mapping[str, int]) -> int | None:
        entry = OPERATORS[e.op]
        if entry.kind != "arithmetic":
            return None
        a, b = self.visit(e.left, values), self.visit(e.right, values)
        if a is None or b is None:
            return None
        try:
            v = entry.exact(a, b)
        except Undecided:  # a zero divisor
            return None
        return int(v) if v.denominator == 1 else None  # "/" only when exact


class _Bool(Visitor["bool | None"]):
    """A condition's truth over integers (:func:`eval_bool`); ``None`` for anything else."""

    def generic_visit(self, e: Any, values: Mapping[str, int]) -> bool | None:
        return None

    def visit_BoolLit(self, e: ast.BoolLit, values: Mapping[str, int]) -> bool | None:
        return e.value

    def visit_Unary(self, e: ast.Unary, values: Mapping[str, int]) -> bool | None:
        v = self.visit(e.operand, values) if e.op == "not" else None
        return None if v is None else not v

    def visit_Binary(self, e: ast.Binary, values: Mapping[str, int]) -> bool | None:
        entry = OPERATORS[e.op]
        if entry.kind != "connective":
            return None
        a, b = self.visit(e.left, values), self.visit(e.right, values)
        if a is None or b is None:
            return None
        return bool(entry.exact(a, b))

    def visit_Compare(self, e: ast.Compare, values: Mapping[str, int]) -> bool | None:
        nums = [eval_int(o, values) for o in e.operands]
        if any(n is None for n in nums):
            return None
        return all(OPERATORS[op].exact(nums[k], nums[k + 1]) for k, op in enumerate(e.ops))


def eval_int(e: ast.Expr, values: Mapping[str, int]) -> int | None:
    """Value of an integer term built from literals, ``values`` and ``+ - *``
    (``/`` when exact); ``None`` when ``e`` is not such a term."""
    return _Int().visit(e, values)


def eval_bool(e: ast.Expr, values: Mapping[str, int]) -> bool | None:
    """Truth of a condition over integers (comparisons, ``and``, ``or``,
    ``not``, ``->``, ``<=>``, ``TRUE``/``FALSE``); ``None`` when it is not one."""
    return _Bool().visit(e, values)


def dnf(f: Form, limit: int = 512) -> Iterator[tuple[tuple[Item, ...], frozenset[str]]]:
    """Disjunctive normal form of a canonical form.

    Yields ``(items, evars)`` per conjunct: ``items`` are literals and
    universally quantified sub-formulas (kept whole, as atoms), ``evars`` the
    variables of the existential quantifiers eliminated into the conjunct
    (``exists v (A or B)`` is ``(exists v A) or (exists v B)``).  Raises
    ``ValueError`` when there would be more than ``limit`` conjuncts.
    """
    out = _dnf(f, limit)
    yield from out


def _dnf(f: Form, limit: int) -> list[tuple[tuple[Item, ...], frozenset[str]]]:
    if isinstance(f, FConst):
        return [((), frozenset())] if f.value else []
    if isinstance(f, FLit):
        return [((f,), frozenset())]
    if isinstance(f, FQuant):
        if f.kind == "exists":
            return [(items, ev | frozenset(f.names)) for items, ev in _dnf(f.body, limit)]
        return [((f,), frozenset())]
    if isinstance(f, FOr):
        out: list[tuple[tuple[Item, ...], frozenset[str]]] = []
        for p in f.parts:
            out.extend(_dnf(p, limit))
            if len(out) > limit:
                raise ValueError(f"the formula has more than {limit} conjuncts in disjunctive normal form")
        return out
    acc: list[tuple[tuple[Item, ...], frozenset[str]]] = [((), frozenset())]
    for p in f.parts:
        nxt = []
        for items2, ev2 in _dnf(p, limit):
            for items1, ev1 in acc:
                nxt.append((items1 + items2, ev1 | ev2))
        if len(nxt) > limit:
            raise ValueError(f"the formula has more than {limit} conjuncts in disjunctive normal form")
        acc = nxt
    return acc
