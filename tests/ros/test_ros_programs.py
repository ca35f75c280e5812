"""Every program accounted for (docs/ros.md, "Every program accounted for").

A self-written workspace, scanned once per module: a C++ package whose
executables and component are declared through the package's own CMake
``function()`` and a ``macro()`` of an included ``cmake/*.cmake`` file (their
source lists as arguments), one of
them a good node, one whose source file is missing, one whose node name
comes from ``argv``, one that constructs no node at all, and a component
whose constructor delegates the node name; a Python package whose
``setup.cfg`` declares two ``console_scripts``, one whose module is missing.
Each declared program is either nodes of the graph or an unaccounted
program with one located ``ROS-PROGRAM`` note at its declaration saying why;
every endpoint of a program that names no node has its own note.  Then the
commands: ``init --from-ros --strict`` refuses, ``init --from-ros`` writes a
workspace whose ``ros check`` passes and lists the unaccounted programs, and
``ros check --strict`` fails on them; with a launch file, a launched node of
a package that is not scanned is listed.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.cli.commands import main
from rclverify.ros.graph.scan import scan

CPP_PKG = ('<?xml version="1.0"?>\n<package format="3"><name>rig_bringup</name><version>0.1.0</version>'
           '<description>d</description><maintainer email="dev@example.org">a</maintainer><license>MIT</license>'
           '<buildtool_depend>ament_cmake</buildtool_depend><depend>rclcpp</depend><depend>std_msgs</depend>'
           '<export><build_type>ament_cmake</build_type></export></package>\n')
PY_PKG = CPP_PKG.replace("rig_bringup", "rig_tools").replace("ament_cmake", "ament_python")

CMAKE = """cmake_minimum_required(VERSION 3.8)
project(rig_bringup)
find_package(rclcpp REQUIRED)
function(rig_exe name)
  add_executable(${name} ${ARGN})
  ament_target_dependencies(${name} rclcpp std_msgs)
endfunction()
include(${CMAKE_CURRENT_SOURCE_DIR}/cmake/rig_component.cmake)
rig_exe(pan_tilt src/pan_tilt.cpp)
rig_exe(lost_exe src/not_there.cpp)
rig_exe(argv_named src/argv_named.cpp)
rig_exe(no_node src/no_node.cpp)
rig_component(gimbal "rig::Gimbal" src/gimbal.cpp)
"""
RIG_COMPONENT = """macro(rig_component lib cls)
  add_library(${lib} SHARED ${ARGN})
  rclcpp_components_register_node(${lib} PLUGIN ${cls} EXECUTABLE ${lib}_exec)
endmacro()
"""
PAN_TILT = """#include <rclcpp/rclcpp.hpp>
#include <std_msgs/msg/float64.hpp>
int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  auto node = rclcpp::Node::make_shared("pan_tilt");
  auto pan = node->create_publisher<std_msgs::msg::Float64>("pan", 10);
  rclcpp::spin(node);
}
"""
ARGV_NAMED = """#include <rclcpp/rclcpp.hpp>
#include <std_msgs/msg/string.hpp>
int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  auto node = std::make_shared<rclcpp::Node>(argv[1]);
  auto beat = node->create_publisher<std_msgs::msg::String>("heartbeat", 1);
  auto echo = node->create_subscription<std_msgs::msg::String>("echo", 1, [](std_msgs::msg::String::SharedPtr) {});
  rclcpp::spin(node);
}
"""
NO_NODE = """#include <cstdio>
int main() { std::puts("calibration table written"); return 0; }
"""
GIMBAL = """#include <rclcpp/rclcpp.hpp>
#include <std_msgs/msg/float64.hpp>
namespace rig
{
class Gimbal : public rclcpp::Node
{
public:
  explicit Gimbal(const rclcpp::NodeOptions & options) : Gimbal("gimbal", options) {}
  Gimbal(const std::string & name, const rclcpp::NodeOptions & options) : Node(name, options)
  {
    tilt_ = create_subscription<std_msgs::msg::Float64>("tilt", 10, [](std_msgs::msg::Float64::SharedPtr) {});
  }
private:
  rclcpp::Subscription<std_msgs::msg::Float64>::SharedPtr tilt_;
};
}  // namespace rig
#include <rclcpp_components/register_node_macro.hpp>
RCLCPP_COMPONENTS_REGISTER_NODE(rig::Gimbal)
"""
SETUP_CFG = """[develop]
script_dir=$base/lib/rig_tools
[options.entry_points]
console_scripts =
    beacon = rig_tools.beacon:main
    phantom = rig_tools.phantom:main
