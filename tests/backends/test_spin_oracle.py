"""An independent check of the model checking: SPIN's verdicts against a direct search of the graph.

On small Gwendolen programs generated at random (Hypothesis), the program is
explored into a :class:`StateGraph`, every property ``[] p`` and
``[] (p -> <> q)`` over a few atoms goes into one Promela model, and each
verdict of ``pan`` is compared with a search of the graph written here,
independently of the Promela translation:

* ``[] p`` holds iff ``p`` holds in every state of the graph (every state
  was reached from state 0);
* ``[] (p -> <> q)`` fails iff some state satisfies ``p`` and not ``q`` and
  starts an infinite path on which ``q`` never holds: a path that stays in
  the states where ``q`` is false and either cycles or ends in a final
  state, which stutters for ever (docs/model-checking.md, "Fairness and
  stuttering").

The vacuity check is compared too: ``[] (p -> <> q)`` that holds is vacuous
exactly when no state satisfies ``p``.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Iterator

import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from rclverify.backends.model_checking.ajpf import psl
from rclverify.backends.model_checking import spin
from rclverify.backends.model_checking.environment import environment_from_plan
from rclverify.backends.model_checking.explore import explore_program
from rclverify.backends.model_checking.graph import StateGraph
from rclverify.backends.model_checking.gwendolen import parse_text
from rclverify.backends.model_checking.promela import Claim, build_model
from rclverify.backends.model_checking.vacuity import check_vacuity

from test_spin import HAVE_SPIN

pytestmark = pytest.mark.skipif(not HAVE_SPIN, reason="spin or gcc not installed (apt-get install spin)")

BELIEFS = ("a", "b", "c")
ATOMS = ("B(ag, a)", "B(ag, b)", "B(ag, c)", "P(p1)", "D(ag, act)", "~B(ag, a)")
TRIGGERS = ("+!g [perform]", "+a", "-a", "+b", "+p1", "+p2", "-p1")
GUARDS = ("B a", "~B a", "B b", "~B c", "B p1", "~B p2")
DEEDS = ("+a", "-a", "+b", "-b", "+c", "-c", "act", "act", "+!g [perform]")


@pytest.fixture(autouse=True, scope="module")
def own_cache(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("XDG_CACHE_HOME", str(tmp_path_factory.mktemp("xdg-cache")))
        yield


@st.composite
def programs(draw: st.DrawFn) -> str:
    """An agent with beliefs among a, b, c, the goal g, and plans that react to
    its beliefs and to the percepts p1, p2 the environment may send after ``act``."""
    beliefs = draw(st.lists(st.sampled_from(BELIEFS), unique=True, max_size=2))
    plans = [f"+!g [perform] : {{ True }} <- {', '.join(draw(st.lists(st.sampled_from(DEEDS), min_size=1, max_size=3)))};"]
    for _ in range(draw(st.integers(1, 4))):
        trigger = draw(st.sampled_from(TRIGGERS))
        guard = draw(st.lists(st.sampled_from(GUARDS), unique=True, max_size=2))
        body = draw(st.lists(st.sampled_from(DEEDS), min_size=1, max_size=3))
        plans.append(f"{trigger} : {{ {', '.join(guard) or 'True'} }} <- {', '.join(body)};")
    return ("GWENDOLEN\n:name: ag\n:Initial Beliefs:\n" + "\n".join(beliefs)
            + "\n:Initial Goals:\ng [perform]\n:Plans:\n" + "\n".join(plans) + "\n")


def state_holds(graph: StateGraph, k: int, text: str) -> bool:
    f = psl.parse(text)
    if isinstance(f, psl.Not):
        return not graph.holds(k, f.operand)  # type: ignore[arg-type]
    return graph.holds(k, f)  # type: ignore[arg-type]


def always_holds(graph: StateGraph, p: str) -> bool:
    return all(state_holds(graph, k, p) for k in range(len(graph.states)))


def response_holds(graph: StateGraph, p: str, q: str) -> bool:
    """``[] (p -> <> q)`` by search: no p-and-not-q state starts an infinite path avoiding q."""
    succ: dict[int, set[int]] = {k: set() for k in range(len(graph.states))}
    for t in graph.transitions:
        succ[t.src].add(t.dst)
    alive = {k for k in succ if not state_holds(graph, k, q)}
    changed = True
    while changed:  # keep the not-q states with an infinite not-q path: final (stutters) or a not-q successor alive
        changed = False
        for k in list(alive):
            if succ[k] and not succ[k] & alive:
                alive.discard(k)
                changed = True
    return not any(state_holds(graph, k, p) for k in alive)


@settings(max_examples=9, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(program=programs(), pairs=st.lists(st.tuples(st.sampled_from(ATOMS), st.sampled_from(ATOMS)),
                                          min_size=1, max_size=4, unique=True))
def test_spin_agrees_with_a_direct_search_of_the_graph(program: str, pairs: list[tuple[str, str]]) -> None:
    env = environment_from_plan({"percepts": ["p1", "p2"], "after": ["act"]})
    graph = explore_program(parse_text(program, "r.gwen"), env, max_states=300)
    assume(graph.complete)  # a program whose intentions grow without end (+!g in +!g's plan) has no whole graph
    claims = [Claim(f"a{k}", psl.parse(f"[] {p}")) for k, p in enumerate(ATOMS)]
    claims += [Claim(f"r{k}", psl.parse(f"[] ({p} -> <> {q})")) for k, (p, q) in enumerate(pairs)]
    tools, why = spin.find_tools()
    assert tools is not None, why
    model = build_model(graph, claims)
    built = spin.compile_model(tools, model.text, timeout_s=120)
    size = model.states + model.transitions
    depth = max(10_000, 20 * size)
    for k, p in enumerate(ATOMS):
        verdict = spin.check(tools, built, f"a{k}", depth, 120, size).verdict
        assert verdict == ("holds" if always_holds(graph, p) else "violated"), (program, p, verdict)
    for k, (p, q) in enumerate(pairs):
        verdict = spin.check(tools, built, f"r{k}", depth, 120, size).verdict
        expected = response_holds(graph, p, q)
        assert verdict == ("holds" if expected else "violated"), (program, p, q, verdict)
        if expected:
            reachable = any(state_holds(graph, s, p) for s in range(len(graph.states)))
            assert bool(check_vacuity(graph, claims[len(ATOMS) + k].formula).vacuous) == (not reachable)
