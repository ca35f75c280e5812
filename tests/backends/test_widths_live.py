"""Widths live as offline (issue 106; docs/monitors.md, "Widths live and offline"): issue 106's
battery node, ``out.low <=> (in.pct <= LOW_PCT or exists(v in in.cells | v < LOW_CELL))`` with
``LOW_PCT = 0.15`` and ``LOW_CELL = 3.3`` named in the context and ``float32`` fields
(``sensor_msgs/BatteryState``'s ``percentage`` and ``cell_voltage``), gets the same verdicts from the
live monitor (:class:`~rclverify.runtime.live.LiveRun` over the nodes as ``rclverify monitor --live``
builds them) and from the offline check of the log that live run wrote, at each boundary: ``pct =
0.15f`` (0.15000000596...) and a cell at ``3.3f`` (3.29999995...).  The correct robot (float32
arithmetic) is satisfied and the robot with the slip (``<`` for ``<=``, ``<=`` for ``<``) violated,
with the named constants and with the same values written inline.  Control: the nodes put at their
widths without the context's constants (the route the live monitor took before) read the correct
robot violated and the slip satisfied, and the inline literals right, so the test tells the two
routes apart.  In-process, a synthetic stream; the widths come from rosbags' definition of
``sensor_msgs/BatteryState``."""
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
  LOW_CELL : REAL = 3.3 ;
}
node Battery {
  inputs( pct : REAL, cells : seq(REAL) )
  outputs( low : BOOL )
  topics( sensor_msgs/BatteryState battery matches(in.pct), sensor_msgs/BatteryState battery matches(in.cells),
          std_msgs/Bool low matches(out.low) )
  assume( TRUE )
  guarantee( out.low <=> (in.pct <= PCT_BOUND or exists(v in in.cells | v < CELL_BOUND)) )
}
"""
MAPPING = "topics:\n  battery: {fields: {pct: [percentage], cells: [cell_voltage]}}\n"


def f32(x: float) -> float:
    """``x`` as a float32 field carries it."""
    return float(struct.unpack("<f", struct.pack("<f", x))[0])


#: the named constants and the same values written inline
BOUNDS = {"named": ("LOW_PCT", "LOW_CELL"), "inline": ("0.15", "3.3")}
#: per boundary: (percentage, cell voltages) published, and what the correct robot (float32 arithmetic, as
#: the contract says) and the robot with the slip (< for <= on the percentage, <= for < on the cells) set
#: ``low`` to: the percentage 0.15f (0.15000000596...) is low, a cell at 3.3f (3.29999995...) is not
CASES = {"percentage": (f32(0.15), [f32(3.9)], True, False), "cell": (f32(0.5), [f32(3.9), f32(3.3)], False, True)}


def _counts(tmp: Path, bounds: tuple[str, str], case: str, robot: str, *,
            constants: bool = True) -> tuple[dict[str, int], dict[str, int]]:
    """``(live counts, offline counts)`` of one robot's run: the live run judged by the nodes as
    ``rclverify monitor --live`` builds them (``constants=False``: without the context's constants),
    the offline check reading the log the live run wrote."""
    ws = tmp / f"{bounds[0]}_{case}_{robot}_{constants}"
    ws.mkdir()
    (ws / "mapping.yaml").write_text(MAPPING)
    checked = check([parse_text(RCL.replace("PCT_BOUND", bounds[0]).replace("CELL_BOUND", bounds[1]), "battery.rcl")])
    cfg = load_mapping(ws, "mapping.yaml")
    node = checked.nodes["Battery"]
    if constants:
        judged = judged_at_widths(checked, node, cfg.rules, [ws / d for d in cfg.msg_dirs])[0]
    else:
        judged = at_carried_widths(node, carried_widths(node, cfg.rules, [ws / d for d in cfg.msg_dirs]))
    pct, cells, correct, slip = CASES[case]
    log = ws / "live.jsonl"
    live = LiveRun(checked, [judged], cfg.rules, cfg.horizon, log, reorder_window=0.0)
    for i in range(3):
        t = 1.0 + i
        live.tick(t)
        live.push("/battery", {"percentage": pct, "cell_voltage": cells}, t)
        live.push("/low", {"data": correct if robot == "correct" else slip}, t + 0.01)
    live.tick(10.0)
    record: dict[str, Any] = live.stop()
    run = recorded.check_recorded(checked, [node], cfg, ws, str(log), lambda w: None)
    return dict(record["nodes"][0]["counts"]), dict(run.results[0].counts)


def _decided(counts: dict[str, int]) -> tuple[int, int]:
    return counts.get("satisfied", 0), counts.get("violated", 0)


@pytest.mark.parametrize("case", sorted(CASES))
@pytest.mark.parametrize("form", sorted(BOUNDS))
def test_a_float32_boundary_reads_the_same_live_and_offline(tmp_path: Path, form: str, case: str) -> None:
    for robot, want in (("correct", (3, 0)), ("slip", (0, 3))):
        live, offline = _counts(tmp_path, BOUNDS[form], case, robot)
        assert _decided(live) == _decided(offline) == want, (robot, live, offline)


@pytest.mark.parametrize("case", sorted(CASES))
def test_without_the_named_constants_at_their_width_the_named_case_reads_otherwise(tmp_path: Path,
                                                                                  case: str) -> None:
    correct, offline = _counts(tmp_path, BOUNDS["named"], case, "correct", constants=False)
    slip, _ = _counts(tmp_path, BOUNDS["named"], case, "slip", constants=False)
    assert _decided(correct) == (0, 3) and _decided(slip) == (3, 0), (correct, slip)
    assert _decided(offline) == (3, 0)  # the offline check of the same log: the correct robot satisfied
    literal, _ = _counts(tmp_path, BOUNDS["inline"], case, "correct", constants=False)
    assert _decided(literal) == (3, 0)  # an inline literal was put at its width on either route
