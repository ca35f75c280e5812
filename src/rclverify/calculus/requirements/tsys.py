"""Transition systems and temporal verdicts: the types the temporal engine shares.

A symbolic transition system (:class:`TransitionSystem`) is a set of state
variables with Z3 sorts, an initial predicate over one state and a step
relation over two.  Its *runs* are its maximal paths: infinite, or finite
and ending in a state with no successor (a deadlock; docs/requirements.md,
"Runs that stop").  The checkers of :mod:`.temporal` and :mod:`.deadlock`
return a :class:`TemporalVerdict`.

Source: the transition-system reading of the paper's stream model
(compositional-verification-paper.tex, lines 462-495) and of bounded model
checking (Biere, Cimatti, Clarke, Zhu, TACAS 1999).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

import z3

from rclverify.semantics.connectives import conj, disj
from rclverify.calculus.shapes import TemporalVerdictJson

State = dict[str, z3.ExprRef]
Pred = Callable[[State], z3.BoolRef]
Trans = Callable[[State, State], z3.BoolRef]


@dataclass(frozen=True)
class Fairness:
    """A strong fairness (compassion) constraint on infinite runs: if
    ``enabled`` holds at infinitely many steps, ``taken`` holds at infinitely
    many (Manna and Pnueli, 1992).  ``label`` names it in verdicts (a node's
    progress: the node, ``enabled`` its assumption, ``taken`` its answer)."""

    label: str
    enabled: Pred
    taken: Pred


@dataclass(frozen=True)
class TransitionSystem:
    """A symbolic transition system.

    ``sorts`` maps each state variable's name to a Z3 sort; ``init`` is a
    predicate over the first state; ``trans`` relates a state to the next;
    ``fairness`` the constraints every infinite run meets (a lasso that
    breaks one is not a run: :func:`fair_loop`).  Finite prefixes are not
    held to them (a safety counterexample need not extend to a fair run, as
    in SPIN's and NuSMV's invariant checks).
    """

    sorts: dict[str, z3.SortRef]
    init: Pred
    trans: Trans
    fairness: tuple[Fairness, ...] = ()

    def state(self, step: int, tag: str = "") -> State:
        """Fresh Z3 constants for the state at ``step`` (0-based); ``tag``
        keeps apart the states of another query over the same steps."""
        return {n: z3.Const(f"{n}@{tag}{step}", s) for n, s in self.sorts.items()}


@dataclass
class TemporalVerdict:
    """The verdict on one temporal property.

    ``status`` is ``proved`` | ``met`` | ``refuted`` | ``inconclusive``;
    ``method`` names how (``k-induction``, ``bounded``, ``ranking``, ``bmc``,
    ``lasso``, ``deadlock``); ``k`` the induction depth used; ``bound`` the
    number of steps checked; ``trace`` the counterexample, one ``{variable:
    value}`` per step (method ``deadlock``: its last state has no
    successor); ``loop`` a lasso's loop step (the last state of ``trace``
    equals state ``loop``); ``deadlock`` what is known of runs that stop
    (``""`` when not asked; else a sentence: deadlock-free and how,
    reachable at which step, or undecided and why); ``certificate`` the
    inductive invariant that proves it, as text, when one was found and
    re-checked (method ``pdr``: :mod:`.safety`).
    """

    status: str
    method: str
    k: int | None = None
    bound: int | None = None
    trace: list[dict[str, str]] = field(default_factory=list)
    detail: str = ""
    loop: int | None = None
    deadlock: str = ""
    certificate: str = ""

    def to_json(self) -> TemporalVerdictJson:
        """The record fields (a JSON-ready dict)."""
        return {"status": self.status, "method": self.method, "k": self.k, "bound": self.bound,
                "trace": self.trace, "detail": self.detail, "loop": self.loop, "deadlock": self.deadlock, "certificate": self.certificate}


def unroll(ts: TransitionSystem, n: int, tag: str = "") -> tuple[list[State], list[z3.BoolRef]]:
    """States 0..``n`` of ``ts`` and the ``n`` steps between them."""
    states = [ts.state(i, tag) for i in range(n + 1)]
    steps = [ts.trans(states[i], states[i + 1]) for i in range(n)]
    return states, steps


def distinct(states: list[State]) -> list[z3.BoolRef]:
    """Every two of ``states`` differ in some variable: the simple-path
    constraint of k-induction's step case.  Sound (a path violating a
    property contains a simple one that does), and it makes k-induction
    complete on a finite-state system for k beyond its longest simple path
    (Sheeran, Singh, Stalmarck, FMCAD 2000)."""
    return [disj(*[a[v] != b[v] for v in a]) for i, a in enumerate(states) for b in states[i + 1:]]


def trace_of(model: z3.ModelRef, states: list[State]) -> list[dict[str, str]]:
    """The values ``model`` gives ``states``, one ``{variable: text}`` per step."""
    return [{n: str(model.eval(v, model_completion=True)) for n, v in s.items()} for s in states]


def with_flag(ts: TransitionSystem, name: str, init: Callable[[Any], Any],
              step: Callable[[Any, Any], Any]) -> TransitionSystem:
    """``ts`` with one more Boolean variable ``name``: ``init(s)`` its first
    value, ``step(s, t)`` its next (a history variable: it constrains
    nothing, and every state of ``ts`` with a successor still has one)."""
    sorts = {**ts.sorts, name: z3.BoolSort()}
    return TransitionSystem(sorts, lambda s: conj(ts.init(s), s[name] == init(s)),
                            lambda s, t: conj(ts.trans(s, t), t[name] == step(s, t)), ts.fairness)


def fair_loop(ts: TransitionSystem, loop: list[State]) -> z3.BoolRef:
    """The states ``loop`` (s_j .. s_{n-1} of a lasso whose s_n equals s_j),
    repeated forever, meet every fairness constraint of ``ts``: for each,
    ``enabled`` at no state of the loop or ``taken`` at one of them."""
    return conj(*[z3.Implies(disj(*[f.enabled(s) for s in loop]), disj(*[f.taken(s) for s in loop]))
                    for f in ts.fairness]) if ts.fairness else z3.BoolVal(True)


class FairLoops:
    """:func:`fair_loop` for the many loops a lasso search asks about (every
    loop start j of every length n), each state's ``enabled`` and ``taken``
    terms built once and kept by the state's terms: the same term as
    ``fair_loop(ts, states[j:n])``, built in time linear in the loop instead
    of in the loop times the predicates' size (the searches asked O(n^2)
    loops of O(n) states each, every predicate built again)."""

    def __init__(self, ts: TransitionSystem) -> None:
        self.fairness = ts.fairness
        # by the ids of a state's terms, the terms kept alive beside them (an id is reused once its term is freed)
        self._marks: dict[tuple[int, ...], tuple[tuple[z3.ExprRef, ...], list[tuple[z3.BoolRef, z3.BoolRef]]]] = {}

    def _of(self, s: State) -> list[tuple[z3.BoolRef, z3.BoolRef]]:
        key = tuple(x.get_id() for x in s.values())
        got = self._marks.get(key)
        if got is None:
            got = self._marks[key] = (tuple(s.values()), [(f.enabled(s), f.taken(s)) for f in self.fairness])
        return got[1]

    def loop(self, states: list[State], j: int, n: int) -> z3.BoolRef:
        """``fair_loop(ts, states[j:n])``."""
        if not self.fairness:
            return z3.BoolVal(True)
        marks = [self._of(s) for s in states[j:n]]
        return conj(*[z3.Implies(disj(*[m[c][0] for m in marks]), disj(*[m[c][1] for m in marks]))
                        for c in range(len(self.fairness))])
