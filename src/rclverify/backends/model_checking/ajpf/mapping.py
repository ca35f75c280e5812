"""The mapping table from RCL atoms to AJPF propositions, and how rows match.

The paper verifies the Agent node with AJPF after translating the RCL
predicates of its guarantees into BDI propositions about the Gwendolen
program by hand (table at paper lines 1396-1412).  Here that table is data in
the verification plan: each row maps an RCL conjunction of atoms, written
with the guarantee's variable names, to an AJPF formula::

    mapping:
      - rcl: "in.at(x', y') == TRUE and in.wayP(x', y') == i"
        ajpf: "B(jackal, going({i})) & B(jackal, movebase_result(_, 3))"
      - rcl: "in.wayP(x, y) == i and out.command == move(x, y)"
        when: "i <= 12"
        ajpf: "B(jackal, going({i}))"

Meaning of a row (what the user asserts by writing it): in every state of
the agent program, the ``ajpf`` formula holds exactly when the ``rcl``
conjunction holds for *some* values of its non-domain variables (``x'``,
``y'`` above).  Rows are matched on the RCL abstract syntax, never on text:

* both sides are put in a canonical form first: negation normal form,
  ``e == TRUE`` is the atom ``e``, ``e == FALSE``/``e != TRUE`` its
  negation, ``a != b`` the negation of ``a == b``, ``x !in S`` the negation
  of ``x in S``, chained comparisons split, ``==`` is symmetric, set
  literals are unordered, bare input/output names are qualified;
* a *domain variable* of the row (a name listed under ``domains``, e.g.
  ``i``) matches any integer term over the instance's values (``i``,
  ``i + 1``, ``0``) and takes its value; ``{i}``, ``{i+1}`` placeholders in
  ``ajpf`` and the optional ``when`` condition are evaluated with it;
* any other variable of the row (``x'``, ``y'``) matches a variable the
  guarantee quantifies existentially, one-to-one (renaming is free);
* enumeration values, constants, constructors and ``in.``/``out.`` names
  match only themselves.

A row covers a *sub-conjunction* of a conjunct of the guarantee (see
:mod:`.instantiate`); a one-atom row without non-domain variables also covers
that atom's negation (its ``ajpf`` formula is then negated), so
``in.inspected(i) == FALSE`` is covered by the row for
``in.inspected(i) == TRUE``.
"""
from __future__ import annotations

import itertools
import re
from dataclasses import dataclass, field, replace
from typing import Any, Iterable, Iterator, Mapping, Sequence, Union, cast

from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.walk import free_names
from rclverify.lang.errors import RclError
from rclverify.lang.parser import parse_formula
from rclverify.backends.model_checking.ajpf import psl

# ---------------------------------------------------------------------------
# Canonical forms
# ---------------------------------------------------------------------------


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


_TYPE_NODES = (ast.TBase, ast.TName, ast.TEnum, ast.TConstructors, ast.TFunc, ast.TEmpty, ast.TSet, ast.TSeq,
               ast.TTuple)


def _is_type(d: Any) -> bool:
    return isinstance(d, _TYPE_NODES)


