"""An unbounded ``eventually`` proved by the plan's ``ranking:`` and
``invariant:`` (issue 34): accepted only when both conditions of the
ranking rule hold (the reason names the one that fails), the keys' located
errors, and an edit of ``ranking:`` re-checks the requirement.  Real Z3."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from rclverify.app.pipeline import Workspace, stage_check, stage_requirements
from rclverify.model.plan.errors import PlanError

RCL = """node Cnt { inputs( a : NATURAL ) outputs( b : NATURAL )
  guarantee( out.b == in.a ) }
"""
# c counts down from any start <= 50 (more than the bound of 10 steps);
# d as well, but declared INTEGER: d >= 0 is an invariant, not a type.
STATE = """state:
  Cnt:
    c:
      type: NATURAL
      init: "state.c <= 50"
      next: "(state.c > 0 -> next.c == state.c - 1) and (state.c == 0 -> next.c == 0)"
    d:
      type: INTEGER
      init: "state.d >= 0 and state.d <= 50"
      next: "(state.d > 0 -> next.d == state.d - 1) and (state.d <= 0 -> next.d == state.d)"
"""


def _ws(tmp: Path, reqs: list[dict[str, str]]) -> Path:
    ws = tmp / "countdown"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/n.rcl").write_text(RCL)
    text = "".join(f"  - id: R{k}\n    text: countdown {k}\n"
                   + "".join(f"    {key}: {json.dumps(v)}\n" for key, v in r.items())
                   for k, r in enumerate(reqs, 1))
    (ws / "contracts/plan.yaml").write_text(f"contracts: [contracts/n.rcl]\nrequirements:\n{text}{STATE}")
    return ws


def _temporal(ws: Path) -> dict[str, dict]:
    from rclverify.report.build import build_report
    w = Workspace(ws)
    stage_check(w)
    stage_requirements(w)
    return {r["id"]: r for r in build_report(w).to_json()["requirements"]}


C0 = "eventually Cnt.state.c == 0"
D0 = "eventually Cnt.state.d == 0"


@pytest.fixture(scope="module")
def countdown(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, dict]]:
    ws = _ws(tmp_path_factory.mktemp("ranking"), [
        {"formal": C0, "ranking": "Cnt.state.c"},                                  # R1 proved by ranking
        {"formal": C0, "ranking": "5"},                                            # R2 does not decrease
        {"formal": C0, "ranking": "Cnt.state.c - 3"},                              # R3 negative at c = 1, 2
        {"formal": D0, "ranking": "Cnt.state.d"},                                  # R4 d < 0 not excluded
        {"formal": D0, "ranking": "Cnt.state.d", "invariant": "Cnt.state.d >= 0"},  # R5 proved with it
        {"formal": D0, "ranking": "Cnt.state.d", "invariant": "Cnt.state.d <= 10"},  # R6 invariant false
        {"formal": C0},                                                            # R7 no ranking
        {"formal": f"Cnt.out.b >= 0 until Cnt.state.c == 0", "ranking": "Cnt.state.c"},  # R8 until
    ])
    return ws, _temporal(ws)


def test_a_ranking_function_from_the_plan_proves_an_unbounded_eventually(countdown) -> None:
    recs = countdown[1]
    for rid in ("R1", "R5"):
        t = recs[rid]["check"]["temporal"]
        # proved, evidence outstanding: Cnt's guarantee has no evidence here
        assert (recs[rid]["verdict"][:6], t["status"], t["method"]) == ("proved", "proved", "ranking"), (rid, t)
    assert recs["R1"]["check"]["temporal"]["ranking"] == "Cnt.state.c"
    assert recs["R5"]["check"]["temporal"]["invariant"] == "Cnt.state.d >= 0"
    assert recs["R5"]["check"]["temporal"]["k"] == 1  # the invariant's induction depth
    t = recs["R8"]["check"]["temporal"]
    assert (recs["R8"]["verdict"][:6], t["method"]) == ("proved", "k-induction + ranking"), t
    # without a ranking function, 50 steps to go are beyond the bound: inconclusive with the bound checked
    t = recs["R7"]["check"]["temporal"]
    assert (recs["R7"]["verdict"], t["bound"]) == ("inconclusive", 10) and "no ranking function" in t["detail"]


def test_a_wrong_ranking_function_is_not_accepted_and_the_reason_names_the_condition(countdown) -> None:
    recs = countdown[1]
    why = {rid: recs[rid]["check"]["temporal"]["detail"] for rid in ("R2", "R3", "R4", "R6")}
    for rid in why:
        assert recs[rid]["verdict"] == "inconclusive" and recs[rid]["check"]["temporal"]["method"] != "ranking"
    assert "does not decrease on every step" in why["R2"] and "(rank 5 then 5)" in why["R2"]
    assert "is not >= 0" in why["R3"]
    assert "is not >= 0" in why["R4"]  # d may be negative in a state the invariant TRUE admits
    assert "its invariant is not proved (refuted" in why["R6"]


def test_report_shows_the_ranking_function_and_invariant(countdown) -> None:
    from rclverify.report.build import build_report
    from rclverify.report.render import render_markdown
    md = render_markdown(build_report(Workspace(countdown[0])))
    line = next(x for x in md.splitlines() if "temporal check:" in x and "Cnt.state.d >= 0" in x)
    assert "proved by ranking" in line and "ranking function `Cnt.state.d`" in line
    assert "ranking function `5`, invariant TRUE (not accepted)" in md


def test_an_edit_of_ranking_rechecks_that_requirement_only(countdown) -> None:
    ws, _ = countdown
    plan = ws / "contracts/plan.yaml"
    before = plan.read_text()
    w = Workspace(ws)
    assert not any(now for _, now in stage_requirements(w))  # incremental: nothing changed
    try:
        plan.write_text(before.replace('ranking: "5"', 'ranking: "Cnt.state.c + 5"'))
        w = Workspace(ws)
        stage_check(w)
        recs = {r["id"]: (r, now) for r, now in stage_requirements(w)}
        assert [rid for rid, (_, now) in recs.items() if now] == ["R2"]
        assert (recs["R2"][0]["temporal"]["method"], recs["R2"][0]["verdict"]) == ("ranking", "proved")
    finally:
        plan.write_text(before)


@pytest.mark.parametrize("req, where, what", [
    ({"formal": C0, "ranking": "Cnt.state.c == 0"}, "plan.yaml:6:15:", "must be an INTEGER or NATURAL term, found BOOL"),
    ({"formal": "always Cnt.state.c <= 50", "ranking": "Cnt.state.c"}, "plan.yaml:6:15:", "only for a liveness"),
    # issue 64: an invariant is read for every temporal statement, never for a state requirement
    ({"formal": "Cnt.out.b >= 0", "invariant": "TRUE"}, "plan.yaml:6:17:", "only for a temporal statement"),
    ({"ranking": "Cnt.state.c"}, "plan.yaml:5:15:", "need a liveness statement in formal:"),
    ({"formal": C0, "ranking": "Cnt.state.q"}, "plan.yaml:6:15:", "Cnt.state.q is not a state variable"),
])
def test_ranking_and_invariant_errors_are_located(tmp_path: Path, req: dict, where: str, what: str) -> None:
    with pytest.raises(PlanError) as e:
        Workspace(_ws(tmp_path, [req])).checked
    text = "\n".join(str(d) for d in e.value.diagnostics)
    assert f"contracts/{where}" in text and what in text, text
