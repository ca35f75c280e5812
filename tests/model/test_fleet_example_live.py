"""examples/fleet_robots monitored live (issue 110): the example's real rclpy nodes (nodes/robots.py,
two robots and the fleet's speed limit in one process) under ``rclverify monitor --live --ros2 --source
rclpy`` on the example's own plan, each instance judged on its own topics.  As written every instance
is green; with ``--slip`` (``/r2``'s guard reading ``/r1/battery/level``) ``/r2``'s guard drives on
while its own battery is low, red at ``Guard_r2`` only.  The robots publish once every topic has the
monitor's reader and each guard has heard its level before the command it answers
(nodes/robots.py), so the verdicts do not depend on the machine's load."""
from __future__ import annotations

import json
import signal
import subprocess
from pathlib import Path
from typing import Any, Iterator

import pytest

from _procs import stop, wait_for, wait_logged
from _ros2 import rclverify, ros2_env, ros2_python

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "fleet_robots"
STEPS = 60  # /r2's battery is low (below 0.2) at steps 36 to 45


def _answered(log: list[dict[str, Any]]) -> bool:
    """Each guard's answer to the last round's command is in the monitor's log."""
    return all(sum(x.get("topic") == f"{r}/cmd_vel" for x in log) >= STEPS for r in ("r1", "r2"))


def _run(tmp: Path, slip: bool) -> dict[str, Any]:
    py = ros2_python()  # skips, with the reason, without a ROS 2 Python
    env = ros2_env(tmp)
    nodes = monitor = None
    try:
        monitor = rclverify(["monitor", "-w", str(EXAMPLE), "--live", "--ros2", "--status", "0", "--duration", "120",
                             "--horizon", "1", "--source", "rclpy", "--ros2-python", str(py),
                             "--evidence", str(tmp / "live.json")], env, tmp, tmp / "monitor.out")
        with open(tmp / "robots.log", "wb") as fh:
            nodes = subprocess.Popen([str(py), str(EXAMPLE / "nodes/robots.py"), "--steps", str(STEPS), "--readers", "1",
                                      *(["--slip"] if slip else [])], cwd=tmp, env=env, stdout=fh,
                                     stderr=subprocess.STDOUT, start_new_session=True)
        wait_for(tmp / "robots.log", "done", 100)
        wait_logged(tmp / "monitor_live.jsonl", _answered, 30)  # the last commands' answers heard, whatever the load
        stop(monitor, signal.SIGINT)
        out = (tmp / "monitor.out").read_text()
        assert (tmp / "live.json").exists(), out + (tmp / "robots.log").read_text()
        return {"out": out, "nodes": {n["node"]: n for n in json.loads((tmp / "live.json").read_text())["nodes"]}}
    finally:
        for p in (nodes, monitor):
            if p is not None:
                stop(p, signal.SIGINT)


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, dict[str, Any]]]:
    yield {name: _run(tmp_path_factory.mktemp(name), name == "slip") for name in ("fleet", "slip")}


NODES = {"SpeedLimit", "Planner_r1", "Planner_r2", "Battery_r1", "Battery_r2", "Guard_r1", "Guard_r2"}


def test_the_fleet_as_written_is_green_at_every_instance(runs: dict[str, Any]) -> None:
    run = runs["fleet"]
    assert set(run["nodes"]) == NODES, run["out"]
    for name, node in run["nodes"].items():
        assert node["status"] == "discharged" and node["counts"]["satisfied"] >= STEPS - 1, (name, node["counts"])


def test_r2s_guard_reading_r1s_battery_is_red_at_its_instance_only(runs: dict[str, Any]) -> None:
    nodes = runs["slip"]["nodes"]
    guard = nodes["Guard_r2"]
    assert guard["status"] == "failed" and guard["counts"]["violated"] >= 5, guard["counts"]
    first = guard["first_violation"]
    assert first["guarantee"] == 2 and float(first["values"]["in.level"]) < 0.2 and first["values"]["out.cmd_vel"] == "1.0"
    for name in NODES - {"Guard_r2"}:
        assert nodes[name]["status"] == "discharged", (name, nodes[name]["counts"])
