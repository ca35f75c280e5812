"""Real code, round two (issue 42): endpoints wherever the program creates them.
Each test writes the smallest code showing one idiom and checks what the scan
reads of it; the corpus (tests/data/ros_corpus, test_ros_idioms.py) checks
whole packages against hand-written graphs."""
from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rclverify.ros.extract import names, namespaces, symbols
from rclverify.ros.extract.cmake import expand
from rclverify.ros.extract.cpp_prep import prepare
from rclverify.ros.extract.cpp_types import message_type, service_type
from rclverify.ros.graph.scan import scan
from rclverify.ros.extract.launch_ros2 import read_python
from rclverify.ros.extract.sources_cpp import scan_cpp
from rclverify.ros.extract.sources_py import scan_python

PKG = ('<package format="2"><name>{n}</name><version>1.0.0</version><description>d</description>'
       '<maintainer email="dev@example.org">m</maintainer><license>MIT</license>'
       '<buildtool_depend>{b}</buildtool_depend></package>')


def _pkg(root: Path, name: str, files: dict[str, str], ros2: bool = False) -> None:
    d = root / name
    for rel, text in {"package.xml": PKG.format(n=name, b="ament_cmake" if ros2 else "catkin"), **files}.items():
        (d / rel).parent.mkdir(parents=True, exist_ok=True)
        (d / rel).write_text(text)


def _edges(g) -> set[tuple[str, str, str, str | None, str]]:  # type: ignore[no-untyped-def]
    return {(n.name, role, e.topic, e.msg_type, f"{Path(e.src.file).name}:{e.src.line}")
            for n in g.nodes.values() for role in ("pub", "sub", "service_servers", "service_clients",
                                                   "action_servers", "action_clients") for e in n.edges_of(role)}


# -- noise: valid C++ the grammar misreads ------------------------------------------------
@pytest.mark.parametrize("code", [
    b'void f(int64_t c) { RCLCPP_INFO(get_logger(), "count %" PRId64 " of %" PRIu32, c, 3u); }\n',
    b'#ifdef __cplusplus\nextern "C" {\n#endif\nint crc(int);\n#ifdef __cplusplus\n}\n#endif\n',
    b'class A {\n public:\n  MY_PKG_PUBLIC\n  explicit A(int x);\n  MY_PKG_EXPORT void g();\n};\n',
    b'void f() { declare_parameter<double>(PREFIX_S AXIS_S, 1.0); }\n',
    b'struct P {\n  float i;  ///< x\n  EIGEN_MAKE_ALIGNED_OPERATOR_NEW  // aligned\n};\n'
    b'PLUGINLIB_EXPORT_CLASS(ns::Nodelet, nodelet::Nodelet)\n',
])
def test_valid_cpp_is_no_syntax_error_and_keeps_every_offset(code: bytes) -> None:
    assert len(prepare(code)) == len(code)
    assert scan_cpp(code, "x.cpp")["notes"] == []


def test_ros1_generated_pointer_names_and_type_adapters_are_message_types() -> None:
    assert message_type("const geometry_msgs::PoseConstPtr&") == "geometry_msgs/msg/Pose"
    assert message_type("sensor_msgs::ImagePtr") == "sensor_msgs/msg/Image"
    assert message_type("boost::shared_ptr<std_msgs::String const>") == "std_msgs/msg/String"
    assert message_type("Adapted", {"Adapted": "rclcpp::TypeAdapter<std::string, std_msgs::msg::String>"}) == \
        "std_msgs/msg/String"
    assert message_type("rclcpp::adapt_type<std::string>::as<std_msgs::msg::Int32>") == "std_msgs/msg/Int32"
    assert message_type("rclcpp::Subscription<std_msgs::msg::String>::SharedPtr") is None
    assert service_type("const std::shared_ptr<std_srvs::srv::SetBool::Request>") == "std_srvs/srv/SetBool"


