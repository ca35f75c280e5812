"""``rclverify init DIR --from-ros PATH``: contract skeletons from the ament
test workspace; the workspace verifies at once and is grounded (docs/ros.md)."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from rclverify.cli.commands import main
from rclverify.tools.scaffold.skeleton import rcl_scalar

AMENT = Path(__file__).parent.parent / "data" / "ros" / "ament_ws"


def test_ros_field_types_to_rcl() -> None:
    assert [rcl_scalar(t) for t in ("float32", "float64", "int16", "uint8", "byte", "bool", "string", "string<=8",
                                    "geometry_msgs/msg/Point")] == \
        ["REAL", "REAL", "INTEGER", "NATURAL", "NATURAL", "BOOL", "STRING", "STRING", None]


def test_init_from_ros_writes_skeletons_that_verify(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    ws = tmp_path / "arm"
    assert main(["init", str(ws), "--from-ros", str(AMENT),
                 "--launch", str(AMENT / "src/arm_planner/launch/arm.launch.py")]) == 0
    assert (ws / "contracts/planner.rcl").read_text().split("node Planner {\n", 1)[1].split("  //")[0] == (
        "  inputs( jointStates : {} )\n"
        "  outputs( jointGoal : JointGoal )\n"
        "  topics( sensor_msgs/JointState joint_states matches(in.jointStates),\n"
        "          arm_interfaces/JointGoal joint_goal matches(out.jointGoal) )\n")
    assert "  JointGoal : STRING x REAL x REAL x REAL --> BOOL ;" in (ws / "contracts/ros_types.rcl").read_text()
    plan = (ws / "contracts/plan.yaml").read_text()
    assert "    - ros/arm_planner/launch/arm.launch.py\n" in plan
    assert "    joint_goal: [joint, position, tolerance.lower, tolerance.upper]\n" in plan
    assert (ws / "ros/arm_driver/src/driver.cpp").is_file()
    capsys.readouterr()
    monkeypatch.chdir(ws)
    assert main(["verify"]) == 0  # doit verify runs at once
    report = json.loads((ws / "reports/assurance.json").read_text())
    g = report["grounding"]
    assert g["counts"] == {"error": 0, "warning": 0}
    assert g["matched"] == {"Driver": "/arm/driver", "Planner": "/arm/planner"}
    # the placeholder guarantee is reported by the health check
    assert any("Guarantee 1 of Planner" in p and "constrains no output" in p for p in report["summary"]["problems"])
    argument = json.loads((ws / "reports/argument.json").read_text())
    elements = argument["elements"] if isinstance(argument, dict) and "elements" in argument else argument
    ctx = [e for e in elements if e["id"].startswith("C-ros")]
    assert len(ctx) == 1 and ctx[0]["text"].startswith(
        "Contracts grounded in the ROS software: arm_driver 2.0.0, arm_interfaces 2.0.1, arm_planner 2.0.1; ")
    top = next(e for e in elements if e["id"] == "G-system")
    assert ctx[0]["id"] in top["in_context_of"]
    sarif = json.loads((ws / "reports/assurance.sarif").read_text())
    assert not [r for r in sarif["runs"][0]["results"] if r["ruleId"].startswith("ROS-")]
    assert main(["init", str(ws), "--from-ros", str(AMENT)]) == 1  # never over an existing workspace
    os.chdir(tmp_path)


DRIVER = Path(__file__).parent.parent / "data" / "ros_corpus" / "driver"


def test_init_from_a_robot_driver_matches_its_endpoints_and_grounds_clean(tmp_path: Path) -> None:
    # A C++ driver whose endpoints are made by helper classes in other files of
    # the executable (namespaced handles, a parameter-given topic, a tf
    # broadcaster member, service servers), and a Python guard script.
    ws = tmp_path / "rover"
    assert main(["init", str(ws), "--from-ros", str(DRIVER),
                 "--launch", str(DRIVER / "src/rover_driver/launch/driver.launch")]) == 0
    driver = (ws / "contracts/rover_driver.rcl").read_text().split("node RoverDriver {\n", 1)[1].split("  //")[0]
    # names as the code writes them, each / written _ (the base handle's base/cmd_vel, imu/raw)
    assert driver == (
        "  inputs( baseCmdVel : Twist, baseWheelTicks : WheelTicks, resetOdometryReq : {}, enableMotorsReq : BOOL )\n"
        "  outputs( baseWheelTicks_ : WheelTicks, battery : BatteryState, imuRaw : Imu, odom : Odometry, "
        "resetOdometryRes : TriggerResponse, enableMotorsRes : SetBoolResponse )\n"
        "  topics( geometry_msgs/Twist base_cmd_vel matches(in.baseCmdVel),\n"
        "          rover_driver/WheelTicks base_wheel_ticks matches(in.baseWheelTicks),\n"
        "          rover_driver/WheelTicks base_wheel_ticks matches(out.baseWheelTicks_),\n"
        "          sensor_msgs/BatteryState battery matches(out.battery),\n"
        "          sensor_msgs/Imu imu_raw matches(out.imuRaw),\n"
        "          nav_msgs/Odometry odom matches(out.odom) )\n"
        "  services( std_srvs/Trigger reset_odometry serves(in.resetOdometryReq, out.resetOdometryRes),\n"
        "            std_srvs/SetBool enable_motors serves(in.enableMotorsReq, out.enableMotorsRes) )\n")
    # the tf broadcaster's /tf is the tf library's: listed apart with its reason (issue 65), not an output
    assert "//   publishes /tf (tf2_msgs/TFMessage) (" in (ws / "contracts/rover_driver.rcl").read_text()
    guard = (ws / "contracts/battery_guard.rcl").read_text()
    assert ("services( std_srvs/SetBool rover_driver_enable_motors calls(out.roverDriverEnableMotorsReq, "
            "in.roverDriverEnableMotorsRes) )") in guard  # written 'rover_driver/enable_motors'
    assert "    - /rover/base/cmd_vel\n" in (ws / "contracts/plan.yaml").read_text()
    # the first `doit verify`, as a new user runs it (its own process: doit's reporter owns the streams)
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).parents[2] / "src")}
    r = subprocess.run([sys.executable, "-m", "doit", "verify"], cwd=ws, env=env, capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    g = json.loads((ws / "reports/assurance.json").read_text())["grounding"]
    assert g["counts"] == {"error": 0, "warning": 0}
    assert g["matched"] == {"BatteryGuard": "/rover/battery_guard", "RoverDriver": "/rover/rover_driver"}
