"""The last silent misses of issue 108 (docs/ros.md, docs/grounding.md), each
with its control:

* a component container (``ComposableNodeContainer``, XML ``node_container``,
  a ``Node`` running ``rclcpp_components``' ``component_container*``) is no
  node of the graph and is said at its line (``ROS-CONTAINER``); one whose
  condition does not hold is not started and not said;
* Nav2's ``LaunchConfigAsBool('x')`` (``nav2_common.launch``) is ``True``
  when the argument is ``true``/``1``/``yes``/``on`` (any case), else
  ``False``: a condition on it is evaluated, an include argument of it has a
  value;
* an endpoint a helper function makes, called at several sites each giving
  the name, is one edge per name at the helper's creating call, each naming
  the call (``via``) whose argument gives it; a helper called once names none;
* a ``tf2_ros::TransformListener`` member declared in a header and
  initialised with a buffer alone in the constructor of another file is on
  tf2's own node (given the node too: on the class's node).

Packages are written into a temporary directory and read by the scan.
"""
from __future__ import annotations

from pathlib import Path

import pytest
from test_ros_launch_run import CMAKE, LISTENER, PKG, PY_HEAD, TALKER, _write

from rclverify.ros.extract.model import Graph
from rclverify.ros.graph import summary
from rclverify.ros.graph.scan import scan

HEAD = PY_HEAD + ("from launch.conditions import IfCondition\n"
                  "from launch_ros.actions import ComposableNodeContainer\n"
                  "from launch_ros.descriptions import ComposableNode\n"
                  "from nav2_common.launch import LaunchConfigAsBool\n\n\n")

LEDS_HPP = """#include <rclcpp/rclcpp.hpp>
#include <std_msgs/msg/int32.hpp>
class Led
{
public:
  void listen(rclcpp::Node * nh, std::string topic)
  {
    sub_ = nh->create_subscription<std_msgs::msg::Int32>(
      topic, 10, std::bind(&Led::on, this, std::placeholders::_1));
  }
  void on(const std_msgs::msg::Int32::SharedPtr) {}
  rclcpp::Subscription<std_msgs::msg::Int32>::SharedPtr sub_;
};
"""
LEDS_CPP = """#include "leds.hpp"
class Panel : public rclcpp::Node
{
public:
  Panel() : Node("panel")
  {
    power_.listen(this, "led/power");
    wifi_.listen(this, "led/wifi");
  }
  Led power_;
  Led wifi_;
};
int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  rclcpp::spin(std::make_shared<Panel>());
}
"""
LOOKER_HPP = """#include <rclcpp/rclcpp.hpp>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
class Looker : public rclcpp::Node
{
public:
  Looker();
  tf2_ros::Buffer buf_;
  tf2_ros::TransformListener tf_;
};
"""
LOOKER_CPP = """#include "looker.hpp"
Looker::Looker()
: Node("looker"),
  buf_(get_clock()),
  tf_(buf_)
{
}
int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  rclcpp::spin(std::make_shared<Looker>());
}
"""