# -- names through the program ----------------------------------------------------------------
def test_constructor_arguments_and_namespaced_handles_across_files(tmp_path: Path) -> None:
    _pkg(tmp_path, "p", {
        "CMakeLists.txt": "project(p)\nadd_library(h src/sensor.cpp)\nadd_executable(n src/main.cpp)\n"
                          "target_link_libraries(n h)\n",
        "include/p/sensor.h": "#include <ros/ros.h>\nclass Sensor {\n public:\n"
                              "  Sensor(ros::NodeHandle nh, const std::string& topic = \"data\");\n};\n",
        "src/sensor.cpp": "#include \"p/sensor.h\"\nSensor::Sensor(ros::NodeHandle nh, const std::string& topic) {\n"
                          "  pub_ = nh.advertise<std_msgs::Float32>(topic, 1);\n}\n",
        "src/main.cpp": "#include \"p/sensor.h\"\nint main(int argc, char** argv) {\n"
                        "  ros::init(argc, argv, \"n\");\n  ros::NodeHandle nh;\n"
                        "  Sensor a(ros::NodeHandle(nh, \"left\"), \"range\");\n"
                        "  Sensor b(ros::NodeHandle(\"~\"));\n  Sensor c(nh, std::string(argv[1]));\n}\n"})
    g = scan([tmp_path], base=tmp_path, standard=False).graph
    assert _edges(g) == {("/n", "pub", "/left/range", "std_msgs/msg/Float32", "sensor.cpp:3"),
                         ("/n", "pub", "/n/data", "std_msgs/msg/Float32", "sensor.cpp:3")}
    # the third instance's name is computed at run time: said at the call, not guessed, with
    # where it comes from (issue 53)
    assert [n.message for n in g.notes] == ["publisher topic name is 'topic', from argv: not resolved statically"]


def test_a_static_method_called_does_not_construct_its_class(tmp_path: Path) -> None:
    _pkg(tmp_path, "q", {
        "q/__init__.py": "",
        "q/driver.py": "import rospy\nfrom std_msgs.msg import String\nclass Driver(object):\n"
                       "    def __init__(self):\n        self.pub = rospy.Publisher('fix', String)\n"
                       "    @staticmethod\n    def frame():\n        return 'gps'\n",
        "scripts/reader.py": "import rospy\nfrom q.driver import Driver\nrospy.init_node('reader')\n"
                             "f = Driver.frame()\n",
        "scripts/runner.py": "import rospy\nfrom q.driver import Driver\nrospy.init_node('runner')\nDriver()\n"})
    g = scan([tmp_path], base=tmp_path, standard=False).graph
    assert _edges(g) == {("/runner", "pub", "/fix", "std_msgs/msg/String", "driver.py:5")}
    assert set(g.nodes) == {"/reader", "/runner"}


def test_module_constants_imports_and_self_attributes(tmp_path: Path) -> None:
    _pkg(tmp_path, "r", {
        "setup.py": "from setuptools import setup\nsetup(entry_points={'console_scripts': ['go = r.node:main']})\n",
        "r/__init__.py": "", "r/names.py": "NODE = 'walker'\nODOM = 'odom'\n",
        "r/chan.py": "from std_msgs.msg import String\nclass Chan:\n    def __init__(self, node, name, suffix='out'):\n"
                     "        self.topic = name + '/' + suffix\n"
                     "        self.pub = node.create_publisher(String, self.topic, 1)\n",
        "r/node.py": "import rclpy\nfrom rclpy.node import Node\nfrom nav_msgs.msg import Odometry\n"
                     "from . import names\nfrom r.chan import Chan\n"
                     "class Walker(Node):\n    def __init__(self):\n        super().__init__(names.NODE)\n"
                     "        self.create_subscription(Odometry, names.ODOM, print, 1)\n"
                     "        self.a = Chan(self, 'left')\n        self.b = Chan(self, 'right', suffix='raw')\n"
                     "def main():\n    rclpy.spin(Walker())\n"}, ros2=True)
    g = scan([tmp_path], base=tmp_path, standard=False).graph
    assert _edges(g) == {("/walker", "sub", "/odom", "nav_msgs/msg/Odometry", "node.py:9"),
                         ("/walker", "pub", "/left/out", "std_msgs/msg/String", "chan.py:5"),
                         ("/walker", "pub", "/right/raw", "std_msgs/msg/String", "chan.py:5")}


