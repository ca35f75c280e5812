"""Safety proofs a user can finish (issue 64): IC3/PDR with Z3's Spacer, its
certificate re-checked, and the plan's ``invariant:`` for every temporal
pattern, with the step that breaks a candidate named.

The oracle compares the verdicts with a brute-force reachability
enumeration of small random finite-state systems; the workspace is a
one-node planner whose cycle counter has a defensive branch no run takes
(``state.c > W``), the case where k-induction alone stays inconclusive.
"""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
import z3
from hypothesis import given, settings
from hypothesis import strategies as st

from rclverify.cli import main
from rclverify.pipeline import Workspace, stage_check, stage_export, stage_run
from rclverify.plan.errors import PlanError
from rclverify.requirements.pdr import recheck, spacer_invariant
from rclverify.requirements.safety import Hint, by_pdr, hint_fails, prove_always
from rclverify.requirements.tsys import TransitionSystem

XS = range(4)
STATES = [(x, b) for x in XS for b in (False, True)]


@st.composite
def systems(draw):
    init = draw(st.sets(st.sampled_from(STATES), min_size=1))
    succ = {s: draw(st.sets(st.sampled_from(STATES), max_size=3)) for s in STATES}  # a state may stop
    bad = draw(st.sets(st.sampled_from(STATES), max_size=3))
    return init, succ, bad


def _reachable(init, succ) -> set:
    seen, todo = set(init), list(init)
    while todo:
        for t in succ[todo.pop()] - seen:
            seen.add(t)
            todo.append(t)
    return seen


def _is(s, state) -> z3.BoolRef:
    return z3.And(s["x"] == state[0], s["b"] == state[1])


def _system(init, succ) -> TransitionSystem:
    return TransitionSystem({"x": z3.IntSort(), "b": z3.BoolSort()},
                            lambda s: z3.Or(*[_is(s, i) for i in init]),
                            lambda s, t: z3.Or(*[z3.And(_is(s, a), _is(t, c)) for a in STATES for c in succ[a]]))


@settings(max_examples=30, deadline=None)
@given(systems())
def test_pdr_equals_reachability(sys_) -> None:
    """Spacer's verdict, its certificate re-checked, and the run it leads to, against the enumeration: x is an
    integer, so the states outside 0..3 (no successor, not initial) are there for Spacer to exclude."""
    init, succ, bad = sys_
    ts = _system(init, succ)
    prop = lambda s: z3.Not(z3.Or(*[_is(s, b) for b in bad])) if bad else z3.BoolVal(True)  # noqa: E731
    holds = not (_reachable(init, succ) & bad)
    v = by_pdr(ts, prop, max_k=0, timeout_ms=5_000)
    assert v.status == ("proved" if holds else "refuted"), (v.status, v.detail)
    if holds:
        assert v.method == "pdr" and v.certificate
    else:  # the run is one of the system's, ending in a bad state, and as short as any
        run = [(int(st_["x"]), st_["b"] == "True") for st_ in v.trace]
        assert run[0] in init and run[-1] in bad and all(b in succ[a] for a, b in zip(run, run[1:]))
        layer, n = set(init), 0
        while not layer & bad:
            layer, n = {t for s in layer for t in succ[s]}, n + 1
        assert len(run) - 1 == n
    w = prove_always(ts, prop, max_k=1, timeout_ms=5_000)  # 1-induction first, then Spacer
    assert w.status == v.status


def _counter(top: int, extra: bool = False) -> TransitionSystem:
    """x counts 0..top and wraps; above top (no run gets there) it counts on.  ``extra``: an array copied
    by a quantified step, which Spacer refuses (a quantifier in a recursive rule)."""
    sorts = {"x": z3.IntSort()}
    if extra:
        sorts["a"] = z3.ArraySort(z3.IntSort(), z3.IntSort())
    i = z3.Int("i")

    def trans(s, t):
        step = t["x"] == z3.If(s["x"] == top, 0, s["x"] + 1)
        return z3.And(step, z3.ForAll([i], t["a"][i] == s["a"][i])) if extra else step
    return TransitionSystem(sorts, lambda s: s["x"] == 0, trans)


def test_a_certificate_is_rechecked_before_it_proves_anything() -> None:
    ts = _counter(5)
    never7 = lambda s: s["x"] != 7  # noqa: E731
    x = z3.Int("x")
    assert recheck(ts, never7, x <= 5, 2_000) is None and recheck(ts, never7, z3.And(x >= 0, x <= 5), 2_000) is None
    assert "a step leaves it" in recheck(ts, never7, x <= 4, 2_000)
    assert "an initial state lies outside it" in recheck(ts, never7, x >= 1, 2_000)
    assert "does not imply the property" in recheck(ts, never7, z3.BoolVal(True), 2_000)
    answer = spacer_invariant(ts, never7, 5_000)
    assert answer.status == "invariant" and recheck(ts, never7, answer.invariant, 2_000) is None


