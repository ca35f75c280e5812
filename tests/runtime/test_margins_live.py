"""Margins of the live monitor (docs/monitors.md, "Margins live"): with
margins on, the live run's verdicts carry their message's margin and the
status line each guarantee's smallest; ``warn_margin`` (``--warn-margin``)
warns once per new smallest margin below it, on a satisfied answer, before
the violation that follows; the control, a threshold below every margin,
warns of nothing; and without margins nothing is computed.  In-process: the
online engine under LiveRun, fed a synthetic stream."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from rclverify.backends.monitors.config import load_mapping
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.runtime.live import LiveRun

BRAKE = """node Brake {
  inputs( dist : REAL )
  outputs( speed : REAL )
  topics( std_msgs/Float64 dist matches(in.dist), std_msgs/Float64 speed matches(out.speed) )
  assume( TRUE )
  guarantee( out.speed <= in.dist )
}
"""
# speed closes in on dist: margins 0.5, 0.3, 0.3, 0.1, then -0.2 (the violation)
STREAM = [(1.0, 0.5), (1.0, 0.7), (2.0, 1.7), (2.0, 1.9), (2.0, 2.2)]


def _live(tmp_path: Path, name: str, **kw: Any) -> tuple[LiveRun, list[str], list[str]]:
    checked = check([parse_text(BRAKE, "brake.rcl")])
    cfg = load_mapping(tmp_path, None)
    published: list[str] = []
    warned: list[str] = []
    live = LiveRun(checked, [checked.nodes["Brake"]], cfg.rules, cfg.horizon, tmp_path / f"{name}.jsonl",
                   reorder_window=0.0, publish=published.append, warn=warned.append, **kw)
    for i, (dist, speed) in enumerate(STREAM):
        t = 1.0 + i
        live.tick(t)
        live.push("/dist", {"data": dist}, t)
        live.push("/speed", {"data": speed}, t + 0.01)
    live.tick(10.0)
    return live, published, warned


def test_a_margin_falling_below_the_threshold_warns_before_the_violation(tmp_path: Path) -> None:
    live, published, warned = _live(tmp_path, "warn", warn_margin=0.35)
    verdicts = [json.loads(p) for p in published if json.loads(p).get("node")]
    assert [v["verdict"] for v in verdicts] == ["satisfied"] * 4 + ["violated"]
    assert [round(v["margin"], 9) for v in verdicts] == [0.5, 0.3, 0.3, 0.1, -0.2]
    # 0.3 (the first below 0.35) and 0.1 (a new smallest); the second 0.3 is not repeated; the violation is no warning
    assert len(warned) == 2
    assert warned[0].startswith("rclverify monitor: warning: Brake guarantee 1 held with margin 0.3 ")
    assert "below --warn-margin 0.35, at t = 2.010000 s" in warned[0] and "(out.speed <= in.dist)" in warned[0]
    assert "margin 0.1 " in warned[1] and "t = 4.010000 s" in warned[1]
    violation = next(v for v in verdicts if v["verdict"] == "violated")
    assert violation["time"] > 4.01  # both warnings came before it
    assert "least margin g1 -0.2" in live.status_line()
    record = live.stop()
    [m] = record["nodes"][0]["margins"]
    assert (m["guarantee"], round(m["margin"], 9), m["answers"]) == (1, -0.2, 5)


def test_the_control_under_every_margin_warns_of_nothing(tmp_path: Path) -> None:
    _, _, warned = _live(tmp_path, "control", warn_margin=0.05)
    assert warned == []


def test_without_margins_none_is_computed(tmp_path: Path) -> None:
    live, published, warned = _live(tmp_path, "plain")
    assert warned == [] and all("margin" not in json.loads(p) for p in published)
    assert "least margin" not in live.status_line()
    on, published, _ = _live(tmp_path, "margins", margins=True)
    assert "least margin g1 -0.2" in on.status_line()
