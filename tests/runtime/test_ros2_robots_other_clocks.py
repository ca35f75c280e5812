"""Robots whose header stamps run in another clock than their source times, live (docs/semantics.md,
"Event time", its "Clocks"; docs/monitors.md, "Generated robots"): generated robots of real rclpy nodes
on Fast DDS (bench/_robot_run.py through tests/_ros2.py's ``robot_run``), each judged live, on its log
and on its MCAP bag, verdict by verdict.

* **``use_sim_time`` through the DDS source** (tests/bench/test_robot_generator.py hears one through the
  rclpy source): seed 1 of 6 nodes on a ``/clock``, every node ``use_sim_time``, header stamps on the
  simulated clock, unstamped messages and calls on their source times: never red (no violation, no false
  deadline, no false declaration), live = log = bag, each stamped sensor's writer named as in another
  clock; the control, seed 4 with its seeded defect on a ``/clock`` too: red at its seeded node only;
* **a driver off the wall clock, through each source**: seed 1 with every sensor stamping 2 s behind (the
  DDS source) or 2 s ahead (the rclpy source) of its publication: never red, live = log = bag, each stamped
  sensor named; the control, seed 4 with its seeded defect and its drivers 2 s ahead: red at its seeded
  node only.
"""
from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import pytest
from _ros2 import REPO, robot_run

sys.path.insert(0, str(REPO / "bench"))  # the generator and its runner
import robot_generator as gen  # noqa: E402

pytestmark = [pytest.mark.live, pytest.mark.slow]


def _red(c: Any) -> int:
    return int(c["violated"] + c["deadline false"] + c["declaration false"])


def _green_with_stamped_writers_named(res: Any) -> None:
    """A correct robot's run: no finding, every node judged and never red, each stamped sensor's writer named
    in another clock."""
    assert not res["errors"] and res["findings"] == [], (res["errors"], res["findings"])
    for node, c in res["live"].items():
        assert c["satisfied"] > 0 and _red(c) == 0, (node, c)
    stamped = [n["topic"] for n in res["spec"]["nodes"] if n["kind"] == "sensor" and gen.SENSORS[n["sensor_kind"]][3]]
    assert stamped and all(any(c.startswith(t + ":") and "another clock" in c for c in res["other_clocks"])
                           for t in stamped), res["other_clocks"]


def _red_at_its_node_only(res: Any) -> None:
    """A seeded robot's run: red at the seeded node, at no other."""
    victim = next(n["name"] for n in res["spec"]["nodes"] if n.get("defect"))
    assert _red(res["live"][victim]) > 0, res["live"][victim]
    assert all(_red(c) == 0 for node, c in res["live"].items() if node != victim), res["live"]


def test_a_correct_robot_on_a_simulated_clock_heard_through_dds(tmp_path: Path) -> None:
    res = robot_run(tmp_path, 1, 6, 4.0, False, kinds=tuple(gen.SENSORS), source="dds", sim_clock=True)
    assert res["clock"] is not None and res["clock"]["rate"] != 1.0, res["clock"]
    _green_with_stamped_writers_named(res)


def test_control_a_seeded_defect_on_a_simulated_clock_is_red_at_its_node_only(tmp_path: Path) -> None:
    res = robot_run(tmp_path, 4, 6, 4.0, True, kinds=tuple(k for k in gen.SENSORS if k != "range"), source="dds",
                    sim_clock=True)
    assert res["clock"] is not None, res["clock"]
    _red_at_its_node_only(res)


@pytest.mark.parametrize("offset, source", [(-2.0, "dds"), (2.0, "rclpy")], ids=["2 s behind, dds", "2 s ahead, rclpy"])
def test_a_correct_robot_beside_a_driver_off_the_wall_clock(tmp_path: Path, offset: float, source: str) -> None:
    res = robot_run(tmp_path, 1, 6, 4.0, False, kinds=tuple(gen.SENSORS), source=source, driver_offset_s=offset)
    _green_with_stamped_writers_named(res)


def test_control_a_seeded_defect_beside_a_driver_two_seconds_ahead_is_red_at_its_node_only(tmp_path: Path) -> None:
    res = robot_run(tmp_path, 4, 6, 4.0, True, kinds=tuple(k for k in gen.SENSORS if k != "range"), source="dds",
                    driver_offset_s=2.0)
    _red_at_its_node_only(res)
