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

import re
from dataclasses import dataclass, replace
from typing import Any, Mapping, Iterable

from rclverify.lang import ast

from rclverify.lang import typeexpr
from rclverify.lang.printer import expr_to_rcl, is_type
from rclverify.lang.errors import RclError
from rclverify.lang.parser import parse_formula
from rclverify.backends.model_checking.ajpf import psl
from rclverify.targets.ajpf.canon import (Canon, FAnd, FConst, FLit, FOr, Form, FQuant, Item,
                                                          dnf, eval_bool, eval_int, expr_vars, form_vars,
                                                          miniscope, subst)
from rclverify.targets.ajpf.match import MatchContext, State, match_expr, match_form

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
    if isinstance(d, typeexpr.TBase):
        return d.name
    if isinstance(d, typeexpr.TName):
        return d.name
    if is_type(d):
        return "<type>"
    return _show(d, 0)


def _show(e: Any, prec: int) -> str:
    """RCL text of a plain AST expression (the shared printer); ``prec`` 7 asks
    for parentheses around anything looser than arithmetic (a comparison operand)."""
    text = expr_to_rcl(e)
    tight = isinstance(e, (ast.Var, ast.BoolLit, ast.NumLit, ast.Apply, ast.SetLit, ast.TupleLit, ast.SeqLit,
                           ast.Quant)) or (isinstance(e, ast.Binary) and e.op in ("+", "-", "*", "/"))
    return text if prec < 7 or tight else f"({text})"


__all__ = ["Canon", "FAnd", "FConst", "FLit", "FOr", "FQuant", "Form", "Item", "MatchContext", "Row", "RowError",
           "State", "build_row", "dnf", "eval_bool", "eval_int", "expr_vars", "form_vars", "match_expr",
           "match_form", "miniscope", "show", "show_form", "subst", "substitute"]
