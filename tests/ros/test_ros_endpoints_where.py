"""Endpoints where C++ and Python put them, only what is built, the side that
differs blamed (issue 108, second part).  Each idiom is a small package the
test writes and the project's scan reads, with a control showing the other
side:

* ``setup.py`` ``package_dir={'': 'src'}`` puts the console scripts' modules
  under ``src`` (before: "not in the package");
* ``set_target_properties(t PROPERTIES OUTPUT_NAME name)`` names the
  executable a launch file runs (before: "no source found");
* ``tf2_ros::TransformListener(buffer)`` without a node subscribes on tf2's
  own node, with a node on the enclosing one (before: always the enclosing);
* alternative preprocessor branches give one edge (before: one per branch);
* a subscriber made by a default member initializer is the class's node's
  (before: no edge);
* endpoints a Python base class makes belong to the subclass's node (before:
  lost);
* interface-spec adaptors take name and type from the ``Spec`` struct
  (before: no edge, a note naming a lambda as the topic);
* a type clash names both programs and blames no contract that matches its
  own code.
"""
from __future__ import annotations

from pathlib import Path

from rclverify.ros.extract.model import Graph
from rclverify.ros.graph import summary
from rclverify.ros.graph.scan import scan

PKG = ('<?xml version="1.0"?>\n<package format="3"><name>{name}</name><version>0.1.0</version>'
       '<description>d</description><maintainer email="dev@example.org">a</maintainer><license>MIT</license>'
       '<buildtool_depend>{tool}</buildtool_depend><depend>rclcpp</depend><depend>rclpy</depend>'
       '<depend>std_msgs</depend><export><build_type>{tool}</build_type></export></package>\n')
CMAKE = "cmake_minimum_required(VERSION 3.8)\nproject({name})\nfind_package(rclcpp REQUIRED)\n"
TALKER = """#include <rclcpp/rclcpp.hpp>
#include <std_msgs/msg/string.hpp>
class Talker : public rclcpp::Node
{
public:
  Talker() : Node("talker")
  {
    pub_ = create_publisher<std_msgs::msg::String>("chatter", 10);
  }
  rclcpp::Publisher<std_msgs::msg::String>::SharedPtr pub_;
};
int main(int argc, char ** argv) { rclcpp::init(argc, argv); rclcpp::spin(std::make_shared<Talker>()); }
"""
PY_NODE = """import rclpy
from rclpy.node import Node
from std_msgs.msg import String


class Speaker(Node):
    def __init__(self):
        super().__init__('speaker')
        self.pub = self.create_publisher(String, 'said', 10)


def main():
    rclpy.init()
    rclpy.spin(Speaker())
"""
SETUP = """from setuptools import setup
setup(
    name='{name}',
    packages=['{name}'],
    package_dir={dirs},
    entry_points={{'console_scripts': ['speak = {name}.speaker:main']}},
)
"""


def _write(root: Path, files: dict[str, str]) -> None:
    for rel, text in files.items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(text)


def _scan(tmp: Path, launch: list[Path] | None = None) -> Graph:
    return scan([tmp / "ws"], launch or [], base=tmp, standard=False).graph


def _said(g: Graph) -> list[str]:
    return [str(n) for n in g.notes]


# -- only what is built ------------------------------------------------------------

def _pypkg(tmp: Path, dirs: str, where: str) -> None:
    _write(tmp / "ws" / "pyp", {"package.xml": PKG.format(name="pyp", tool="ament_python"),
                                "setup.py": SETUP.format(name="pyp", dirs=dirs),
                                f"{where}pyp/__init__.py": "", f"{where}pyp/speaker.py": PY_NODE})


def test_setup_py_package_dir_places_the_console_scripts(tmp_path: Path) -> None:
    _pypkg(tmp_path, "{'': 'src'}", "src/")
    g = _scan(tmp_path)
    assert {(e.topic, e.msg_type) for e in g.nodes["/speaker"].publishes} == {("/said", "std_msgs/msg/String")}
    assert [p for p in g.programs if p["name"] == "speak"][0]["unaccounted"] is None
    assert not [s for s in _said(g) if "not in the package" in s]


def test_a_module_where_package_dir_does_not_put_it_is_not_in_the_package(tmp_path: Path) -> None:
    _pypkg(tmp_path, "{'': 'lib'}", "src/")  # control: package_dir names another directory
    g = _scan(tmp_path)
    assert [p for p in g.programs if p["name"] == "speak"][0]["unaccounted"] is not None


LAUNCH = """from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription([Node(package='cxx', executable='{exe}', name='front')])
"""


