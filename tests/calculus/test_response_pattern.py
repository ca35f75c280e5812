"""The response pattern (issue 48): ``always (P -> eventually[<= N] Q)``,
``always (P -> eventually Q)`` and ``always (P -> next Q)`` parsed, decided
over the composed system and checked against a brute-force enumeration of
small systems."""
from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import pytest
import z3
from hypothesis import given, settings
from hypothesis import strategies as st

from rclverify.cli.commands import main
from rclverify.calculus.requirements.response import check_response, check_unbounded_response
from rclverify.calculus.requirements.tsys import TransitionSystem

STATES = range(4)


@st.composite
def systems(draw):
    init = draw(st.sets(st.sampled_from(STATES), min_size=1))
    succ = {s: draw(st.sets(st.sampled_from(STATES), min_size=1)) for s in STATES}  # every state goes on
    p = draw(st.sets(st.sampled_from(STATES)))
    q = draw(st.sets(st.sampled_from(STATES)))
    n = draw(st.sampled_from([None, 0, 1, 2, math.inf]))
    return init, succ, p, q, n


def _brute(init, succ, p, q, n) -> bool:
    """Whether every run meets the statement, by enumeration: the reachable
    states; then a P not answered in time is a path from a reachable P-state."""
    seen, todo = set(init), list(init)
    while todo:
        s = todo.pop()
        for t in succ[s] - seen:
            seen.add(t)
            todo.append(t)
    if n is None:  # always (P -> next Q): a reachable P-state with a successor outside Q
        return not any(s in p and succ[s] - q for s in seen)
    if n == math.inf:  # always (P -> eventually Q): a reachable P-state outside Q with an infinite path outside Q
        stay = set(STATES) - q
        while True:  # the states outside Q with a successor in the set: the greatest fixpoint
            keep = {s for s in stay if succ[s] & stay}
            if keep == stay:
                break
            stay = keep
        return not any(s in p and s in stay for s in seen)

    def misses(s, left: int) -> bool:  # a path from s of `left` more steps never in Q (s itself not in Q)
        return s not in q and (left == 0 or any(misses(t, left - 1) for t in succ[s]))
    return not any(s in p and misses(s, n) for s in seen)


@settings(max_examples=120, deadline=None)
@given(systems())
def test_response_equals_enumeration(sys_) -> None:
    init, succ, p, q, n = sys_
    ts = TransitionSystem({"x": z3.IntSort()},
                          lambda s: z3.Or(*[s["x"] == i for i in init]),
                          lambda s, t: z3.Or(*[z3.And(s["x"] == a, t["x"] == b) for a in STATES for b in succ[a]]))
    inside = lambda s, xs: z3.Or(*[s["x"] == i for i in xs]) if xs else z3.BoolVal(False)  # noqa: E731
    if n == math.inf:
        v = check_unbounded_response(ts, lambda s: inside(s, p), lambda s: inside(s, q), max_k=6, timeout_ms=5_000)
    else:
        v = check_response(ts, lambda s: inside(s, p), lambda s: inside(s, q), n, max_k=4 * ((n or 0) + 2) + 2,
                           timeout_ms=5_000)
    assert v.status == ("proved" if _brute(init, succ, p, q, n) else "refuted"), (v.status, v.detail)


# -- in the plan, on a three-node chain -------------------------------------------------------------------

def _with(root: Path, formal: str) -> None:
    plan = root / "contracts/plan.yaml"
    plan.write_text(plan.read_text().replace("requirements:\n", "requirements:\n  - id: RESP\n    text: answered\n"
                                                                f"    formal: \"{formal}\"\n", 1))


