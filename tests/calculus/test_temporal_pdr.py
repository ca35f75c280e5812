"""Safety proofs a user can finish (issue 64): k-induction with invariants
generated from the system's constants (Houdini), IC3/PDR with Z3's Spacer,
its certificate re-checked, and the plan's ``invariant:`` for every temporal
pattern, with the step that breaks a candidate named.

The oracle compares the verdicts with a brute-force reachability
enumeration of small random finite-state systems; the workspace is a
one-node planner whose cycle counter has a defensive branch no run takes
(``state.c > W``), the case where k-induction alone stays inconclusive.
"""
from __future__ import annotations

import json
import random
import shutil
from pathlib import Path

import pytest
import z3
from hypothesis import given, settings
from hypothesis import strategies as st

from rclverify.cli.commands import main
from rclverify.app.pipeline import Workspace, stage_check, stage_export, stage_run
from rclverify.model.plan.errors import PlanError
from rclverify.calculus.requirements.houdini import generate
from rclverify.calculus.requirements.pdr import recheck, spacer_invariant
from rclverify.calculus.requirements.safety import Hint, by_pdr, hint_fails, prove_always
from rclverify.calculus.requirements.tsys import TransitionSystem
from rclverify.semantics.world import fresh

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


@settings(max_examples=25, deadline=None)
@given(systems())
def test_pdr_equals_reachability(sys_) -> None:
    """Spacer's verdict, its certificate re-checked, and the run it leads to, against the enumeration: x is an
    integer, so the states outside 0..3 (no successor, not initial) are there for Spacer to exclude; the whole
    procedure (after 1-induction) agrees, and the invariant Houdini generates holds in every reachable state.
    Each example starts in a fresh Z3 world, as each unit of the pipeline's work does (semantics/world.py):
    in one context shared by the examples, Spacer once spent its whole budget on a system whose one
    reachable state has no successor, and proved it at once when Hypothesis ran the example again."""
    fresh()
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
    w = prove_always(ts, prop, max_k=1, timeout_ms=5_000)  # 1-induction, generated bounds, then Spacer
    assert w.status == v.status
    generated = generate(ts, prop, 5_000, 10_000)  # Houdini's invariant holds in every reachable state
    assert not isinstance(generated, str)
    for x, b in _reachable(init, succ):
        assert all(z3.is_true(z3.simplify(p({"x": z3.IntVal(x), "b": z3.BoolVal(b)}))) for _, p in generated)


def _counter(top: int, extra: bool = False) -> TransitionSystem:
    """x counts 0..top and wraps; above top (no run gets there) it counts on.  ``extra``: an array copied
    by a quantified step, which Spacer refuses (a quantifier in a recursive rule)."""
    return _counters(top, ("x",), extra)


def _counters(top: int, names: tuple[str, ...], extra: bool = False) -> TransitionSystem:
    """Counters that count 0..top in step, wrapping together (``_counter``'s, one per name)."""
    sorts = {n: z3.IntSort() for n in names}
    if extra:
        sorts["a"] = z3.ArraySort(z3.IntSort(), z3.IntSort())
    i = z3.Int("i")

    def trans(s, t):
        steps = [t[n] == z3.If(s[n] == top, 0, s[n] + 1) for n in names]
        return z3.And(*steps, z3.ForAll([i], t["a"][i] == s["a"][i])) if extra else z3.And(*steps)
    def init(s):
        return z3.And(*[s[n] == 0 for n in names], *([z3.ForAll([i], s["a"][i] == 0)] if extra else []))
    return TransitionSystem(sorts, init, trans)


#: two counters in step never read x = 0, y = 5; the invariant it needs, x == y, is no bound
PAIR = lambda s: z3.Not(z3.And(s["x"] == 0, s["y"] == 5))  # noqa: E731
#: the same, and the array's first element stays 0: the array, with its quantified step, is in the cone
PAIR_A = lambda s: z3.And(PAIR(s), s["a"][0] == 0)  # noqa: E731


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


