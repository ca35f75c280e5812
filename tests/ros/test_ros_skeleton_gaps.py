"""What skeletons and the scan still got wrong (issue 87's last points), on a small
self-written package of the same shape: a node publishing a message of two
``builtin_interfaces/Duration`` fields, one of a fixed-size array, one with fields
no RCL value holds (a header, arrays of variable length, a message of an absent
package), a topic with a namespaced name (``/robot/arm/cmd``), and types of three
packages neither scanned nor installed, each used another way (a subscription and
two fields of the package's own interfaces; a service; an action).

* every field a skeleton leaves out is listed in its comment (path, type, why) and
  ``init --from-ros`` prints one line per node that has any;
* ``topics()`` carry the whole name as written, each ``/`` written ``_``
  (``robot_arm_cmd``), the form the grounding matches; two names that read alike
  are said;
* an absent interface package is one located warning naming it and all it leaves
  untyped, wherever its types appear; the endpoints keep their type names; a type
  a present package lacks is no absent package;
* the skeleton passes ``rclverify check`` and ``ros check`` (exit 0, warnings);
  ``ros check --strict`` and ``init --from-ros --strict`` fail on the absent
  packages, every time.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.cli.commands import main
from rclverify.ros.extract.interfaces import ABSENT, field_path
from rclverify.ros.graph.scan import ScanResult, scan

PKG = ('<?xml version="1.0"?>\n<package format="3"><name>{name}</name><version>0.1.0</version>'
       '<description>d</description><maintainer email="dev@example.org">a</maintainer><license>MIT</license>'
       '<buildtool_depend>ament_cmake</buildtool_depend><depend>rclcpp</depend><depend>std_msgs</depend>'
       '<member_of_group>rosidl_interface_packages</member_of_group>'
       '<export><build_type>ament_cmake</build_type></export></package>\n')
CMAKE = """cmake_minimum_required(VERSION 3.8)
project(borer)
rosidl_generate_interfaces(${PROJECT_NAME} "msg/Pace.msg" "msg/Gains.msg" "msg/Core.msg" "srv/Aim.srv")
add_executable(borer src/borer.cpp)
add_executable(level src/level.cpp)
"""
BORER = """#include <rclcpp/rclcpp.hpp>
#include <rclcpp_action/rclcpp_action.hpp>
#include <borer/msg/pace.hpp>
#include <borer/msg/gains.hpp>
#include <borer/msg/core.hpp>
#include <borer/srv/aim.hpp>
#include <far_msgs/msg/blip.hpp>
#include <gone_srvs/srv/poke.hpp>
#include <hole_actions/action/dig.hpp>
#include <std_msgs/msg/float64.hpp>
int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  auto node = rclcpp::Node::make_shared("borer");
  auto pace = node->create_publisher<borer::msg::Pace>("pace", 10);
  auto gains = node->create_publisher<borer::msg::Gains>("gains", 10);
  auto core = node->create_publisher<borer::msg::Core>("core", 10);
  auto cmd = node->create_publisher<std_msgs::msg::Float64>("/robot/arm/cmd", 10);
  auto blip = node->create_subscription<far_msgs::msg::Blip>("blip", 10, [](far_msgs::msg::Blip::SharedPtr) {});
  auto poke = node->create_service<gone_srvs::srv::Poke>("poke", nullptr);
  auto aim = node->create_service<borer::srv::Aim>("aim", nullptr);
  auto dig = rclcpp_action::create_client<hole_actions::action::Dig>(node, "dig");
  rclcpp::spin(node);
}
"""
LEVEL = """#include <rclcpp/rclcpp.hpp>
#include <std_msgs/msg/float64.hpp>
int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  auto node = rclcpp::Node::make_shared("level");
  auto a = node->create_publisher<std_msgs::msg::Float64>("left/level", 10);
  auto b = node->create_publisher<std_msgs::msg::Float64>("left_level", 10);
  rclcpp::spin(node);
}
"""
FILES = {"package.xml": PKG.format(name="borer"), "CMakeLists.txt": CMAKE, "src/borer.cpp": BORER,
         "src/level.cpp": LEVEL,
         "msg/Pace.msg": "builtin_interfaces/Duration period\nbuiltin_interfaces/Duration jitter\n",
         "msg/Gains.msg": "float64[4] coeffs\n",
         "msg/Core.msg": "std_msgs/Header header\nfloat64 depth\nfloat64[] samples\nstring[] tags\n"
                         "far_msgs/Blip blip\n",
         "srv/Aim.srv": "far_msgs/Blip target\nfloat64 range\n---\nbool ok\n"}
ABSENT_CODE = "ROS-INTERFACE-ABSENT"


def _write(root: Path, files: dict[str, str]) -> None:
    for rel, text in files.items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(text)


@pytest.fixture(scope="module")
def code(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("gaps") / "code"
    _write(root / "borer", FILES)
    return root


@pytest.fixture(scope="module")
def scanned(code: Path) -> ScanResult:
    return scan([code], base=code.parent)


def test_one_located_warning_per_absent_package_naming_what_it_leaves_untyped(scanned: ScanResult) -> None:
    notes = {n.message.split()[2]: n for n in scanned.graph.notes if n.code == ABSENT_CODE}
    assert sorted(notes) == ["far_msgs", "gone_srvs", "hole_actions"], scanned.graph.notes
    far = notes["far_msgs"]
    assert (far.src.file, far.src.line, far.severity) == ("code/borer/src/borer.cpp", 19, "warning")
    assert far.message.endswith("untyped: topic /blip (far_msgs/Blip) of /borer; field blip of borer/Core "
                                "(far_msgs/Blip); field target of borer/Aim_Request (far_msgs/Blip)"), far.message
    assert "service /poke (gone_srvs/Poke) of /borer" in notes["gone_srvs"].message
    assert (notes["hole_actions"].src.line, "action /dig (hole_actions/Dig) of /borer") == (
        22, notes["hole_actions"].message.split("untyped: ")[1])
    # one warning: the fields of the package's types are not noted again one by one
    assert not [n for n in scanned.graph.notes if n.code == "ROS-TYPE"], scanned.graph.notes
    # the endpoints keep their type names
    node = scanned.graph.nodes["/borer"]
    assert {(e.topic, e.msg_type) for e in node.subscribes} == {("/blip", "far_msgs/msg/Blip")}
    assert ("/poke", "gone_srvs/srv/Poke") in {(e.topic, e.msg_type) for e in node.service_servers}
    assert {(e.topic, e.msg_type) for e in node.action_clients} == {("/dig", "hole_actions/action/Dig")}
    # known by name only: no field, said so by a field path, and no entry of the graph's types
    blip = scanned.table.get("far_msgs/msg/Blip")
    assert blip is not None and blip.origin == ABSENT and blip.fields == []
    assert "its interface package far_msgs is in neither" in str(field_path(scanned.table, "far_msgs/msg/Blip",
                                                                            "x")[1])
    assert scanned.table.get("gone_srvs/srv/Poke_Request") is not None
    assert not [t for t in scanned.graph.types if t.startswith(("far_msgs/", "gone_srvs/", "hole_actions/"))]


def test_a_type_a_present_package_lacks_is_no_absent_package(tmp_path: Path) -> None:
    typo = BORER.replace("std_msgs::msg::Float64", "std_msgs::msg::Flaot64")
    _write(tmp_path / "ws/borer", {**FILES, "src/borer.cpp": typo, "msg/Gains.msg": "std_msgs/Nope coeffs\n"})
    res = scan([tmp_path / "ws"], base=tmp_path)
    assert res.table.get("std_msgs/msg/Flaot64") is None  # unknown: the grounding says so of a contract's type
    said = [(n.code, n.src.file, n.src.line) for n in res.graph.notes if "std_msgs" in n.message]
    assert said == [("ROS-TYPE", "ws/borer/msg/Gains.msg", 1)], res.graph.notes
    # without the installed packages read, nothing can be said absent: fields are noted as before
    bare = scan([tmp_path / "ws"], base=tmp_path, standard=False)
    assert not [n for n in bare.graph.notes if n.code == ABSENT_CODE]
    assert ("ROS-TYPE", "ws/borer/msg/Core.msg", 5) in {(n.code, n.src.file, n.src.line) for n in bare.graph.notes}


def test_skeletons_list_the_fields_they_leave_out_and_keep_whole_names(code: Path, tmp_path: Path,
                                                                       monkeypatch: pytest.MonkeyPatch,
                                                                       capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(code.parent)
    ws = tmp_path / "ws"
    assert main(["init", str(ws), "--from-ros", "code"]) == 0
    err = capsys.readouterr().err
    assert [ln for ln in err.splitlines() if "leave out" in ln] == [
        "contracts/borer.rcl: its RCL types leave out 5 message field(s), each listed in its comment with why"]
    borer = (ws / "contracts/borer.rcl").read_text()
    listed = borer.split("(field path, ROS type: why):\n", 1)[1].split("\n\n", 1)[0]
    assert listed == (
        "//   borer/Core (out.core):\n"
        "//     header (std_msgs/Header): the message's header (time stamp, frame id), which a skeleton does not read\n"
        "//     samples (float64[]): an array of variable length: no single RCL value holds it\n"
        "//     tags (string[]): an array of variable length: no single RCL value holds it\n"
        "//     blip (far_msgs/Blip): its interface package far_msgs is in neither the scanned tree nor an installed "
        "ROS: its fields are unknown\n"
        "//   borer/Aim_Request (in.aimReq):\n"
        "//     target (far_msgs/Blip): its interface package far_msgs is in neither the scanned tree nor an "
        "installed ROS: its fields are unknown"), listed
    assert "  std_msgs/Float64 robot_arm_cmd matches(out.robotArmCmd)" in borer.replace("topics(", "")
    assert "core : REAL" in borer and "aimReq : REAL" in borer
    for var, what in (("blip", "subscribes to /blip"), ("pokeReq", "serves /poke"), ("digGoal", "calls action /dig")):
        assert f"{var} : {{}}" in borer
        assert f"//   {what} (" in borer and "kept with its type name, untyped" in borer
    plan = (ws / "contracts/plan.yaml").read_text()
    assert "    robot_arm_cmd: [data]\n" in plan and "    core: [depth]\n" in plan, plan
    types = (ws / "contracts/ros_types.rcl").read_text()
    assert "Pace : INTEGER x NATURAL x INTEGER x NATURAL --> BOOL" in types and "Gains : REAL x REAL" in types
    level = (ws / "contracts/level.rcl").read_text()
    assert "//   /left_level and /left/level both read `left_level` (an RCL name holds no /" in level, level


def test_the_skeleton_checks_and_strict_fails_on_absent_packages(code: Path, tmp_path: Path,
                                                                 monkeypatch: pytest.MonkeyPatch,
                                                                 capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(code.parent)
    assert main(["init", str(tmp_path / "refused"), "--from-ros", "code", "--strict"]) == 1
    assert not (tmp_path / "refused").exists()
    assert "code: error: 3 interface package(s) are in neither the scanned tree nor an installed ROS (--strict); " \
           "nothing written" in capsys.readouterr().err
    ws = tmp_path / "ws"
    assert main(["init", str(ws), "--from-ros", "code"]) == 0
    monkeypatch.chdir(ws)
    capsys.readouterr()
    assert main(["check"] + sorted(str(p) for p in (ws / "contracts").glob("*.rcl"))) == 0
    assert main(["ros", "check"]) == 0
    out = capsys.readouterr().out
    absent = [ln for ln in out.splitlines() if f"({ABSENT_CODE})" in ln]
    assert [ln.split(": warning: interface package ")[0] for ln in absent] == [
        "ros/borer/src/borer.cpp:19:15", "ros/borer/src/borer.cpp:20:15", "ros/borer/src/borer.cpp:22:14"], out
    assert "grounding: 0 error(s), 4 warning(s)" in out  # the three packages and /left/level undocumented
    for _ in range(2):  # the second run finds the graph unchanged: still a failure
        assert main(["ros", "check", "--strict"]) == 1
        assert "ros check --strict: 3 interface package(s) are in neither the scanned tree nor an installed ROS" \
               in capsys.readouterr().err
    # the endpoint kept its type name: a contract naming another type of the package is an error
    contract = ws / "contracts/borer.rcl"
    contract.write_text(contract.read_text().replace("far_msgs/Blip blip", "far_msgs/Blap blip"))
    assert main(["ros", "check"]) == 1
    assert "topic 'blip' carries far_msgs/Blip in the code, the contract says far_msgs/Blap" in capsys.readouterr().out
    # a variable given a real type on the absent type: its fields cannot be checked, which the package's one
    # warning says; never an error here and a warning elsewhere
    text = contract.read_text().replace("far_msgs/Blap blip", "far_msgs/Blip blip")
    assert "blip : {}" in text, text
    contract.write_text(text.replace("blip : {}", "blip : REAL", 1))
    assert main(["ros", "check"]) == 0, capsys.readouterr().out
    assert "grounding: 0 error(s)" in capsys.readouterr().out
