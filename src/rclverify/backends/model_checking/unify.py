"""Unification and belief queries of the Gwendolen interpreter.

Terms are those of :mod:`.gwendolen` (psl terms plus :class:`Var`).  A
substitution is a plain ``dict`` from variable name to term, never mutated
once returned.  ``_`` (:class:`psl.Wild`) unifies with anything and binds
nothing.  Numbers unify by value (``3`` with ``3.0``), as Gwendolen's
numeric terms do.

A belief query ``B t`` is answered from the belief base and the reasoning
rules by SLD resolution (Prolog's order: the belief base first, then the
rules in program order, body literals left to right), ``~`` by negation as
failure (a negated literal succeeds, binding nothing, when the query has no
answer).  Source: the reasoning rules of the MCAPL manual's Gwendolen
chapter (Prolog-style rules with negation as failure).
"""
from __future__ import annotations

from typing import Iterator, Sequence

from rclverify.backends.model_checking.ajpf import psl
from rclverify.backends.model_checking.gwendolen import MAX_TERM_DEPTH, Rule, Term, Var, as_psl, located

#: How deep reasoning rules may call each other before the query is refused.
MAX_RULE_DEPTH = 64
#: Unification attempts the reasoning rules may make for one state (all its
#: queries together) before the exploration is cut there.
MAX_RESOLUTION_STEPS = 200_000


class BoundReached(Exception):
    """A bound of the interpreter was reached while running the program (a
    term nested deeper than :data:`MAX_TERM_DEPTH`, more than
    :data:`MAX_RESOLUTION_STEPS` resolution steps for one state): not an
    error of the program, but the exploration cannot go on from that state;
    it is cut there (``bound``: which one, for the graph's ``cut``)."""

    def __init__(self, bound: str) -> None:
        super().__init__(bound)
        self.bound = bound

Subst = dict[str, Term]


def walk(t: Term, s: Subst) -> Term:
    """``t`` with its variable chain followed (one level of binding resolved)."""
    while isinstance(t, Var) and t.name in s:
        t = s[t.name]
    return t


def _num_value(t: psl.Num) -> float | str:
    try:
        return float(t.text)
    except ValueError:  # pragma: no cover - the grammar's numbers all parse
        return t.text


def unify(a: Term, b: Term, s: Subst) -> Subst | None:
    """The most general extension of ``s`` unifying ``a`` and ``b``, or ``None``."""
    a, b = walk(a, s), walk(b, s)
    if isinstance(a, psl.Wild) or isinstance(b, psl.Wild):
        return s
    if isinstance(a, Var):
        if isinstance(b, Var) and b.name == a.name:
            return s
        return {**s, a.name: b}
    if isinstance(b, Var):
        return {**s, b.name: a}
    if isinstance(a, psl.Num) and isinstance(b, psl.Num):
        return s if _num_value(a) == _num_value(b) else None
    if isinstance(a, psl.Sym) and isinstance(b, psl.Sym):
        return s if a.name == b.name else None
    if isinstance(a, psl.Compound) and isinstance(b, psl.Compound):
        if a.name != b.name or len(a.args) != len(b.args):
            return None
        for x, y in zip(a.args, b.args):
            s2 = unify(x, y, s)
            if s2 is None:
                return None
            s = s2
        return s
    return None


def substitute(t: Term, s: Subst) -> Term:
    """``t`` with every bound variable replaced (recursively)."""
    t = walk(t, s)
    if isinstance(t, psl.Compound):
        return psl.Compound(t.name, tuple(substitute(a, s) for a in t.args))
    return t


def variables(t: Term) -> list[str]:
    """The names of the variables of ``t``, left to right, each once."""
    out: list[str] = []

    def go(u: Term) -> None:
        if isinstance(u, Var) and u.name not in out:
            out.append(u.name)
        elif isinstance(u, psl.Compound):
            for a in u.args:
                go(a)
    go(t)
    return out


def _rename(t: Term, suffix: str) -> Term:
    if isinstance(t, Var):
        return Var(t.name + suffix)
    if isinstance(t, psl.Compound):
        return psl.Compound(t.name, tuple(_rename(a, suffix) for a in t.args))
    return t


