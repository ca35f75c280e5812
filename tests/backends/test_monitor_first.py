"""``first(in.x)`` judged on recorded runs (issue 113; docs/semantics.md, "The
first published value"): a log that starts with the run's start-of-run
marker decides it on its first message of the topic (the control: a node
that answers its first message as it answers every other one is violated
there), a log without the marker makes what it decides ``inconclusive``,
naming why.  Small workspaces written here, judged through the recorded
path (``rclverify monitor LOG``'s)."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from rclverify.backends.monitors import recorded
from rclverify.backends.monitors.config import load_mapping
from rclverify.backends.monitors.run_origin import origin_line
from rclverify.lang.typecheck import load

# Hold answers 0 to the first command it hears and echoes every later one.
HOLD = """
node Hold {
  inputs( cmd : REAL )
  outputs( out : REAL )
  topics( std_msgs/Float64 cmd matches(in.cmd), std_msgs/Float64 out matches(out.out) )
  guarantee( (first(in.cmd) -> out.out == 0) and (not first(in.cmd) -> out.out == in.cmd) )
}
"""
MAPPING = "topics:\n  cmd: {fields: [data]}\n  out: {fields: [data]}\n"


def _judge(tmp: Path, lines: list[dict[str, Any]]) -> tuple[dict[str, int], Any]:
    (tmp / "contracts").mkdir(exist_ok=True)
    (tmp / "contracts" / "c.rcl").write_text(HOLD)
    (tmp / "mapping.yaml").write_text(MAPPING)
    run = tmp / "run.jsonl"
    run.write_text("".join(json.dumps(x) + "\n" for x in lines))
    checked = load([tmp / "contracts" / "c.rcl"])
    cfg = load_mapping(tmp, "mapping.yaml")
    got = recorded.check_recorded(checked, [checked.nodes["Hold"]], cfg, tmp, str(run), lambda w: None)
    return dict(got.results[0].counts), got.results[0]


def _run(first_answer: float) -> list[dict[str, Any]]:
    return [{"topic": "cmd", "time": 1.0, "data": 5.0}, {"topic": "out", "time": 1.01, "data": first_answer},
            {"topic": "cmd", "time": 2.0, "data": 7.0}, {"topic": "out", "time": 2.01, "data": 7.0}]


def _start() -> dict[str, Any]:
    return dict(origin_line(0.5, "rclpy", "rmw_fastrtps_cpp", "Fast DDS"))


def test_the_first_message_of_a_run_with_its_start_marker_decides_first(tmp_path: Path) -> None:
    counts, _ = _judge(tmp_path, [_start(), *_run(0.0)])
    assert counts["satisfied"] == 2 and counts["violated"] == 0 and counts["inconclusive"] == 0
    # control: the first command echoed like every other one breaks the guarantee on that message only
    (tmp_path / "b").mkdir()
    counts, res = _judge(tmp_path / "b", [_start(), *_run(5.0)])
    assert counts["violated"] == 1 and counts["satisfied"] == 1
    assert res.first_violation is not None and res.first_violation["time"] == 1.01


def test_a_log_without_the_start_marker_leaves_first_inconclusive_and_says_why(tmp_path: Path) -> None:
    counts, res = _judge(tmp_path, _run(0.0))
    assert counts["satisfied"] == 0 and counts["violated"] == 0 and counts["inconclusive"] == 2
    why = res.first_inconclusive["reason"]
    assert "no start-of-run marker" in why and "in.cmd" in why, why


# -- a requirement's first(Node.in.x) on a recorded run: Inc answers each a with a + 1 -----------------------

INC = """node Inc { inputs( a : NATURAL ) outputs( b : NATURAL )
  topics( std_msgs/Int32 a matches(in.a), std_msgs/Int32 b matches(out.b) )
  guarantee( out.b == in.a + 1 ) }
