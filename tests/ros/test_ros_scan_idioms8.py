"""Real ROS 2 code, round four, second pass (issue 65): values followed into a
workspace's own functions.

Small self-written packages, one construct each, scanned once per module:

* a wrapper of ``declare_parameter`` in another package's header, a free
  function template with overloads (``rigutil::param_or(node, "p", default,
  warn)`` forwarding to ``param_or(logger, params, "p", default)``, both
  taking four arguments: a string literal never goes to the ``Logger`` or
  parameters-interface parameter, so the call is not read as the parameter
  ``~layers``), returning the parameter on two paths: the topic it names is
  the parameter, its default the wrapper's argument (also through a member
  set in another method); a recursive function names nothing;
* the same wrapper as a method of the node's own base class
  (``node->param_or("p", default)`` with ``auto node = shared_from_this()``),
  forwarding to the free function;
* a wrapper whose paths return different values, or one the scan cannot read,
  names nothing: a located note, no edge (never a guess);
* the same in Python: a helper module's ``param_or(node, "p", default)``
  (two paths, one parameter) and ``make_pub(node, String, topic)``, the
  message type a parameter read at the call; a helper returning one of two
  names by a branch names nothing;
* a stack's factory taking the node first, ``rigutil::make_sub<T>(parent,
  topic, cb)``, inside a helper constructor whose node parameter is a template
  parameter (``template<typename NodeT> Smoother(const NodeT & parent, ...)``),
  the topic from the constructor's default or its caller; a factory whose
  first argument is a string is rclcpp-like, not a node.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.ros.graph.scan import scan

PKG = ('<?xml version="1.0"?>\n<package format="3"><name>{name}</name><version>0.1.0</version>'
       '<description>d</description>\n<maintainer email="dev@example.org">a</maintainer><license>MIT</license>\n'
       '<buildtool_depend>ament_cmake</buildtool_depend><depend>rclcpp</depend><depend>std_msgs</depend>{deps}\n'
       '<export><build_type>ament_cmake</build_type></export></package>\n')
CMAKE = "cmake_minimum_required(VERSION 3.8)\nproject({name})\nfind_package(rclcpp REQUIRED)\n{exes}"

PARAMS = """#pragma once
#include <string>
#include <rclcpp/rclcpp.hpp>
#include <std_msgs/msg/string.hpp>

namespace rigutil
{
template<typename T, typename NodeT>
T param_or(NodeT node, const std::string & name)
{
  return node->get_parameter(name).template get_value<T>();
}

template<typename T>
T param_or(
  const rclcpp::Logger & logger, rclcpp::node_interfaces::NodeParametersInterface::SharedPtr params,
  const std::string & name, const T & fallback)
{
  if (params->has_parameter(name)) {
    rclcpp::Parameter p(name, fallback);
    params->get_parameter(name, p);
    return p.get_value<T>();
  }
  auto got = params->declare_parameter(name, rclcpp::ParameterValue{fallback}).template get<T>();
  return got;
}

template<typename T, typename NodeT>
T param_or(NodeT node, const std::string & name, const T & fallback, bool warn = false)
{
  return param_or(node->get_logger(), node->get_node_parameters_interface(), name, fallback);
}

template<typename NodeT>
std::string either(NodeT node, bool left)
{
  if (left) {
    return "left_topic";
  }
  return "right_topic";
}

std::string opaque(const std::string & seed);

template<typename MessageT, typename NodeT, typename CallbackT>
typename rclcpp::Subscription<MessageT>::SharedPtr make_sub(
  const NodeT & node, const std::string & topic, CallbackT && cb)
{
  return node->template create_subscription<MessageT>(topic, 10, cb);
}

class RigNode : public rclcpp::Node
{
public:
  explicit RigNode(const std::string & name)
  : rclcpp::Node(name)
  {
  }
  template<typename T>
  T param_or(const std::string & name, const T & fallback)
  {
    return rigutil::param_or(this, name, fallback);
  }
};

class Smoother
{
public:
  template<typename NodeT>
  explicit Smoother(const NodeT & parent, const std::string & topic = "odom")
  {
    sub_ = rigutil::make_sub<std_msgs::msg::String>(
      parent, topic, [](std_msgs::msg::String::SharedPtr) {});
  }
  rclcpp::Subscription<std_msgs::msg::String>::SharedPtr sub_;
};
}  // namespace rigutil
"""

MAPPER = """#include <rigutil/params.hpp>
#include <std_msgs/msg/string.hpp>