def test_generated_bounds_finish_what_k_induction_cannot_and_pdr_finds_the_relation() -> None:
    """x <= 100 comes from the system's constant; x == y is no bound: Spacer finds it (without the array)."""
    v = prove_always(_counter(100, extra=True), lambda s: s["x"] != 150, max_k=3, timeout_ms=2_000)
    assert (v.status, v.method) == ("proved", "k-induction with generated invariant")
    assert "x >= 0 and x <= 100" in v.detail
    w = prove_always(_counters(10, ("x", "y")), PAIR, max_k=3, timeout_ms=2_000)
    assert (w.status, w.method) == ("proved", "pdr") and "is not 3-inductive either" not in w.detail
    assert w.certificate
    # a plan invariant that is false (from step 6) is named in the proof that did without it
    h = prove_always(_counters(10, ("x", "y")), PAIR, max_k=3, timeout_ms=2_000, hint=Hint(lambda s: s["x"] <= 5, "x <= 5"))
    assert (h.status, h.method) == ("proved", "pdr")
    assert "(the plan's invariant did not help: the invariant 'x <= 5' is false on a run of the system: at step 6, " \
           "{x = 6, y = 6}" in h.detail


def test_a_time_limit_or_a_refused_clause_is_inconclusive_with_the_reason() -> None:
    v = prove_always(_counters(100, ("x", "y"), extra=True), PAIR_A, max_k=3, timeout_ms=2_000)
    assert v.status == "inconclusive"
    assert "not 3-inductive" in v.detail and "IC3/PDR (Z3 Spacer) found no inductive invariant" in v.detail
    assert "k-induction assuming the generated invariant (x >= 0 and x <= 100 and y >= 0 and y <= 100" in v.detail
    assert "spacer: quantifier in a recursive rule)" in v.detail  # Spacer's own reason, its first line
    # the step that breaks induction, and what to do
    assert "the step that breaks induction goes from {" in v.detail and "to {x = 0, y = 5" in v.detail
    assert "next step: if the first state cannot be reached, give the requirement an invariant:" in v.detail
    never150 = lambda s: s["x"] != 150  # noqa: E731
    limited = spacer_invariant(_counter(100), never150, 1)  # 1 ms of steps: stopped with the reason, or a valid answer
    assert (limited.status == "unknown" and limited.reason in ("timeout", "canceled", "max. resource limit exceeded")) or \
           (limited.status == "invariant" and recheck(_counter(100), never150, limited.invariant, 2_000) is None)


def test_the_users_invariant_finishes_the_proof_or_is_named_with_the_step_that_breaks_it() -> None:
    ts = _counters(100, ("x", "y"), extra=True)  # neither Spacer nor the generated bounds can help: the hint must
    good = prove_always(ts, PAIR_A, max_k=3, timeout_ms=2_000, hint=Hint(lambda s: s["x"] == s["y"], "x == y"))
    assert (good.status, good.method) == ("proved", "k-induction with invariant")
    weak = prove_always(ts, PAIR_A, max_k=3, timeout_ms=2_000, hint=Hint(lambda s: s["x"] <= 100, "x <= 100"))
    assert weak.status == "inconclusive"
    assert "the invariant 'x <= 100' holds on every run (k-induction) but is not strong enough: it allows the " \
           "state {" in weak.detail and "where the property fails; next step: add to the invariant a conjunct" in weak.detail
    # false from step 51 on, which neither k-induction nor Spacer (the array is in its cone) can tell
    wrong = hint_fails(ts, PAIR_A, Hint(lambda s: z3.And(s["x"] <= 50, s["a"][0] == 0), "x <= 50 and a[0] == 0"),
                       max_k=3, timeout_ms=2_000)
    assert isinstance(wrong, tuple) and not wrong[1]
    # Z3 picks the step: one that leaves the invariant (50 -> 51) or one that breaks the property; named as such
    assert "the invariant 'x <= 50 and a[0] == 0' is not inductive with the property: from the state {x = " in wrong[0]
    assert "where the invariant fails" in wrong[0] or "where the property fails" in wrong[0]
    # Spacer refutes a hint that only a long run breaks: the step and its values are named
    deep = hint_fails(_counter(100), lambda s: s["x"] != 150, Hint(lambda s: s["x"] <= 50, "x <= 50"), max_k=3,
                      timeout_ms=2_000)
    assert isinstance(deep, tuple) and "is false on a run of the system: at step 51, {x = 51}" in deep[0]
    assert "next step: weaken it" in deep[0]


# -- in a workspace: a planner whose cycle counter wraps at 11 ------------------------------------------------

