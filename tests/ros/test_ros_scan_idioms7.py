"""Real ROS 2 code, round four (issue 65): values followed, never a node invented.

Small self-written packages, one construct each, scanned once per module:

* a node name that is empty (a constructor parameter's default ``""``) names
  no node: before, the node ``/`` appeared and ``~/board`` became ``/board``;
* a name passed from ``main`` through a delegating constructor into
  ``rclcpp::Node(name, ns, options)``;
* a user's own method named ``create_publisher(node, "t")`` is followed into
  its body (``topic + "_out"``), not read as rclcpp's; with its body not in the
  workspace it is one located note and no edge;
* a dependent call ``node->template create_service<ServiceT>(...)`` in a class
  template, its type from the template argument of the construction
  (``make_unique<Server<T>>``), also through a template base's initialiser;
* a constructor overload nobody calls makes no endpoint; an explicit
  instantiation ``template class Server<T>;`` is no syntax error;
* a Python module's client cache reached through imported functions: each
  caller's name and service type (a parameter of the helper) read together,
  an argparse name one located note;
* a parameter read into a variable that already holds a value
  (``std::string t = "scan"; get_parameter("t", t);``): that value is the
  parameter's default, never "no default".
"""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.ros.graph.scan import scan

PKG = '<?xml version="1.0"?>\n<package format="3"><name>{name}</name><version>0.1.0</version><description>d</description>\n<maintainer email="dev@example.org">a</maintainer><license>MIT</license>\n<buildtool_depend>ament_cmake</buildtool_depend><depend>rclcpp</depend><depend>std_msgs</depend><depend>std_srvs</depend>\n<export><build_type>ament_cmake</build_type></export></package>\n'
CMAKE = "cmake_minimum_required(VERSION 3.8)\nproject({name})\nfind_package(rclcpp REQUIRED)\n{exes}"