def subst(e: ast.Expr, m: Mapping[str, ast.Expr]) -> ast.Expr:
    """Replace free unprefixed variables of ``e`` by ``m[name]`` (respects shadowing)."""
    if not m:
        return e
    if isinstance(e, ast.Var):
        return m.get(e.name, e) if e.prefix is None else e
    if isinstance(e, ast.Apply):
        return replace(e, args=tuple(subst(a, m) for a in e.args))
    if isinstance(e, ast.Unary):
        return replace(e, operand=subst(e.operand, m))
    if isinstance(e, ast.Binary):
        return replace(e, left=subst(e.left, m), right=subst(e.right, m))
    if isinstance(e, ast.Compare):
        return replace(e, operands=tuple(subst(o, m) for o in e.operands))
    if isinstance(e, ast.Member):
        return replace(e, elem=subst(e.elem, m), collection=subst(e.collection, m))
    if isinstance(e, (ast.SetLit, ast.TupleLit, ast.SeqLit)):
        return replace(e, items=tuple(subst(o, m) for o in e.items))
    if isinstance(e, ast.Quant):
        inner = {k: v for k, v in m.items() if k not in e.variables}
        bindings = tuple(b if _is_type(b.domain) else replace(b, domain=subst(cast(ast.Expr, b.domain), m))
                         for b in e.bindings)
        return replace(e, bindings=bindings, body=subst(e.body, inner))
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
        if isinstance(e, ast.Var):
            if e.prefix is None and e.name not in bound and e.name in self.io:
                return ast.Var(e.name, self.io[e.name], e.loc)  # type: ignore[arg-type]
            return e
        if isinstance(e, ast.Apply):
            return replace(e, args=tuple(self.term(a, bound) for a in e.args))
        if isinstance(e, ast.Unary):
            return replace(e, operand=self.term(e.operand, bound))
        if isinstance(e, ast.Binary):
            return replace(e, left=self.term(e.left, bound), right=self.term(e.right, bound))
        if isinstance(e, ast.Compare):
            return replace(e, operands=tuple(self.term(o, bound) for o in e.operands))
        if isinstance(e, ast.Member):
            return replace(e, elem=self.term(e.elem, bound), collection=self.term(e.collection, bound))
        if isinstance(e, (ast.SetLit, ast.TupleLit, ast.SeqLit)):
            return replace(e, items=tuple(self.term(o, bound) for o in e.items))
        if isinstance(e, ast.Quant):
            return replace(e, body=self.term(e.body, bound | frozenset(e.variables)))
        return e

    # -- formulas ----------------------------------------------------------
    def form(self, e: ast.Expr, positive: bool = True, bound: frozenset[str] = frozenset()) -> Form:
        """Canonical form of ``e`` (negated when ``positive`` is false)."""
        if isinstance(e, ast.BoolLit):
            return FConst(e.value == positive)
        if isinstance(e, ast.Unary) and e.op == "not":
            return self.form(e.operand, not positive, bound)
        if isinstance(e, ast.Binary) and e.op in ("and", "or"):
            left, right = self.form(e.left, positive, bound), self.form(e.right, positive, bound)
            return FAnd((left, right)) if (e.op == "and") == positive else FOr((left, right))
        if isinstance(e, ast.Binary) and e.op == "->":
            if positive:
                return FOr((self.form(e.left, False, bound), self.form(e.right, True, bound)))
            return FAnd((self.form(e.left, True, bound), self.form(e.right, False, bound)))
        if isinstance(e, ast.Binary) and e.op == "<=>":
            a, na = self.form(e.left, True, bound), self.form(e.left, False, bound)
            b, nb = self.form(e.right, True, bound), self.form(e.right, False, bound)
            if positive:
                return FOr((FAnd((a, b)), FAnd((na, nb))))
            return FOr((FAnd((a, nb)), FAnd((na, b))))
        if isinstance(e, ast.Compare):
            pairs = [self._pair(e.operands[k], e.ops[k], e.operands[k + 1], positive, bound, e)
                     for k in range(len(e.ops))]
            if len(pairs) == 1:
                return pairs[0]
            return FAnd(tuple(pairs)) if positive else FOr(tuple(pairs))
        if isinstance(e, ast.Member):
            atom = ast.Member(self.term(e.elem, bound), self.term(e.collection, bound), False, e.loc)
            return FLit(atom, positive != e.negated, e)
        if isinstance(e, ast.Quant) and e.kind in ("forall", "exists"):
            return self._quant(e, positive, bound)
        return FLit(self.term(e, bound), positive, e)

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


def miniscope(q: FQuant) -> Form:
    """Narrow a quantifier to the conjuncts that mention its variables.

    ``forall v (A and B)`` with ``v`` not in ``B`` is ``(forall v A) and B``
    (and likewise for ``exists``) when ``v`` ranges over a type, whose values
    exist; variables not used in the body are dropped.  Finite-set domains
    (which may be empty) are left as they are.
    """
    if not all(_is_type(d) for d in q.domains):
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


def eval_int(e: ast.Expr, values: Mapping[str, int]) -> int | None:
    """Value of an integer term built from literals, ``values`` and ``+ - *``
    (``/`` when exact); ``None`` when ``e`` is not such a term."""
    if isinstance(e, ast.NumLit):
        return int(e.value) if e.value.denominator == 1 else None
    if isinstance(e, ast.Var):
        return values.get(e.name) if e.prefix is None else None
    if isinstance(e, ast.Unary) and e.op == "-":
        v = eval_int(e.operand, values)
        return None if v is None else -v
    if isinstance(e, ast.Binary) and e.op in ("+", "-", "*", "/"):
        a, b = eval_int(e.left, values), eval_int(e.right, values)
        if a is None or b is None:
            return None
        if e.op == "+":
            return a + b
        if e.op == "-":
            return a - b
        if e.op == "*":
            return a * b
        return a // b if b != 0 and a % b == 0 else None
    return None


