"""Vacuity: a property that holds only because its antecedents never do.

``[] (H -> <> C)`` holds on every path of a program in which ``H`` is never
true -- an agent that does nothing satisfies every such property.  A model
checker's "holds" is then no evidence about the program's behaviour (Beer,
Ben-David, Eisner, Rodeh, "Efficient detection of vacuity in temporal model
checking", 1997/2001; Kupferman and Vardi, "Vacuity detection in temporal
model checking", 2003: a formula passes vacuously when a subformula can be
replaced by ``false`` without changing the verdict).  rclverify checks the
case AJPF's properties are written in: **the antecedent of each
implication** (``->``) of the property, at every nesting.

Where an antecedent is evaluated:

* under a temporal operator (``[]``, ``<>``, ``U``, ``R``) it is evaluated
  at every position of every path, i.e. in every state of the explored
  graph (every state of the graph is reachable: it was found by search
  from state 0);
* outside every temporal operator, at the first position only: state 0.

A **state formula** antecedent (atoms, ``~``, ``&``, ``||``, ``->``, ``T``,
``F``) is evaluated directly on the graph with :meth:`StateGraph.holds`
(:func:`state_holds`); the property is vacuous when it holds in none of the
states where it is evaluated.  A **temporal** antecedent ``A`` cannot be
evaluated state by state: :func:`temporal_checks` gives the claim whose
truth means that ``A`` never holds (``[] ~A`` under a temporal operator,
``~A`` at the top), which SPIN checks on the same model; when that claim
holds, the property is vacuous.  A property that simplifies to the constant
``T`` is vacuous too (its hypothesis mapped to ``F``).

A vacuous pass is reported ``inconclusive`` (``vacuous``), never
``discharged`` (docs/model-checking.md, "Vacuity").
"""
from __future__ import annotations

from dataclasses import dataclass
from rclverify.backends.model_checking.ajpf import psl
from rclverify.backends.model_checking.graph import StateGraph

_TEMPORAL = (psl.Always, psl.Eventually, psl.Until, psl.Release)


@dataclass(frozen=True)
class Antecedent:
    """The antecedent ``formula`` of one implication of a property, whether it
    is under a temporal operator (``temporal_context``), and whether it is a
    state formula (no temporal operator inside: ``state``)."""

    formula: psl.Formula
    temporal_context: bool
    state: bool

    @property
    def text(self) -> str:
        return psl.to_text(self.formula)


def is_state_formula(f: psl.Formula) -> bool:
    """No temporal operator in ``f``."""
    if isinstance(f, _TEMPORAL):
        return False
    if isinstance(f, psl.Not):
        return is_state_formula(f.operand)
    if isinstance(f, (psl.And, psl.Or)):
        return all(is_state_formula(p) for p in f.parts)
    if isinstance(f, psl.Implies):
        return is_state_formula(f.left) and is_state_formula(f.right)
    return True


def antecedents(f: psl.Formula) -> list[Antecedent]:
    """The antecedent of every implication in ``f``, outermost first, each once."""
    out: list[Antecedent] = []

    def walk(g: psl.Formula, temporal: bool) -> None:
        if isinstance(g, psl.Implies):
            a = Antecedent(g.left, temporal, is_state_formula(g.left))
            if a not in out:
                out.append(a)
        inner = temporal or isinstance(g, _TEMPORAL)
        for child in _children(g):
            walk(child, inner)

    walk(f, False)
    return out


def _children(g: psl.Formula) -> tuple[psl.Formula, ...]:
    if isinstance(g, (psl.Not, psl.Always, psl.Eventually)):
        return (g.operand,)
    if isinstance(g, (psl.And, psl.Or)):
        return g.parts
    if isinstance(g, (psl.Implies, psl.Until, psl.Release)):
        return (g.left, g.right)
    return ()


def state_holds(graph: StateGraph, k: int, f: psl.Formula, memo: dict[psl.Formula, frozenset[int]] | None = None
                ) -> bool:
    """Whether the state formula ``f`` holds in state ``k`` of ``graph``
    (atoms by :meth:`StateGraph.holds`).  ``memo`` (atom -> the states where
    it holds) saves evaluating an atom again.  Raises ``TypeError`` for a
    temporal operator."""
    if isinstance(f, psl.Const):
        return f.value
    if isinstance(f, (psl.Modal, psl.Percept)):
        if memo is None:
            return graph.holds(k, f)
        if f not in memo:
            memo[f] = frozenset(s for s in range(len(graph.states)) if graph.holds(s, f))
        return k in memo[f]
    if isinstance(f, psl.Not):
        return not state_holds(graph, k, f.operand, memo)
    if isinstance(f, psl.And):
        return all(state_holds(graph, k, p, memo) for p in f.parts)
    if isinstance(f, psl.Or):
        return any(state_holds(graph, k, p, memo) for p in f.parts)
    if isinstance(f, psl.Implies):
        return not state_holds(graph, k, f.left, memo) or state_holds(graph, k, f.right, memo)
    raise TypeError(f"not a state formula: {psl.to_text(f)}")


@dataclass(frozen=True)
class Vacuity:
    """What :func:`check_vacuity` found: ``vacuous`` the reasons the property
    passes vacuously (empty: it does not, as far as decided here);
    ``witnessed`` for each state antecedent, a state where it holds;
    ``pending`` the temporal antecedents left to SPIN (:func:`temporal_checks`)."""

    vacuous: tuple[str, ...]
    witnessed: tuple[tuple[str, int], ...]
    pending: tuple[Antecedent, ...]


def check_vacuity(graph: StateGraph, f: psl.Formula, memo: dict[psl.Formula, frozenset[int]] | None = None
                  ) -> Vacuity:
    """Decide, on ``graph``, whether the property ``f`` can only pass vacuously
    (module docstring): a state antecedent that holds in no state where it is
    evaluated, or ``f`` simplifying to ``T``."""
    memo = {} if memo is None else memo
    vacuous: list[str] = []
    witnessed: list[tuple[str, int]] = []
    pending: list[Antecedent] = []
    if psl.simplify(f) == psl.TRUE:
        vacuous.append(f"the property {psl.to_text(f)} simplifies to T: it holds whatever the agent does")
    for a in antecedents(f):
        if not a.state:
            pending.append(a)
            continue
        where = range(len(graph.states)) if a.temporal_context else range(1)
        hit = next((k for k in where if state_holds(graph, k, a.formula, memo)), None)
        if hit is None:
            place = "in no state of the explored graph" if a.temporal_context else "in the initial state"
            vacuous.append(f"the antecedent {a.text} holds {place}")
        else:
            witnessed.append((a.text, hit))
    return Vacuity(tuple(vacuous), tuple(witnessed), tuple(pending))


def temporal_checks(a: Antecedent) -> psl.Formula:
    """The claim that holds exactly when the temporal antecedent ``a`` never
    holds where it is evaluated: ``[] ~A`` under a temporal operator, ``~A``
    at the top."""
    never = psl.Not(a.formula)
    return psl.Always(never) if a.temporal_context else never