PANEL = '#include <rclcpp/rclcpp.hpp>\n#include <std_msgs/msg/string.hpp>\n#include <std_srvs/srv/trigger.hpp>\n\nclass Panel : public rclcpp::Node\n{\npublic:\n  Panel(const std::string & name, const std::string & ns, const rclcpp::NodeOptions & options)\n  : rclcpp::Node(name, ns, options)\n  {\n    status_ = create_publisher<std_msgs::msg::String>("~/status", 10);\n    reset_ = create_service<std_srvs::srv::Trigger>("reset", [](auto, auto) {});\n  }\n  explicit Panel(const std::string & name)\n  : Panel(name, "", rclcpp::NodeOptions())\n  {\n  }\n  rclcpp::Publisher<std_msgs::msg::String>::SharedPtr status_;\n  rclcpp::Service<std_srvs::srv::Trigger>::SharedPtr reset_;\n};\n\nint main(int argc, char ** argv)\n{\n  rclcpp::init(argc, argv);\n  std::string node_name = "operator_panel";\n  auto node = std::make_shared<Panel>(node_name);\n  rclcpp::spin(node);\n  return 0;\n}\n'
EMPTY = '#include <rclcpp/rclcpp.hpp>\n#include <std_msgs/msg/string.hpp>\n\nclass Board : public rclcpp::Node\n{\npublic:\n  explicit Board(const rclcpp::NodeOptions & options, const std::string & name = "")\n  : rclcpp::Node(name, options)\n  {\n    pub_ = create_publisher<std_msgs::msg::String>("~/board", 10);\n  }\n  rclcpp::Publisher<std_msgs::msg::String>::SharedPtr pub_;\n};\n\nint main(int argc, char ** argv)\n{\n  rclcpp::init(argc, argv);\n  rclcpp::spin(std::make_shared<Board>(rclcpp::NodeOptions()));\n  return 0;\n}\n'
HELPERS = '#pragma once\n#include <rclcpp/rclcpp.hpp>\n#include <std_msgs/msg/string.hpp>\n#include <std_srvs/srv/trigger.hpp>\n#include <std_srvs/srv/set_bool.hpp>\n\nnamespace dock\n{\nstruct Bus\n{\n  rclcpp::Publisher<std_msgs::msg::String>::SharedPtr create_publisher(\n    rclcpp::Node * node, const std::string & topic)\n  {\n    return node->create_publisher<std_msgs::msg::String>(topic + "_out", 10);\n  }\n};\n\ntemplate<typename ServiceT>\nclass ClientBase\n{\npublic:\n  ClientBase(rclcpp::Node * node, const std::string & name)\n  {\n    client_ = node->template create_client<ServiceT>(name);\n  }\n  typename rclcpp::Client<ServiceT>::SharedPtr client_;\n};\n\ntemplate<typename ServiceT>\nclass Caller : public ClientBase<ServiceT>\n{\npublic:\n  Caller(rclcpp::Node * node, const std::string & name)\n  : ClientBase<ServiceT>(node, name)\n  {\n  }\n};\n\ntemplate<typename ServiceT>\nclass Server\n{\npublic:\n  template<typename NodeT>\n  Server(NodeT node, const std::string & name)\n  {\n    server_ = node->template create_service<ServiceT>(name, [](auto, auto) {});\n  }\n  Server(rclcpp::Node * node, const std::string & name, int unused)\n  {\n    server_ = node->template create_service<ServiceT>(name + "_never", [](auto, auto) {});\n  }\n  typename rclcpp::Service<ServiceT>::SharedPtr server_;\n};\n\ntemplate class Server<std_srvs::srv::SetBool>;\n}  // namespace dock\n'
DOCK = '#include <dock/helpers.hpp>\n\nclass DockNode : public rclcpp::Node\n{\npublic:\n  DockNode()\n  : rclcpp::Node("dock_node")\n  {\n    alerts_ = bus_.create_publisher(this, "alerts");\n    undock_ = std::make_unique<dock::Caller<std_srvs::srv::Trigger>>(this, "undock");\n    enable_ = std::make_unique<dock::Server<std_srvs::srv::SetBool>>(this, "enable");\n  }\n  dock::Bus bus_;\n  rclcpp::Publisher<std_msgs::msg::String>::SharedPtr alerts_;\n  std::unique_ptr<dock::Caller<std_srvs::srv::Trigger>> undock_;\n  std::unique_ptr<dock::Server<std_srvs::srv::SetBool>> enable_;\n};\n\nint main(int argc, char ** argv)\n{\n  rclcpp::init(argc, argv);\n  rclcpp::spin(std::make_shared<DockNode>());\n  return 0;\n}\n'
# two constructor overloads told apart by their number of arguments, the last parameter
# of each defaulted with a value the scan does not read (rclcpp::SystemDefaultsQoS())
WATCH = """class Watch
{
public:
  template<typename CallbackT, typename OtherT>
  Watch(rclcpp::Node * node, const std::string & name, CallbackT && cb, OtherT && other, int depth,
    const rclcpp::QoS & qos = rclcpp::SystemDefaultsQoS())
  {
    sub_ = node->create_subscription<std_msgs::msg::String>(name + "_pair", qos, cb);
  }
  template<typename CallbackT>
  Watch(rclcpp::Node * node, const std::string & name, CallbackT && cb,
    const rclcpp::QoS & qos = rclcpp::SystemDefaultsQoS())
  {
    sub_ = node->create_subscription<std_msgs::msg::String>(name, qos, cb);
  }
  rclcpp::Subscription<std_msgs::msg::String>::SharedPtr sub_;
};

"""
HELPERS = HELPERS.replace("template class Server", WATCH + "template class Server")
DOCK = DOCK.replace("  dock::Bus bus_;\n", "  dock::Bus bus_;\n  std::unique_ptr<dock::Watch> watch_;\n").replace(
    "    enable_ = std::make_unique", "    watch_ = std::make_unique<dock::Watch>(this, \"watched\", "
    "[](std_msgs::msg::String::SharedPtr) {});\n    enable_ = std::make_unique")
