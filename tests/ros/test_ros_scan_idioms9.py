"""The idioms of issue 87, each in a small self-written package of the same shape
(never code of the repositories it was seen in):

* a node class template reached through a ``using`` alias
  (``using Tracker = TrackerNode<Kalman>; std::make_shared<Tracker>(options)``);
* the node name given in ``NodeOptions``' arguments and read back in the
  constructor (``options.arguments({"name"})`` set in place, then
  ``Node(options.arguments()[0], options)``; also ``.at(0)``), or as a remap
  (``NodeOptions().arguments({"--ros-args", "-r", "__node:=n", "-r", "__ns:=/x"})``);
  a ``Node(name, options)`` whose options are a parameter is no namespace note;
* a delegating constructor carrying the node name;
* names built at the call site: ``name + "/cmd"`` with ``name`` a local literal,
  a helper returning a name built from literals, a local map of literals
  iterated (``kv.second``, ``[key, topic]``) and a vector of literals;
* a class template's endpoint type taken per instantiation
  (``Caller<Trigger>(this, "halt")`` gives ``Trigger`` only, ``Caller<SetBool>``
  ``SetBool`` only), through a derived template's base initialiser too, and
  for members initialised in a constructor (``Client<Trigger> halt_;``,
  ``: halt_(this, "halt")``) and a function template's explicit arguments
  (``listen<String>(this, "words")``); a deduced argument keeps its name, its
  type unread and said.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.ros.extract.interfaces import ABSENT
from rclverify.ros.graph.scan import scan

PKG = ('<?xml version="1.0"?>\n<package format="3"><name>{name}</name><version>0.1.0</version>'
       '<description>d</description><maintainer email="dev@example.org">a</maintainer><license>MIT</license>'
       '<buildtool_depend>ament_cmake</buildtool_depend><depend>rclcpp</depend><depend>std_msgs</depend>'
       '<export><build_type>ament_cmake</build_type></export></package>\n')

TRACKER_HPP = """#pragma once
#include <rclcpp/rclcpp.hpp>
#include <std_msgs/msg/float64.hpp>
namespace track
{
struct Kalman {};
struct Particle {};
template<typename Estimator>
class TrackerNode : public rclcpp::Node
{
public:
  explicit TrackerNode(const rclcpp::NodeOptions & options)
  : Node(options.arguments()[0], options)
  {
    out_ = create_publisher<std_msgs::msg::Float64>("estimate", 10);
  }
private:
  rclcpp::Publisher<std_msgs::msg::Float64>::SharedPtr out_;
};
using KalmanTracker = TrackerNode<Kalman>;
}  // namespace track
"""
KALMAN_MAIN = """#include "track/tracker.hpp"
int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  rclcpp::NodeOptions options;
  options.arguments({"kalman_tracker"});
  auto node = std::make_shared<track::KalmanTracker>(options);
  rclcpp::spin(node);
}
"""
PARTICLE_MAIN = """#include "track/tracker.hpp"
using Tracker = track::TrackerNode<track::Particle>;
int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  auto options = rclcpp::NodeOptions().arguments({"particle_tracker"}).use_intra_process_comms(true);
  rclcpp::spin(std::make_shared<Tracker>(options));
}
"""
REMAP_MAIN = """#include <rclcpp/rclcpp.hpp>
#include <std_msgs/msg/string.hpp>
class Probe : public rclcpp::Node
{
public:
  explicit Probe(const rclcpp::NodeOptions & options) : Node("probe", options)
  {
    pub_ = create_publisher<std_msgs::msg::String>("reading", 5);
  }
  rclcpp::Publisher<std_msgs::msg::String>::SharedPtr pub_;
};
std::shared_ptr<rclcpp::Node> make_helper(const rclcpp::NodeOptions & options)
{
  return std::make_shared<rclcpp::Node>("probe_helper", options);
}
int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  auto options = rclcpp::NodeOptions().arguments({"--ros-args", "-r", "__node:=left_probe", "-r", "__ns:=/arm"});
  auto probe = std::make_shared<Probe>(options);
  auto helper = make_helper(rclcpp::NodeOptions());
  rclcpp::spin(probe);
}
"""
AT_MAIN = """#include <rclcpp/rclcpp.hpp>
#include <std_msgs/msg/bool.hpp>
class Bumper : public rclcpp::Node
{
public:
  explicit Bumper(const rclcpp::NodeOptions & options) : Node(options.arguments().at(0), options)
  {
    hit_ = create_publisher<std_msgs::msg::Bool>("hit", 1);
  }
  rclcpp::Publisher<std_msgs::msg::Bool>::SharedPtr hit_;
};
int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  rclcpp::spin(std::make_shared<Bumper>(rclcpp::NodeOptions().arguments({"front_bumper"})));
}
"""
NAMES_MAIN = """#include <map>
#include <vector>
#include <rclcpp/rclcpp.hpp>
#include <std_msgs/msg/string.hpp>
#include <std_srvs/srv/trigger.hpp>
#include <std_srvs/srv/set_bool.hpp>
std::string status_of(const std::string & part) { return part + "/status"; }
template<typename ServiceT>
class ClientBase
{
public:
  ClientBase(rclcpp::Node * node, const std::string & name) { client_ = node->create_client<ServiceT>(name); }
  typename rclcpp::Client<ServiceT>::SharedPtr client_;
};
template<typename ServiceT>
class Caller : public ClientBase<ServiceT>
{
public:
  Caller(rclcpp::Node * node, const std::string & name) : ClientBase<ServiceT>(node, name) {}
};
class Arm : public rclcpp::Node
{
public:
  explicit Arm(const rclcpp::NodeOptions & options) : Arm("arm", options) {}
  Arm(const std::string & node_name, const rclcpp::NodeOptions & options) : Node(node_name, options)
  {
    std::string joint = "elbow";
    cmd_ = create_publisher<std_msgs::msg::String>(joint + "/cmd", 10);
    status_ = create_publisher<std_msgs::msg::String>(status_of("wrist"), 10);
    std::map<std::string, std::string> fingers{{"index", "finger_a"}, {"thumb", "finger_b"}};
    for (const auto & kv : fingers) {
      pubs_.push_back(create_publisher<std_msgs::msg::String>(kv.second, 10));
    }
    for (const auto & [part, topic] : fingers) {
      pubs_.push_back(create_publisher<std_msgs::msg::String>(topic + "/force", 10));
    }
    std::vector<std::string> cams{"cam_left", "cam_right"};
    for (const auto & cam : cams) {
      pubs_.push_back(create_publisher<std_msgs::msg::String>(cam, 1));
    }
    halt_ = std::make_shared<Caller<std_srvs::srv::Trigger>>(this, "halt");
    grip_ = std::make_shared<Caller<std_srvs::srv::SetBool>>(this, "grip");
  }
  rclcpp::Publisher<std_msgs::msg::String>::SharedPtr cmd_, status_;
  std::vector<rclcpp::Publisher<std_msgs::msg::String>::SharedPtr> pubs_;
  std::shared_ptr<Caller<std_srvs::srv::Trigger>> halt_;
  std::shared_ptr<Caller<std_srvs::srv::SetBool>> grip_;
};
int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  rclcpp::spin(std::make_shared<Arm>(rclcpp::NodeOptions()));
}
"""
TEMPLATES_MAIN = """#include <rclcpp/rclcpp.hpp>
#include <std_msgs/msg/string.hpp>
#include <std_msgs/msg/bool.hpp>
#include <std_srvs/srv/trigger.hpp>
#include <std_srvs/srv/set_bool.hpp>
template<typename MessageT>
void listen(rclcpp::Node * node, const std::string & topic)
{
  static auto s = node->create_subscription<MessageT>(topic, 1, [](typename MessageT::SharedPtr) {});
}
template<typename M>
void announce(rclcpp::Node * node, const std::string & topic, const M &)
{
  static auto p = node->create_publisher<M>(topic, 1);
}
template<typename ServiceT>
class Client
{
public:
  Client(rclcpp::Node * node, const std::string & name) { c_ = node->create_client<ServiceT>(name); }
  typename rclcpp::Client<ServiceT>::SharedPtr c_;
};
class Gripper : public rclcpp::Node
{
public:
  Gripper() : Node("gripper"), halt_(this, "halt"), grip_(this, "grip")
  {
    listen<std_msgs::msg::String>(this, "words");
    listen<std_msgs::msg::Bool>(this, "flags");
    announce<std_msgs::msg::String>(this, "tight", std_msgs::msg::String());
    announce(this, "loose", std_msgs::msg::Bool());
  }
  Client<std_srvs::srv::Trigger> halt_;
  Client<std_srvs::srv::SetBool> grip_;
};
int main(int argc, char ** argv) { rclcpp::init(argc, argv); rclcpp::spin(std::make_shared<Gripper>()); }
"""
CMAKE = """cmake_minimum_required(VERSION 3.8)
project(track)
find_package(rclcpp REQUIRED)
foreach(exe kalman_main particle_main remap_main at_main names_main templates_main)
  add_executable(${exe} src/${exe}.cpp)