@pytest.fixture(scope="module")
def chain(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("resp") / "ws"
    assert main(["init", str(root)]) == 0
    for f in ("sensor", "controller", "actuator"):  # each node answers at the step its assumption holds
        p = root / f"contracts/{f}.rcl"
        p.write_text(p.read_text().replace("\n  assume(", "\n  progress( within 0 steps )\n  assume(", 1))
    return root


@pytest.mark.parametrize("n, verdict", [(1, "refuted"), (2, "proved, evidence outstanding")])
def test_a_chain_answers_within_its_length(chain: Path, tmp_path: Path, n: int, verdict: str,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    root = tmp_path / "ws"
    shutil.copytree(chain, root)
    _with(root, f"always (Sensor.in.reading >= 90 -> eventually[<= {n}] Actuator.out.actuator_value >= 0)")
    main(["requirements", "-w", str(root)])
    assert f"RESP: {verdict}" in capsys.readouterr().out


def test_the_unbounded_response_is_decided(chain: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``always (P -> eventually Q)`` on the chain: proved from the bounded form, every node answering
    at the step its assumption holds (the refutations are the oracle's above)."""
    root = tmp_path / "ws"
    shutil.copytree(chain, root)
    _with(root, "always (Sensor.in.reading >= 90 -> eventually Actuator.out.actuator_value >= 0)")
    main(["requirements", "-w", str(root)])
    assert "RESP: proved, evidence outstanding" in capsys.readouterr().out
    rec = json.loads((root / "artifacts/requirements/RESP.json").read_text())
    assert rec["temporal"]["method"] == "bounded response" and rec["temporal"]["bound"] == 2



def test_the_plans_ranking_and_invariant_are_read_for_the_unbounded_response(chain: Path, tmp_path: Path) -> None:
    """docs/requirements.md: ``always (P -> eventually Q)`` is proved by the plan's ``ranking:`` (and
    ``invariant:``); the plan refused both on it (E-temporal).  Neither proves what does not hold: an
    invariant that is not proved leaves the ranking unused (it read proved: the rank 0 "decreases"
    vacuously inside a false invariant)."""
    root = tmp_path / "ws"
    shutil.copytree(chain, root)
    for f in ("sensor", "controller", "actuator"):  # answering eventually: no bound proves it
        p = root / f"contracts/{f}.rcl"
        p.write_text(p.read_text().replace("progress( within 0 steps )", "progress( eventually )"))
    _with(root, "always (Sensor.in.reading >= 90 -> eventually Actuator.out.actuator_value >= 0)")
    plan = root / "contracts/plan.yaml"
    text = plan.read_text()
    hints = '    ranking: "0"\n    invariant: "Sensor.in.reading >= 0 and Sensor.in.reading < 0"\n'
    plan.write_text(text.replace("    text: answered\n", "    text: answered\n" + hints, 1))
    assert main(["requirements", "-w", str(root)]) in (0, 1)
    rec = json.loads((root / "artifacts/requirements/RESP.json").read_text())
    assert rec["verdict"] == "inconclusive" and "invariant is not proved" in rec["reason"], rec.get("reason")


# -- on a recorded run: the tracker of backends/monitors/response_trace.py against the definition ----------

@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(st.booleans(), st.booleans()), max_size=12), st.sampled_from([None, 0, 1, 3, math.inf]))
def test_the_trace_tracker_equals_the_definition(run, n) -> None:
    from rclverify.backends.monitors.response_trace import ResponseTracker
    tr = ResponseTracker(n)
    got = None
    for i, (p, q) in enumerate(run):
        said = tr.step(i, p, q)
        if said is not None and said[0] == "false":
            got = i
            break
    # the definition: the first step at which some trigger's window ran out without its response
    if n is None:
        fails = [i + 1 for i in range(len(run) - 1) if run[i][0] and not run[i + 1][1]]
    else:
        fails = [k + n for k in range(len(run)) if run[k][0] and k + n < len(run)
                 and not any(run[j][1] for j in range(k, k + n + 1))]
    assert got == (min(fails) if fails else None)
    if got is None and n is not None:  # still pending at the end: a trigger whose window is not over
        open_ = any(run[k][0] and not any(run[j][1] for j in range(k, len(run))) for k in range(len(run)))
        assert (tr.pending is not None) == open_



def test_an_unproved_invariant_never_proves_the_unbounded_response() -> None:
    """The ranking rule holds inside its invariant only: an invariant that is not proved must not let it
    prove (x counts up from 0, the trigger at 0 is never answered; 10 - x is a ranking function only
    inside the false invariant x <= 10)."""
    ts = TransitionSystem({"x": z3.IntSort()}, lambda s: s["x"] == 0, lambda s, t: t["x"] == s["x"] + 1)
    v = check_unbounded_response(ts, lambda s: s["x"] == 0, lambda s: s["x"] < 0, max_k=3, timeout_ms=5_000,
                                 ranking=lambda s: 10 - s["x"], invariant=lambda s: s["x"] <= 10)
    assert v.status == "inconclusive" and "invariant is not proved" in v.detail, (v.status, v.detail)


@settings(max_examples=120, deadline=None)
@given(st.lists(st.tuples(st.sampled_from([True, False, None]), st.sampled_from([True, False, None])), max_size=7),
       st.sampled_from([None, 0, 1, 3, math.inf]))
def test_the_trace_tracker_says_false_only_where_every_reading_fails(run, n) -> None:
    """With undecided operands (``None``): ``false`` only when every way of deciding them fails the
    definition (a response undecided in the window may have answered the trigger)."""
    import itertools

    from rclverify.backends.monitors.response_trace import ResponseTracker
    tr = ResponseTracker(n)
    got = None
    for i, (p, q) in enumerate(run):
        said = tr.step(i, p, q)
        if said is not None and said[0] == "false":
            got = i
            break
    if got is None:
        return
    holes = [(i, j) for i in range(got + 1) for j in (0, 1) if run[i][j] is None]
    for fill in itertools.product([True, False], repeat=len(holes)):
        r = [list(x) for x in run[:got + 1]]
        for (i, j), b in zip(holes, fill):
            r[i][j] = b
        if n is None:
            fails = any(r[i][0] and not r[i + 1][1] for i in range(len(r) - 1))
        else:
            fails = any(r[k][0] and k + n < len(r) and not any(r[j][1] for j in range(k, k + n + 1))
                        for k in range(len(r)))
        assert fails, (run, n, got, fill)



def test_a_run_that_stops_with_a_trigger_pending_refutes_the_unbounded_response() -> None:
    """docs/requirements.md: a run that stops with a P pending is a counterexample (it is never
    answered); it read inconclusive when the bounded pattern failed and no fair lasso exists (x stays 0,
    an unfair loop, or steps to 1, where no step follows; the trigger at 0, no response anywhere)."""
    from rclverify.calculus.requirements.deadlock import runs_go_on
    from rclverify.calculus.requirements.tsys import Fairness
    ts = TransitionSystem({"x": z3.IntSort()}, lambda s: s["x"] == 0,
                          lambda s, t: z3.And(s["x"] == 0, z3.Or(t["x"] == 0, t["x"] == 1)),
                          (Fairness("N", lambda s: s["x"] == 0, lambda s: s["x"] == 1),))
    v = runs_go_on(ts, check_unbounded_response(ts, lambda s: s["x"] == 0, lambda s: s["x"] == 5, max_k=4,
                                                timeout_ms=5_000), max_k=4, timeout_ms=5_000)
    assert (v.status, v.method) == ("refuted", "deadlock"), (v.status, v.method, v.detail)
