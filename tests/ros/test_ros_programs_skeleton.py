"""Skeletons of a package whose messages nothing typed before (issue 87): a
message of two ``builtin_interfaces/Duration`` fields and one of a fixed-size
array are RCL predicates over their fields (``budget.sec``, ``kp[0]`` ...),
never ``{}``; a service request wrapping a ``PoseWithCovarianceStamped`` keeps
its pose fields; the skeletons' comments name the sources relative to the
scanned tree, never by an absolute path; the new workspace checks and ``ros
check --strict`` passes (nothing unaccounted, no grounding error).
"""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.cli.commands import main

PKG = ('<?xml version="1.0"?>\n<package format="3"><name>pacer</name><version>0.1.0</version>'
       '<description>d</description><maintainer email="dev@example.org">a</maintainer><license>MIT</license>'
       '<buildtool_depend>ament_cmake</buildtool_depend><depend>rclcpp</depend><depend>geometry_msgs</depend>'
       '<member_of_group>rosidl_interface_packages</member_of_group>'
       '<export><build_type>ament_cmake</build_type></export></package>\n')
CMAKE = """cmake_minimum_required(VERSION 3.8)
project(pacer)
rosidl_generate_interfaces(${PROJECT_NAME} "msg/Timing.msg" "msg/Gains.msg" "srv/Relocate.srv")
add_executable(pacer src/pacer.cpp)
"""
NODE = """#include <rclcpp/rclcpp.hpp>
#include <pacer/msg/timing.hpp>
#include <pacer/msg/gains.hpp>
#include <pacer/srv/relocate.hpp>
int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  auto node = rclcpp::Node::make_shared("pacer");
  auto timing = node->create_publisher<pacer::msg::Timing>("timing", 10);
  auto gains = node->create_publisher<pacer::msg::Gains>("gains", 10);
  auto relocate = node->create_service<pacer::srv::Relocate>("relocate", nullptr);
  rclcpp::spin(node);
}
"""
FILES = {"package.xml": PKG, "CMakeLists.txt": CMAKE, "src/pacer.cpp": NODE,
         "msg/Timing.msg": "builtin_interfaces/Duration budget\nbuiltin_interfaces/Duration slack\n",
         "msg/Gains.msg": "float64[3] kp\n",
         "srv/Relocate.srv": "geometry_msgs/PoseWithCovarianceStamped pose\n---\nbool accepted\n"}


def test_present_types_are_typed_and_sources_are_shown_relative(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                                capsys: pytest.CaptureFixture[str]) -> None:
    code = tmp_path / "code"
    for rel, text in FILES.items():
        (code / "pacer" / rel).parent.mkdir(parents=True, exist_ok=True)
        (code / "pacer" / rel).write_text(text)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)  # the scanned tree is outside the current directory
    ws = tmp_path / "ws"
    assert main(["init", str(ws), "--from-ros", str(code), "--strict"]) == 0
    types = (ws / "contracts/ros_types.rcl").read_text()
    assert "Timing : INTEGER x NATURAL x INTEGER x NATURAL --> BOOL" in types, types
    assert "Gains : REAL x REAL x REAL --> BOOL" in types, types
    contract = (ws / "contracts/pacer.rcl").read_text()
    assert str(tmp_path) not in contract and "code/pacer/src/pacer.cpp" in contract, contract
    assert "relocateReq : {}" not in contract, contract
    plan = (ws / "contracts/plan.yaml").read_text()
    assert "budget.sec" in plan and "kp[2]" in plan, plan
    monkeypatch.chdir(ws)
    capsys.readouterr()
    assert main(["check"] + sorted(str(p) for p in (ws / "contracts").glob("*.rcl"))) == 0
    assert main(["ros", "check", "-w", str(ws), "--strict"]) == 0
    assert "grounding: 0 error(s)" in capsys.readouterr().out