OPAQUE = """#include <rclcpp/rclcpp.hpp>
#include <vendor/bus.hpp>

class Relay : public rclcpp::Node
{
public:
  Relay()
  : rclcpp::Node("relay")
  {
    out_ = bus_.create_publisher(this, "relayed");
  }
  vendor::Bus bus_;
  vendor::Bus::Handle out_;
};

int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  rclcpp::spin(std::make_shared<Relay>());
  return 0;
}
"""
FILTER = '#include <rclcpp/rclcpp.hpp>\n#include <sensor_msgs/msg/laser_scan.hpp>\n\nclass Filter : public rclcpp::Node\n{\npublic:\n  Filter()\n  : rclcpp::Node("scan_filter")\n  {\n    std::string in_topic = "scan";\n    declare_parameter("in_topic", rclcpp::ParameterValue(in_topic));\n    get_parameter("in_topic", in_topic);\n    std::string out_topic;\n    out_topic = "scan_filtered";\n    this->get_parameter("out_topic", out_topic);\n    sub_ = create_subscription<sensor_msgs::msg::LaserScan>(in_topic, 10, [](sensor_msgs::msg::LaserScan::SharedPtr) {});\n    pub_ = create_publisher<sensor_msgs::msg::LaserScan>(out_topic, 10);\n  }\n  rclcpp::Subscription<sensor_msgs::msg::LaserScan>::SharedPtr sub_;\n  rclcpp::Publisher<sensor_msgs::msg::LaserScan>::SharedPtr pub_;\n};\n\nint main(int argc, char ** argv)\n{\n  rclcpp::init(argc, argv);\n  rclcpp::spin(std::make_shared<Filter>());\n  return 0;\n}\n'

PY_SERVICES = "from std_srvs.srv import Trigger, SetBool\n\n_clients = {}\n\n\ndef client(node, srv_type, name):\n    key = (srv_type, name)\n    if key not in _clients:\n        _clients[key] = node.create_client(srv_type, name)\n    return _clients[key]\n\n\ndef trigger(node, name):\n    return client(node, Trigger, name).call_async(Trigger.Request())\n\n\ndef enable(node, on):\n    req = SetBool.Request()\n    req.data = on\n    return client(node, SetBool, 'enable_drive').call_async(req)\n"
PY_PANEL = "import argparse\n\nimport rclpy\nfrom rclpy.node import Node\n\nfrom hmi_py.services import enable, trigger\n\n\ndef main():\n    parser = argparse.ArgumentParser()\n    parser.add_argument('--service', default='dock')\n    args, _ = parser.parse_known_args()\n    rclpy.init()\n    node = Node('panel')\n    trigger(node, args.service)\n    trigger(node, 'undock')\n    enable(node, True)\n    rclpy.spin(node)\n"
PY_SETUP = "from setuptools import setup\nsetup(name='hmi_py', packages=['hmi_py'],\n      entry_points={'console_scripts': ['panel = hmi_py.panel:main']})\n"


def _package(root: Path, name: str, files: dict[str, str]) -> None:
    d = root / "src" / name
    for rel, text in files.items():
        (d / rel).parent.mkdir(parents=True, exist_ok=True)
        (d / rel).write_text(text)
    exes = "".join(f"add_executable({Path(r).stem} {r})\n" for r in files if r.endswith(".cpp"))
    (d / "package.xml").write_text(PKG.format(name=name))
    (d / "CMakeLists.txt").write_text(CMAKE.format(name=name, exes=exes))


@pytest.fixture(scope="module")
def graph(tmp_path_factory):  # type: ignore[no-untyped-def]
    root = tmp_path_factory.mktemp("idioms7")
    _package(root, "hmi", {"src/panel.cpp": PANEL, "src/empty.cpp": EMPTY})
    _package(root, "dock", {"include/dock/helpers.hpp": HELPERS, "src/dock_node.cpp": DOCK})
    _package(root, "relay", {"src/relay.cpp": OPAQUE})
    _package(root, "lidar", {"src/filter.cpp": FILTER})
    py = root / "src" / "hmi_py"
    for rel, text in {"package.xml": PKG.format(name="hmi_py").replace("ament_cmake", "ament_python"),
                      "setup.py": PY_SETUP, "resource/hmi_py": "", "hmi_py/__init__.py": "",
                      "hmi_py/services.py": PY_SERVICES, "hmi_py/panel.py": PY_PANEL}.items():
        (py / rel).parent.mkdir(parents=True, exist_ok=True)
        (py / rel).write_text(text)
    return scan([root], [], base=root).graph