class Beliefs:
    """The belief base (ground terms, in the state's canonical order) with the program's rules."""

    def __init__(self, beliefs: Sequence[Term], rules: Sequence[Rule], source: str) -> None:
        self.beliefs = beliefs
        self.rules = rules
        self.source = source
        self._fresh = 0
        self._steps = 0

    def _step(self, n: int) -> None:
        self._steps += n
        if self._steps > MAX_RESOLUTION_STEPS:
            raise BoundReached(f"resolution steps > {MAX_RESOLUTION_STEPS} in one state")

    def solve(self, query: Term, s: Subst, depth: int = 0) -> Iterator[Subst]:
        """Every answer to ``B query`` extending ``s``, in SLD order.  Raises
        :class:`BoundReached` past :data:`MAX_RESOLUTION_STEPS` (counted over
        this object's queries)."""
        self._step(len(self.beliefs) + len(self.rules) if self.rules else len(self.beliefs))
        for b in self.beliefs:
            s2 = unify(query, b, s)
            if s2 is not None:
                yield s2
        for rule in self.rules:
            if depth >= MAX_RULE_DEPTH:
                raise located(self.source, rule.line, 1, f"reasoning rules nest deeper than {MAX_RULE_DEPTH} "
                              f"calls (a rule that calls itself without end?)")
            self._fresh += 1
            suffix = f"#{self._fresh}"
            s2 = unify(query, _rename(rule.head, suffix), s)
            if s2 is None:
                continue
            yield from self._body(rule.body, 0, s2, suffix, depth + 1)

    def _body(self, body: tuple[tuple[bool, Term], ...], i: int, s: Subst, suffix: str,
              depth: int) -> Iterator[Subst]:
        if i == len(body):
            yield s
            return
        positive, lit = body[i]
        lit = _rename(lit, suffix)
        if positive:
            for s2 in self.solve(lit, s, depth):
                yield from self._body(body, i + 1, s2, suffix, depth)
        elif not self.holds(lit, s, depth):
            yield from self._body(body, i + 1, s, suffix, depth)

    def holds(self, query: Term, s: Subst | None = None, depth: int = 0) -> bool:
        """Whether ``B query`` has an answer."""
        return next(self.solve(query, s or {}, depth), None) is not None

    def derived(self) -> frozenset[psl.Term]:
        """Every ground instance of a rule head that follows (the beliefs rules add)."""
        out: set[psl.Term] = set()
        for rule in self.rules:
            self._fresh += 1
            head = _rename(rule.head, f"#h{self._fresh}")
            for s in self.solve(head, {}):
                t = substitute(head, s)
                if not variables(t) and not _has_wild(t):
                    if term_depth(t) > MAX_TERM_DEPTH:
                        raise BoundReached(f"term depth > {MAX_TERM_DEPTH}")
                    out.add(as_psl(t))
        return frozenset(out - {as_psl(b) for b in self.beliefs})


def _has_wild(t: Term) -> bool:
    if isinstance(t, psl.Wild):
        return True
    return isinstance(t, psl.Compound) and any(_has_wild(a) for a in t.args)


def term_depth(t: Term) -> int:
    """Nesting depth of ``t`` (1 for a name, number or variable), without recursion."""
    best, stack = 0, [(t, 1)]
    while stack:
        u, d = stack.pop()
        best = max(best, d)
        if isinstance(u, psl.Compound):
            stack.extend((a, d + 1) for a in u.args)
    return best


def ground(t: Term, s: Subst, source: str, line: int, col: int, what: str) -> psl.Term:
    """``t`` under ``s``, which must leave no variable; else a located error
    naming it.  Raises :class:`BoundReached` when the result nests deeper
    than :data:`MAX_TERM_DEPTH` (a program that builds ever deeper terms)."""
    g = substitute(t, s)
    if term_depth(g) > MAX_TERM_DEPTH:
        raise BoundReached(f"term depth > {MAX_TERM_DEPTH}")
    free = variables(g)
    if free:
        raise located(source, line, col, f"variable {free[0]} of {what} is not bound by the plan's trigger or guard")
    return as_psl(g)