def _cxx(tmp: Path, exe: str) -> Path:
    _write(tmp / "ws" / "cxx", {
        "package.xml": PKG.format(name="cxx", tool="ament_cmake"),
        "CMakeLists.txt": CMAKE.format(name="cxx") + "add_executable(talker_node src/talker.cpp)\n"
                          "set_target_properties(talker_node PROPERTIES OUTPUT_NAME talker)\n",
        "src/talker.cpp": TALKER, "launch/run.launch.py": LAUNCH.format(exe=exe)})
    return tmp / "ws" / "cxx" / "launch" / "run.launch.py"


def test_cmake_output_name_is_the_executable_a_launch_file_runs(tmp_path: Path) -> None:
    g = _scan(tmp_path, [_cxx(tmp_path, "talker")])
    assert {(e.topic, e.msg_type) for e in g.nodes["/front"].publishes} == {("/chatter", "std_msgs/msg/String")}
    assert not [s for s in _said(g) if "no source found" in s]


def test_the_target_name_an_output_name_replaces_runs_nothing(tmp_path: Path) -> None:
    g = _scan(tmp_path, [_cxx(tmp_path, "talker_node")])  # control: the file built is 'talker'
    assert not g.nodes["/front"].publishes
    assert [s for s in _said(g) if "executable 'talker_node' of package 'cxx' has no source found" in s]


# -- endpoints where C++ puts them ---------------------------------------------------

LISTENS = """#include <rclcpp/rclcpp.hpp>
#include <std_msgs/msg/string.hpp>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
class Looker : public rclcpp::Node
{
public:
  Looker() : Node("looker")
  {
    buffer_ = std::make_shared<tf2_ros::Buffer>(get_clock());
    listener_ = std::make_shared<tf2_ros::TransformListener>(LISTENER_ARGS);
#if defined(HUMBLE)
    sub_ = create_subscription<std_msgs::msg::String>("seen", 10, [](std_msgs::msg::String::SharedPtr) {});
#elif defined(IRON)
    sub_ = create_subscription<std_msgs::msg::String>("seen", 10, [](std_msgs::msg::String::SharedPtr) {});
#else
    sub_ = create_subscription<std_msgs::msg::String>(BRANCH_TOPIC, 10, [](std_msgs::msg::String::SharedPtr) {});
#endif
  }
  rclcpp::Subscription<std_msgs::msg::String>::SharedPtr sub_;
  rclcpp::Subscription<std_msgs::msg::String>::SharedPtr member_sub_ =
    create_subscription<std_msgs::msg::String>("kept", 10, [](std_msgs::msg::String::SharedPtr) {});
  autoware_utils::InterProcessPollingSubscriber<std_msgs::msg::String> polled_{this, "~/input/polled"};
  std::shared_ptr<tf2_ros::Buffer> buffer_;
  std::shared_ptr<tf2_ros::TransformListener> listener_;
};
int main(int argc, char ** argv) { rclcpp::init(argc, argv); rclcpp::spin(std::make_shared<Looker>()); }
"""


def _looker(tmp: Path, listener_args: str, branch_topic: str = '"seen"', polled: str = "") -> Graph:
    _write(tmp / "ws" / "eyes", {
        "package.xml": PKG.format(name="eyes", tool="ament_cmake"),
        "CMakeLists.txt": CMAKE.format(name="eyes") + "add_executable(looker src/looker.cpp)\n",
        "src/looker.cpp": LISTENS.replace("LISTENER_ARGS", listener_args).replace("BRANCH_TOPIC", branch_topic)
        .replace('polled_{this, "~/input/polled"};', polled or 'polled_{this, "~/input/polled"};')})
    return _scan(tmp)


def _subs_at(g: Graph, node: str) -> list[tuple[str, int]]:
    return sorted((e.topic, e.src.line) for e in g.nodes[node].subscribes)


def test_a_transform_listener_given_no_node_subscribes_on_tf2s_own_node(tmp_path: Path) -> None:
    g = _looker(tmp_path, "*buffer_")
    assert "/tf" not in {t for t, _ in _subs_at(g, "/looker")}
    assert "ws/eyes/src/looker.cpp:11:17: warning: tf2_ros::TransformListener made without a node subscribes /tf " \
           "and /tf_static on tf2's own node (transform_listener_impl_...), not on this one" in _said(g)
    assert summary.cause_of("ROS-TF-OWN-NODE", "").key == "endpoints-own-node"
    g = _looker(tmp_path, "*buffer_, false")  # the spin_thread flag is no node either
    assert "/tf" not in {t for t, _ in _subs_at(g, "/looker")}


def test_a_transform_listener_given_the_node_subscribes_on_it(tmp_path: Path) -> None:
    g = _looker(tmp_path, "*buffer_, this, false")  # control: the enclosing node is given
    assert {("/tf", 11), ("/tf_static", 11)} <= set(_subs_at(g, "/looker"))
    assert not [s for s in _said(g) if "own node" in s]


