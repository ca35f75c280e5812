"""Temporal requirements decided over the composed contracts (issue 34):
the transition system built from a small workspace's contracts and its
plan's ``state:`` declaration, the record and report of proved / refuted /
bounded requirements, the declaration's located errors.  Real Z3."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from _restore import restored
from rclverify.app.pipeline import Workspace, stage_check, stage_requirements
from rclverify.model.plan.errors import PlanError

# Inc adds one to what Fwd hands back, up to 10; Fwd forwards it: a loop
# (Inc.out.b -> Fwd.in.b, Fwd.out.a -> Inc.in.a) that Fwd's initial value 0
# starts (docs/semantics.md: without it neither node ever has an input).
# Inc's state n counts its steps up to 10.  Both answer at every step they
# have a question (progress within 0 steps: the synchronous reading;
# tests/calculus/test_temporal_progress.py has nodes without it).
RCL = """node Inc { inputs( a : NATURAL ) outputs( b : NATURAL )
  guarantee( (in.a < 10 -> out.b == in.a + 1) and (in.a >= 10 -> out.b == in.a) )
  progress( within 0 steps ) }
node Fwd { inputs( b : NATURAL ) outputs( a : NATURAL )
  guarantee( out.a == in.b )
  initially( out.a == 0 )
  progress( within 0 steps ) }
"""
STATE = """state:
  Inc:
    n:
      type: NATURAL
      init: "state.n == 0"
      next: "(state.n < 10 -> next.n == state.n + 1) and (state.n >= 10 -> next.n == state.n)"
"""


def _ws(tmp: Path, formals: list[str], state: str = STATE) -> Path:
    ws = tmp / "loop"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/n.rcl").write_text(RCL)
    reqs = "".join(f"  - id: T{k}\n    text: temporal {k}\n    formal: {json.dumps(f)}\n" for k, f in enumerate(formals, 1))
    (ws / "contracts/plan.yaml").write_text(f"contracts: [contracts/n.rcl]\nrequirements:\n{reqs}{state}")
    return ws


def _check(ws: Path) -> dict[str, dict]:
    from rclverify.report.build import build_report
    w = Workspace(ws)
    stage_check(w)
    stage_requirements(w)
    return {r["id"]: r for r in build_report(w).to_json()["requirements"]}


@pytest.fixture(scope="module")
def loop(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, dict]]:
    ws = _ws(tmp_path_factory.mktemp("temporal"), [
        "always Inc.state.n <= 10",                       # T1 proved by 1-induction
        "always Inc.state.n <= 6",                        # T2 refuted at step 7
        "eventually[<= 5] Inc.state.n >= 5",              # T3 met within its bound
        "eventually[<= 4] Inc.state.n >= 5",              # T4 refuted beyond it
        "always Fwd.out.a <= 10",                         # T5 proved: only published values count
        "eventually Inc.state.n == 20",                   # T6 never; no lasso within 10 steps
        "always next Fwd.in.b >= 1",                      # T7 the connection, from step 1 on
        "always Fwd.in.b >= 1",                           # T8 proved: nothing before Inc's first answer
    ])
    return ws, _check(ws)


def test_always_proved_by_1_induction_over_the_contracts(loop) -> None:
    r = loop[1]["T1"]
    t = r["check"]["temporal"]
    assert (t["status"], t["method"], t["k"]) == ("proved", "k-induction", 1)
    assert r["check"]["consistency"] == "consistent"
    # no obligation discharges the guarantees it rests on: proved, never met
    assert r["verdict"] == "proved, evidence outstanding" and r["status"] != "discharged"


def test_always_refuted_at_depth_7_with_the_trace_step_by_step_node_by_node(loop) -> None:
    r = loop[1]["T2"]
    t = r["check"]["temporal"]
    assert (r["verdict"], r["status"], t["bound"]) == ("refuted", "failed", 7)
    assert [s["step"] for s in t["trace"]] == list(range(8))
    n = [next(x for x in s["nodes"] if x["node"] == "Inc")["values"]["state.n"] for s in t["trace"]]
    assert n == [str(i) for i in range(8)]
    assert {x["node"] for x in t["trace"][0]["nodes"]} == {"Inc", "Fwd"}


def test_bounded_eventually_met_within_its_bound_refuted_beyond(loop) -> None:
    met, short = loop[1]["T3"]["check"]["temporal"], loop[1]["T4"]
    assert (met["status"], met["method"], met["bound"]) == ("proved", "bounded", 5)
    assert short["verdict"] == "refuted" and len(short["check"]["temporal"]["trace"]) == 5


def test_a_value_nobody_published_is_absent_not_arbitrary(loop, tmp_path: Path) -> None:
    """Issue 47: an input before its producer's first answer held any value "from
    before the run", and `always Fwd.out.a <= 1000` was refuted at step 0."""
    assert loop[1]["T5"]["check"]["temporal"]["status"] == "proved"
    assert loop[1]["T8"]["check"]["temporal"]["status"] == "proved"
    # without Fwd's initial value the loop never starts: nothing is ever published, the goal is missed, and
    # the verdict names the initial value to declare
    ws = _ws(tmp_path, ["eventually Fwd.out.a == 5"], state="")
    (ws / "contracts/n.rcl").write_text(RCL.replace("  initially( out.a == 0 )\n", ""))
    t = _check(ws)["T1"]["check"]["temporal"]
    assert t["status"] == "refuted" and t["missing_initially"], t
    assert {r["node"] for r in t["missing_initially"]} <= {"Inc", "Fwd"}
    assert "never publishes" in t["detail"] and "initially" in t["detail"]


