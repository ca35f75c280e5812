"""Temporal requirements checked on recorded runs (docs/monitors.md,
"Temporal requirements on traces"): the finite-trace verdicts of
backends/monitors/temporal_trace.py on small JSON-lines traces of a small
workspace, a state variable advanced by its ``next`` on the trace, the case
study's REQ4 on its nominal run, and the staleness of a ``state:`` edit.

A step is a step of the composed system (docs/semantics.md, "Steps"): on
``RUN`` each input ``a`` and its answer ``b`` are one step, so its six
messages are the steps 0 (a 1, b 2), 1 (a 2, b 3) and 2 (a 5, b 6)."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from rclverify.backends.monitors.temporal_trace import check_temporal_trace
from rclverify.model.plan.state import state_types
from rclverify.model.plan.temporal import parse_temporal
from rclverify.model.plan.formal import Source
from rclverify.traces import read_trace
from rclverify.stages.workspace import Workspace

# Inc answers each a with b = a + 1; its state n counts the b it produced.
RCL = """node Inc { inputs( a : NATURAL ) outputs( b : NATURAL )
  topics( std_msgs/Int32 a matches(in.a), std_msgs/Int32 b matches(out.b) )
  guarantee( out.b == in.a + 1 ) }
"""
STATE = """state:
  Inc:
    n:
      type: NATURAL
      init: "state.n == 0"
      next: "next.n == state.n + 1"