endforeach()
"""


@pytest.fixture(scope="module")
def graph(tmp_path_factory):  # type: ignore[no-untyped-def]
    root = tmp_path_factory.mktemp("idioms9")
    files = {"package.xml": PKG.format(name="track"), "CMakeLists.txt": CMAKE,
             "include/track/tracker.hpp": TRACKER_HPP, "src/kalman_main.cpp": KALMAN_MAIN,
             "src/particle_main.cpp": PARTICLE_MAIN, "src/remap_main.cpp": REMAP_MAIN,
             "src/at_main.cpp": AT_MAIN, "src/names_main.cpp": NAMES_MAIN,
             "src/templates_main.cpp": TEMPLATES_MAIN}
    for rel, text in files.items():
        (root / "track" / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / "track" / rel).write_text(text)
    return scan([root], base=root).graph


def _edges(graph, node: str) -> set[tuple[str, str, str | None]]:  # type: ignore[no-untyped-def]
    n = graph.nodes[node]
    return {(k, e.topic, e.msg_type) for k in ("pub", "sub", "service_servers", "service_clients")
            for e in n.edges_of(k)}


def test_a_node_class_template_through_a_using_alias_named_by_its_options(graph) -> None:  # type: ignore[no-untyped-def]
    assert _edges(graph, "/kalman_tracker") == {("pub", "/estimate", "std_msgs/msg/Float64")}
    assert _edges(graph, "/particle_tracker") == {("pub", "/estimate", "std_msgs/msg/Float64")}
    assert graph.nodes["/kalman_tracker"].executable == "kalman_main"


def test_node_options_remaps_rename_the_node_and_are_no_namespace(graph) -> None:  # type: ignore[no-untyped-def]
    assert _edges(graph, "/arm/left_probe") == {("pub", "/arm/reading", "std_msgs/msg/String")}
    assert "/probe" not in graph.nodes
    assert not [n for n in graph.notes if "namespace of node" in n.message], graph.notes
    assert _edges(graph, "/front_bumper") == {("pub", "/hit", "std_msgs/msg/Bool")}


def test_a_delegating_constructor_and_names_built_at_the_call_site(graph) -> None:  # type: ignore[no-untyped-def]
    s = "std_msgs/msg/String"
    assert _edges(graph, "/arm") == {
        ("pub", "/elbow/cmd", s), ("pub", "/wrist/status", s), ("pub", "/finger_a", s), ("pub", "/finger_b", s),
        ("pub", "/finger_a/force", s), ("pub", "/finger_b/force", s), ("pub", "/cam_left", s),
        ("pub", "/cam_right", s),
        ("service_clients", "/halt", "std_srvs/srv/Trigger"), ("service_clients", "/grip", "std_srvs/srv/SetBool")}
    assert not [n for n in graph.notes if n.src.file.endswith("names_main.cpp")], graph.notes


def test_every_program_of_the_package_is_its_node(graph) -> None:  # type: ignore[no-untyped-def]
    assert not graph.unaccounted()
    assert sorted(n for p in graph.programs for n in p["nodes"]) == [
        "/arm", "/arm/left_probe", "/front_bumper", "/gripper", "/kalman_tracker", "/particle_tracker",
        "/probe_helper"]
    assert "/probe_helper" in graph.nodes  # Node(name, options) made in a helper main calls


def test_one_type_per_instantiation_of_members_and_function_templates(graph) -> None:  # type: ignore[no-untyped-def]
    assert _edges(graph, "/gripper") == {
        ("sub", "/words", "std_msgs/msg/String"), ("sub", "/flags", "std_msgs/msg/Bool"),
        ("pub", "/tight", "std_msgs/msg/String"), ("pub", "/loose", None),
        ("service_clients", "/halt", "std_srvs/srv/Trigger"), ("service_clients", "/grip", "std_srvs/srv/SetBool")}
    said = [(n.src.line, n.message) for n in graph.notes if n.src.file.endswith("templates_main.cpp")]
    assert said == [(14, "type of publisher topic 'loose' not resolved statically")], said  # the deduced one


HALT_NODE = """#include <rclcpp/rclcpp.hpp>
#include <rig_core/srv/halt.hpp>
int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  auto node = rclcpp::Node::make_shared("halter");
  auto halt = node->create_client<rig_core::srv::Halt>("halt");
  rclcpp::spin(node);
}
"""


def test_interfaces_of_a_sourced_ros2_come_from_its_ament_index(tmp_path: Path,
                                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    ws, prefix = tmp_path / "ws", tmp_path / "install"
    files = {ws / "halter/package.xml": PKG.format(name="halter"),
             ws / "halter/CMakeLists.txt": "project(halter)\nadd_executable(halter src/halter.cpp)\n",
             ws / "halter/src/halter.cpp": HALT_NODE,
             prefix / "share/ament_index/resource_index/rosidl_interfaces/rig_core": "srv/Halt.idl\nsrv/Halt.srv\n",
             prefix / "share/rig_core/srv/Halt.srv": "bool hard\n---\nbool done\nstring why\n"}
    for f, text in files.items():
        f.parent.mkdir(parents=True, exist_ok=True)
        f.write_text(text)
    monkeypatch.delenv("AMENT_PREFIX_PATH", raising=False)
    unknown = scan([ws], base=tmp_path)
    absent = unknown.table.get("rig_core/srv/Halt_Request")  # known by name only: its package is absent
    assert absent is not None and absent.origin == ABSENT and absent.fields == []
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(prefix))
    got = scan([ws], base=tmp_path)
    assert [n for n, _d in got.table.get("rig_core/srv/Halt_Response").fields] == ["done", "why"]
    assert {(e.topic, e.msg_type) for e in got.graph.nodes["/halter"].service_clients} == {
        ("/halt", "rig_core/srv/Halt")}


def test_the_core_interfaces_of_the_installed_ros2_are_known(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    prefix = Path(__file__).resolve().parents[2] / ".venv-ros2"
    if not (prefix / "share/ament_index/resource_index/rosidl_interfaces/rcl_interfaces").is_file():
        pytest.skip("the ROS 2 wheels (.venv-ros2, scripts/setup.sh --tests) are not installed")
    (tmp_path / "p").mkdir()
    (tmp_path / "p/package.xml").write_text(PKG.format(name="p"))
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(prefix))
    t = scan([tmp_path], base=tmp_path).table
    for name in ("rcl_interfaces/srv/SetParameters_Request", "lifecycle_msgs/srv/ChangeState_Request",
                 "action_msgs/srv/CancelGoal_Response"):
        assert t.get(name) is not None, name
