"""The explored state graph of an agent program: the interface between the two stages.

Stage one (the Gwendolen interpreter and its explorer) produces a
:class:`StateGraph`; stage two (Promela emission and SPIN) reads it.  The
graph is a plain value: states, labelled transitions, and for each state the
agent's mental state as ground terms, on which the property language's
atoms (``B``, ``G``, ``D``, ``I``, ``ItD``, ``P``; see
:mod:`rclverify.backends.model_checking.ajpf.psl`) are evaluated by :meth:`StateGraph.holds`.

Source of the atoms' meaning: AJPF's property specification language
(paper lines 1366-1394): ``B(ag, f)`` the agent believes ``f``; ``G(ag, f)``
it has the goal ``f``; ``D(ag, f)`` the last action it performed was ``f``;
``I(ag, f)`` it has an intention whose top event is the goal ``f``;
``ItD(ag, f)`` it intends to do action ``f`` next; ``P(f)`` ``f`` is a
percept of the environment.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from rclverify.backends.model_checking.ajpf import psl


@dataclass(frozen=True)
class MentalState:
    """What the atoms of one state are evaluated on; every entry a ground term.

    ``beliefs``   the belief base after rule closure is *not* stored here: the
                  stored beliefs only (rules are applied by ``holds`` through
                  :attr:`StateGraph.derived`, when stage one fills it);
    ``goals``     goal terms (``inspect(1)``), with no goal type;
    ``last_action``  the last action performed (``inspect``, ``move(0.5,0.5,0.0)``)
                  or ``None`` before the first;
    ``intentions``   goal terms at the base of each intention;
    ``intended_actions``  actions at the head of an intention's deed stack;
    ``percepts``  the environment's current percepts.
    """

    beliefs: frozenset[psl.Term]
    goals: frozenset[psl.Term] = frozenset()
    last_action: psl.Term | None = None
    intentions: frozenset[psl.Term] = frozenset()
    intended_actions: frozenset[psl.Term] = frozenset()
    percepts: frozenset[psl.Term] = frozenset()


@dataclass(frozen=True)
class Transition:
    """One step of the reasoning cycle or of the environment.

    ``src``/``dst`` state indices; ``label`` what happened, readable
    (``"plan jackal.gwen:84 +!inspect(1): deed +going(1)"``,
    ``"environment asserts movebase_result(1,3)"``); ``line`` the Gwendolen
    source line of the plan or deed (1-based) or ``None`` for an
    environment step; ``stage`` the reasoning-cycle stage (``A`` .. ``E``)
    or ``"env"``.
    """

    src: int
    dst: int
    label: str
    line: int | None = None
    stage: str = ""


@dataclass(frozen=True)
class StateGraph:
    """The explored graph of one program under one verification environment.

    ``agent``       the agent's name (``jackal``);
    ``source``      workspace-relative path of the Gwendolen file;
    ``states``      index -> :class:`MentalState`; state 0 is the initial state;
    ``transitions`` every explored transition (a state with none is a final
                    state: SPIN sees it stutter);
    ``complete``    False when a state or depth bound cut the exploration
                    (then no verdict may be ``discharged``);
    ``cut``         the bound that cut it (``"states > 100000"``), else ``""``;
    ``depth``       the greatest depth reached (transitions from state 0);
    ``identifiers`` how the environment's reactions got their identifiers,
                    one sentence (:meth:`.identifiers.IdentifierUse.describe`;
                    ``""`` for a graph not made by the explorer).
    """

    agent: str
    source: str
    states: tuple[MentalState, ...]
    transitions: tuple[Transition, ...]
    complete: bool = True
    cut: str = ""
    depth: int = 0
    identifiers: str = ""
    derived: dict[int, frozenset[psl.Term]] = field(default_factory=dict, compare=False)
    #: ``(state, modality) -> {term head: terms}`` of the pools ``holds`` searched (filled on use).
    _heads: dict[tuple[int, str], dict[tuple[object, ...], tuple[psl.Term, ...]]] = field(
        default_factory=dict, compare=False, repr=False)

    def holds(self, state: int, atom: psl.Modal | psl.Percept) -> bool:
        """Whether the atom holds in state ``state``.

        ``_`` in the atom's term matches any value; numbers compare by value
        (``3`` matches ``3.0``).  ``B`` also sees the beliefs ``derived`` holds
        for the state (Gwendolen's Prolog-style rules).  An atom about another
        agent than :attr:`agent` is false.
        """
        op = "P" if isinstance(atom, psl.Percept) else atom.op
        if not isinstance(atom, psl.Percept) and atom.agent != self.agent:
            return False
        heads = self._heads.get((state, op))
        if heads is None:
            heads = self._heads[(state, op)] = _by_head(self._pool(state, op))
        if isinstance(atom.term, psl.Wild):
            return any(heads.values())
        # matches() is false on terms of another head, so only those of the pattern's head are tried
        return any(matches(atom.term, t) for t in heads.get(_head(atom.term), ()))

    def _pool(self, state: int, op: str) -> frozenset[psl.Term]:
        """The terms an atom of modality ``op`` (``P`` for a percept) is matched against in ``state``."""
        ms = self.states[state]
        pool: frozenset[psl.Term]
        if op == "P":
            pool = ms.percepts
        elif op == "B":
            pool = ms.beliefs | self.derived.get(state, frozenset())
        elif op == "G":
            pool = ms.goals
        elif op == "D":
            pool = frozenset() if ms.last_action is None else frozenset({ms.last_action})
        elif op == "I":
            pool = ms.intentions
        elif op == "ItD":
            pool = ms.intended_actions
        else:  # pragma: no cover - psl.MODALITIES is closed
            raise ValueError(f"unknown modality {op}")
        return pool


def _head(t: psl.Term) -> tuple[object, ...]:
    """What :func:`matches` compares first: the kind of term, and a symbol's name or a
    compound's name and arity (every number has the same head)."""
    if isinstance(t, psl.Compound):
        return ("compound", t.name, len(t.args))
    if isinstance(t, psl.Sym):
        return ("symbol", t.name)
    return (type(t).__name__,)


def _by_head(pool: frozenset[psl.Term]) -> dict[tuple[object, ...], tuple[psl.Term, ...]]:
    out: dict[tuple[object, ...], list[psl.Term]] = {}
    for t in pool:
        out.setdefault(_head(t), []).append(t)
    return {k: tuple(v) for k, v in out.items()}


def matches(pattern: psl.Term, term: psl.Term) -> bool:
    """``pattern`` (may hold ``_``) matches the ground ``term``.

    A compound with no arguments and the symbol of the same name are the
    same term (AJPF writes ``inspect`` and ``inspect()`` alike); numbers
    compare by value.
    """
    if isinstance(pattern, psl.Wild):
        return True
    if isinstance(pattern, psl.Num) and isinstance(term, psl.Num):
        try:
            return float(pattern.text) == float(term.text)
        except ValueError:
            return pattern.text == term.text
    if isinstance(pattern, psl.Sym) and isinstance(term, psl.Sym):
        return pattern.name == term.name
    if isinstance(pattern, psl.Compound) and isinstance(term, psl.Compound):
        return (pattern.name == term.name and len(pattern.args) == len(term.args)
                and all(matches(p, t) for p, t in zip(pattern.args, term.args)))
    return False