def eval_bool(e: ast.Expr, values: Mapping[str, int]) -> bool | None:
    """Truth of a condition over integers (comparisons, ``and``, ``or``,
    ``not``, ``->``, ``<=>``, ``TRUE``/``FALSE``); ``None`` when it is not one."""
    if isinstance(e, ast.BoolLit):
        return e.value
    if isinstance(e, ast.Unary) and e.op == "not":
        v = eval_bool(e.operand, values)
        return None if v is None else not v
    if isinstance(e, ast.Binary) and e.op in ("and", "or", "->", "<=>"):
        a, b = eval_bool(e.left, values), eval_bool(e.right, values)
        if a is None or b is None:
            return None
        return {"and": a and b, "or": a or b, "->": (not a) or b, "<=>": a == b}[e.op]
    if isinstance(e, ast.Compare):
        nums = [eval_int(o, values) for o in e.operands]
        if any(n is None for n in nums):
            return None
        ops = {"==": lambda x, y: x == y, "!=": lambda x, y: x != y, "<": lambda x, y: x < y,
               "<=": lambda x, y: x <= y, ">": lambda x, y: x > y, ">=": lambda x, y: x >= y}
        return all(ops[op](nums[k], nums[k + 1]) for k, op in enumerate(e.ops))
    return None


# ---------------------------------------------------------------------------
# Matching
# ---------------------------------------------------------------------------


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
        for s in _match_struct(p, t, st, cx):
            found = True
            yield s
        if not found:
            pv, tv = eval_int(p, st.values), eval_int(t, cx.values)
            if pv is not None and pv == tv:
                yield st
        return
    yield from _match_struct(p, t, st, cx)


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


def _match_struct(p: ast.Expr, t: ast.Expr, st: State, cx: MatchContext) -> Iterator[State]:
    if type(p) is not type(t):
        return
    if isinstance(p, ast.BoolLit):
        if isinstance(t, ast.BoolLit) and p.value == t.value:
            yield st
    elif isinstance(p, ast.NumLit):
        if isinstance(t, ast.NumLit) and p.value == t.value:
            yield st
    elif isinstance(p, ast.Apply):
        assert isinstance(t, ast.Apply)
        if p.func.qualified == t.func.qualified:
            yield from _match_seq(p.args, t.args, st, cx)
    elif isinstance(p, ast.Unary):
        assert isinstance(t, ast.Unary)
        if p.op == t.op:
            yield from match_expr(p.operand, t.operand, st, cx)
    elif isinstance(p, ast.Binary):
        assert isinstance(t, ast.Binary)
        if p.op == t.op:
            yield from _match_seq((p.left, p.right), (t.left, t.right), st, cx)
            if p.op in ("+", "*", "and", "or", "<=>"):
                yield from _match_seq((p.left, p.right), (t.right, t.left), st, cx)
    elif isinstance(p, ast.Compare):
        assert isinstance(t, ast.Compare)
        if p.ops == t.ops:
            yield from _match_seq(p.operands, t.operands, st, cx)
            if p.ops in (("==",), ("!=",)):
                yield from _match_seq(p.operands, tuple(reversed(t.operands)), st, cx)
    elif isinstance(p, ast.Member):
        assert isinstance(t, ast.Member)
        if p.negated == t.negated:
            yield from _match_seq((p.elem, p.collection), (t.elem, t.collection), st, cx)
    elif isinstance(p, ast.SetLit):
        assert isinstance(t, ast.SetLit)
        if len(p.items) == len(t.items) and len(p.items) <= 6:
            for perm in itertools.permutations(t.items):
                yield from _match_seq(p.items, perm, st, cx)
    elif isinstance(p, (ast.TupleLit, ast.SeqLit)):
        assert isinstance(t, (ast.TupleLit, ast.SeqLit))
        yield from _match_seq(p.items, t.items, st, cx)
    elif isinstance(p, ast.Quant):
        assert isinstance(t, ast.Quant)
        pv, tv = p.variables, t.variables
        if p.kind == t.kind and len(pv) == len(tv) and _domains(p) == _domains(t):
            inner = cx.with_targets(tv)
            for s in match_expr(p.body, t.body, st, inner):
                ren = s.renaming
                if all(ren.get(n, None) in tv for n in pv if n in ren):
                    yield s.unbind(pv)


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


# ---------------------------------------------------------------------------
# Rows
# ---------------------------------------------------------------------------

_PLACEHOLDER = re.compile(r"\{([^{}]*)\}")