def test_a_time_limit_or_a_refused_clause_is_inconclusive_with_the_reason() -> None:
    ts = _counter(100, extra=True)
    v = prove_always(ts, lambda s: s["x"] != 150, max_k=3, timeout_ms=2_000)
    assert v.status == "inconclusive"
    assert "not 3-inductive" in v.detail and "IC3/PDR (Z3 Spacer) found no inductive invariant" in v.detail
    assert "quantifier" in v.detail  # Spacer's own reason
    # the step that breaks induction, and what to do
    assert "the step that breaks induction goes from {x = 149" in v.detail and "to {x = 150}" in v.detail
    assert "next step: if the first state cannot be reached, give the requirement an invariant:" in v.detail
    never150 = lambda s: s["x"] != 150  # noqa: E731
    limited = spacer_invariant(_counter(100), never150, 1)  # 1 ms: stopped with the reason, or a valid answer
    assert (limited.status == "unknown" and limited.reason in ("timeout", "canceled")) or \
           (limited.status == "invariant" and recheck(_counter(100), never150, limited.invariant, 2_000) is None)


def test_the_users_invariant_finishes_the_proof_or_is_named_with_the_step_that_breaks_it() -> None:
    ts = _counter(100, extra=True)  # Spacer cannot help: the hint must
    prop = lambda s: s["x"] != 150  # noqa: E731
    good = prove_always(ts, prop, max_k=3, timeout_ms=2_000, hint=Hint(lambda s: s["x"] <= 100, "x <= 100"))
    assert (good.status, good.method) == ("proved", "k-induction with invariant")
    weak = prove_always(ts, prop, max_k=3, timeout_ms=2_000, hint=Hint(lambda s: s["x"] <= 200, "x <= 200"))
    assert weak.status == "inconclusive"
    # Z3 picks the step: 149 -> 150 breaks the property, 200 -> 201 the invariant; either is named as such
    assert "the invariant 'x <= 200' is not inductive with the property: from the state {x = " in weak.detail
    d = weak.detail
    assert ("from the state {x = 149" in d and "one step leads to {x = 150}, where the property fails" in d) or \
           ("from the state {x = 200" in d and "one step leads to {x = 201}, where the invariant fails" in d)
    assert "spacer: quantifier in a recursive rule)" in weak.detail
    wrong = hint_fails(ts, prop, Hint(lambda s: s["x"] <= 50, "x <= 50"), max_k=3, timeout_ms=2_000)
    assert isinstance(wrong, tuple) and not wrong[1]
    assert "from the state {x = 50" in wrong[0] and "one step leads to {x = 51}, where the invariant fails" in wrong[0]
    # Spacer refutes a hint that only a long run breaks: the step and its values are named
    deep = hint_fails(_counter(100), prop, Hint(lambda s: s["x"] <= 50, "x <= 50"), max_k=3, timeout_ms=2_000)
    assert isinstance(deep, tuple) and "is false on a run of the system: at step 51, {x = 51}" in deep[0]
    assert "next step: weaken it" in deep[0]


# -- in a workspace: a planner whose cycle counter wraps at W ------------------------------------------------

RCL = """node Planner {
  inputs( request : REAL )
  outputs( plan_id : REAL )
  assume( 0 <= in.request and in.request <= 100 )
  guarantee( 0 <= out.plan_id and out.plan_id <= 100 )
}
"""
PLAN = """name: cycle
contracts:
  - contracts/planner.rcl
requirements:
  - id: RESTART
    text: A late request is followed by a new planning cycle within 6 steps.
    formal: "always (Planner.in.request >= 90 and Planner.state.c >= 12 -> eventually[<= 6] Planner.state.c == 0)"
    supported_by:
      - {node: Planner, guarantees: [1]}
state:
  Planner:
    c:
      type: NATURAL
      init: "state.c == 0"
      next: "(state.c < W -> next.c == state.c + 1) and (state.c == W -> next.c == 0) and (state.c > W -> next.c == state.c + 1)"
nodes:
  Planner:
    evidence:
      - backend: hoare
        program: backends/hoare/planner.imp
        binding: {in.request: request, out.plan_id: plan_id}
"""


