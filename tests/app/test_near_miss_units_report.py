"""A near-miss threshold with a unit, converted to the unit of the margin it is compared with, on a
recorded run through ``rclverify verify`` (docs/monitors.md, "Near misses"; the threshold's reading:
tests/backends/test_near_miss_units.py).

Two brakes in metres on one run, each held with a smallest margin of 0.1 mm (0.0001 m): under
``0.5 mm`` (0.0005 m) BrakeA's margin is a near miss, named with the threshold in the margin's unit;
the control, BrakeB under ``0.05 mm``, is not named.  Read in the margin's own unit, as a bare number
is, 0.5 would have named both and 0.05 both as well.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from rclverify.cli.commands import main

BRAKE = """node Brake{x} {{
  inputs( dist : REAL [m] )
  outputs( reach : REAL [m] )
  topics( std_msgs/Float64 {y}_dist matches(in.dist), std_msgs/Float64 {y}_reach matches(out.reach) )
  assume( TRUE )
  guarantee( out.reach <= in.dist ) triggered by in.dist within 100 ms
}}
"""
PLAN = """name: brakes
contracts: [contracts/brake.rcl]
nodes:
  BrakeA:
    evidence:
      - {backend: monitors, traces: [runs/run.jsonl], mapping: contracts/mapping.yaml, near_miss: {value: 0.5 mm}}
  BrakeB:
    evidence:
      - {backend: monitors, traces: [runs/run.jsonl], mapping: contracts/mapping.yaml, near_miss: {value: 0.05 mm}}
"""
# each brake: dist 1.0 answered by reach 0.9999 (a margin of 0.1 mm), dist 2.0 by reach 1.5
RUN = sorted(({"topic": f"{x}_{t}", "time": s, "data": v} for x in "ab" for t, s, v in
              (("dist", 1.0, 1.0), ("reach", 1.01, 0.9999), ("dist", 2.0, 2.0), ("reach", 2.01, 1.5))),
             key=lambda r: float(r["time"]))  # type: ignore[arg-type]


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    root = tmp_path_factory.mktemp("nmu") / "ws"
    for d in ("contracts", "runs"):
        (root / d).mkdir(parents=True)
    (root / "contracts" / "brake.rcl").write_text(BRAKE.format(x="A", y="a") + BRAKE.format(x="B", y="b"))
    (root / "contracts" / "plan.yaml").write_text(PLAN)
    (root / "contracts" / "mapping.yaml").write_text("horizon: 1.0\n")
    (root / "runs" / "run.jsonl").write_text("".join(json.dumps(r) + "\n" for r in RUN))
    assert main(["verify", "-w", str(root)]) == 0
    return json.loads((Path(root) / "reports" / "assurance.json").read_text())  # type: ignore[no-any-return]


def test_the_threshold_is_converted_to_the_margins_unit(report: dict[str, Any]) -> None:
    rows = report["near_misses"]
    assert [(r["node"], r["kind"], r["unit"]) for r in rows] == [("BrakeA", "value", "m")]
    [row] = rows
    assert abs(row["margin"] - 0.0001) < 1e-12 and abs(row["threshold"] - 0.0005) < 1e-15
    assert row["atom"] == "out.reach <= in.dist"
    assert {o["node"]: o["status"] for o in report["obligations"]} == {"BrakeA": "discharged", "BrakeB": "discharged"}