class Mapper : public rigutil::RigNode
{
public:
  Mapper()
  : rigutil::RigNode("mapper")
  {
    auto node = shared_from_this();
    std::string grid = node->param_or("grid_topic", std::string("grid"));
    grid_pub_ = create_publisher<std_msgs::msg::String>(grid, 10);
    std::string side = rigutil::either(this, true);
    side_pub_ = create_publisher<std_msgs::msg::String>(side, 10);
    std::string hidden = rigutil::opaque("seed");
    hidden_pub_ = create_publisher<std_msgs::msg::String>(hidden, 10);
    smoother_ = std::make_unique<rigutil::Smoother>(this);
    configure();
  }
  void configure()
  {
    auto node = shared_from_this();
    layer_topic_ = rigutil::param_or(node, "layer_topic", std::string{"layers"}, true);
    layer_pub_ = create_publisher<std_msgs::msg::String>(layer_topic_, 10);
  }
  std::string layer_topic_;
  std::unique_ptr<rigutil::Smoother> smoother_;
  rclcpp::Publisher<std_msgs::msg::String>::SharedPtr grid_pub_, side_pub_, hidden_pub_, layer_pub_;
};

int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  rclcpp::spin(std::make_shared<Mapper>());
  return 0;
}
"""

TRACKER = """#include <rigutil/params.hpp>
#include <std_msgs/msg/string.hpp>

namespace feeds
{
template<typename MessageT>
void create_subscription(const std::string & topic, int depth);
}

class Tracker : public rclcpp::Node
{
public:
  Tracker()
  : rclcpp::Node("tracker")
  {
    std::string odom = declare_parameter("odom_topic", std::string("wheel_odom"));
    smoother_ = std::make_unique<rigutil::Smoother>(this, odom);
    feeds::create_subscription<std_msgs::msg::String>("feed", 5);
  }
  std::unique_ptr<rigutil::Smoother> smoother_;
};

int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  rclcpp::spin(std::make_shared<Tracker>());
  return 0;
}
"""

PY_UTIL = """def param_or(node, name, default):
    if node.has_parameter(name):
        return node.get_parameter(name).value
    return node.declare_parameter(name, default).value


def pick(node, left):
    if left:
        return 'left_topic'
    return 'right_topic'


def make_pub(node, msg_type, topic):
    return node.create_publisher(msg_type, topic, 10)
"""
PY_WATCH = """import rclpy
from rclpy.node import Node
from std_msgs.msg import String

from rig_py.util import make_pub, param_or, pick


class Watch(Node):
    def __init__(self):
        super().__init__('watch')
        topic = param_or(self, 'status_topic', 'status')
        self.pub = make_pub(self, String, topic)
        self.sub = self.create_subscription(String, param_or(self, 'in_topic', 'incoming'), print, 10)
        self.side = self.create_publisher(String, pick(self, True), 10)


def main():
    rclpy.init()
    rclpy.spin(Watch())