@dataclass(frozen=True)
class Row:
    """One mapping row, checked and in canonical form.

    ``index``      0-based position in the plan's ``mapping`` list;
    ``rcl``/``ajpf``/``when_text`` the texts as written;
    ``items``      the RCL side: a conjunction of canonical atoms;
    ``dom_vars``   domain variables occurring in the RCL side;
    ``row_vars``   its other variables (stand for existential variables);
    ``when``       parsed condition (``None`` when absent);
    ``loc``        where the row's ``rcl`` text is in the plan.
    """

    index: int
    rcl: str
    ajpf: str
    when_text: str | None
    items: tuple[Item, ...]
    dom_vars: frozenset[str]
    row_vars: frozenset[str]
    when: ast.Expr | None
    loc: ast.Loc

    @property
    def negatable(self) -> bool:
        """A one-atom row without existential variables also covers the atom's negation."""
        return len(self.items) == 1 and isinstance(self.items[0], FLit) and not self.row_vars

    def applies(self, values: Mapping[str, int]) -> bool:
        """The ``when`` condition holds for the bound domain values."""
        if self.when is None:
            return True
        return bool(eval_bool(self.when, values))

    def render(self, values: Mapping[str, int]) -> psl.Formula:
        """The AJPF formula with placeholders evaluated (``{i+1}`` -> ``5``).

        Raises ``ValueError`` when a placeholder cannot be evaluated (checked
        when the row is loaded, so only for values outside the row's domain).
        """
        return psl.parse(substitute(self.ajpf, values))


def substitute(text: str, values: Mapping[str, int]) -> str:
    """Replace every ``{expr}`` in ``text`` by the integer value of ``expr``.

    ``expr`` is an RCL integer term over ``values`` (``i``, ``i+1``,
    ``i - 1``).  Raises ``ValueError`` naming the placeholder otherwise.
    """
    def one(m: re.Match[str]) -> str:
        try:
            e = parse_formula(m.group(1))
        except RclError:
            raise ValueError(f"placeholder {m.group(0)!r} is not an integer expression") from None
        v = eval_int(e, values)
        if v is None:
            raise ValueError(f"placeholder {m.group(0)!r} cannot be evaluated with {dict(values)}")
        return str(v)

    return _PLACEHOLDER.sub(one, text)


class RowError(ValueError):
    """A mapping row the user got wrong; ``col`` is 1-based within the offending text
    (0 when unknown) and ``key`` names the row key (``rcl``, ``ajpf``, ``when``)."""

    def __init__(self, message: str, key: str, col: int = 0) -> None:
        super().__init__(message)
        self.key = key
        self.col = col


def build_row(index: int, raw: Mapping[str, Any], *, dom_names: Iterable[str], fixed: Iterable[str],
              io: Mapping[str, str], agent: str, loc: ast.Loc = ast.NOLOC) -> Row:
    """Check and canonicalise one plan row ``{rcl: str, ajpf: str, when?: str}``.

    ``loc`` is where the ``rcl`` text starts in the plan (for RCL syntax
    errors, which are raised as :class:`RclError` located there).  Other
    problems raise :class:`RowError`: missing keys, an ``rcl`` side that is
    not a conjunction of atoms, an ``ajpf`` side that does not parse, names
    another agent than ``agent``, or uses placeholders / a ``when`` over
    variables the ``rcl`` side does not bind.
    """
    if not isinstance(raw, Mapping):
        raise RowError("a mapping row is a mapping with keys 'rcl', 'ajpf' and optionally 'when'", "rcl")
    unknown = sorted(set(raw) - {"rcl", "ajpf", "when"})
    if unknown:
        raise RowError(f"unknown key {unknown[0]!r} in mapping row (allowed: rcl, ajpf, when)", unknown[0])
    for key in ("rcl", "ajpf"):
        if not isinstance(raw.get(key), str) or not raw[key].strip():
            raise RowError(f"mapping row needs a non-empty text '{key}'", key)
    when_text = raw.get("when")
    if when_text is not None and not isinstance(when_text, str):
        raise RowError("'when' must be an RCL condition text", "when")
    dom = frozenset(dom_names)
    expr = parse_formula(raw["rcl"], loc.file, loc.line or 1, loc.col or 1)
    canon = Canon(io)
    form = canon.form(expr)
    disjuncts = list(dnf(form))
    if len(disjuncts) != 1:
        raise RowError("the 'rcl' side of a mapping row must be a conjunction of atoms (no 'or', no '->')", "rcl")
    items, evars = disjuncts[0]
    if not items:
        raise RowError("the 'rcl' side of a mapping row has no atom", "rcl")
    names: set[str] = set()
    for it in items:
        names |= form_vars(it) if isinstance(it, FQuant) else expr_vars(it.atom)
    fixed_set = frozenset(fixed)
    dom_vars = frozenset(n for n in names if n in dom)
    row_vars = frozenset(n for n in names if n not in dom and n not in fixed_set)
    for m in _PLACEHOLDER.finditer(raw["ajpf"]):
        try:
            ph = parse_formula(m.group(1))
        except RclError:
            raise RowError(f"placeholder {m.group(0)!r} is not an integer expression", "ajpf", m.start() + 1) from None
        missing = sorted(expr_vars(ph) - dom_vars)
        if missing:
            raise RowError(f"placeholder variable {missing[0]!r} is not a domain variable bound by the 'rcl' side",
                           "ajpf", m.start() + 1)
        if eval_int(ph, {v: 0 for v in dom_vars}) is None:
            raise RowError(f"placeholder {m.group(0)!r} is not an integer expression", "ajpf", m.start() + 1)
    try:
        # syntax check with every placeholder standing for a number
        formula = psl.parse(_PLACEHOLDER.sub("0", raw["ajpf"]))
    except psl.PslSyntaxError as exc:
        raise RowError(f"AJPF formula: {exc.message}", "ajpf") from None
    for prop in psl.propositions(formula):
        if isinstance(prop, psl.Modal) and prop.agent != agent:
            raise RowError(f"the AJPF formula names agent {prop.agent!r}, but the plan's agent is {agent!r}", "ajpf")
    when = None
    if when_text is not None:
        try:
            when = parse_formula(when_text)
        except RclError as exc:
            d = exc.diagnostics[0]
            raise RowError(f"'when': {d.message}", "when", d.loc.col) from None
        extra = sorted(expr_vars(when) - dom_vars)
        if extra:
            raise RowError(f"'when' uses {extra[0]!r}, which is not a domain variable bound by the 'rcl' side",
                           "when")
        if eval_bool(when, {v: 0 for v in dom_vars}) is None:
            raise RowError("'when' must be a condition over integers (comparisons, and, or, not)", "when")
    return Row(index, raw["rcl"], raw["ajpf"], when_text, tuple(items), dom_vars, row_vars, when, loc)


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


