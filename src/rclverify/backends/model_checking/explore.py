"""Explicit-state exploration of a Gwendolen program under a verification environment.

Breadth-first search over :class:`~.cycle.AgentState` values: a state is
canonical and hashable (beliefs, intentions, percepts, last action and the
environment's state), so a state reached twice is one node of the graph.
The result is the :class:`~.graph.StateGraph` stage two (SPIN) reads; this
is stage one of AJPF's two-stage verification (Dennis, Fisher, Webster,
"Two-stage agent program verification", 2018), with this interpreter in
place of AJPF's JPF run.
"""
from __future__ import annotations

import time
from collections import deque
from pathlib import Path
from typing import Iterable

from rclverify.backends.model_checking.ajpf import psl
from rclverify.backends.model_checking.cycle import AgentState, Cycle, goals, initial_state
from rclverify.backends.model_checking.environment import Environment
from rclverify.backends.model_checking.graph import MentalState, StateGraph, Transition
from rclverify.backends.model_checking.gwendolen import Program, as_psl, parse_file
from rclverify.backends.model_checking.identifiers import ALTERNATE, FRESH, analyse, numbers
from rclverify.backends.model_checking.unify import BoundReached


def mental_state(state: AgentState) -> MentalState:
    """What the property language's atoms see of ``state`` (graph.MentalState's fields)."""
    bases = [i[0].event.term for i in state.intentions if i[0].event.goal_type and i[0].event.sign == "+"]
    acts = [as_psl(deeds[0].term) for i in state.intentions
            if (deeds := i[-1].deeds) and deeds[0].kind == "act"]
    return MentalState(
        beliefs=state.beliefs.frozen(),
        goals=frozenset(goals(state)),
        last_action=state.last_action,
        intentions=frozenset(bases),
        intended_actions=frozenset(acts),
        percepts=state.percepts.frozen(),
    )


def program_numbers(program: Program, environment: Environment) -> set[float]:
    """Every number written in ``program`` (beliefs, rules, goals, plans) and in ``environment``'s percepts."""
    terms: list[object] = [*program.beliefs, *(g for g, _ in program.goals), *environment.percepts,
                           *environment.initial]
    for rule in program.rules:
        terms += [rule.head, *(t for _, t in rule.body)]
    for plan in program.plans:
        terms += [plan.trigger.term, *(lit.term for lit in plan.guard), *(d.term for d in plan.body)]
    return numbers(terms)  # type: ignore[arg-type]


def explore_program(program: Program, environment: Environment, max_states: int = 100_000,
                    max_depth: int = 10_000, time_limit_s: float | None = None,
                    avoid: Iterable[float] = ()) -> StateGraph:
    """Explore ``program`` (see :func:`explore`)."""
    use = analyse(program, environment.percepts, environment.initial)
    extra = frozenset(program_numbers(program, environment) | set(avoid)) if use.mode == FRESH else frozenset()
    cycle = Cycle(program, environment, FRESH if use.mode == FRESH else ALTERNATE, extra)
    init = initial_state(program, environment)
    index: dict[AgentState, int] = {init: 0}
    states: list[AgentState] = [init]
    depth = [0]
    transitions: list[Transition] = []
    queue = deque([0])
    cut = ""
    deepest = 0
    deadline = None if time_limit_s is None else time.monotonic() + time_limit_s
    while queue:
        i = queue.popleft()
        if deadline is not None and time.monotonic() > deadline:
            cut = f"time > {time_limit_s:g} s"
            break
        try:
            steps = cycle.successors(states[i])
        except BoundReached as exc:  # the program builds ever deeper terms, or its rules explode
            cut = exc.bound
            break
        except RecursionError:  # a last resort: Python's stack, not a verdict
            cut = "recursion depth of the interpreter"
            break
        if steps and depth[i] >= max_depth:
            cut = cut or f"depth > {max_depth}"
            continue
        for step in steps:
            j = index.get(step.state)
            if j is None:
                if len(states) >= max_states:
                    cut = f"states > {max_states}"
                    queue.clear()
                    break
                j = len(states)
                index[step.state] = j
                states.append(step.state)
                depth.append(depth[i] + 1)
                deepest = max(deepest, depth[i] + 1)
                queue.append(j)
            transitions.append(Transition(i, j, step.label, step.line, step.stage))
    derived: dict[int, frozenset[psl.Term]] = {}
    if program.rules and not cut:
        try:
            for k, s in enumerate(states):
                d = cycle.beliefs(s).derived()
                if d:
                    derived[k] = d
        except BoundReached as exc:
            cut = exc.bound
        except RecursionError:
            cut = "recursion depth of the interpreter"
    return StateGraph(agent=program.name, source=program.source,
                      states=tuple(mental_state(s) for s in states), transitions=tuple(transitions),
                      complete=not cut, cut=cut, depth=deepest, identifiers=use.describe(), derived=derived)


def explore(program_path: Path, source_name: str, environment: Environment, max_states: int = 100_000,
            max_depth: int = 10_000, time_limit_s: float | None = None, avoid: Iterable[float] = ()
            ) -> StateGraph:
    """Parse the Gwendolen program at ``program_path`` and explore it under ``environment``.

    ``source_name`` is the workspace-relative path used in messages and
    labels.  Every state reachable within the bounds is a node (state 0 the
    initial state); every agent step and environment choice a transition.
    When more than ``max_states`` states are found, a state at depth
    ``max_depth`` (transitions from state 0) has successors, the exploration
    has run ``time_limit_s`` seconds, the program builds a term nested
    deeper than :data:`~.gwendolen.MAX_TERM_DEPTH` or its reasoning rules
    take more than :data:`~.unify.MAX_RESOLUTION_STEPS` steps in one state,
    exploration stops there: the graph has ``complete=False`` and ``cut``
    names the bound (``"states > 100000"``, ``"time > 300 s"``,
    ``"term depth > 64"``).  Identifiers are chosen as
    :func:`.identifiers.analyse` decides; ``avoid`` are further numbers a
    fresh identifier must differ from (the properties').  Raises
    :class:`~.gwendolen.GwendolenError` for errors in the program, also those
    found while running it (an unbound variable in a deed, rules nesting
    deeper than :data:`~.unify.MAX_RULE_DEPTH` calls).
    """
    return explore_program(parse_file(program_path, source_name), environment, max_states, max_depth,
                           time_limit_s, avoid)