"""
PY_SETUP = ("from setuptools import setup\nsetup(name='rig_py', packages=['rig_py'],\n"
            "      entry_points={'console_scripts': ['watch = rig_py.watch:main']})\n")


def _package(root: Path, name: str, files: dict[str, str], deps: str = "") -> None:
    d = root / "src" / name
    for rel, text in files.items():
        (d / rel).parent.mkdir(parents=True, exist_ok=True)
        (d / rel).write_text(text)
    exes = "".join(f"add_executable({Path(r).stem} {r})\n" for r in files if r.endswith(".cpp"))
    (d / "package.xml").write_text(PKG.format(name=name, deps=deps))
    (d / "CMakeLists.txt").write_text(CMAKE.format(name=name, exes=exes))


@pytest.fixture(scope="module")
def graph(tmp_path_factory):  # type: ignore[no-untyped-def]
    root = tmp_path_factory.mktemp("idioms8")
    _package(root, "rigutil", {"include/rigutil/params.hpp": PARAMS})
    _package(root, "rig_mapping", {"src/mapper.cpp": MAPPER, "src/tracker.cpp": TRACKER},
             "<depend>rigutil</depend>")
    py = root / "src" / "rig_py"
    for rel, text in {"package.xml": PKG.format(name="rig_py", deps="").replace("ament_cmake", "ament_python"),
                      "setup.py": PY_SETUP, "resource/rig_py": "", "rig_py/__init__.py": "",
                      "rig_py/util.py": PY_UTIL, "rig_py/watch.py": PY_WATCH}.items():
        (py / rel).parent.mkdir(parents=True, exist_ok=True)
        (py / rel).write_text(text)
    return scan([root], [], base=root).graph


def _edges(g, node: str) -> set[tuple[str, str, str | None]]:  # type: ignore[no-untyped-def]
    n = g.nodes[node]
    return {(r, e.topic, e.msg_type) for r in ("pub", "sub", "service_servers", "service_clients")
            for e in n.edges_of(r)}


def _notes(g, file: str) -> list[str]:  # type: ignore[no-untyped-def]
    return [f"{n.src.line}: {n.message}" for n in g.notes if n.src.file.endswith(file)]


S = "std_msgs/msg/String"


def test_a_free_wrapper_of_declare_parameter_names_the_topic(graph) -> None:  # type: ignore[no-untyped-def]
    n = graph.nodes["/mapper"]
    got = {(e.topic, e.param) for e in n.edges_of("pub")}
    assert ("/layers", "/mapper/layer_topic") in got  # through a member set in another method


def test_a_base_class_method_wrapper_forwarding_to_the_free_one(graph) -> None:  # type: ignore[no-untyped-def]
    n = graph.nodes["/mapper"]
    assert ("/grid", "/mapper/grid_topic") in {(e.topic, e.param) for e in n.edges_of("pub")}


def test_paths_returning_different_or_unread_values_name_nothing(graph) -> None:  # type: ignore[no-untyped-def]
    got = _edges(graph, "/mapper")
    assert not any(t in ("/left_topic", "/right_topic", "/seed") for _r, t, _ty in got)
    notes = _notes(graph, "mapper.cpp")
    assert any(m.startswith("14: publisher topic name is 'side', not a string literal") for m in notes), notes
    assert any(m.startswith("16: publisher topic name is 'hidden', not a string literal") for m in notes), notes


def test_a_factory_given_a_template_parameter_node(graph) -> None:  # type: ignore[no-untyped-def]
    assert ("sub", "/odom", S) in _edges(graph, "/mapper")  # the constructor's default topic
    tracker = _edges(graph, "/tracker")
    assert ("sub", "/wheel_odom", S) in tracker  # the caller's parameter, with its default
    assert not any(t in ("/parent", "/odom") for _r, t, _ty in tracker)


def test_mapper_edges_are_exactly_the_read_ones(graph) -> None:  # type: ignore[no-untyped-def]
    assert _edges(graph, "/mapper") == {("pub", "/grid", S), ("pub", "/layers", S), ("sub", "/odom", S)}


def test_a_factory_given_a_string_first_is_no_node_factory(graph) -> None:  # type: ignore[no-untyped-def]
    # feeds::create_subscription<T>("feed", 5): no node is given, so nothing is read as the node's
    assert not any(t in ("/5", "/feed") for _r, t, _ty in _edges(graph, "/tracker"))
    assert "18: feeds::create_subscription(...) is a function of another namespace than rclcpp's, given no node, " \
        "so it is no rclcpp method, and its body is not in the workspace: its endpoints are not read" in \
        _notes(graph, "tracker.cpp")


def test_a_python_wrapper_of_declare_parameter_and_a_factory(graph) -> None:  # type: ignore[no-untyped-def]
    n = graph.nodes["/watch"]
    got = {(r, e.topic, e.msg_type, e.param) for r in ("pub", "sub") for e in n.edges_of(r)}
    assert got == {("pub", "/status", S, "/watch/status_topic"), ("sub", "/incoming", S, "/watch/in_topic")}
    # pick() returns one of two names by a branch: not guessed
    assert any(m.startswith("14: publisher topic name is 'pick(self, True)', not a string literal")
               for m in _notes(graph, "rig_py/watch.py")), _notes(graph, "rig_py/watch.py")


RECURSIVE = """#include <rclcpp/rclcpp.hpp>
#include <std_msgs/msg/string.hpp>

