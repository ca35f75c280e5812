"""No wrong green from runs that stop (issue 39, temporal requirements).

A system whose runs all stop before the goal made ``eventually P``,
``eventually[<= N] P`` and ``P until Q`` met, and ``doit verify --strict``
passed: a run that stops before the goal is a counterexample, and a proof
stands only over a system whose runs never stop (docs/requirements.md,
"Runs that stop").  The bound of ``eventually[<= N]`` is ASCII digits up to
a documented limit.  Real Z3, the real pipeline.
"""
from __future__ import annotations

import json
from pathlib import Path

import pytest
import z3

from rclverify.cli.commands import main
from rclverify.semantics.world import fresh
from rclverify.app.pipeline import Workspace, stage_check, stage_requirements
from rclverify.model.plan.errors import PlanError
from rclverify.model.plan.temporal import MAX_BOUND
from rclverify.calculus.requirements.deadlock import runs_go_on
from rclverify.calculus.requirements.temporal import (
    TransitionSystem, check_always, check_eventually, check_eventually_within, check_next, check_until)


@pytest.fixture(autouse=True)
def _fresh_z3_world() -> None:
    fresh()


def _counter(start: int, step: int, last: int) -> TransitionSystem:
    """c from ``start`` by ``step`` while c != ``last``; no successor at ``last``."""
    return TransitionSystem({"c": z3.IntSort()}, lambda s: s["c"] == start,
                            lambda s, t: z3.And(t["c"] == s["c"] + step, s["c"] != last))


# --- the engine ----------------------------------------------------------------------------------

def test_no_n_step_run_is_not_every_run_reaching_the_goal() -> None:
    up = _counter(0, 1, 3)
    goal = lambda s: s["c"] == 1000  # noqa: E731
    v = check_eventually_within(up, goal, 5)
    assert (v.status, v.method, v.bound) == ("refuted", "deadlock", 3)
    assert [st["c"] for st in v.trace] == ["0", "1", "2", "3"] and "stops at step 3" in v.detail
    assert check_eventually(up, goal).method == "deadlock"
    assert check_until(up, lambda s: s["c"] <= 100, goal).status == "refuted"
    assert check_eventually_within(up, lambda s: s["c"] == 3, 5).status == "met"  # reached, then it stops
    assert check_eventually_within(up, lambda s: s["c"] == 3, 2).status == "refuted"


def test_the_ranking_rule_does_not_prove_a_goal_a_countdown_stops_before() -> None:
    down = _counter(5, -1, 0)
    v = check_eventually(down, lambda s: s["c"] == 1000, ranking=lambda s: s["c"], invariant=lambda s: s["c"] >= 0)
    assert (v.status, v.method, v.bound) == ("refuted", "deadlock", 5)


def test_always_holds_on_runs_that_stop_but_the_requirement_is_not_proved() -> None:
    up = _counter(0, 1, 3)
    v = check_always(up, lambda s: s["c"] <= 3)
    assert v.status == "proved"  # true of every state of every run, finite ones too
    r = runs_go_on(up, v)
    assert (r.status, r.method, r.bound, r.deadlock) == ("refuted", "deadlock", 3, "reachable at step 3")
    assert check_next(_counter(3, 1, 3), lambda s: s["c"] == 4).method == "deadlock"  # there is no step 1


def test_deadlock_freedom_undecided_is_inconclusive_never_proved() -> None:
    # from 0, x counts up forever; below 0 (never reached) it counts down to -100 and stops there,
    # so "no run stops" holds but is not k-inductive for any k up to the bound
    ts = TransitionSystem({"x": z3.IntSort()}, lambda s: s["x"] == 0,
                          lambda s, t: z3.Or(z3.And(s["x"] >= 0, t["x"] == s["x"] + 1),
                                             z3.And(s["x"] < 0, s["x"] > -100, t["x"] == s["x"] - 1)))
    v = check_always(ts, lambda s: s["x"] >= 0)
    assert v.status == "proved"
    r = runs_go_on(ts, v, max_k=5)
    assert r.status == "inconclusive" and "whether a run of the system stops" in r.detail