def _planner(root: Path, wrap: int, extra: str = "") -> Path:
    (root / "contracts").mkdir(parents=True)
    (root / "backends/hoare").mkdir(parents=True)
    (root / "contracts/planner.rcl").write_text(RCL)
    (root / "contracts/plan.yaml").write_text(PLAN.replace("W", str(wrap)).replace("    supported_by:", extra + "    supported_by:", 1))
    (root / "backends/hoare/planner.imp").write_text("var request : REAL;\nvar plan_id : REAL;\nplan_id := request\n")
    w = Workspace(root)
    stage_check(w)
    for o in stage_export(w, "Planner"):
        stage_run(w, "Planner", o["id"])
    return root


@pytest.fixture(scope="module")
def planners(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("pdr")


def _record(root: Path, capsys: pytest.CaptureFixture[str]) -> tuple[str, dict]:
    main(["requirements", "-w", str(root)])
    return capsys.readouterr().out, json.loads((root / "artifacts/requirements/RESTART.json").read_text())


def test_a_correct_bounded_response_is_proved_by_pdr_and_met(planners: Path, capsys) -> None:
    """Wrapping at 15, a request at c >= 12 sees c == 0 within 4 steps; k-induction alone said "not
    10-inductive" (the branch above 15 counts on for ever), Spacer's invariant bounds c and the pending age."""
    out, rec = _record(_planner(planners / "ok", 15), capsys)
    assert "RESTART: met [discharged]" in out
    t = rec["temporal"]
    assert (t["status"], t["method"]) == ("proved", "pdr") and "Planner.state.c < 16" in t["certificate"]
    assert "re-checked by Z3" in t["detail"]
    root = planners / "ok"  # the report and the explanation show the certificate
    assert main(["report", "-w", str(root)]) == 0
    assert f"certificate (an inductive invariant, re-checked): `{t['certificate']}`" in \
        (root / "reports/assurance.md").read_text()
    capsys.readouterr()
    assert main(["explain", "RESTART", "-w", str(root)]) == 0
    assert f"certificate (inductive invariant, re-checked): {t['certificate']}" in capsys.readouterr().out


def test_a_wrong_bounded_response_is_refuted_with_its_run(planners: Path, capsys) -> None:
    """Wrapping at 20, a request at c == 12 waits 8 steps: refuted by the run of 18 steps (beyond the
    k-induction's bound, found once Spacer said a run exists)."""
    out, rec = _record(_planner(planners / "late", 20), capsys)
    assert "RESTART: refuted" in out
    t = rec["temporal"]
    assert (t["status"], t["method"], t["bound"]) == ("refuted", "bmc", 18) and len(t["trace"]) == 19
    assert t["trace"][12]["nodes"][0]["values"]["state.c"] == "12"


def test_a_plan_invariant_that_fails_is_named_with_the_step_that_breaks_it(planners: Path, capsys) -> None:
    """The plan's invariant is read for the bounded response; c <= 10 is false at step 11 of every run (a
    run longer than the k-induction's, found through Spacer), which the detail names with its values; the
    requirement is still proved by Spacer without it, and the report says the invariant was not used."""
    out, rec = _record(_planner(planners / "hint", 15, '    invariant: "Planner.state.c <= 10"\n'), capsys)
    t = rec["temporal"]
    assert "RESTART: met [discharged]" in out and t["method"] == "pdr"
    assert "the plan's invariant did not help: the invariant 'Planner.state.c <= 10' is false on a run of the " \
           "system: at step 11, {" in t["detail"] and "Planner.state.c = 11" in t["detail"]
    assert "next step: weaken it so that it holds there" in t["detail"]


def test_an_invariant_is_refused_on_a_state_requirement_only(tmp_path: Path) -> None:
    root = tmp_path / "ws"
    (root / "contracts").mkdir(parents=True)
    (root / "contracts/planner.rcl").write_text(RCL)
    plan = PLAN.split("nodes:")[0].replace("W", "15")
    for formal in ("always Planner.state.c <= 15", "next Planner.state.c == 1", "eventually[<= 3] Planner.state.c == 3"):
        (root / "contracts/plan.yaml").write_text(plan.replace(
            '"always (Planner.in.request >= 90 and Planner.state.c >= 12 -> eventually[<= 6] Planner.state.c == 0)"',
            f'"{formal}"\n    invariant: "Planner.state.c <= 15"'))
        assert Workspace(root).checked is not None
    (root / "contracts/plan.yaml").write_text(plan.replace(
        '"always (Planner.in.request >= 90 and Planner.state.c >= 12 -> eventually[<= 6] Planner.state.c == 0)"',
        '"Planner.out.plan_id >= 0"\n    invariant: "TRUE"'))
    with pytest.raises(PlanError) as e:
        Workspace(root).checked
    assert "an invariant is read only for a temporal statement" in str(e.value.diagnostics[0])
