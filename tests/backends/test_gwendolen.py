"""The Gwendolen interpreter and explorer (model checking, stage one; issue 31).

Small programs under tests/data/gwendolen/ with known traces, and the case
study's agent (backends/ajpf/jackal.gwen) explored under the case study's
verification environment, spot-checked with ``StateGraph.holds``.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.backends.model_checking.ajpf import psl
from rclverify.backends.model_checking.environment import Environment, environment_from_plan
from rclverify.backends.model_checking.explore import explore, explore_program
from rclverify.backends.model_checking.graph import StateGraph
from rclverify.backends.model_checking.gwendolen import GwendolenError, parse_file, parse_text
from rclverify.model.plan.errors import PlanError
from rclverify.lang.ast import Loc

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data" / "gwendolen"
JACKAL = ROOT / "backends" / "ajpf" / "jackal.gwen"
#: The case study's environment: after each move, a move_base result, a radiation alarm, or nothing.
CASE_STUDY_ENV = {"percepts": ["movebase_result(_, 3)", "movebase_result(_, 2)", "danger_red", "danger_orange"],
                  "after": ["move"], "at_most": 1}
QUIET = Environment(percepts=(psl.Sym("never"),), after=("no_such_action",))


def run(name: str, env: Environment = QUIET, **kw) -> StateGraph:
    return explore(DATA / name, f"tests/data/gwendolen/{name}", env, **kw)


def trace(g: StateGraph) -> list[str]:
    """The labels along the only path of a deterministic graph."""
    out, state, seen = [], 0, set()
    while True:
        succ = [t for t in g.transitions if t.src == state]
        if not succ:
            return out
        assert len(succ) == 1, f"state {state} branches: {succ}"
        assert state not in seen, "the path loops"
        seen.add(state)
        out.append(succ[0].label)
        state = succ[0].dst


def actions(g: StateGraph) -> list[str]:
    """The actions along the only path, in order."""
    return [label.split(": deed ", 1)[1] for label in trace(g)
            if ": deed " in label and label.split(": deed ", 1)[1][:1] not in "+-"]


def atom(text: str):
    return psl.parse(text)


def reachable(g: StateGraph, start: int) -> set[int]:
    succ: dict[int, list[int]] = {}
    for t in g.transitions:
        succ.setdefault(t.src, []).append(t.dst)
    seen, todo = {start}, [start]
    while todo:
        for j in succ.get(todo.pop(), []):
            if j not in seen:
                seen.add(j)
                todo.append(j)
    return seen


# -- the parser --------------------------------------------------------------

def test_jackal_parses_with_its_plans_in_order_and_lines():
    prog = parse_file(JACKAL, "backends/ajpf/jackal.gwen")
    assert prog.name == "jackal"
    assert len(prog.beliefs) == 25 and prog.goals == ((psl.Compound("inspect", (psl.Num("1"),)), "perform"),)
    texts = [p.trigger.text() for p in prog.plans]
    assert texts == ["+!inspect(Location) [perform]", "+movebase_result(Id, 3)", "+movebase_result(Id, 3)",
                     "+movebase_result(Id, 2)", "+danger_red", "+danger_orange"]
    lines = JACKAL.read_text().splitlines()
    for plan in prog.plans:  # each plan's line is where its trigger is written
        assert lines[plan.line - 1].lstrip().startswith(plan.trigger.sign)
        for deed in plan.body:
            assert deed.text().split("(")[0].lstrip("+-!") in lines[deed.line - 1]


def test_unsupported_construct_is_refused_by_name_at_its_location():
    with pytest.raises(GwendolenError) as exc:
        parse_file(DATA / "unsupported.gwen", "tests/data/gwendolen/unsupported.gwen")
    assert str(exc.value) == ("tests/data/gwendolen/unsupported.gwen:11:39: error: Gwendolen construct .send "
                              "(as a deed) is not supported by rclverify's interpreter")


@pytest.mark.parametrize("text, where, what", [
    ("+b <- *c;", "1:34", "*b (wait for a belief)"),
    ("+.received(:tell, x) <- a;", "1:28", "+.received (as a plan trigger)"),
    ("+b <- +.lock, a;", "1:34", "+.lock (as a deed)"),
    ("+b : { X > 1 } <- a;", "1:37", "comparison '>' (in a guard)"),
    ("+b : { .sent(x) } <- a;", "1:35", ".sent (in a guard)"),
    ("+b <- ?c;", "1:34", "?b (test goal)"),
])
def test_each_unsupported_construct_names_itself(text, where, what):
    with pytest.raises(GwendolenError) as exc:
        parse_text(f"GWENDOLEN :name: a :Plans: {text}", "x.gwen")
    assert str(exc.value) == f"x.gwen:{where}: error: Gwendolen construct {what} is not supported by rclverify's interpreter"


def test_syntax_errors_are_located_and_say_what_was_expected():
    with pytest.raises(GwendolenError) as exc:
        parse_text("GWENDOLEN\n:name: a\n:Plans:\n+b : { B x <- a;\n", "p.gwen")
    assert str(exc.value) == "p.gwen:4:12: error: unexpected '<-' (expected one of: ',', '}')"
    with pytest.raises(GwendolenError, match=r"p.gwen:1:39: error: unknown goal type \[soon\]"):
        parse_text("GWENDOLEN :name: a :Initial Goals: g [soon]", "p.gwen")
    with pytest.raises(GwendolenError, match=r"p.gwen:1:38: error: an initial belief must be ground"):
        parse_text("GWENDOLEN :name: a :Initial Beliefs: at(X)", "p.gwen")
    with pytest.raises(GwendolenError, match="unexpected end of the program"):
        parse_text("GWENDOLEN :name: a :Plans: +b <- a", "p.gwen")
    with pytest.raises(GwendolenError, match="^p.gwen:1:1: error: empty program"):
        parse_text("\n", "p.gwen")


def test_terminators_comments_and_empty_argument_lists():
    prog = parse_text("GWENDOLEN\n/* block\n comment */ :name: a // line comment\n:Reasoning Rules:\nr :- s.\n"
                      ":Plans:\n+!g() [perform] : { True } <- act(), +b(\"text\", -1.5, _).\n+b <- c;\n", "p.gwen")
    assert prog.rules[0].line == 5
    assert [p.trigger.text() for p in prog.plans] == ["+!g [perform]", "+b"]
    assert [d.text() for d in prog.plans[0].body] == ["act", '+b("text", -1.5, _)']
    assert [p.line for p in prog.plans] == [7, 8]


def test_mutated_programs_give_a_program_or_one_located_error():
    """Never a traceback: each damaged copy of the case study's program parses
    and explores, or fails with a GwendolenError located in the file."""
    import random
    rnd = random.Random(31)
    text = JACKAL.read_text()
    pieces = list("+-!~_.,;:(){}[]<>*?\"/ \nBGX0") + ["<-", ":-", "True", ".send", "[achieve]", "going(0)", "L2"]
    env = environment_from_plan(CASE_STUDY_ENV)
    outcomes = {"parsed": 0, "refused": 0}
    for _ in range(60):
        t = text
        for _ in range(rnd.randint(1, 2)):
            i = rnd.randrange(len(t))
            t = t[:i] + rnd.choice(pieces) + t[i + rnd.randint(0, 4):]
        try:
            prog = parse_text(t, "f.gwen")
            explore_program(prog, env, max_states=500)
            outcomes["parsed"] += 1
        except GwendolenError as exc:
            assert str(exc).startswith("f.gwen:") and ": error: " in str(exc)
            outcomes["refused"] += 1
    assert outcomes["parsed"] > 0 and outcomes["refused"] > 0


# -- the reasoning cycle -----------------------------------------------------

def test_first_applicable_plan_in_program_order_is_chosen():
    g = run("plan_order.gwen")
    assert g.complete
    # the first plan's guard fails (no c); the second and third are applicable: the second is chosen
    assert trace(g) == ["plan tests/data/gwendolen/plan_order.gwen:18 +!pick [perform]: deed from_second"]
    assert [t.line for t in g.transitions] == [18]
    assert g.holds(1, atom("D(chooser, from_second)")) and not g.holds(1, atom("D(chooser, from_third)"))
    assert g.holds(0, atom("G(chooser, pick)")) and not g.holds(1, atom("G(chooser, pick)"))


def test_belief_additions_and_deletions_are_events_that_trigger_plans():
    g = run("belief_events.gwen")
    # +seen(3) and -old(7) each post an event, handled in turn (round robin);
    # the guard-free plans bind N and X by unification with the event
    assert actions(g) == ["noticed(3)", "forgot(7)"]
    final = len(g.states) - 1
    assert g.holds(final, atom("B(noticer, seen(3))")) and not g.holds(final, atom("B(noticer, old(_))"))
    assert g.holds(0, atom("B(noticer, old(7))"))


def test_achieve_goal_persists_until_believed_then_is_dropped():
    g = run("goals.gwen")
    t = trace(g)
    # built [achieve]: the first plan runs, the goal is not yet believed, so a
    # plan is chosen again (the second); once +built is believed the goal is
    # dropped before after_built runs.  tidy [perform] is dropped when its
    # plan completes.  unknown [achieve] has no plan: it is dropped.
    assert actions(g) == ["sweep", "lay_foundation"]
    assert "goal achieved, dropped: +!built [achieve]" in t
    assert "no applicable plan for goal +!unknown [achieve]: dropped" in t
    assert not any("after_built" in label for label in t)
    final = len(g.states) - 1
    assert g.holds(0, atom("G(worker, built)")) and g.holds(0, atom("G(worker, tidy)"))
    assert g.holds(final, atom("B(worker, built)"))
    for goal in ("built", "tidy", "unknown"):
        assert not g.holds(final, atom(f"G(worker, {goal})"))
    # the goal stays adopted while its first plan completes without achieving it
    lay = next(i for i in range(len(g.states)) if g.holds(i, atom("D(worker, lay_foundation)")))
    assert g.holds(lay, atom("G(worker, built)"))


def test_perform_goal_runs_its_whole_plan_where_achieve_stops_at_belief(tmp_path):
    body = "+!g [{t}] : {{ True }} <- +g, after;"
    runs = {}
    for t in ("achieve", "perform"):
        p = tmp_path / f"{t}.gwen"
        p.write_text(f"GWENDOLEN :name: a :Initial Goals: g [{t}] :Plans: {body.format(t=t)}")
        runs[t] = actions(explore(p, p.name, QUIET))
    assert runs == {"achieve": [], "perform": ["after"]}


def test_dropping_a_goal_removes_its_subgoals_and_posts_the_drop_event():
    g = run("drop_goal.gwen")
    assert actions(g) == ["cleaned_up"]
    assert "plan tests/data/gwendolen/drop_goal.gwen:14 +!step [perform]: deed -!work [achieve]" in trace(g)
    step = next(i for i in range(len(g.states)) if g.holds(i, atom("G(quitter, step)")))
    assert g.holds(step, atom("G(quitter, work)")) and g.holds(step, atom("I(quitter, work)"))
    final = len(g.states) - 1
    assert not g.holds(final, atom("G(quitter, work)")) and not g.holds(final, atom("G(quitter, step)"))


def test_reasoning_rules_answer_guards_and_derived_beliefs():
    g = run("rules.gwen")
    assert actions(g) == ["walk_out(hall)"]
    assert g.holds(0, atom("B(reasoner, can_leave)")) and g.holds(0, atom("B(reasoner, near(hall))"))
    assert not g.holds(0, atom("B(reasoner, near(kitchen))"))


def test_unbound_variable_in_a_deed_is_a_located_error(tmp_path):
    p = tmp_path / "unbound.gwen"
    p.write_text("GWENDOLEN\n:name: a\n:Initial Goals:\ng [perform]\n:Plans:\n+!g [perform] <- go(Where);\n")
    with pytest.raises(GwendolenError, match=r"^unbound.gwen:6:18: error: variable Where of deed go\(Where\)"):
        explore(p, "unbound.gwen", QUIET)


def test_runaway_rules_and_wildcard_additions_are_located_errors(tmp_path):
    loop = tmp_path / "loop.gwen"
    loop.write_text("GWENDOLEN\n:name: a\n:Reasoning Rules:\nup :- up;\n:Initial Goals:\ng [perform]\n"
                    ":Plans:\n+!g [perform] : { B up } <- go;\n")
    with pytest.raises(GwendolenError, match=r"^loop.gwen:4:1: error: reasoning rules nest deeper than 64"):
        explore(loop, "loop.gwen", QUIET)
    wild = tmp_path / "wild.gwen"
    wild.write_text("GWENDOLEN\n:name: a\n:Initial Goals:\ng [perform]\n:Plans:\n+!g [perform] <- +seen(_);\n")
    with pytest.raises(GwendolenError, match=r"^wild.gwen:6:18: error: '_' in deed \+seen\(_\)"):
        explore(wild, "wild.gwen", QUIET)


# -- the verification environment --------------------------------------------

def test_environment_branches_after_the_declared_actions_only():
    env = environment_from_plan({"percepts": ["pong(_)"], "after": ["ping"]})
    g = run("reactive.gwen", env)
    assert g.complete
    env_steps = [t for t in g.transitions if t.stage == "env"]
    assert {t.label for t in env_steps} == {"environment after ping: asserts nothing",
                                            "environment after ping: asserts pong(1)",
                                            "environment after ping: asserts pong(2)"}
    assert all(t.line is None for t in env_steps)
    assert all(t.line for t in g.transitions if t.stage == "D")
    # the second answer carries the next identifier, so it is a new percept and triggers the second plan
    done = [i for i in range(len(g.states)) if g.holds(i, atom("D(pinger, done)"))]
    assert done and all(g.holds(i, atom("P(pong(2))")) and g.holds(i, atom("B(pinger, answered)")) for i in done)
    # answering nothing leaves the agent waiting: a final state where it has pinged once
    finals = reachable(g, 0) - {t.src for t in g.transitions}
    assert any(g.holds(i, atom("D(pinger, ping)")) and not g.holds(i, atom("B(pinger, answered)")) for i in finals)


def test_environment_from_plan_shape_and_defaults():
    env = environment_from_plan(CASE_STUDY_ENV)
    assert env.after == ("move",) and env.at_most == 1 and len(env.percepts) == 4
    assert env.reacts_to(psl.Compound("move", (psl.Num("1"),))) and not env.reacts_to(psl.Sym("inspect"))
    assert [len(c) for c in env.choices(1)] == [0, 1, 1, 1, 1]
    assert env.choices(2)[1] == (psl.Compound("movebase_result", (psl.Num("2"), psl.Num("3"))),)
    every = environment_from_plan({"percepts": ["a", "b"], "at_most": 2})
    assert every.after is None and every.reacts_to(psl.Sym("anything")) and len(every.choices(1)) == 4
    always = environment_from_plan({"percepts": ["a", "b"], "at_least": 1})
    assert always.choices(1) == [(psl.Sym("a"),), (psl.Sym("b"),)]


@pytest.mark.parametrize("raw, message, path", [
    ({"percepts": ["a"], "when": "x"}, "unknown key 'when'", ("when",)),
    ({"after": "action"}, "'percepts' is required", ()),
    ({"percepts": []}, "'percepts' is empty", ("percepts",)),
    ({"percepts": "a"}, "'percepts' must be a list of terms", ("percepts",)),
    ({"percepts": ["a", "f(X)"]}, "percepts[1] 'f(X)' is not a term", ("percepts", 1)),
    ({"percepts": ["a", "a"]}, "percepts[1] 'a' is listed twice", ("percepts", 1)),
    ({"percepts": ["a"], "at_most": 2}, "'at_most' must be an integer from 1 to 1", ("at_most",)),
    ({"percepts": ["a"], "at_least": 2}, "'at_least' must be an integer from 0 to 1", ("at_least",)),
    ({"percepts": ["a"], "after": ["Move"]}, "'after' must be \"action\"", ("after",)),
    ({"percepts": ["a"], "initial": ["f(_)"]}, "initial[0] 'f(_)': an initial percept must be ground", ("initial", 0)),
])
def test_environment_errors_are_located_in_the_plan(raw, message, path):
    def locate(*p):
        return Loc("contracts/plan.yaml", 40 + len(p), 7)
    with pytest.raises(PlanError) as exc:
        environment_from_plan(raw, locate)
    text = str(exc.value)
    assert text.startswith(f"contracts/plan.yaml:{40 + len(path)}:") and f"error: environment: {message}" in text


# -- the case study's agent --------------------------------------------------

@pytest.fixture(scope="module")
def jackal() -> StateGraph:
    return explore(JACKAL, "backends/ajpf/jackal.gwen", environment_from_plan(CASE_STUDY_ENV))


def test_jackal_explores_to_a_complete_graph(jackal):
    g = jackal
    assert g.complete and g.cut == "" and g.agent == "jackal" and g.source == "backends/ajpf/jackal.gwen"
    assert len(g.states) > 100 and g.depth > 100
    assert {t.stage for t in g.transitions} <= {"A", "B", "C", "D", "env"}
    assert all(0 <= t.src < len(g.states) and 0 <= t.dst < len(g.states) for t in g.transitions)
    assert g.transitions[0].label == "plan backends/ajpf/jackal.gwen:72 +!inspect(1) [perform]: deed +going(1)"


def test_jackal_danger_leads_back_to_the_entrance(jackal):
    g = jackal
    red = [i for i in range(len(g.states)) if g.holds(i, atom("B(jackal, danger_red)"))]
    assert red
    for i in red:
        assert any(g.holds(j, atom("B(jackal, going(0))")) for j in reachable(g, i))


def test_jackal_inspects_and_records_every_waypoint(jackal):
    g = jackal
    n = range(len(g.states))
    assert any(g.holds(i, atom("D(jackal, inspect)")) for i in n)
    for k in range(1, 13):
        assert any(g.holds(i, atom(f"B(jackal, inspected({k}))")) for i in n)
    assert not any(g.holds(i, atom("B(jackal, inspected(0))")) for i in n)
    # arrived at waypoint 12, the rover heads for the entrance
    at12 = [i for i in n if g.holds(i, atom("B(jackal, going(12))")) and g.holds(i, atom("B(jackal, movebase_result(_, 3))"))
            and g.holds(i, atom("B(jackal, inspected(11))"))]
    assert at12 and all(any(g.holds(j, atom("B(jackal, going(0))")) for j in reachable(g, i)) for i in at12)


DIGEST = """
import hashlib, sys
from pathlib import Path
from rclverify.backends.model_checking.ajpf import psl
from rclverify.backends.model_checking.environment import environment_from_plan
from rclverify.backends.model_checking.explore import explore, explore_program
g = explore(Path(sys.argv[1]), "jackal.gwen", environment_from_plan(%r))
rows = [sorted(psl.term_text(t) for t in s.beliefs) + ["|"] + sorted(psl.term_text(t) for t in s.goals)
        + ["|", psl.term_text(s.last_action) if s.last_action else ""] for s in g.states]