# --- the workspaces ----------------------------------------------------------------------

# The sensor answers at every step (progress within 0 steps: without it its
# first output would be free, and `always Sensor.out.value <= 100` refuted at
# step 0 before any run stops).
RCL = """node Sensor { inputs( r : INTEGER ) outputs( value : INTEGER )
  guarantee( out.value <= 100 )
  progress( within 0 steps ) }
"""
PROGRAM = "var r : INTEGER;\nvar value : INTEGER;\nvalue := 7\n"
COUNTER = ('      init: "state.c == 0"\n'
           '      next: "next.c == state.c + 1 and state.c < 3"\n')
COUNTDOWN = ('      init: "state.c == 5"\n'
             '      next: "next.c == state.c - 1 and state.c > 0"\n')


def _ws(tmp: Path, state: str, reqs: list[dict[str, str]]) -> Path:
    ws = tmp / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "backends/hoare").mkdir(parents=True)
    (ws / "contracts/s.rcl").write_text(RCL)
    (ws / "backends/hoare/sensor.imp").write_text(PROGRAM)
    text = "".join(f"  - id: T{k}\n    text: temporal {k}\n" + "".join(f"    {key}: {json.dumps(v)}\n"
                                                                       for key, v in r.items())
                   for k, r in enumerate(reqs, 1))
    (ws / "contracts/plan.yaml").write_text(
        f"contracts: [contracts/s.rcl]\nrequirements:\n{text}"
        f"state:\n  Sensor:\n    c:\n      type: NATURAL\n{state}"
        "nodes:\n  Sensor:\n    evidence:\n      - backend: hoare\n        program: backends/hoare/sensor.imp\n"
        "        binding: {in.r: r, out.value: value}\n")
    return ws


GOALS = [{"formal": "eventually Sensor.out.value == 1000"},
         {"formal": "eventually[<= 7] Sensor.out.value == 1000"},
         {"formal": "Sensor.out.value <= 100 until Sensor.out.value == 1000"},
         {"formal": "always Sensor.out.value <= 100"}]


def _records(ws: Path) -> dict[str, dict]:
    from rclverify.report.build import build_report
    w = Workspace(ws)
    stage_check(w)
    stage_requirements(w)
    return {r["id"]: r for r in build_report(w).to_json()["requirements"]}


def test_a_counter_that_stops_after_3_meets_nothing_and_strict_fails(tmp_path: Path) -> None:
    ws = _ws(tmp_path, COUNTER, GOALS)
    from rclverify.report.strict import strict_reasons
    assert main(["verify", "-w", str(ws), "--strict"]) != 0
    report = json.loads((ws / "reports/assurance.json").read_text())
    assert strict_reasons(report) == ["4 formal requirements are not met (T1, T2, T3, T4)"]
    assert {o["status"] for o in report["obligations"]} == {"discharged"}  # the guarantee itself is discharged
    reqs = {r["id"]: r for r in report["requirements"]}
    for rid in ("T1", "T2", "T3", "T4"):
        r = reqs[rid]
        assert (r["verdict"], r["status"]) == ("refuted", "failed"), r
        t = r["check"]["temporal"]
        assert (t["method"].split(" + ")[-1], t["bound"]) == ("deadlock", 3), t
        assert [st["nodes"][0]["values"]["state.c"] for st in t["trace"]] == ["0", "1", "2", "3"]
        assert "stops at step 3" in r["note"]
    assert "stops at step 3" in (ws / "reports/assurance.md").read_text()


def test_a_countdown_with_no_successor_at_0_meets_nothing_not_even_by_ranking(tmp_path: Path) -> None:
    recs = _records(_ws(tmp_path, COUNTDOWN, GOALS + [
        {"formal": "eventually Sensor.out.value == 1000", "ranking": "Sensor.state.c"}]))
    for rid in ("T1", "T2", "T3", "T4", "T5"):
        t = recs[rid]["check"]["temporal"]
        assert (recs[rid]["verdict"], t["method"].split(" + ")[-1], t["bound"]) == ("refuted", "deadlock", 5), (rid, t)