"""


@pytest.fixture(scope="module")
def ws(tmp_path_factory: pytest.TempPathFactory) -> Workspace:
    root = tmp_path_factory.mktemp("tt")
    (root / "contracts").mkdir()
    (root / "contracts/n.rcl").write_text(RCL)
    (root / "contracts/plan.yaml").write_text("contracts: [contracts/n.rcl]\n" + STATE)
    return Workspace(root)


def _trace(ws: Workspace, name: str, msgs: list[tuple[str, int]]) -> Path:
    p = ws.root / name
    p.write_text("".join(json.dumps({"topic": t, "time": round(0.1 * k, 1), "data": v}) + "\n"
                         for k, (t, v) in enumerate(msgs)))
    return p


def _check(ws: Workspace, formal: str, trace: Path):
    c = ws.checked
    t = parse_temporal(Source(formal, 1, 1, "plan.yaml"), c, "T", state_types(ws.plan.states, c))
    return check_temporal_trace(t, c, ws.plan.states, read_trace(trace), {})


RUN = [("a", 1), ("b", 2), ("a", 2), ("b", 3), ("a", 5), ("b", 6)]


def test_always_violated_at_a_step_is_false_with_the_step_and_stamp(ws) -> None:
    v = _check(ws, "always Inc.out.b <= 3", _trace(ws, "run.jsonl", RUN))
    assert (v.verdict, v.step, v.time, v.where) == ("false", 2, 0.5, "run.jsonl:6")
    assert v.witness[0]["values"]["Inc.out.b"] == "6" and v.witness[0]["holds"] is False


def test_always_holding_on_every_step_is_true_on_this_trace_only(ws) -> None:
    v = _check(ws, "always next Inc.out.b >= 2", _trace(ws, "run.jsonl", RUN[1:]))
    # b 2 published before any input is step 0; each a and its b the steps 1 and 2
    assert v.verdict == "true" and v.steps == 3 and "not a proof" in v.reason


def test_always_constrains_published_values_only(ws) -> None:
    """Issue 47 (docs/semantics.md): b is not published at step 0, so ``always`` is
    not evaluated there (before, the run was inconclusive for a value nobody
    published); it holds on every published b.  Step 0 is an input left
    unanswered; the second a opens step 1 (a second message on one topic)."""
    v = _check(ws, "always Inc.out.b >= 2", _trace(ws, "run.jsonl", [("a", 1), ("a", 2), ("b", 3)]))
    assert v.verdict == "true" and v.steps == 2


def test_eventually_met(ws) -> None:
    v = _check(ws, "eventually Inc.out.b == 3", _trace(ws, "run.jsonl", RUN))
    assert (v.verdict, v.step, v.time) == ("true", 1, 0.3)


def test_eventually_unmet_at_the_end_is_currently_false_never_failed(ws) -> None:
    v = _check(ws, "eventually Inc.out.b == 7", _trace(ws, "run.jsonl", RUN))
    assert v.verdict == "currently_false" and v.steps == 3 and "inconclusive" in v.reason


def test_bounded_eventually_false_once_its_bound_passed(ws) -> None:
    # b 1 before any input is step 0: b 6 answers the input of step 3
    v = _check(ws, "eventually[<= 2] Inc.out.b == 6", _trace(ws, "run.jsonl", [("b", 1)] + RUN))
    assert (v.verdict, v.step, v.time) == ("false", 2, 0.4)
    # on RUN b 6 answers the input of step 2: met, six messages in (counting messages, it was false)
    met = _check(ws, "eventually[<= 2] Inc.out.b == 6", _trace(ws, "run.jsonl", RUN))
    assert (met.verdict, met.step, met.where) == ("true", 2, "run.jsonl:6")
    assert _check(ws, "eventually[<= 1] Inc.out.b == 6", _trace(ws, "run.jsonl", RUN)).verdict == "false"
    short = _check(ws, "eventually[<= 9] Inc.out.b == 7", _trace(ws, "run.jsonl", RUN))
    assert short.verdict == "currently_false"  # the trace ended before the bound


def test_state_variable_advances_by_its_next_on_the_trace(ws) -> None:
    # n counts steps: 0 at step 0, 2 at step 2
    v = _check(ws, "eventually Inc.state.n == 2", _trace(ws, "run.jsonl", RUN))
    assert (v.verdict, v.step) == ("true", 2)
    assert v.witness[0]["values"]["Inc.state.n"] == "2"
    f = _check(ws, "always Inc.state.n <= 1", _trace(ws, "run.jsonl", RUN))
    assert (f.verdict, f.step) == ("false", 2)


def test_until(ws) -> None:
    run = _trace(ws, "run.jsonl", [("b", 1)] + RUN)
    ok = _check(ws, "Inc.out.b <= 2 until Inc.out.b == 3", run)
    assert (ok.verdict, ok.step) == ("true", 2)
    bad = _check(ws, "Inc.out.b <= 1 until Inc.out.b == 6", run)
    assert (bad.verdict, bad.step) == ("false", 1)


def test_case_study_req4_on_the_nominal_run_is_currently_false() -> None:
    root = Path(__file__).resolve().parents[2]
    w = Workspace(root)
    from rclverify.backends.monitors.config import load_mapping
    c, plan = w.checked, w.plan
    req = next(r for r in plan.requirements if r.id == "REQ4")
    t = parse_temporal(req.formal, c, "REQ4", state_types(plan.states, c))
    cfg = load_mapping(root, "backends/monitors/mapping.yaml")
    v = check_temporal_trace(t, c, plan.states, read_trace(root / "backends/monitors/traces/nominal.jsonl"),
                             cfg.rules)
    # the run ends after 6 of the 13 waypoints, the radiation never red: not reached, not failed
    # 63 messages on the topics of its cone (Agent, Navigation, RadiationSensor), 38 steps of the system:
    # each command, the answer it causes and the readings that come with it are one step
    assert v.verdict == "currently_false" and v.steps == 38 and v.where == "nominal.jsonl:63"


def test_state_edit_shows_the_requirement_record_stale_before_the_stage_ran(tmp_path: Path) -> None:
    from rclverify.app.pipeline import stage_check, stage_requirements
    from rclverify.report.build import build_report
    (tmp_path / "contracts").mkdir()
    (tmp_path / "contracts/n.rcl").write_text(RCL)
    plan = ("contracts: [contracts/n.rcl]\nrequirements:\n  - id: T1\n    text: t\n"
            "    formal: \"eventually[<= 2] Inc.state.n >= 2\"\n" + STATE)
    (tmp_path / "contracts/plan.yaml").write_text(plan)
    w = Workspace(tmp_path)
    stage_check(w)
    stage_requirements(w)
    before = {r["id"]: r for r in build_report(Workspace(tmp_path)).to_json()["requirements"]}
    assert before["T1"]["verdict"] != "stale"
    (tmp_path / "contracts/plan.yaml").write_text(plan.replace("state.n + 1", "state.n"))
    after = {r["id"]: r for r in build_report(Workspace(tmp_path)).to_json()["requirements"]}
    assert after["T1"]["verdict"] == "stale"


def test_recorded_runs_are_evidence_of_the_temporal_requirement_in_the_report(tmp_path: Path) -> None:
    from rclverify.app.pipeline import stage_check, stage_requirements
    from rclverify.report.build import build_report
    (tmp_path / "contracts").mkdir()
    (tmp_path / "contracts/n.rcl").write_text(RCL)
    (tmp_path / "contracts/plan.yaml").write_text(
        "contracts: [contracts/n.rcl]\nrequirements:\n"
        "  - id: T1\n    text: b stays small\n    formal: \"always Inc.out.b <= 3\"\n"
        "  - id: T2\n    text: b reaches 3\n    formal: \"eventually Inc.out.b == 3\"\n"
        "nodes:\n  Inc:\n    evidence:\n      - backend: monitors\n        traces: [run.jsonl]\n" + STATE)
    w = Workspace(tmp_path)
    _trace(w, "run.jsonl", RUN)
    stage_check(w)
    stage_requirements(w)
    from rclverify.report.render import render_html, render_markdown
    report = build_report(Workspace(tmp_path))
    md, html = render_markdown(report), render_html(report)
    assert "recorded run `run.jsonl`: failed (trace verdict false, step 2 at t = 0.5 s)" in md
    assert "recorded run <code>run.jsonl</code>" in html
    reqs = {r["id"]: r for r in report.to_json()["requirements"]}
    t1, t2 = reqs["T1"], reqs["T2"]
    row = t1["check"]["traces"][0]
    assert (row["trace"], row["status"], row["verdict"]["verdict"], row["verdict"]["step"]) == \
        ("run.jsonl", "failed", "false", 2)
    # a failed run refutes it whatever Z3 says; Z3's own verdict is kept beside it
    assert t1["status"] == "failed" and "run.jsonl refutes it" in t1["note"]
    assert t2["check"]["traces"][0]["status"] == "discharged" and t2["status"] != "discharged"
    # an edited trace: the record is stale before the stage ran again
    _trace(w, "run.jsonl", [("b", 1)] + RUN[:4])
    assert {r["id"]: r for r in build_report(Workspace(tmp_path)).to_json()["requirements"]}["T1"]["verdict"] == "stale"
    stage_requirements(Workspace(tmp_path))
    again = {r["id"]: r for r in build_report(Workspace(tmp_path)).to_json()["requirements"]}
    assert again["T1"]["check"]["traces"][0]["verdict"]["verdict"] == "true"
    # doit re-runs the requirements stage when a recorded run changes
    from rclverify.app.tasks import build_tasks
    assert str(tmp_path / "run.jsonl") in build_tasks(tmp_path)["task_requirements"]()["file_dep"]



@pytest.mark.parametrize("bad", ['"six"', "NaN", "true"])
def test_an_unreadable_value_never_stands_in_for_the_one_before(ws, bad: str) -> None:
    """Issue 63, row 5: a message whose value cannot be read (a string, NaN,
    a bool for a number) leaves what reads it undecided at that step; the
    value before it does not stand in, so ``always`` is not true."""
    p = ws.root / "unreadable.jsonl"
    lines = [json.dumps({"topic": t, "time": round(0.1 * k, 1), "data": v}) for k, (t, v) in enumerate(RUN[:4])]
    lines.append('{"topic": "b", "time": 0.4, "data": %s}' % bad)
    p.write_text("\n".join(lines) + "\n")
    v = _check(ws, "always Inc.out.b <= 3", p)
    assert v.verdict == "inconclusive", v.reason
    assert v.step == 2 and "could not be read" in v.reason and "unreadable.jsonl:5" in v.reason
    # read again, the value is judged as usual
    p.write_text("\n".join(lines + ['{"topic": "b", "time": 0.5, "data": 9}']) + "\n")
    assert _check(ws, "always Inc.out.b <= 3", p).verdict == "false"
