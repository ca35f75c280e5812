"""Margins in steps (docs/semantics.md, "Margins in steps"): the steps to
spare of a bounded ``eventually`` and of a bounded response on a recorded
run, and of ``progress( within K steps )``; with the controls that have none
(an unbounded form, a verdict that is not true).

A step is a step of the composed system: on ``RUN`` each input ``a`` and its
answer ``b`` are one step, so its messages are the steps 0 (a 1, b 2),
1 (a 2, b 3) and 2 (a 5, b 6)."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.declarations import check_declarations
from rclverify.backends.monitors.temporal_trace import TraceVerdict, check_temporal_trace
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.model.plan.formal import Source
from rclverify.model.plan.state import state_types
from rclverify.model.plan.temporal import parse_temporal
from rclverify.stages.workspace import Workspace
from rclverify.traces import read_trace
from rclverify.traces.events import Event

RCL = """node Inc { inputs( a : NATURAL ) outputs( b : NATURAL )
  topics( std_msgs/Int32 a matches(in.a), std_msgs/Int32 b matches(out.b) )
  guarantee( out.b == in.a + 1 )
  progress( within 2 steps ) }
"""
RUN = [("a", 1), ("b", 2), ("a", 2), ("b", 3), ("a", 5), ("b", 6)]


@pytest.fixture(scope="module")
def ws(tmp_path_factory: pytest.TempPathFactory) -> Workspace:
    root = tmp_path_factory.mktemp("steps")
    (root / "contracts").mkdir()
    (root / "contracts/n.rcl").write_text(RCL)
    (root / "contracts/plan.yaml").write_text("contracts: [contracts/n.rcl]\n")
    return Workspace(root)


def _check(ws: Workspace, formal: str, msgs: list[tuple[str, int]]) -> TraceVerdict:
    p = ws.root / "run.jsonl"
    p.write_text("".join(json.dumps({"topic": t, "time": round(0.1 * k, 1), "data": v}) + "\n"
                         for k, (t, v) in enumerate(msgs)))
    c = ws.checked
    t = parse_temporal(Source(formal, 1, 1, "plan.yaml"), c, "T", state_types(ws.plan.states, c))
    return check_temporal_trace(t, c, ws.plan.states, read_trace(p), {})


def test_a_bounded_eventually_met_has_the_steps_it_spared(ws) -> None:
    v = _check(ws, "eventually[<= 5] Inc.out.b == 6", RUN)
    assert (v.verdict, v.step, v.spare) == ("true", 2, 3) and v.to_json()["spare"] == 3
    assert _check(ws, "eventually[<= 2] Inc.out.b == 6", RUN).spare == 0  # met at its bound: none to spare
    # controls: unbounded (no bound to spare), and not met (no margin in steps)
    assert _check(ws, "eventually Inc.out.b == 6", RUN).spare is None
    missed = _check(ws, "eventually[<= 1] Inc.out.b == 6", RUN)
    assert missed.verdict == "false" and missed.spare is None and "spare" not in missed.to_json()


def test_a_bounded_response_has_its_slowest_answer_s_spare(ws) -> None:
    # a 2 (step 1) is answered by b 6 at step 2 (a wait of one step); a 5 answered at once
    v = _check(ws, "always (Inc.in.a >= 2 -> eventually[<= 3] Inc.out.b == 6)", RUN)
    assert (v.verdict, v.spare) == ("true", 2)
    tight = _check(ws, "always (Inc.in.a >= 2 -> eventually[<= 1] Inc.out.b == 6)", RUN)
    assert (tight.verdict, tight.spare) == ("true", 0)
    assert _check(ws, "always (Inc.in.a >= 1 -> eventually[<= 1] Inc.out.b == 6)", RUN).verdict == "false"


def _events(rows: list[tuple[str, int]]) -> list[Event]:
    return [Event(i, 0.1 * i, t, {"data": v}, f"run.jsonl:{i + 1}") for i, (t, v) in enumerate(rows)]


def test_progress_within_k_steps_has_k_less_its_longest_unanswered_row() -> None:
    c = check([parse_text(RCL, "n.rcl")])
    node = c.nodes["Inc"]

    def row(msgs: list[tuple[str, int]]) -> dict[str, Any]:
        [r] = check_declarations(c, node, _events(msgs), {}).rows()
        return dict(r)
    every = row([("b", 0)] + RUN)  # every input answered before the next: rows of one step
    assert (every["verdict"], every["spare"]) == ("true", 1)
    two = row([("b", 0), ("a", 1), ("a", 2), ("b", 3), ("a", 4), ("b", 5)])  # two inputs in a row unanswered
    assert (two["verdict"], two["spare"]) == ("true", 0)
    broken = row([("b", 0), ("a", 1), ("a", 2), ("a", 3), ("a", 4), ("b", 5)])  # three in a row: broken
    assert broken["verdict"] == "false" and "spare" not in broken


def test_the_report_says_the_steps_to_spare(ws) -> None:
    from rclverify.report.templating import environment
    v = _check(ws, "eventually[<= 5] Inc.out.b == 6", RUN).to_json()
    row = {"trace": "run.jsonl", "status": "discharged", "verdict": v}
    html = environment().get_template("parts/trace_verdicts.html.j2").render(rows=[row])
    md = environment().get_template("parts/trace_verdicts.md.j2").render(rows=[row])
    assert "step 2 at t = 0.5 s, 3 step(s) to spare" in html and "3 step(s) to spare" in md
    none = _check(ws, "eventually Inc.out.b == 6", RUN).to_json()
    assert "to spare" not in environment().get_template("parts/trace_verdicts.md.j2").render(
        rows=[{**row, "verdict": none}])
