"""Which identifiers the verification environment gives its reactions, and why that is sound.

``_`` in a declared percept (``movebase_result(_, 3)``) stands for the
**identifier of the action the reaction answers**.  Its meaning
(docs/model-checking.md, "Identifiers"): each reaction carries a *fresh*
identifier, equal to no other value -- no identifier of an earlier reaction,
no number of the program, of the environment or of the properties -- as a
ROS action's goal id is.  The Gwendolen subset has no arithmetic and no
ordering comparison (comparisons in guards are refused), so a program can
only test identifiers for equality; any choice of fresh values gives the
same behaviour up to renaming (data independence: Wolper, "Expressing
interesting properties of programs in propositional temporal logic", POPL
1986).

Two ways of choosing the values, decided per program by :func:`analyse`:

``alternate``  1, 2, 1, 2 ... (the reaction's number modulo two).  Sound
    when the program is **identifier-oblivious**: every place where a term
    of the program can meet a percept's identifier -- belief triggers, ``B``
    guard literals, belief additions and deletions, reasoning rules, initial
    beliefs, the environment's other percepts -- holds there ``_``, a
    variable that occurs nowhere else in its plan or rule, or a non-numeric
    constant (which no identifier equals).  Such a program never copies an
    identifier into a belief, goal or action and never compares one, so an
    identifier lives only in the last reaction's percepts, their beliefs and
    the events they posted; two consecutive reactions need different values
    (or the second percept would not be new), and no state holds the
    identifiers of two reactions that are not consecutive except inside
    events whose identifier no plan reads.  Mapping every fresh identifier
    ``k`` to ``1 + (k - 1) mod 2`` is then a bisimulation between the
    fresh-identifier system and the explored one that preserves every
    proposition not naming an identifier value.  The case study's agent is
    oblivious.
``fresh``  each reaction takes the smallest positive integer that occurs
    nowhere in the current state, in the program, in the environment or in
    the entry's properties (:func:`fresh_identifier`): never equal to a
    remembered identifier nor to other data, as the meaning asks; values the
    state has forgotten are used again, so a program that remembers
    boundedly many identifiers still has a finite graph.  Used for every
    program that is not oblivious (the reasons are recorded).

A property whose atom names an identifier value (``P(movebase_result(1,
3))``) has no meaning under either choice: :func:`named_identifiers` finds
such atoms and the backend reports the property ``inconclusive``.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable

from rclverify.backends.model_checking.ajpf import psl
from rclverify.backends.model_checking.gwendolen import Program, Term, Var
from rclverify.backends.model_checking.unify import unify

ALTERNATE = "alternate"
FRESH = "fresh"
NONE = "none"


@dataclass(frozen=True)
class IdentifierUse:
    """What :func:`analyse` decided: ``mode`` (:data:`ALTERNATE`,
    :data:`FRESH`, or :data:`NONE` when no declared percept has ``_``) and
    ``reasons`` (``file:line: ...`` for each place that makes the program
    not identifier-oblivious)."""

    mode: str
    reasons: tuple[str, ...] = ()

    def describe(self) -> str:
        """One sentence for the evidence."""
        if self.mode == NONE:
            return "no percept carries an identifier"
        if self.mode == ALTERNATE:
            return ("identifiers: two alternating values, sound because the program never keeps or tests an "
                    "identifier (identifier-oblivious; docs/model-checking.md, Identifiers)")
        shown = "; ".join(self.reasons[:3]) + (f"; and {len(self.reasons) - 3} more" if len(self.reasons) > 3 else "")
        return f"identifiers: a fresh value per reaction, as the program keeps or tests identifiers ({shown})"


def _has_wild(t: Term) -> bool:
    if isinstance(t, psl.Wild):
        return True
    return isinstance(t, psl.Compound) and any(_has_wild(a) for a in t.args)


def _vars(t: Term, out: dict[str, int]) -> None:
    if isinstance(t, Var):
        out[t.name] = out.get(t.name, 0) + 1
    elif isinstance(t, psl.Compound):
        for a in t.args:
            _vars(a, out)


def meets(term: Term, pattern: psl.Term, singles: frozenset[str]) -> str:
    """How ``term`` (a program term, maybe with variables) meets the
    identifiers of the percept ``pattern`` (``_`` at the identifiers'
    places): ``""`` when it cannot see their values, else why it can (a
    variable used elsewhere bound to one, a number where one is)."""
    if not _has_wild(pattern) or unify(term, pattern, {}) is None:
        return ""
    return _walk(term, pattern, singles)


def _walk(t: Term, p: psl.Term, singles: frozenset[str]) -> str:
    if not _has_wild(p) or isinstance(t, psl.Wild):
        return ""
    if isinstance(t, Var):
        return "" if t.name in singles else f"variable {t.name} takes an identifier and is used again"
    if isinstance(p, psl.Wild):  # a constant where the identifier is: only a number can equal one
        return f"the number {t.text} stands where an identifier is" if isinstance(t, psl.Num) else ""
    if isinstance(t, psl.Compound) and isinstance(p, psl.Compound):
        for a, b in zip(t.args, p.args):
            why = _walk(a, b, singles)
            if why:
                return why
    return ""


def analyse(program: Program, percepts: Iterable[psl.Term], initial: Iterable[psl.Term] = ()) -> IdentifierUse:
    """Decide how identifiers are chosen for ``program`` under an environment
    declaring ``percepts`` (and ``initial`` percepts): see the module docstring."""
    declared = tuple(percepts)
    patterns = [p for p in declared if _has_wild(p)]
    if not patterns:
        return IdentifierUse(NONE)
    src = program.source
    reasons: list[str] = []

    def check(terms: Iterable[tuple[Term, str]], singles: frozenset[str]) -> None:
        for term, where in terms:
            for p in patterns:
                why = meets(term, p, singles)
                if why and f"{where}: {why}" not in reasons:
                    reasons.append(f"{where}: {why} ({psl.term_text(p)})")

    for plan in program.plans:
        counts: dict[str, int] = {}
        _vars(plan.trigger.term, counts)
        for lit in plan.guard:
            if lit.term is not None:
                _vars(lit.term, counts)
        for d in plan.body:
            _vars(d.term, counts)
        singles = frozenset(v for v, c in counts.items() if c == 1)
        terms: list[tuple[Term, str]] = []
        if not plan.trigger.goal:
            terms.append((plan.trigger.term, f"{src}:{plan.line}"))
        terms += [(lit.term, f"{src}:{plan.line}") for lit in plan.guard if lit.kind == "B" and lit.term is not None]
        terms += [(d.term, f"{src}:{d.line}") for d in plan.body if d.kind in ("+b", "-b")]
        check(terms, singles)
    for rule in program.rules:
        counts = {}
        _vars(rule.head, counts)
        for _, t in rule.body:
            _vars(t, counts)
        singles = frozenset(v for v, c in counts.items() if c == 1)
        check([(rule.head, f"{src}:{rule.line}")] + [(t, f"{src}:{rule.line}") for _, t in rule.body], singles)
    check([(b, f"{src}: initial belief") for b in program.beliefs], frozenset())
    others = [p for p in declared if not _has_wild(p)] + list(initial)
    check([(t, "the environment's percept " + psl.term_text(t)) for t in others], frozenset())
    return IdentifierUse(FRESH if reasons else ALTERNATE, tuple(reasons))


def named_identifiers(formula: psl.Formula, percepts: Iterable[psl.Term]) -> list[str]:
    """The atoms of ``formula`` that name an identifier value of a declared
    percept (a number where the percept has ``_``), as text."""
    patterns = [p for p in percepts if _has_wild(p)]
    out = []
    for atom in psl.propositions(formula):
        term = atom.term if isinstance(atom, (psl.Modal, psl.Percept)) else None
        if term is None:
            continue
        if any(meets(term, p, frozenset()) for p in patterns):
            text = psl.to_text(atom)
            if text not in out:
                out.append(text)
    return out


def numbers(terms: Iterable[psl.Term | Term | None], out: set[float] | None = None) -> set[float]:
    """The values of every number in ``terms`` (recursively), as floats (``3``
    and ``3.0`` are one value, as in unification)."""
    acc = set() if out is None else out
    stack = [t for t in terms if t is not None]
    while stack:
        t = stack.pop()
        if isinstance(t, psl.Num):
            try:
                acc.add(float(t.text))
            except ValueError:
                pass
        elif isinstance(t, psl.Compound):
            stack.extend(t.args)
    return acc


def fresh_identifier(used: set[float]) -> int:
    """The smallest positive integer not in ``used``."""
    n = 1
    while float(n) in used:
        n += 1
    return n