"""
RUN = [("a", 1), ("b", 2), ("a", 2), ("b", 3), ("a", 5), ("b", 6)]


def _requirement(tmp: Path, formal: str, start: bool) -> Any:
    from rclverify.backends.monitors.temporal_trace import check_temporal_trace
    from rclverify.model.plan.formal import Source
    from rclverify.model.plan.temporal import parse_temporal
    from rclverify.traces import read_trace
    checked = load_text(INC)
    p = tmp / "run.jsonl"
    lines = ([_start()] if start else []) + [{"topic": t, "time": round(1 + 0.1 * k, 1), "data": v}
                                             for k, (t, v) in enumerate(RUN)]
    p.write_text("".join(json.dumps(x) + "\n" for x in lines))
    t = parse_temporal(Source(formal, 1, 1, "plan.yaml"), checked, "T", {})
    return check_temporal_trace(t, checked, (), read_trace(p), {})


def load_text(rcl: str) -> Any:
    from rclverify.lang.parser import parse_text
    from rclverify.lang.typecheck import check
    return check([parse_text(rcl, "n.rcl")])


def test_a_requirement_reads_the_first_value_on_a_run_with_its_start_marker(tmp_path: Path) -> None:
    assert _requirement(tmp_path, "always (first(Inc.in.a) -> Inc.in.a == 1)", True).verdict == "true"
    # control: the later values are not 1, and the first is not 2
    assert _requirement(tmp_path, "always Inc.in.a == 1", True).verdict == "false"
    v = _requirement(tmp_path, "always (first(Inc.in.a) -> Inc.in.a == 2)", True)
    assert (v.verdict, v.step) == ("false", 0)


def test_a_requirement_over_first_on_a_run_without_the_marker_is_inconclusive(tmp_path: Path) -> None:
    v = _requirement(tmp_path, "always (first(Inc.in.a) -> Inc.in.a == 1)", False)
    assert v.verdict == "inconclusive" and "no start-of-run marker" in v.reason, v.reason


# -- live: the start-of-run marker a live monitor notes decides first(in.x) as its log does ----------------

def _live(tmp: Path, start: bool, first_answer: float) -> tuple[list[str], Path]:
    from rclverify.runtime.live import LiveRun
    checked = load([_workspace(tmp)])
    cfg = load_mapping(tmp, "mapping.yaml")
    published: list[str] = []
    live = LiveRun(checked, [checked.nodes["Hold"]], cfg.rules, cfg.horizon, tmp / "live.jsonl",
                   reorder_window=0.0, publish=published.append)
    if start:
        live.note(_start())
    for x in _run(first_answer):
        live.tick(float(x["time"]))
        live.push(str(x["topic"]), {"data": x["data"]}, float(x["time"]))
    live.tick(10.0)
    live.stop()
    return [json.loads(p)["verdict"] for p in published if json.loads(p).get("node")], tmp / "live.jsonl"


def _workspace(tmp: Path) -> Path:
    (tmp / "contracts").mkdir(exist_ok=True)
    (tmp / "contracts" / "c.rcl").write_text(HOLD)
    (tmp / "mapping.yaml").write_text(MAPPING)
    return tmp / "contracts" / "c.rcl"


def test_a_live_run_decides_first_after_its_start_marker_as_its_log_is_judged(tmp_path: Path) -> None:
    verdicts, log = _live(tmp_path, True, 0.0)
    assert verdicts == ["satisfied", "satisfied"], verdicts
    (tmp_path / "offline").mkdir()
    counts, _ = _judge(tmp_path / "offline", [json.loads(x) for x in log.read_text().splitlines()
                                              if json.loads(x).get("topic") in ("cmd", "out", "rclverify/run")])
    assert counts["satisfied"] == 2 and counts["inconclusive"] == 0  # live = log
    (tmp_path / "v").mkdir()
    assert _live(tmp_path / "v", True, 5.0)[0] == ["violated", "satisfied"]  # control: the first answer wrong
    (tmp_path / "n").mkdir()
    unknown = _live(tmp_path / "n", False, 0.0)[0]  # control: no marker noted, so first(in.cmd) is unknown
    assert unknown and set(unknown) == {"inconclusive"}, unknown