def test_every_call_site_is_its_own_edge(tmp_path: Path) -> None:
    _pkg(tmp_path, "s", {"scripts/two.py": "import rospy\nfrom std_msgs.msg import String\nrospy.init_node('two')\n"
                                           "rospy.Subscriber('chatter', String, print)\n"
                                           "rospy.Subscriber('chatter', String, len)\n"})
    g = scan([tmp_path], base=tmp_path, standard=False).graph
    assert [e.src.line for e in g.nodes["/two"].subscribes] == [4, 5]


# -- scripts, build files, imports ----------------------------------------------------------
def test_scripts_without_extension_anywhere_and_shell_scripts_skipped(tmp_path: Path) -> None:
    _pkg(tmp_path, "t", {
        "CMakeLists.txt": "project(t)\ncatkin_install_python(PROGRAMS tools/probe DESTINATION bin)\n"
                          "install(PROGRAMS tools/udev DESTINATION bin)\n",
        "tools/probe": "import rospy\nfrom std_msgs.msg import Empty\nrospy.init_node('probe')\n"
                       "rospy.Publisher('ping', Empty)\n",
        "tools/udev": "#!/bin/bash\necho 'KERNEL==\"ttyUSB*\"' > /etc/udev/rules.d/99.rules\n",
        "nodes/legacy": "#!/usr/bin/env python\nimport rospy\nrospy.init_node('legacy')\nprint 'old'\n"})
    g = scan([tmp_path], base=tmp_path, standard=False).graph
    assert set(g.nodes) == {"/probe", "/legacy"}
    assert [n.message.split(":")[0] for n in g.notes] == ["Python source is not Python 3 (Missing parentheses in "
                                                          "call to 'print'. Did you mean print(...)?)"]


def test_cmake_foreach_over_a_macro_and_subdirectories(tmp_path: Path) -> None:
    text = ("project(u)\nmacro(demo N)\n  add_executable(${N} src/${N}.cpp)\nendmacro()\n"
            "foreach(d talker listener)\n  demo(${d})\nendforeach()\n"
            "foreach(i RANGE 1 2)\n  add_executable(x${i} x.cpp)\nendforeach()\n"
            "set(L a b)\nforeach(i IN LISTS L ITEMS c)\n  add_executable(y${i} y.cpp)\nendforeach()\n")
    assert [a[0] for c, a, _l in expand(text, "u") if c == "add_executable"] == [
        "talker", "listener", "x1", "x2", "ya", "yb", "yc"]
    _pkg(tmp_path, "v", {"CMakeLists.txt": "project(v)\nadd_subdirectory(src/nodes)\n",
                         "src/nodes/CMakeLists.txt": "add_executable(w w.cpp)\n",
                         "src/nodes/w.cpp": "int main(int c, char** v) { ros::init(c, v, \"w\"); }\n"})
    g = scan([tmp_path / "v"], [], base=tmp_path, standard=False).graph
    assert g.nodes["/w"].executable == "w"
    # a glob or a subdirectory leaving the package reads nothing there
    from rclverify.ros.extract.executables import targets
    (tmp_path / "v" / "CMakeLists.txt").write_text("project(v)\nfile(GLOB_RECURSE S /*.cpp ../*.cpp)\n"
                                                   "add_executable(z ${S})\nadd_subdirectory(../v/src/nodes)\n")
    assert targets(tmp_path / "v", "v").executables == {"z": []}