# ---------------------------------------------------------------------------
# Showing RCL (for reports of unmapped atoms)
# ---------------------------------------------------------------------------

def show(e: Any) -> str:
    """RCL text of an expression or canonical item (for messages, not for re-parsing
    guarantees; parenthesised where precedence needs it)."""
    if isinstance(e, FLit):
        if e.positive:
            return show(e.atom)
        a = e.atom
        if isinstance(a, ast.Compare) and a.ops == ("==",):
            return f"{_show(a.operands[0], 7)} != {_show(a.operands[1], 7)}"
        if isinstance(a, ast.Member):
            return show(replace(a, negated=True))
        if isinstance(a, (ast.Apply, ast.Var)):
            return f"{show(a)} == FALSE"
        return f"not ({show(a)})"
    if isinstance(e, FQuant):
        groups: list[tuple[list[str], Any]] = []
        for n, d in zip(e.names, e.domains):
            if groups and groups[-1][1] == d:
                groups[-1][0].append(n)
            else:
                groups.append(([n], d))
        binds = ", ".join(f"{', '.join(ns)} in {_show_domain(d)}" for ns, d in groups)
        return f"{e.kind}({binds} | {show_form(e.body)})"
    return _show(e, 0)


def show_form(f: Form) -> str:
    """RCL-like text of a canonical form."""
    if isinstance(f, FConst):
        return "TRUE" if f.value else "FALSE"
    if isinstance(f, (FLit, FQuant)):
        return show(f)
    sep = " and " if isinstance(f, FAnd) else " or "
    return sep.join(show_form(p) if isinstance(p, (FLit, FQuant, FConst)) else f"({show_form(p)})"
                    for p in f.parts)


def _show_domain(d: Any) -> str:
    if isinstance(d, ast.TBase):
        return d.name
    if isinstance(d, ast.TName):
        return d.name
    if _is_type(d):
        return "<type>"
    return _show(d, 0)


def _show(e: Any, prec: int) -> str:
    """RCL text of a plain AST expression (the shared printer); ``prec`` 7 asks
    for parentheses around anything looser than arithmetic (a comparison operand)."""
    text = expr_to_rcl(e)
    tight = isinstance(e, (ast.Var, ast.BoolLit, ast.NumLit, ast.Apply, ast.SetLit, ast.TupleLit, ast.SeqLit,
                           ast.Quant)) or (isinstance(e, ast.Binary) and e.op in ("+", "-", "*", "/"))
    return text if prec < 7 or tight else f"({text})"