def test_unbounded_eventually_never_met_on_a_bound(loop, tmp_path: Path) -> None:
    # n stops at 10: no run of 10 steps reaches 20, but no state repeats within 10 steps either
    r = loop[1]["T6"]
    assert r["verdict"] == "inconclusive" and r["check"]["temporal"]["bound"] == 10
    # without the counter, a run whose Fwd.out.a stays at 10 (its initial value) is a lasso: refuted
    ws = _ws(tmp_path, ["eventually Fwd.out.a == 20"], state="")
    (ws / "contracts/n.rcl").write_text(RCL.replace("initially( out.a == 0 )", "initially( out.a == 10 )"))
    t = _check(ws)["T1"]["check"]["temporal"]
    assert (t["status"], t["method"]) == ("refuted", "lasso") and t["loop"] is not None
    assert t["trace"][-1]["nodes"] == t["trace"][t["loop"]]["nodes"]
    assert all(next(x for x in st["nodes"] if x["node"] == "Fwd")["values"]["out.a"] != "20" for st in t["trace"])


def test_always_next_reads_the_connection(loop) -> None:
    assert loop[1]["T7"]["check"]["temporal"]["status"] == "proved"


def test_incremental_equals_clean_and_a_state_edit_rechecks(loop, tmp_path: Path) -> None:
    ws, _ = loop
    w = Workspace(ws)
    again = stage_requirements(w)
    assert not any(now for _, now in again)
    plan = ws / "contracts/plan.yaml"
    # the edit and its records put back afterwards (tests/_restore.py), so the module's later tests meet the
    # checked workspace without deciding every requirement again
    with restored(ws, tmp_path / "before"):
        plan.write_text(plan.read_text().replace('init: "state.n == 0"', 'init: "state.n == 1"'))
        w = Workspace(ws)
        stage_check(w)
        recs = {r["id"]: (r, now) for r, now in stage_requirements(w)}
        assert all(now for _, now in recs.values())  # every cone holds Inc, whose state changed
        assert recs["T2"][0]["temporal"]["bound"] == 6
    assert 'init: "state.n == 0"' in plan.read_text()