print(hashlib.sha256(repr((rows, g.transitions)).encode()).hexdigest())
""" % (CASE_STUDY_ENV,)


def test_the_graph_does_not_depend_on_the_hash_seed():
    """State numbering and labels are the same in every process (evidence is reproducible)."""
    import os
    import subprocess
    import sys
    digests = set()
    for seed in ("1", "2"):
        env = {**os.environ, "PYTHONHASHSEED": seed}
        out = subprocess.run([sys.executable, "-c", DIGEST, str(JACKAL)], env=env, capture_output=True, text=True,
                             timeout=120, check=True)
        digests.add(out.stdout.strip())
    assert len(digests) == 1


def test_bounds_cut_the_exploration(jackal):
    env = environment_from_plan(CASE_STUDY_ENV)
    small = explore(JACKAL, "backends/ajpf/jackal.gwen", env, max_states=50)
    assert not small.complete and small.cut == "states > 50" and len(small.states) == 50
    shallow = explore(JACKAL, "backends/ajpf/jackal.gwen", env, max_depth=10)
    assert not shallow.complete and shallow.cut == "depth > 10" and shallow.depth == 10
    assert len(shallow.states) < len(jackal.states)
    # a bound the exploration does not reach does not cut it
    exact = explore(JACKAL, "backends/ajpf/jackal.gwen", env, max_depth=jackal.depth,
                    max_states=len(jackal.states))
    assert exact.complete and exact.transitions == jackal.transitions
    assert not explore(JACKAL, "backends/ajpf/jackal.gwen", env, max_depth=jackal.depth - 1).complete
