"""From one RCL guarantee to AJPF property instances.

Paper lines 1414-1420: a guarantee ``forall vars | H -> C`` of the Agent
becomes properties ``[] (H' -> <> C')`` where ``H'``/``C'`` are ``H``/``C``
mapped into AJPF's property language; having no quantifiers, LTL needs one
property per value of the guarantee's waypoint variable.  This module does
that mechanically:

1. The outer ``forall`` is peeled.  Its variables listed in the plan's
   ``domains`` (e.g. ``i`` in ``[0, 12]``) are instantiated over their
   inclusive ranges, one instance per combination of values.
2. Its other variables (``x'``, ``y'``) must be eliminated by the mapping:
   one occurring only in ``H`` reads existentially there
   (``forall v (H(v) -> C)`` is ``(exists v H(v)) -> C``), as do the
   variables of ``exists`` quantifiers in positive position.  One occurring in
   ``C`` (or in both) cannot be eliminated by an existential row and leaves
   the atoms mentioning it unmapped.
3. ``H`` and ``C`` are put in canonical form (:mod:`.mapping`) and in
   disjunctive normal form.  Every conjunct must be *covered*: split into
   sub-conjunctions each matched by one mapping row (rows tried in plan
   order), such that all atoms mentioning an eliminated variable are covered
   by the same row application -- otherwise ``exists v (A(v) and B(v))`` would
   wrongly become ``(exists v A(v)) and (exists v B(v))``.
4. The AJPF formulas of the rows (placeholders evaluated, ``i + 1`` with
   ``i = 4`` giving ``5``) are joined with ``&``/``||``, and the property is
   simplified (constants folded; ``T``/``F`` rows come from ``when``
   conditions that decide an atom for the scenario).

An atom no row covers is *unmapped*.  No formula is invented for it: the
instance then has no property (``formula is None``) and lists the atom in
``unmapped``.  (A hypothesis atom could soundly be dropped -- that makes the
property stronger -- but whether the stronger property still holds is the
user's call: they make it explicit with a row mapping the atom to ``T``.)
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from typing import Iterable, Iterator, Mapping, Sequence

from rclverify.lang import ast
from rclverify.backends.model_checking.ajpf import psl
from rclverify.backends.model_checking.ajpf.mapping import Canon, FLit, FQuant, Form, Item, MatchContext, Row, State, dnf, expr_vars, form_vars, \
    match_form, show

#: Largest conjunct (number of atoms) the cover search handles.
MAX_ITEMS = 12


@dataclass(frozen=True)
class Application:
    """One row covering some atoms of a conjunct."""

    row: Row
    covered: tuple[int, ...]
    state: State
    negated: bool
    formula: psl.Formula


@dataclass(frozen=True)
class Instance:
    """One instance of one guarantee.

    ``guarantee``  1-based index of the guarantee in its node;
    ``values``     the domain variables' values, in binding order;
    ``formula``    the AJPF property, or ``None`` when some atom is unmapped;
    ``unmapped``   RCL text of every atom no row covers (as written, with the
                   guarantee's variable names; ``values`` says which instance);
    ``rows``       0-based indices of the rows used, sorted;
    ``notes``      further remarks (variables that cannot be eliminated ...);
    ``constants``  ``(row index, value)`` of every row whose formula, as
                   applied in this instance, is a constant after
                   simplification (:func:`psl.constant_value`): the agent is
                   not checked on the atoms it covers.
    """

    guarantee: int
    values: tuple[tuple[str, int], ...]
    formula: psl.Formula | None
    unmapped: tuple[str, ...] = ()
    rows: tuple[int, ...] = ()
    notes: tuple[str, ...] = ()
    constants: tuple[tuple[int, bool], ...] = ()

    @property
    def label(self) -> str:
        """``i=4`` (``j=1,i=4`` for two variables; ``""`` without variables)."""
        return ",".join(f"{k}={v}" for k, v in self.values)

    @property
    def trivial(self) -> bool:
        """The property simplified to a constant (e.g. its hypothesis maps to ``F``)."""
        return isinstance(self.formula, psl.Const)


@dataclass(frozen=True)
class Shape:
    """A guarantee taken apart: ``forall outer | hyp -> concl``."""

    outer: tuple[tuple[str, object], ...]
    hyp: ast.Expr | None
    concl: ast.Expr


def shape(formula: ast.Expr) -> Shape:
    """Peel consecutive outer ``forall`` quantifiers and split at a top-level ``->``.

    A body without ``->`` is all conclusion (hypothesis ``TRUE``).
    """
    outer: list[tuple[str, object]] = []
    body = formula
    while isinstance(body, ast.Quant) and body.kind == "forall":
        for b in body.bindings:
            outer.extend((n, b.domain) for n in b.names)
        body = body.body
    if isinstance(body, ast.Binary) and body.op == "->":
        return Shape(tuple(outer), body.left, body.right)
    return Shape(tuple(outer), None, body)


def domain_values(domains: Mapping[str, tuple[int, int]], names: Sequence[str]) -> list[tuple[tuple[str, int], ...]]:
    """Every combination of values of ``names`` (inclusive ranges), in order."""
    ranges = [[(n, v) for v in range(domains[n][0], domains[n][1] + 1)] for n in names]
    return [tuple(c) for c in itertools.product(*ranges)]


@dataclass
class _Side:
    """One side (hypothesis or conclusion) in DNF, with what covering it needs."""

    conjuncts: list[tuple[tuple[Item, ...], frozenset[str]]]
    error: str | None = None
    notes: list[str] = field(default_factory=list)


class Translator:
    """Translates the guarantees of one node with one mapping table.

    ``rows``      the checked mapping rows (:func:`.mapping.build_row`);
    ``domains``   domain variable -> inclusive ``(low, high)``;
    ``fixed``     names matching only themselves (enumeration values, constants);
    ``io``        bare input/output name -> ``"in"``/``"out"``.
    """

    def __init__(self, rows: Sequence[Row], domains: Mapping[str, tuple[int, int]], fixed: Iterable[str] = (),
                 io: Mapping[str, str] | None = None) -> None:
        self.rows = list(rows)
        self.domains = dict(domains)
        self.fixed = frozenset(fixed)
        self.io = dict(io or {})

    def guarantee(self, formula: ast.Expr, index: int) -> list[Instance]:
        """All instances of guarantee number ``index`` (1-based) with formula ``formula``."""
        sh = shape(formula)
        outer_names = [n for n, _ in sh.outer]
        dom_here = [n for n in outer_names if n in self.domains]
        others = {n for n in outer_names if n not in self.domains}
        canon = Canon(self.io, used=outer_names)
        hyp_form = canon.form(sh.hyp) if sh.hyp is not None else None
        concl_form = canon.form(sh.concl)
        hyp_vars = form_vars(hyp_form) if hyp_form is not None else set()
        concl_vars = form_vars(concl_form)
        both = others & hyp_vars & concl_vars
        notes: list[str] = []
        for v in sorted(both):
            notes.append(f"{v} links the hypothesis and the conclusion; no existential mapping row can eliminate it")
        for v in sorted((others & concl_vars) - both):
            notes.append(f"{v} is universally quantified in the conclusion; no existential mapping row can "
                         f"eliminate it")
        free_dom = sorted((hyp_vars | concl_vars) & set(self.domains) - set(dom_here))
        for v in free_dom:
            notes.append(f"{v} is a domain variable but not bound by the guarantee's outer forall")
        hyp = self._side(hyp_form, frozenset(others - both))
        concl = self._side(concl_form, frozenset())
        out = []
        for values in domain_values(self.domains, dom_here):
            out.append(self._instance(index, values, hyp, concl, notes))
        return out

    def _side(self, form: Form | None, outer_evars: frozenset[str]) -> _Side:
        if form is None:
            return _Side([((), frozenset())])
        try:
            conj = [(items, ev | outer_evars) for items, ev in dnf(form)]
        except ValueError as exc:
            return _Side([], error=str(exc))
        return _Side(conj)

    def _instance(self, index: int, values: tuple[tuple[str, int], ...], hyp: _Side, concl: _Side,
                  notes: Sequence[str]) -> Instance:
        inst = dict(values)
        unmapped: list[str] = []
        used_rows: set[int] = set()
        constants: dict[int, bool] = {}
        extra_notes = list(notes)
        sides: list[psl.Formula] = []
        for side in (hyp, concl):
            if side.error is not None:
                unmapped.append(f"(whole {'hypothesis' if side is hyp else 'conclusion'}: {side.error})")
                sides.append(psl.FALSE)
                continue
            disjuncts: list[psl.Formula] = []
            for items, evars in side.conjuncts:
                apps, skipped, why = self.cover(items, evars, inst)
                for k in skipped:
                    text = _atom_text(items[k])
                    if text not in unmapped:
                        unmapped.append(text)
                if why and why not in extra_notes:
                    extra_notes.append(why)
                used_rows.update(a.row.index for a in apps)
                for a in apps:
                    value = psl.constant_value(a.formula)
                    if value is not None and a.row.index not in constants:
                        constants[a.row.index] = value
                disjuncts.append(psl.And(tuple(a.formula for a in apps)) if apps else psl.TRUE)
            sides.append(psl.Or(tuple(disjuncts)) if disjuncts else psl.FALSE)
        if unmapped:
            return Instance(index, values, None, tuple(unmapped), tuple(sorted(used_rows)), tuple(extra_notes))
        prop = psl.simplify(psl.Always(psl.Implies(sides[0], psl.Eventually(sides[1]))))
        return Instance(index, values, prop, (), tuple(sorted(used_rows)), tuple(extra_notes),
                        tuple(sorted(constants.items())))

    # -- covering ----------------------------------------------------------
    def cover(self, items: Sequence[Item], evars: frozenset[str], values: Mapping[str, int]
              ) -> tuple[list[Application], list[int], str]:
        """Cover the atoms ``items`` of one conjunct with row applications.

        Returns ``(applications, skipped, note)``: the fewest atoms possible
        are left ``skipped`` (unmapped).  ``evars`` are the conjunct's
        eliminated variables, ``values`` the instance.
        """
        n = len(items)
        if n > MAX_ITEMS:
            return [], list(range(n)), f"a conjunct with {n} atoms is too large to match (limit {MAX_ITEMS})"
        mentions = {v: frozenset(k for k, it in enumerate(items) if v in _item_vars(it)) for v in evars}
        cx = MatchContext(frozenset(self.domains), self.fixed, dict(values), evars)
        memo: dict[tuple[frozenset[int], int], tuple[list[Application], list[int]] | None] = {}

        def search(open_: frozenset[int], skips: int) -> tuple[list[Application], list[int]] | None:
            key = (open_, skips)
            if key in memo:
                return memo[key]
            result: tuple[list[Application], list[int]] | None = None
            if not open_:
                result = ([], [])
            else:
                k = min(open_)
                for app in self._applications(items, k, open_, mentions, cx):
                    rest = search(open_ - frozenset(app.covered), skips)
                    if rest is not None:
                        result = ([app] + rest[0], rest[1])
                        break
                if result is None and skips > 0:
                    rest = search(open_ - {k}, skips - 1)
                    if rest is not None:
                        result = (rest[0], [k] + rest[1])
            memo[key] = result
            return result

        for skips in range(n + 1):
            found = search(frozenset(range(n)), skips)
            if found is not None:
                return found[0], sorted(found[1]), ""
        return [], list(range(n)), ""  # pragma: no cover - skipping everything always succeeds

    def _applications(self, items: Sequence[Item], k: int, open_: frozenset[int],
                      mentions: Mapping[str, frozenset[int]], cx: MatchContext) -> Iterator[Application]:
        """Row applications covering atom ``k`` and other open atoms: rows in plan
        order, rows matching with their own polarity before negated one-atom rows."""
        others = sorted(open_ - {k})
        for row in self.rows:
            m = len(row.items)
            if m - 1 > len(others):
                continue
            for pos in range(m):
                for rest in itertools.permutations(others, m - 1):
                    targets = list(rest[:pos]) + [k] + list(rest[pos:])
                    for st in _match_items(row.items, [items[t] for t in targets], cx):
                        app = self._finish(row, tuple(targets), st, False, mentions, cx)
                        if app is not None:
                            yield app
                            break
        for row in self.rows:
            if row.negatable:
                lit = row.items[0]
                assert isinstance(lit, FLit)
                flipped = FLit(lit.atom, not lit.positive)
                for st in match_form(flipped, items[k], State(), cx):
                    app = self._finish(row, (k,), st, True, mentions, cx)
                    if app is not None:
                        yield app
                        break

    def _finish(self, row: Row, covered: tuple[int, ...], st: State, negated: bool,
                mentions: Mapping[str, frozenset[int]], cx: MatchContext) -> Application | None:
        values = st.values
        if not row.applies(values):
            return None
        for target in st.renaming.values():
            if target in mentions and not mentions[target] <= set(covered):
                return None
        try:
            formula = row.render(values)
        except ValueError:
            return None
        if negated:
            formula = psl.negate(formula)
        return Application(row, covered, st, negated, formula)


def _match_items(ps: Sequence[Item], ts: Sequence[Item], cx: MatchContext, st: State | None = None
                 ) -> Iterator[State]:
    st = st or State()
    if not ps:
        yield st
        return
    for s in match_form(ps[0], ts[0], st, cx):
        yield from _match_items(ps[1:], ts[1:], cx, s)


def _item_vars(it: Item) -> set[str]:
    return form_vars(it) if isinstance(it, FQuant) else expr_vars(it.atom)


def _atom_text(it: Item) -> str:
    src = it.source
    if src is not None and isinstance(it, FLit):
        return show(src) if it.positive != _negative_source(src) else f"not ({show(src)})"
    return show(it)


def _negative_source(src: ast.Expr) -> bool:
    """The source text already reads negatively (``!=``, ``!in``, ``== FALSE``, ``not``)."""
    if isinstance(src, ast.Unary) and src.op == "not":
        return True
    if isinstance(src, ast.Member):
        return src.negated
    if isinstance(src, ast.Compare) and len(src.ops) == 1:
        if src.ops[0] == "!=":
            return not any(isinstance(o, ast.BoolLit) and not o.value for o in src.operands)
        return any(isinstance(o, ast.BoolLit) and not o.value for o in src.operands)
    return False