std::string deeper(const std::string & t, int n)
{
  if (n > 0) {
    return deeper(t + "x", n - 1);
  }
  return t;
}

class Loop : public rclcpp::Node
{
public:
  Loop()
  : rclcpp::Node("loop")
  {
    pub_ = create_publisher<std_msgs::msg::String>(deeper("chatter", 3), 10);
  }
  rclcpp::Publisher<std_msgs::msg::String>::SharedPtr pub_;
};

int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  rclcpp::spin(std::make_shared<Loop>());
  return 0;
}
"""


def test_a_recursive_function_names_nothing(tmp_path) -> None:  # type: ignore[no-untyped-def]
    _package(tmp_path, "looping", {"src/loop.cpp": RECURSIVE})
    g = scan([tmp_path], [], base=tmp_path).graph
    assert _edges(g, "/loop") == set()  # deeper() returns 'chatter' or itself: never guessed
    assert any(m.startswith("18: publisher topic name is 'deeper(\"chatter\", 3)', not a string literal")
               for m in _notes(g, "loop.cpp")), _notes(g, "loop.cpp")


HANDLE = """#pragma once
#include <rclcpp/rclcpp.hpp>
#include <std_msgs/msg/string.hpp>

namespace muxer
{
class Handle
{
public:
  Handle(rclcpp::Node * node, const std::string & topic)
  {
    sub_ = node->create_subscription<std_msgs::msg::String>(
      topic, 10, [](std_msgs::msg::String::SharedPtr) {});
  }
  rclcpp::Subscription<std_msgs::msg::String>::SharedPtr sub_;
};
}  // namespace muxer
"""
MUX = """#include <muxer/handle.hpp>

class Mux : public rclcpp::Node
{
public:
  Mux()
  : rclcpp::Node("mux")
  {
    handles_ = std::make_shared<Handles>();
    fill(*handles_);
  }
  template<typename List>
  void fill(List & list)
  {
    list.emplace_back(this, "in_a");
  }
  using Handles = std::list<muxer::Handle>;
  std::shared_ptr<Handles> handles_;
};

int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  rclcpp::spin(std::make_shared<Mux>());
  return 0;
}
"""
DIRECT = """#include <muxer/handle.hpp>

class Direct : public rclcpp::Node
{
public:
  Direct()
  : rclcpp::Node("direct")
  {
    handle_ = std::make_unique<muxer::Handle>(this, "direct_in");
  }
  std::unique_ptr<muxer::Handle> handle_;
};

int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  rclcpp::spin(std::make_shared<Direct>());
  return 0;
}
"""
UNBUILT = ("subscriber topic of class muxer::Handle: nothing this program runs is read to construct the class")


def test_a_class_made_only_through_a_container_is_a_note_not_silence(tmp_path) -> None:  # type: ignore[no-untyped-def]
    _package(tmp_path, "muxer", {"include/muxer/handle.hpp": HANDLE, "src/mux.cpp": MUX})
    g = scan([tmp_path], [], base=tmp_path).graph
    assert _edges(g, "/mux") == set()
    assert [m for m in _notes(g, "handle.hpp") if UNBUILT in m] == [f"12: {UNBUILT} (a construction through a "
                                                                    "container's emplace_back/push_back or a factory "
                                                                    "the scan does not follow is not read): not in "
                                                                    "the graph"]


def test_a_class_another_program_makes_gets_no_note(tmp_path) -> None:  # type: ignore[no-untyped-def]
    _package(tmp_path, "muxer", {"include/muxer/handle.hpp": HANDLE, "src/mux.cpp": MUX, "src/direct.cpp": DIRECT})
    g = scan([tmp_path], [], base=tmp_path).graph
    assert _edges(g, "/direct") == {("sub", "/direct_in", S)}
    assert not any(UNBUILT in m for m in _notes(g, "handle.hpp"))  # the graph has the class's edge