def test_state_declaration_errors_are_located(tmp_path: Path) -> None:
    ws = _ws(tmp_path, ["always Inc.state.m <= 1"], STATE.replace("state.n == 0", "state.k == 0"))
    with pytest.raises(PlanError) as e:
        Workspace(ws).checked
    text = "\n".join(str(d) for d in e.value.diagnostics)
    assert "contracts/plan.yaml:10:14:" in text and "declares no state variable 'k'" in text
    assert "Inc.state.m is not a state variable" in text


def test_a_state_variable_outside_a_temporal_operator_is_an_error(tmp_path: Path) -> None:
    ws = _ws(tmp_path, ["Inc.state.n <= 10"])
    with pytest.raises(PlanError) as e:
        Workspace(ws).checked
    assert "under a temporal operator" in str(e.value.diagnostics[0])


def test_report_and_sarif_show_the_refuted_trace(loop) -> None:
    from rclverify.report.build import build_report
    from rclverify.report.render import render_html, render_markdown
    from rclverify.report.sarif import sarif_log
    ws, _ = loop
    w = Workspace(ws)
    stage_check(w)
    stage_requirements(w)  # the plan as the fixture wrote it (another test edits and restores it)
    report = build_report(w)
    sarif = sarif_log(report)
    res = next(r for r in sarif["runs"][0]["results"] if r.get("properties", {}).get("requirement") == "T2")
    msg = res["message"]["text"]
    assert "Temporal check: refuted by bmc, 7 steps checked" in msg and "step 7: Inc (in.a = " in msg
    assert "heard.a" not in msg  # a run flag of a node the run does not rest on: left out (issue 48)
    loc = res["locations"][0]["physicalLocation"]
    assert loc["artifactLocation"]["uri"] == "contracts/plan.yaml" and loc["region"]["startLine"] == 8
    md = render_markdown(report)
    assert "temporal check: proved by k-induction, k = 1" in md and "| 7 | Inc | " in md
    html = render_html(report)
    assert '<table class="trace">' in html


def test_an_undecided_nesting_is_a_located_error(tmp_path: Path) -> None:
    ws = _ws(tmp_path, ["eventually always Inc.state.n <= 10"])
    with pytest.raises(PlanError) as e:
        Workspace(ws).checked
    d = str(e.value.diagnostics[0])
    assert d.startswith("contracts/plan.yaml:5:14: error") and "not decided" in d


@pytest.mark.parametrize("formal", ["always (Inc.out.b >= 1 and eventually Inc.out.b >= 2)",
                                    "always (Inc.out.b >= 1 or next Inc.out.b >= 2)"])
def test_an_operator_inside_a_state_formula_is_a_located_error_naming_the_shapes(tmp_path: Path, formal: str) -> None:
    """Issue 48: an operator inside a state formula failed with the parser's raw message."""
    ws = _ws(tmp_path, [formal])
    with pytest.raises(PlanError) as e:
        Workspace(ws).checked
    d = str(e.value.diagnostics[0])
    col = formal.index("eventually" if "eventually" in formal else "next") + 1
    assert d.startswith(f"contracts/plan.yaml:5:{13 + col}: error: T1 formal:") and "inside a state formula" in d
    assert "always F, always next F" in d and "always (F -> eventually[<= N] G)" in d and "expected one of" not in d


def test_the_unbounded_response_is_decided(tmp_path: Path) -> None:
    """``always (P -> eventually Q)`` (calculus/requirements/response.py; the oracle is
    tests/calculus/test_response_pattern.py): Inc's output, once at least 1, reaches 2
    (proved through the bounded form); it never reaches 11, so that response
    is never proved."""
    recs = _check(_ws(tmp_path, ["always (Inc.out.b >= 1 -> eventually Inc.out.b >= 2)",
                                 "always (Inc.out.b >= 1 -> eventually Inc.out.b >= 11)"]))
    assert recs["T1"]["check"]["temporal"]["status"] == "proved", recs["T1"]["check"]["temporal"]
    assert recs["T1"]["check"]["temporal"]["method"] == "bounded response"
    assert recs["T2"]["check"]["temporal"]["status"] in ("refuted", "inconclusive"), recs["T2"]["check"]["temporal"]