"""
BEACON = """import rclpy
from rclpy.node import Node
from std_msgs.msg import String


class Beacon(Node):
    def __init__(self):
        super().__init__('beacon')
        self.pub = self.create_publisher(String, 'beacon', 10)


def main():
    rclpy.init()
    rclpy.spin(Beacon())
"""
LAUNCH = """<launch>
  <node pkg="rig_bringup" exec="pan_tilt" name="pan_tilt"/>
  <node pkg="absent_driver" exec="driver_node" name="driver"/>
</launch>
"""


@pytest.fixture(scope="module")
def code(tmp_path_factory) -> Path:  # type: ignore[no-untyped-def]
    root = tmp_path_factory.mktemp("programs")
    files = {
        "rig_bringup/package.xml": CPP_PKG, "rig_bringup/CMakeLists.txt": CMAKE,
        "rig_bringup/cmake/rig_component.cmake": RIG_COMPONENT,
        "rig_bringup/src/pan_tilt.cpp": PAN_TILT, "rig_bringup/src/argv_named.cpp": ARGV_NAMED,
        "rig_bringup/src/no_node.cpp": NO_NODE, "rig_bringup/src/gimbal.cpp": GIMBAL,
        "rig_bringup/launch/rig.launch.xml": LAUNCH,
        "rig_tools/package.xml": PY_PKG, "rig_tools/setup.cfg": SETUP_CFG,
        "rig_tools/setup.py": "from setuptools import setup\nsetup(name='rig_tools', packages=['rig_tools'])\n",
        "rig_tools/resource/rig_tools": "", "rig_tools/rig_tools/__init__.py": "",
        "rig_tools/rig_tools/beacon.py": BEACON,
    }
    for rel, text in files.items():
        (root / "src" / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / "src" / rel).write_text(text)
    return root


@pytest.fixture(scope="module")
def graph(code: Path):  # type: ignore[no-untyped-def]
    return scan([code / "src"], base=code).graph


def _program(graph, name: str) -> dict:  # type: ignore[no-untyped-def,type-arg]
    got = [p for p in graph.programs if p["name"] == name]
    assert len(got) == 1, graph.programs
    return got[0]


def test_programs_declared_in_cmake_functions_and_macros_are_nodes(graph) -> None:  # type: ignore[no-untyped-def]
    assert _program(graph, "pan_tilt")["nodes"] == ["/pan_tilt"]
    gimbal = _program(graph, "rig::Gimbal")
    assert gimbal["kind"] == "component" and gimbal["nodes"] == ["/gimbal"] and gimbal["unaccounted"] is None
    assert {(e.topic, e.msg_type) for e in graph.nodes["/gimbal"].subscribes} == {("/tilt", "std_msgs/msg/Float64")}
    assert _program(graph, "beacon")["nodes"] == ["/beacon"]


def test_each_unaccounted_program_is_one_located_note_saying_why(graph) -> None:  # type: ignore[no-untyped-def]
    notes = {n.src.file.rsplit("/", 2)[-2] + "/" + n.src.file.rsplit("/", 1)[-1] + f":{n.src.line}": n.message
             for n in graph.notes if n.code == "ROS-PROGRAM"}
    assert set(notes) == {"rig_bringup/CMakeLists.txt:10", "rig_bringup/CMakeLists.txt:11",
                          "rig_bringup/CMakeLists.txt:12", "rig_tools/setup.cfg:6"}, notes
    assert "executable lost_exe" in notes["rig_bringup/CMakeLists.txt:10"]
    assert "its sources (src/not_there.cpp) are not in the package" in notes["rig_bringup/CMakeLists.txt:10"]
    assert "its node name is not read statically (at " in notes["rig_bringup/CMakeLists.txt:11"]
    assert "no node is constructed in the code it runs (" in notes["rig_bringup/CMakeLists.txt:12"]
    assert "entry point phantom" in notes["rig_tools/setup.cfg:6"] and "rig_tools/phantom.py" in \
        notes["rig_tools/setup.cfg:6"]
    assert len(graph.unaccounted()) == 4


def test_every_endpoint_of_a_nameless_program_has_its_own_note(graph) -> None:  # type: ignore[no-untyped-def]
    at = {n.src.line for n in graph.notes if n.src.file.endswith("argv_named.cpp")}
    assert {6, 7, 8} <= at  # the node name (argv), and each endpoint, never only the first
    assert not any(e.topic in ("/heartbeat", "/echo") for n in graph.nodes.values()
                   for e in n.publishes + n.subscribes)


def test_a_launched_node_of_a_package_not_scanned_is_listed(code: Path) -> None:
    g = scan([code / "src"], [code / "src/rig_bringup/launch/rig.launch.xml"], base=code).graph
    listed = g.unaccounted()
    assert [(p["kind"], p["name"], p["declared"]["line"]) for p in listed] == [("launch node", "driver_node", 3)]
    assert "/pan_tilt" in g.nodes  # a program no launch file starts is no part of that deployment


def test_strict_commands_fail_on_unaccounted_programs(code: Path, tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    refused = tmp_path / "refused"
    assert main(["init", str(refused), "--from-ros", str(code / "src"), "--strict"]) == 1
    err = capsys.readouterr().err
    assert err.count(": unaccounted: ") == 4 and "4 declared program(s) are no node of the graph" in err
    assert not refused.exists() or not any(refused.iterdir())
    ws = tmp_path / "ws"
    assert main(["init", str(ws), "--from-ros", str(code / "src")]) == 0
    capsys.readouterr()
    assert main(["ros", "check", "-w", str(ws)]) == 0
    out = capsys.readouterr().out
    assert "grounding: 0 error(s)" in out and out.count(": unaccounted: ") == 4
    assert "programs: 4 of 7 declared are no node of the graph" in out
    assert main(["ros", "check", "-w", str(ws), "--strict"]) == 1
    assert "4 declared program(s) are no node of the graph" in capsys.readouterr().err


def test_the_programs_list_matches_the_graph_schema(graph) -> None:  # type: ignore[no-untyped-def]
    import json

    import jsonschema
    schema = json.loads((Path(__file__).parents[2] / "docs" / "ros-graph.schema.json").read_text())
    data = graph.to_json()
    jsonschema.validate(data, schema)
    assert {p["kind"] for p in data["programs"]} == {"executable", "component", "entry point"}


def test_a_test_driver_built_only_with_build_testing_is_no_robot_program(tmp_path: Path) -> None:
    """An executable declared inside ``if(BUILD_TESTING)`` (a test driver, built for ``colcon test`` only) is
    accounted for as a test executable, never an unaccounted program; the same one outside the block is."""
    from rclverify.ros.graph.accounting import in_testing_block
    cmake = tmp_path / "CMakeLists.txt"
    cmake.write_text("project(p)\nadd_executable(tool src/tool.cpp)\nif(BUILD_TESTING)\n"
                     "  # a driver of the checks\n  add_executable(driver test/driver.cpp)\nendif()\n"
                     "if(NOT BUILD_TESTING)\n  add_executable(other src/other.cpp)\nendif()\n")
    assert [in_testing_block(cmake, n) for n in (2, 5, 8)] == [False, True, False]