def test_alternative_preprocessor_branches_give_one_edge(tmp_path: Path) -> None:
    g = _looker(tmp_path, "*buffer_")
    assert [x for x in _subs_at(g, "/looker") if x[0] == "/seen"] == [("/seen", 13)]
    # control: branches creating different topics keep each
    g = _looker(tmp_path, "*buffer_", '"other"')
    assert [x for x in _subs_at(g, "/looker") if x[0] in ("/seen", "/other")] == [("/other", 17), ("/seen", 13)]


def test_a_subscription_made_by_a_default_member_initializer_is_the_nodes(tmp_path: Path) -> None:
    g = _looker(tmp_path, "*buffer_")
    assert {("/kept", 22), ("/looker/input/polled", 23)} <= set(_subs_at(g, "/looker"))
    types = {e.topic: e.msg_type for e in g.nodes["/looker"].subscribes}
    assert types["/looker/input/polled"] == types["/kept"] == "std_msgs/msg/String"
    # control: a member declared without an initializer creates nothing
    g = _looker(tmp_path, "*buffer_", '"seen"', polled="polled_;")
    assert "/looker/input/polled" not in {t for t, _ in _subs_at(g, "/looker")}


# -- endpoints where Python puts them -----------------------------------------------

BASE = """from rclpy.node import Node
from std_msgs.msg import Int32, String


class Joint(Node):
    def __init__(self, name):
        super().__init__(name)
        self.state = self.create_publisher(String, 'state', 10)
        self.setup()

    def setup(self):
        self.cmd = self.create_subscription(Int32, 'command', self.on_cmd, 10)

    def on_cmd(self, msg):
        pass
"""
SUBCLASS = """import rclpy
from rclpy.node import Node
from std_msgs.msg import String
from limbs.base import Joint


class {cls}({base}):
    def __init__(self):
        super().__init__('{node}')
        self.extra = self.create_publisher(String, '{node}_extra', 10)


def main():
    rclpy.init()
    rclpy.spin({cls}())
"""
LIMBS_SETUP = """from setuptools import setup
setup(name='limbs', packages=['limbs'], entry_points={'console_scripts': [
    'arm = limbs.arm:main', 'leg = limbs.leg:main', 'solo = limbs.solo:main']})
"""


def test_endpoints_a_python_base_class_makes_are_the_subclass_nodes(tmp_path: Path) -> None:
    _write(tmp_path / "ws" / "limbs", {
        "package.xml": PKG.format(name="limbs", tool="ament_python"), "setup.py": LIMBS_SETUP,
        "limbs/__init__.py": "", "limbs/base.py": BASE,
        "limbs/arm.py": SUBCLASS.format(cls="Arm", base="Joint", node="arm"),
        "limbs/leg.py": SUBCLASS.format(cls="Leg", base="Joint", node="leg"),
        # control: a node importing the base module without deriving from its class
        "limbs/solo.py": SUBCLASS.format(cls="Solo", base="Node", node="solo")})
    g = _scan(tmp_path)
    assert sorted(g.nodes) == ["/arm", "/leg", "/solo"]
    for n in ("arm", "leg"):
        assert sorted((e.topic, str(e.src)) for e in g.nodes[f"/{n}"].publishes) == [
            (f"/{n}_extra", f"ws/limbs/limbs/{n}.py:10:22"), ("/state", "ws/limbs/limbs/base.py:8:22")]
        assert [(e.topic, e.msg_type) for e in g.nodes[f"/{n}"].subscribes] == [("/command", "std_msgs/msg/Int32")]
    assert [e.topic for e in g.nodes["/solo"].publishes] == ["/solo_extra"] and not g.nodes["/solo"].subscribes
    assert _said(g) == []


# -- interface-spec adaptors --------------------------------------------------------

SPECS = """namespace specs
{
struct RouteState
{
  using Message = std_msgs::msg::String;
  static constexpr char name[] = "/api/routing/state";
  static constexpr size_t depth = 1;
};
struct SetRoute
{
  using Service = std_srvs::srv::Trigger;
  static constexpr char name[] = "/api/routing/set_route";
};
}  // namespace specs
"""
ROUTER = """#include <rclcpp/rclcpp.hpp>
#include <std_msgs/msg/string.hpp>
#include <std_srvs/srv/trigger.hpp>
SPECS
class Router : public rclcpp::Node
{
public:
  Router() : Node("router")
  {
    component_interface_utils::NodeAdaptor adaptor(this);
    pub_ = adaptor.create_publisher<specs::RouteState>();
    srv_ = adaptor.create_service<specs::SetRoute>(this, &Router::on_set);
    sub_ = adaptor.create_subscription<specs::RouteState>(std::bind(&Router::on_state, this, std::placeholders::_1));
  }
};
int main(int argc, char ** argv) { rclcpp::init(argc, argv); rclcpp::spin(std::make_shared<Router>()); }
"""


