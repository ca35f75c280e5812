"""Widths live as offline (issue 106; docs/monitors.md, "Widths live and offline"): a battery
node whose guarantee compares a ``float32`` field with a context constant
(``in.pct <= LOW_PCT``, ``LOW_PCT = 0.15``) gets the same verdicts from the live
monitor (:class:`~rclverify.runtime.live.LiveRun`, the nodes as ``rclverify
monitor --live`` judges them) and from the offline check of the log that live
run wrote, at the boundary ``pct = 0.15f`` (0.15000000596...): the correct robot
(``low`` when ``pct <= 0.15f``) satisfied, the robot with the ``<``-for-``<=``
slip violated; the same with the literal written inline.  Control: the nodes put
at their widths without the context's constants (the route the live monitor
took before) read the correct robot violated and the slip satisfied, so the
test tells the two routes apart.  In-process, a synthetic stream; the widths
come from rosbags' definition of ``sensor_msgs/BatteryState``."""
from __future__ import annotations

import struct
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors import recorded
from rclverify.backends.monitors.config import load_mapping
from rclverify.backends.monitors.widths import at_carried_widths, carried_widths, judged_at_widths
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.runtime.live import LiveRun

pytest.importorskip("rosbags")  # the widths come from the message definitions (the ros extra)

RCL = """context {
  LOW_PCT : REAL = 0.15 ;
}
node Battery {
  inputs( pct : REAL )
  outputs( low : BOOL )
  topics( sensor_msgs/BatteryState battery matches(in.pct), std_msgs/Bool low matches(out.low) )
  assume( TRUE )
  guarantee( out.low <=> (in.pct <= BOUND) )
}
"""
MAPPING = "topics:\n  battery: {fields: [percentage]}\n"
#: 0.15 as a float32 field carries it: 0.15000000596046448
P = struct.unpack("<f", struct.pack("<f", 0.15))[0]
#: what each robot publishes on /low for pct = 0.15f: the correct one (<=) and the slip (<), in float32
ROBOTS = {"correct": True, "slip": False}


def _statuses(tmp: Path, bound: str, low: bool, *, constants: bool = True) -> tuple[dict[str, int], dict[str, int]]:
    """``(live counts, offline counts)`` of one robot's run: the live run judged by the nodes as
    ``rclverify monitor --live`` builds them (``constants=False``: without the context's constants),
    the offline check reading the log the live run wrote."""
    ws = tmp / f"{bound}_{low}_{constants}"
    ws.mkdir()
    (ws / "mapping.yaml").write_text(MAPPING)
    checked = check([parse_text(RCL.replace("BOUND", bound), "battery.rcl")])
    cfg = load_mapping(ws, "mapping.yaml")
    node = checked.nodes["Battery"]
    if constants:
        judged = judged_at_widths(checked, node, cfg.rules, [ws / d for d in cfg.msg_dirs])[0]
    else:
        judged = at_carried_widths(node, carried_widths(node, cfg.rules, [ws / d for d in cfg.msg_dirs]))
    log = ws / "live.jsonl"
    live = LiveRun(checked, [judged], cfg.rules, cfg.horizon, log, reorder_window=0.0)
    for i in range(3):
        t = 1.0 + i
        live.tick(t)
        live.push("/battery", {"percentage": P}, t)
        live.push("/low", {"data": low}, t + 0.01)
    live.tick(10.0)
    record: dict[str, Any] = live.stop()
    run = recorded.check_recorded(checked, [node], cfg, ws, str(log), lambda w: None)
    return dict(record["nodes"][0]["counts"]), dict(run.results[0].counts)


def _decided(counts: dict[str, int]) -> tuple[int, int]:
    return counts.get("satisfied", 0), counts.get("violated", 0)


@pytest.mark.parametrize("bound", ["LOW_PCT", "0.15"])
def test_a_float32_boundary_reads_the_same_live_and_offline(tmp_path: Path, bound: str) -> None:
    for robot, low in ROBOTS.items():
        live, offline = _statuses(tmp_path, bound, low)
        assert _decided(live) == _decided(offline), (robot, live, offline)
        want = (3, 0) if robot == "correct" else (0, 3)
        assert _decided(live) == want, (robot, bound, live)


def test_without_the_named_constants_at_their_width_the_named_case_reads_otherwise(tmp_path: Path) -> None:
    correct, offline = _statuses(tmp_path, "LOW_PCT", True, constants=False)
    slip, _ = _statuses(tmp_path, "LOW_PCT", False, constants=False)
    assert _decided(correct) == (0, 3) and _decided(slip) == (3, 0), (correct, slip)
    assert _decided(offline) == (3, 0)  # the offline check of the same log: the correct robot satisfied
    literal, _ = _statuses(tmp_path, "0.15", True, constants=False)
    assert _decided(literal) == (3, 0)  # an inline literal was put at its width on either route
