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

from collections import deque
from pathlib import Path

from ..ajpf import psl
from .cycle import AgentState, Cycle, goals, initial_state
from .environment import Environment
from .graph import MentalState, StateGraph, Transition
from .gwendolen import Program, as_psl, parse_file


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


def explore_program(program: Program, environment: Environment, max_states: int = 100_000,
                    max_depth: int = 10_000) -> StateGraph:
    """Explore ``program`` (see :func:`explore`)."""
    cycle = Cycle(program, environment)
    init = initial_state(program, environment)
    index: dict[AgentState, int] = {init: 0}
    states: list[AgentState] = [init]
    depth = [0]
    transitions: list[Transition] = []
    queue = deque([0])
    cut = ""
    deepest = 0
    while queue:
        i = queue.popleft()
        steps = cycle.successors(states[i])
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
    if program.rules:
        for k, s in enumerate(states):
            d = cycle.beliefs(s).derived()
            if d:
                derived[k] = d
    return StateGraph(agent=program.name, source=program.source,
                      states=tuple(mental_state(s) for s in states), transitions=tuple(transitions),
                      complete=not cut, cut=cut, depth=deepest, derived=derived)


def explore(program_path: Path, source_name: str, environment: Environment, max_states: int = 100_000,
            max_depth: int = 10_000) -> StateGraph:
    """Parse the Gwendolen program at ``program_path`` and explore it under ``environment``.

    ``source_name`` is the workspace-relative path used in messages and
    labels.  Every state reachable within the bounds is a node (state 0 the
    initial state); every agent step and environment choice a transition.
    When more than ``max_states`` states are found, or a state at depth
    ``max_depth`` (transitions from state 0) has successors, exploration
    stops there: the graph has ``complete=False`` and ``cut`` names the
    bound.  Raises :class:`~.gwendolen.GwendolenError` for errors in the
    program, also those found while running it (an unbound variable in a
    deed, rules nesting without end).
    """
    return explore_program(parse_file(program_path, source_name), environment, max_states, max_depth)