def test_a_counter_that_goes_on_still_proves(tmp_path: Path) -> None:
    """The same goals over a counter with a successor in every state: the
    deadlock rule changes nothing (no false alarm)."""
    recs = _records(_ws(tmp_path, '      init: "state.c == 0"\n      next: "next.c == state.c + 1"\n', [
        {"formal": "always Sensor.out.value <= 100"}, {"formal": "eventually[<= 5] Sensor.state.c >= 5"},
        {"formal": "eventually Sensor.state.c == 3"}, {"formal": "next Sensor.state.c == 1"}]))
    for rid in ("T1", "T2", "T3", "T4"):
        t = recs[rid]["check"]["temporal"]
        # proved (met once the guarantee's evidence is in: not run here)
        assert recs[rid]["verdict"] == "proved, evidence outstanding" and t["status"] == "proved", (rid, t)
        assert t["deadlock"].startswith("no run stops"), t


# --- the bound of eventually[<= N] -------------------------------------------------------------

@pytest.mark.parametrize("bound, col, words", [
    ("²", 28, "written in the digits 0-9, found '²'"),
    ("٣", 28, "written in the digits 0-9, found '٣'"),
    ("100000", 28, f"is at most {MAX_BOUND} steps, found 100000"),
    ("1000000000", 28, f"is at most {MAX_BOUND} steps, found 1000000000"),
    ("9" * 5000, 28, "found 99999999...(5000 digits)"),  # past Python's int() digit limit: no crash
    ("1e3", 28, "found '1e3'"),
], ids=["superscript-2", "arabic-indic-3", "1e5", "1e9", "5000-digits", "1e3"])
def test_a_bound_past_the_limit_or_not_in_ascii_digits_is_a_located_error(tmp_path: Path, bound: str, col: int,
                                                                          words: str) -> None:
    ws = _ws(tmp_path, COUNTER, [{"formal": "always Sensor.out.value <= 100"},
                                 {"formal": f"eventually[<= {bound}] Sensor.out.value == 1000"}])
    with pytest.raises(PlanError) as e:
        Workspace(ws).checked
    d = str(e.value.diagnostics[0])
    assert d.startswith(f"contracts/plan.yaml:8:{col}: error") and words in d, d


def test_the_limit_itself_and_leading_zeros_are_accepted(tmp_path: Path) -> None:
    from rclverify.model.plan.temporal import Temporal
    ws = _ws(tmp_path, COUNTER, [{"formal": f"eventually[<= {MAX_BOUND}] Sensor.out.value == 1000"},
                                 {"formal": "eventually[<=  0012 ] Sensor.out.value == 1000"}])
    from rclverify.calculus.requirements.temporal_check import statement
    w = Workspace(ws)
    bounds = [statement(r, w.checked, w.plan) for r in w.plan.requirements]
    assert [t.bound for t in bounds if isinstance(t, Temporal)] == [MAX_BOUND, 12]


def test_the_deadlock_searchs_budget_is_resource_steps_where_it_stops_is_the_same_every_run() -> None:
    """The step-by-step search's budget for all its queries counts Z3 resource steps (issue 67):
    a long counter (stops at 400) searched with tiny query budgets stops at the same step with the
    same words on every run, and says its budget of steps was spent; with ample budgets the stop
    itself is found."""
    from rclverify.calculus.requirements.deadlock import find_deadlock
    seen = []
    for _ in range(2):
        fresh()
        v = find_deadlock(_counter(0, 1, 400), 500, timeout_ms=1)
        assert v is not None and v.status == "inconclusive"
        seen.append((v.bound, v.detail, v.deadlock))
    assert seen[0] == seen[1] and "query budgets of Z3 resource steps" in seen[0][1], seen
    fresh()
    found = find_deadlock(_counter(0, 1, 12), 20)
    assert found is not None and (found.status, found.bound) == ("refuted", 12)