def _edges(g, node: str) -> set[tuple[str, str, str | None]]:  # type: ignore[no-untyped-def]
    n = g.nodes[node]
    return {(r, e.topic, e.msg_type) for r in ("pub", "sub", "service_servers", "service_clients")
            for e in n.edges_of(r)}


def _notes(g, file: str) -> list[str]:  # type: ignore[no-untyped-def]
    return [f"{n.src.line}: {n.message}" for n in g.notes if n.src.file.endswith(file)]


def test_an_empty_node_name_names_no_node(graph) -> None:  # type: ignore[no-untyped-def]
    assert "/" not in graph.nodes and not any(n.endswith("/") for n in graph.nodes)
    assert not any(e.topic == "/board" for n in graph.nodes.values() for e in n.edges_of("pub"))
    assert "8: node name is empty: not resolved statically; its endpoints are not in the graph" in _notes(
        graph, "empty.cpp")


def test_a_name_through_a_delegating_constructor(graph) -> None:  # type: ignore[no-untyped-def]
    assert _edges(graph, "/operator_panel") == {
        ("pub", "/operator_panel/status", "std_msgs/msg/String"),
        ("service_servers", "/reset", "std_srvs/srv/Trigger")}


def test_users_create_publisher_is_followed_into_its_body(graph) -> None:  # type: ignore[no-untyped-def]
    got = _edges(graph, "/dock_node")
    assert ("pub", "/alerts_out", "std_msgs/msg/String") in got
    assert not any(t in ("/alerts", "/this") for _r, t, _ty in got)
    assert not any("'this'" in m for m in _notes(graph, "dock_node.cpp"))


def test_users_create_publisher_without_its_body_is_a_note_not_an_edge(graph) -> None:  # type: ignore[no-untyped-def]
    assert _edges(graph, "/relay") == set()
    assert _notes(graph, "relay.cpp") == [
        "10: bus_.create_publisher(...) takes the node first, so it is no rclcpp method, and its body is not in "
        "the workspace: its endpoints are not read"]


def test_template_types_and_dependent_calls(graph) -> None:  # type: ignore[no-untyped-def]
    got = _edges(graph, "/dock_node")
    assert ("service_servers", "/enable", "std_srvs/srv/SetBool") in got  # ->template create_service<ServiceT>
    assert ("service_clients", "/undock", "std_srvs/srv/Trigger") in got  # through a template base's constructor


def test_an_overload_nobody_calls_makes_no_endpoint(graph) -> None:  # type: ignore[no-untyped-def]
    assert not any(t == "/enable_never" for _r, t, _ty in _edges(graph, "/dock_node"))
    # three arguments: the overload whose last parameter has a default (its value unread) runs, not the other
    assert _edges(graph, "/dock_node") == {
        ("pub", "/alerts_out", "std_msgs/msg/String"), ("service_servers", "/enable", "std_srvs/srv/SetBool"),
        ("service_clients", "/undock", "std_srvs/srv/Trigger"), ("sub", "/watched", "std_msgs/msg/String")}


def test_an_explicit_instantiation_is_no_syntax_error(graph) -> None:  # type: ignore[no-untyped-def]
    assert _notes(graph, "helpers.hpp") == []


def test_python_client_cache_through_imported_functions(graph) -> None:  # type: ignore[no-untyped-def]
    assert _edges(graph, "/panel") == {
        ("service_clients", "/undock", "std_srvs/srv/Trigger"),
        ("service_clients", "/enable_drive", "std_srvs/srv/SetBool")}
    assert _notes(graph, "hmi_py/services.py") == [
        "9: service client name is 'name', from argparse option --service: not resolved statically"]


def test_a_value_held_before_a_parameter_read_is_its_default(graph) -> None:  # type: ignore[no-untyped-def]
    n = graph.nodes["/scan_filter"]
    got = {(r, e.topic, e.param) for r in ("pub", "sub") for e in n.edges_of(r)}
    assert got == {("sub", "/scan", "/scan_filter/in_topic"), ("pub", "/scan_filtered", "/scan_filter/out_topic")}
    assert _notes(graph, "filter.cpp") == []