RCL = """node Planner {
  inputs( request : REAL )
  outputs( plan_id : REAL )
  assume( 0 <= in.request and in.request <= 100 )
  guarantee( 0 <= out.plan_id and out.plan_id <= 100 )
}
"""
LATE_REQUEST = "Planner.in.request >= 90 and Planner.state.c >= 9"
PLAN = f"""name: cycle
contracts:
  - contracts/planner.rcl
requirements:
  - id: RESTART
    text: A late request is followed by a new planning cycle within 6 steps.
    formal: "always ({LATE_REQUEST} -> eventually[<= 6] Planner.state.c == 0)"
    supported_by:
      - {{node: Planner, guarantees: [1]}}
  - id: LATE
    text: A late request is followed by a new planning cycle within 1 step (it is not).
    formal: "always ({LATE_REQUEST} -> eventually[<= 1] Planner.state.c == 0)"
  - id: CYCLE
    text: A new cycle starts with all its steps left.
    formal: "always (Planner.state.c == 0 -> Planner.state.left == 11)"
  - id: HINTED
    text: RESTART, with an invariant that does not hold.
    formal: "always ({LATE_REQUEST} -> eventually[<= 6] Planner.state.c == 0)"
    invariant: "Planner.state.c <= 7"
state:
  Planner:
    c:
      type: NATURAL
      init: "state.c == 0"
      next: "(state.c < 11 -> next.c == state.c + 1) and (state.c == 11 -> next.c == 0) and (state.c > 11 -> next.c == state.c + 1)"
    left:
      type: NATURAL
      init: "state.left == 11"
      next: "(state.left > 0 -> next.left == state.left - 1) and (state.left == 0 -> next.left == 11)"
nodes:
  Planner:
    evidence:
      - backend: hoare
        program: backends/hoare/planner.imp
        binding: {{in.request: request, out.plan_id: plan_id}}
"""