def test_star_and_run_time_imports(tmp_path: Path) -> None:
    text = ("import rospy\nfrom std_msgs.msg import *\nfrom my_msgs.msg import *\n"
            "try:\n    from geometry_msgs.msg import TwistStamped as Cmd\nexcept ImportError:\n"
            "    from geometry_msgs.msg import Twist as Cmd\n"
            "rospy.init_node('n')\nrospy.Publisher('a', Bool)\nrospy.Publisher('b', Cmd)\n")
    r = scan_python(text, "n.py")
    a, b = r["endpoints"]
    assert a.pending[2] == ("cands", ("my_msgs/msg/Bool", "std_msgs/msg/Bool"))  # the type table decides
    assert b.msg_type == "geometry_msgs/msg/TwistStamped"
    assert [str(n) for n in r["notes"]] == [
        "n.py:10:22: warning: 'Cmd' is imported 2 times (lines 5, 7), chosen at run time: read as "
        "geometry_msgs.msg.TwistStamped, the first (line 5)"]


# -- namespaces -----------------------------------------------------------------------------
_seg = st.sampled_from(["a", "b", "~", "/g", "c/d"])
_name = st.sampled_from(["t", "~p", "/abs", "x/y"])


@settings(max_examples=60, deadline=None)
@given(st.lists(_seg, max_size=3), _name, st.sampled_from(["/", "/r1", "/r1/r2"]))
def test_a_handle_without_remaps_resolves_as_its_written_form(handle: list[str], written: str, ns: str) -> None:
    """Oracle: with no remap, resolving a name through a handle step by step (namespaces.resolve)
    equals resolving the name written with the handle's namespaces folded in (symbols.under),
    the rule of the ROS 1 wiki "Names"."""
    full = names.join(ns, "node")
    folded = symbols.under(handle, written)
    assert namespaces.resolve(written, tuple(handle), ns, full, [])[0] == names.resolve(folded, ns, full)


def test_a_handle_namespace_is_remapped_when_the_handle_is_made() -> None:
    remaps = [("input", "/alpha/base", None)]
    got, at = namespaces.resolve("pose", ("input",), "/follow", "/follow/mimic", remaps)  # type: ignore[list-item]
    assert got == "/alpha/base/pose" and at is None


# -- launch files -----------------------------------------------------------------------------
def test_python_launch_variables_are_read_and_a_literal_is_never_called_not_a_literal(tmp_path: Path) -> None:
    lf = tmp_path / "a.launch.py"
    lf.write_text("from launch import LaunchDescription\nfrom launch.actions import DeclareLaunchArgument\n"
                  "from launch.substitutions import LaunchConfiguration\nfrom launch_ros.actions import Node\n"
                  "def generate_launch_description():\n"
                  "    port = LaunchConfiguration('port', default='/dev/ttyACM0')\n"
                  "    ns = LaunchConfiguration('ns')\n"
                  "    prefix = LaunchConfiguration('prefix', default='')\n"
                  "    return LaunchDescription([\n"
                  "        DeclareLaunchArgument('port', default_value=port),\n"
                  "        DeclareLaunchArgument('ns', default_value='robot'),\n"
                  "        Node(package='p', executable='e', namespace=ns, arguments=['-i', port]),\n"
                  "        Node(package='p', executable='f', name=undefined_name),\n"
                  "        Node(package='p', executable='g', namespace=prefix),\n"
                  "    ])\n")
    el, notes = read_python(lf, "a.launch.py")
    assert el is not None
    assert [(c.tag, c.attrs) for c in el.children[:3]] == [
        ("arg", {"name": "port", "default": "$(var-default port /dev/ttyACM0)"}), ("arg", {"name": "ns", "default": "robot"}),
        ("node", {"pkg": "p", "exec": "e", "namespace": "$(var ns)"})]
    assert [n.message for n in notes] == ["Node(...): name variable 'undefined_name' (not assigned in "
                                          "generate_launch_description()) cannot be read statically; the name the "
                                          "code gives is kept"]
    from rclverify.ros.extract.launch import Interpreter
    it = Interpreter(lambda p: None, lambda p: read_python(p, p.name), lambda p: p.name)
    it.run(lf, {})
    # an unreadable name drops the name, never the node; an empty default is no namespace
    assert [(n.exe, n.name, n.ns) for n in it.nodes] == [("e", None, "/robot"), ("f", None, "/"), ("g", None, "/")]
    assert it.notes == notes