@pytest.fixture(scope="module")
def ws(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("launchlast")
    _write(root / "ws" / "demo", {
        "package.xml": PKG.format(name="demo", tool="ament_cmake", export=""),
        "CMakeLists.txt": CMAKE.format(name="demo") + "add_executable(talker src/talker.cpp)\n"
                                                      "add_executable(listener src/listener.cpp)\n"
                                                      "add_executable(panel src/leds.cpp)\n"
                                                      "add_executable(looker src/looker.cpp)\n",
        "src/talker.cpp": TALKER, "src/listener.cpp": LISTENER, "src/leds.hpp": LEDS_HPP, "src/leds.cpp": LEDS_CPP,
        "src/looker.hpp": LOOKER_HPP, "src/looker.cpp": LOOKER_CPP})
    return root


def _py(ws: Path, name: str, body: str) -> Path:
    f = ws / "ws" / "demo" / "launch" / name
    f.parent.mkdir(exist_ok=True)
    f.write_text(HEAD + "def generate_launch_description():\n    return LaunchDescription([\n"
                 + "".join(f"        {line}\n" for line in body.strip().splitlines()) + "    ])\n")
    return f


def _graph(ws: Path, lf: Path | None) -> Graph:
    return scan([ws / "ws"], [lf] if lf else [], base=ws, standard=False).graph


def _said(g: Graph) -> list[str]:
    return [str(n) for n in g.notes]


# -- component containers --------------------------------------------------------

CONTAINER = ("ComposableNodeContainer(name='cams', namespace='', package='rclcpp_components',\n"
             "    executable='component_container', composable_node_descriptions=[]{cond}),\n"
             "Node(package='rclcpp_components', executable='component_container_mt', name='mt'{cond}),\n"
             "Node(package='demo', executable='talker'),")


def test_a_component_container_is_said_at_its_line(ws: Path) -> None:
    g = _graph(ws, _py(ws, "containers.launch.py", CONTAINER.format(cond="")))
    assert sorted(g.nodes) == ["/talker"]
    said = "is started here: a container is no node of the graph (its endpoints are rclcpp_components'); " \
           "its components are"
    assert _said(g) == [f"ws/demo/launch/containers.launch.py:17:9: warning: component container '/cams' {said}",
                        f"ws/demo/launch/containers.launch.py:19:9: warning: component container '/mt' {said}"]
    assert {summary.cause_of(n.code, n.message).key for n in g.notes} == {"containers"}
    # control: under a condition that does not hold, launch starts no container and nothing is said
    g = _graph(ws, _py(ws, "containers.launch.py", CONTAINER.format(cond=", condition=IfCondition('false')")))
    assert sorted(g.nodes) == ["/talker"] and _said(g) == []


def test_an_xml_node_container_is_said_and_its_components_are_nodes(ws: Path) -> None:
    f = ws / "ws" / "demo" / "launch" / "cams.launch.xml"
    f.parent.mkdir(exist_ok=True)
    f.write_text('<launch>\n  <node_container pkg="rclcpp_components" exec="component_container" name="box" '
                 'namespace="rig">\n    <composable_node pkg="demo" plugin="demo::Missing" name="cam"/>\n'
                 '  </node_container>\n</launch>\n')
    said = _said(_graph(ws, f))
    assert said[0] == ("ws/demo/launch/cams.launch.xml:2:1: warning: component container '/rig/box' is started "
                       "here: a container is no node of the graph (its endpoints are rclcpp_components'); its "
                       "components are")
    assert len(said) == 2 and "demo::Missing" in said[1]  # the component is read (its class is not found: said)


# -- Nav2's LaunchConfigAsBool ----------------------------------------------------

@pytest.mark.parametrize("given, started", [("True", True), ("yes", True), (" ON ", True), ("1", True),
                                            ("false", False), ("no", False), ("", False)])
def test_launch_config_as_bool_is_evaluated(ws: Path, given: str, started: bool) -> None:
    lf = _py(ws, "asbool.launch.py", f"DeclareLaunchArgument('use_ear', default_value='{given}'),\n"
                                     "Node(package='demo', executable='talker'),\n"
                                     "Node(package='demo', executable='listener',\n"
                                     "     condition=IfCondition(LaunchConfigAsBool('use_ear'))),")
    g = _graph(ws, lf)
    assert sorted(g.nodes) == (["/listener", "/talker"] if started else ["/talker"]) and _said(g) == []


def test_launch_config_as_bool_of_an_argument_without_a_value_is_said(ws: Path) -> None:
    # control: no value for the argument: the condition is not evaluated, said at its line
    lf = _py(ws, "asbool.launch.py", "Node(package='demo', executable='listener',\n"
                                     "     condition=IfCondition(LaunchConfigAsBool('use_ear'))),")
    said = _said(_graph(ws, lf))
    assert len(said) == 1 and said[0].startswith("ws/demo/launch/asbool.launch.py:") and "use_ear" in said[0]


# -- a helper called at several sites ---------------------------------------------

def test_an_endpoint_of_a_helper_names_each_call_site(ws: Path) -> None:
    g = _graph(ws, None)
    subs = {(e.topic, f"{e.src.file}:{e.src.line}", f"{e.via.file}:{e.via.line}" if e.via else None)
            for e in g.nodes["/panel"].subscribes}
    assert subs == {("/led/power", "ws/demo/src/leds.hpp:8", "ws/demo/src/leds.cpp:7"),
                    ("/led/wifi", "ws/demo/src/leds.hpp:8", "ws/demo/src/leds.cpp:8")}
    assert g.nodes["/panel"].subscribes[0].to_json()["via"]["line"] in (7, 8)
    # control: the helper called once: the edge is at its creating call and names no call site
    (ws / "ws/demo/src/leds.cpp").write_text(LEDS_CPP.replace('    wifi_.listen(this, "led/wifi");\n', ""))
    try:
        [e] = _graph(ws, None).nodes["/panel"].subscribes
        assert (e.topic, e.src.line, e.via) == ("/led/power", 8, None) and "via" not in e.to_json()
    finally:
        (ws / "ws/demo/src/leds.cpp").write_text(LEDS_CPP)


# -- a TransformListener member initialised in another file ------------------------

def test_a_listener_member_initialised_elsewhere_with_a_buffer_is_on_tf2s_own_node(ws: Path) -> None:
    g = _graph(ws, None)
    assert g.nodes["/looker"].subscribes == []
    assert [str(n) for n in g.notes if n.code == "ROS-TF-OWN-NODE"] == [
        "ws/demo/src/looker.cpp:5:3: warning: tf2_ros::TransformListener made without a node subscribes /tf and "
        "/tf_static on tf2's own node (transform_listener_impl_...), not on this one"]
    # control: given the node, the listener subscribes on the class's node
    (ws / "ws/demo/src/looker.cpp").write_text(LOOKER_CPP.replace("tf_(buf_)", "tf_(buf_, this, false)"))
    try:
        g = _graph(ws, None)
        assert {e.topic for e in g.nodes["/looker"].subscribes} == {"/tf", "/tf_static"}
        assert not [n for n in g.notes if n.code == "ROS-TF-OWN-NODE"]
    finally:
        (ws / "ws/demo/src/looker.cpp").write_text(LOOKER_CPP)