@pytest.fixture(scope="module")
def planner(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    """The workspace, its Hoare evidence discharged and its requirements checked once: ``(root, output)``.
    The counter's branch above 11 counts on for ever: no run takes it, and it keeps k-induction alone from
    proving RESTART and CYCLE ("not 10-inductive")."""
    root = tmp_path_factory.mktemp("pdr") / "ws"
    (root / "contracts").mkdir(parents=True)
    (root / "backends/hoare").mkdir(parents=True)
    (root / "contracts/planner.rcl").write_text(RCL)
    (root / "contracts/plan.yaml").write_text(PLAN)
    (root / "backends/hoare/planner.imp").write_text("var request : REAL;\nvar plan_id : REAL;\nplan_id := request\n")
    w = Workspace(root)
    stage_check(w)
    for o in stage_export(w, "Planner"):
        stage_run(w, "Planner", o.id)
    import contextlib
    import io
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        main(["requirements", "-w", str(root)])
        assert main(["report", "-w", str(root)]) == 0
    return root, buf.getvalue()


def _temporal(root: Path, rid: str) -> dict:
    return json.loads((root / f"artifacts/requirements/{rid}.json").read_text())["temporal"]


def test_a_correct_bounded_response_is_proved_with_a_generated_invariant_and_met(planner) -> None:
    """A request at c >= 9 sees c == 0 within 3 steps; in the states where c <= 11 (a bound from the
    system's own constant, Houdini) the response is 7-inductive."""
    root, out = planner
    assert "RESTART: met [discharged]" in out
    t = _temporal(root, "RESTART")
    assert (t["status"], t["method"]) == ("proved", "k-induction with generated invariant")
    assert "Planner.state.c >= 0 and Planner.state.c <= 11" in t["detail"]


def test_a_relation_is_proved_by_pdr_with_its_certificate_shown(planner, capsys) -> None:
    """c == 0 -> left == 11 needs c + left == 11, no bound: Spacer's invariant, re-checked, is the
    certificate, in the record, the report and the explanation."""
    root, out = planner
    assert "CYCLE: met [discharged]" in out
    t = _temporal(root, "CYCLE")
    assert (t["status"], t["method"]) == ("proved", "pdr") and "Planner.state.left" in t["certificate"]
    assert "re-checked by Z3" in t["detail"]
    assert f"certificate (an inductive invariant, re-checked): `{t['certificate']}`" in \
        (root / "reports/assurance.md").read_text()
    capsys.readouterr()
    assert main(["explain", "CYCLE", "-w", str(root)]) == 0
    assert f"certificate (inductive invariant, re-checked): {t['certificate']}" in capsys.readouterr().out


def test_a_wrong_bounded_response_is_refuted_with_its_run(planner) -> None:
    """Within 1 step it is not: the request at c == 9 (step 9) is still waiting at step 10, beyond the
    k-induction's 9 steps; found once Spacer said a run exists."""
    root, out = planner
    assert "LATE: refuted" in out
    t = _temporal(root, "LATE")
    assert (t["status"], t["method"], t["bound"]) == ("refuted", "bmc", 10) and len(t["trace"]) == 11
    assert t["trace"][9]["nodes"][0]["values"]["state.c"] == "9"


def test_a_plan_invariant_that_fails_is_named_with_the_step_that_breaks_it(planner) -> None:
    """c <= 7 is false at step 8 of every run, which the detail names with its values; the requirement is
    still proved without it (by the generated bound), and the report says the invariant was not used."""
    root, out = planner
    t = _temporal(root, "HINTED")
    assert "HINTED: met [discharged]" in out and t["method"] == "k-induction with generated invariant"
    assert "the plan's invariant did not help: the invariant 'Planner.state.c <= 7' is false on a run of the " \
           "system: at step 8, {" in t["detail"] and "Planner.state.c = 8" in t["detail"]
    assert "next step: weaken it so that it holds there" in t["detail"]
    assert "the plan's invariant `Planner.state.c <= 7` (not used by the proof)" in \
        (root / "reports/assurance.md").read_text()


def test_an_invariant_is_refused_on_a_state_requirement_only(tmp_path: Path) -> None:
    root = tmp_path / "ws"
    (root / "contracts").mkdir(parents=True)
    (root / "contracts/planner.rcl").write_text(RCL)
    head = PLAN.split("requirements:")[0] + "requirements:\n  - id: R\n    text: t\n    formal: "
    states = "state:" + PLAN.split("state:", 1)[1].split("nodes:")[0]
    for formal in ("always Planner.state.c <= 11", "next Planner.state.c == 1", "eventually[<= 3] Planner.state.c == 3"):
        (root / "contracts/plan.yaml").write_text(f'{head}"{formal}"\n    invariant: "Planner.state.c <= 11"\n{states}')
        assert Workspace(root).checked is not None
    (root / "contracts/plan.yaml").write_text(f'{head}"Planner.out.plan_id >= 0"\n    invariant: "TRUE"\n{states}')
    with pytest.raises(PlanError) as e:
        Workspace(root).checked
    assert "an invariant is read only for a temporal statement" in str(e.value.diagnostics[0])


def test_houdinis_budget_is_steps_the_same_on_any_load() -> None:
    """Houdini's budget of all its queries counts Z3 resource steps (issue 67: results never depend
    on the wall clock): an ample budget gives the invariant, a budget of a few steps says it was
    spent, the same on every run."""
    ts = _counters(5, ("x", "y"))
    prop = lambda s: s["x"] <= 5  # noqa: E731
    ample = generate(ts, prop, 5_000, 10_000)
    assert not isinstance(ample, str) and ample
    again = generate(ts, prop, 5_000, 10_000)
    assert not isinstance(again, str) and [c[0] for c in again] == [c[0] for c in ample]
    tiny = generate(ts, prop, 5_000, 0.001)  # two steps for all the queries together
    assert tiny == "the step budget of invariant generation was spent"


def _fill_context(n: int) -> None:
    """Earlier work in the caller's context: terms and decided queries that have nothing to do with the system."""
    s = z3.Solver()
    xs = [z3.Int(f"junk{k}") for k in range(n)]
    for k in range(0, n - 2, 3):
        s.add(xs[k] + 2 * xs[k + 1] <= xs[k + 2] * 3 + k)
        s.check()


def test_spacer_answers_the_same_whatever_the_context_held_before() -> None:
    """Spacer works in a context of its own (calculus/requirements/pdr.py): the certificate it gives
    after the caller's context was filled by other work is the one it gives in a fresh world."""
    rng = random.Random(7)
    certificates = []
    for _ in range(12):
        init = set(rng.sample(STATES, 2))
        succ = {s: set(rng.sample(STATES, rng.randrange(3))) for s in STATES}
        reach = _reachable(init, succ)
        bad = set(rng.sample([s for s in STATES if s not in reach] or STATES, 1))
        answers = []
        for filled in (False, True):
            fresh()
            if filled:
                _fill_context(600)
            ts = _system(init, succ)
            ans = spacer_invariant(ts, lambda s: z3.Not(z3.Or(*[_is(s, b) for b in bad])), 5_000)
            answers.append((ans.status, None if ans.invariant is None else ans.invariant.sexpr()))
        certificates.append(answers)
    assert all(a == b for a, b in certificates), [c for c in certificates if c[0] != c[1]]
