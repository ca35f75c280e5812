"""A stale value after a NaN (hostile round eight, from round seven): x = 5,
then x = NaN, then an output y = 0 (and z = 1 before or after it).  One twin
judged y against x = 5, the value before the NaN (violated), the other was
undecided: the same question, two answers.  An input that changes to a value
that does not map supersedes the question before it with an undecided one,
so both twins are undecided; the control, y answering x = 5 before the NaN
came, is still a violation.  The batch path, the event path and the live
engine agree."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from rclverify.backends.monitors.check import check_trace
from rclverify.backends.monitors.config import load_mapping
from rclverify.backends.monitors.online import OnlineEngine
from rclverify.lang.typecheck import load
from rclverify.traces import read_trace

F = """
node F {
  inputs( x : REAL, z : REAL )
  outputs( y : REAL )
  topics( pkg/X x matches(in.x), pkg/Z z matches(in.z), pkg/Y y matches(out.y) )
  assume( TRUE )
  guarantee( out.y >= in.x )
}
"""


def _verdicts(tmp: Path, order: list[tuple[str, str]]) -> list[list[str]]:
    (tmp / "c.rcl").write_text(F)
    (tmp / "mapping.yaml").write_text("topics:\n  x: {fields: [v]}\n  z: {fields: [v]}\n  y: {fields: [v]}\n")
    run = tmp / "run.jsonl"
    run.write_text("".join(json.dumps({"topic": t, "time": 1.0 + 0.1 * k, "v": v}).replace('"NaN"', "NaN") + "\n"
                           for k, (t, v) in enumerate(order)))
    checked = load([tmp / "c.rcl"])
    rules = load_mapping(tmp, "mapping.yaml").rules
    out = []
    for batch in (True, False):
        got: list = []
        check_trace(checked, [checked.nodes["F"]], read_trace(run), rules, 2.0, got.append, batch=batch)
        out.append(sorted(v.verdict for v in got))
    live: list = []
    engine = OnlineEngine(checked, [checked.nodes["F"]], rules, 2.0, reorder_window=0.0, on_verdict=live.append)
    for ev in read_trace(run):  # heard in the log's order, each at its own time
        engine.push(ev.topic, dict(ev.fields), ev.time, ev.where)
    engine.finish()
    out.append(sorted(v.verdict for v in live if v.node == "F"))
    return out


@pytest.mark.parametrize("order", [
    [("x", 5.0), ("x", "NaN"), ("y", 0.0), ("z", 1.0)],
    [("x", 5.0), ("x", "NaN"), ("z", 1.0), ("y", 0.0)],
])
def test_an_answer_after_a_nan_is_never_judged_on_the_value_before_it(tmp_path: Path, order: list) -> None:
    batch, events, live = _verdicts(tmp_path, order)
    assert batch == events == live
    assert "violated" not in events and "inconclusive" in events


def test_the_control_an_answer_before_the_nan_is_judged(tmp_path: Path) -> None:
    batch, events, live = _verdicts(tmp_path, [("x", 5.0), ("y", 0.0), ("x", "NaN"), ("z", 1.0)])
    assert batch == events == live and "violated" in events