def _router(tmp: Path, specs: str, header: str = "") -> Graph:
    _write(tmp / "ws" / "api", {
        "package.xml": PKG.format(name="api", tool="ament_cmake"),
        "CMakeLists.txt": CMAKE.format(name="api") + "add_executable(router src/router.cpp)\n",
        "src/router.cpp": ROUTER.replace("SPECS\n", specs), "include/api/specs.hpp": header})
    return _scan(tmp)


def _router_edges(g: Graph) -> list[tuple[str, str, str | None, int]]:
    r = g.nodes["/router"]
    return sorted((role, e.topic, e.msg_type, e.src.line) for role, es in (
        ("pub", r.publishes), ("sub", r.subscribes), ("srv", r.service_servers)) for e in es)


def test_an_interface_spec_adaptor_takes_name_and_type_from_the_spec(tmp_path: Path) -> None:
    g = _router(tmp_path, SPECS)
    assert _router_edges(g) == [("pub", "/api/routing/state", "std_msgs/msg/String", 24),
                                ("srv", "/api/routing/set_route", "std_srvs/srv/Trigger", 25),
                                ("sub", "/api/routing/state", "std_msgs/msg/String", 26)]
    assert _said(g) == []


def test_an_interface_spec_of_a_header_is_read_by_the_linker(tmp_path: Path) -> None:
    g = _router(tmp_path, '#include "api/specs.hpp"\n', SPECS)
    assert _router_edges(g) == [("pub", "/api/routing/state", "std_msgs/msg/String", 11),
                                ("srv", "/api/routing/set_route", "std_srvs/srv/Trigger", 12),
                                ("sub", "/api/routing/state", "std_msgs/msg/String", 13)]
    assert _said(g) == []


def test_an_adaptor_of_a_spec_not_read_is_said_at_each_call(tmp_path: Path) -> None:
    # control: the header defines RouteState only; SetRoute is nowhere, and no other class's name[] is taken
    g = _router(tmp_path, '#include "api/specs.hpp"\n', SPECS[:SPECS.index("struct SetRoute")] + "}\n")
    assert [x[:2] for x in _router_edges(g)] == [("pub", "/api/routing/state"), ("sub", "/api/routing/state")]
    assert _said(g) == ["ws/api/src/router.cpp:12:12: warning: service server name is 'specs::SetRoute::name', "
                        "not a string literal: not resolved statically"]


ROUTER_HPP = """#include <rclcpp/rclcpp.hpp>
#include "api/specs.hpp"
class Router : public rclcpp::Node
{
public:
  Router();
  component_interface_utils::Publisher<specs::RouteState>::SharedPtr pub_;
  component_interface_utils::Subscription<specs::RouteState>::SharedPtr sub_;
  component_interface_utils::Service<specs::SetRoute>::SharedPtr srv_;
};
"""
ROUTER_INIT = """#include "api/router.hpp"
Router::Router() : Node("router")
{
  const auto adaptor = component_interface_utils::NodeAdaptor(this);
  adaptor.init_pub(pub_);
  adaptor.init_sub(sub_, this, &Router::on_state);
  adaptor.init_srv(srv_, this, &Router::on_set);
}
int main(int argc, char ** argv) { rclcpp::init(argc, argv); rclcpp::spin(std::make_shared<Router>()); }
"""


def test_adaptor_init_methods_make_members_declared_with_a_spec(tmp_path: Path) -> None:
    _write(tmp_path / "ws" / "api", {
        "package.xml": PKG.format(name="api", tool="ament_cmake"),
        "CMakeLists.txt": CMAKE.format(name="api") + "add_executable(router src/router.cpp)\n",
        "src/router.cpp": ROUTER_INIT, "include/api/specs.hpp": SPECS, "include/api/router.hpp": ROUTER_HPP})
    g = _scan(tmp_path)
    assert _router_edges(g) == [("pub", "/api/routing/state", "std_msgs/msg/String", 5),
                                ("srv", "/api/routing/set_route", "std_srvs/srv/Trigger", 7),
                                ("sub", "/api/routing/state", "std_msgs/msg/String", 6)]
    assert _said(g) == []
    # control: a member declared with no spec is said at its init call, never named
    (tmp_path / "ws" / "api" / "include" / "api" / "router.hpp").write_text(
        ROUTER_HPP.replace("component_interface_utils::Service<specs::SetRoute>", "std::shared_ptr<Other>"))
    g = _scan(tmp_path)
    assert [x[0] for x in _router_edges(g)] == ["pub", "sub"]
    assert _said(g) == ["ws/api/src/router.cpp:7:3: warning: service server name is 'srv_ (interface spec)', "
                        "not a string literal: not resolved statically"]
