"""Real code, round three: what robot drivers write (ROS 1 nodelets, diagnostics,
dynamic_reconfigure, realtime publishers, lifecycle nodes, a node class made
twice, classes defined through ``using``).  Each test writes the smallest code
showing one idiom and checks what the scan reads of it; the corpus
(tests/data/ros_corpus/idioms3, idioms4; test_ros_idioms.py) checks whole
packages against hand-written graphs."""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.ros.extract.cpp_prep import prepare
from rclverify.ros.graph.scan import scan
from rclverify.ros.ground.ground_services import servers
from rclverify.ros.ground.lifecycle import MANAGEMENT, implicit
from rclverify.ros.extract.model import GraphNode, Src
from rclverify.ros.extract.nodelets import launch_args, plugin_classes, registered
from rclverify.ros.extract.sources_cpp import scan_cpp
from rclverify.ros.extract.sources_py import scan_python

CORPUS = Path(__file__).parent.parent / "data" / "ros_corpus"
PKG = ('<package format="2"><name>{n}</name><version>1.0.0</version><description>d</description>'
       '<maintainer email="dev@example.org">m</maintainer><license>MIT</license>'
       '<buildtool_depend>{b}</buildtool_depend>{x}</package>')
ROLES = ("pub", "sub", "service_servers", "service_clients", "action_servers", "action_clients")


def _pkg(root: Path, name: str, files: dict[str, str], ros2: bool = False, export: str = "") -> None:
    d = root / name
    xml = PKG.format(n=name, b="ament_cmake" if ros2 else "catkin", x=f"<export>{export}</export>" if export else "")
    for rel, text in {"package.xml": xml, **files}.items():
        (d / rel).parent.mkdir(parents=True, exist_ok=True)
        (d / rel).write_text(text)


def _edges(g) -> set[tuple[str, str, str, str | None, str]]:  # type: ignore[no-untyped-def]
    return {(n.name, role, e.topic, e.msg_type, f"{Path(e.src.file).name}:{e.src.line}")
            for n in g.nodes.values() for role in ROLES for e in n.edges_of(role)}


def _eps(record: dict) -> set[tuple[str, str, str | None, tuple[str, ...]]]:  # type: ignore[type-arg]
    return {(e.kind, e.topic, e.msg_type, e.handle) for e in record["endpoints"]}


# -- nodelets ---------------------------------------------------------------------------------
def test_pluginlib_registrations_of_nodelets_only() -> None:
    src = (b"PLUGINLIB_EXPORT_CLASS(drv::Range, nodelet::Nodelet)\n"
           b"PLUGINLIB_EXPORT_CLASS(drv::Panel, rviz::Panel)\n"
           b"PLUGINLIB_DECLARE_CLASS(drv, Median, drv::MedianFilter, nodelet::Nodelet)\n")
    assert [(c, k, at.line) for c, k, at in registered(src, "x.cpp")] == [
        ("drv::Range", None, 1), ("drv::MedianFilter", "drv/Median", 3)]


@pytest.mark.parametrize("args, want", [
    ("manager", ("manager", None)), ("load drv/Range /sensors", ("load", "drv/Range")),
    ("standalone drv/Median", ("standalone", "drv/Median")), ("unload drv/Range mgr", None), ("", None),
    ("load", None)])
def test_nodelet_launch_args(args: str, want: tuple[str, str | None] | None) -> None:
    assert launch_args(args) == want


def test_plugin_description_names_class_and_library(tmp_path: Path) -> None:
    _pkg(tmp_path, "drv", {"plugins.xml": '<library path="lib/libdrv_nodelets"><class name="drv/Range" '
                                          'type="drv::RangeNodelet" base_class_type="nodelet::Nodelet"/>'
                                          '<class type="drv::Other" base_class_type="nodelet::Nodelet"/></library>'},
         export='<nodelet plugin="${prefix}/plugins.xml"/>')
    assert plugin_classes(tmp_path / "drv") == {"drv/Range": ("drv::RangeNodelet", "drv_nodelets"),
                                                 "drv::Other": ("drv::Other", "drv_nodelets")}
    # a plugin file leaving the package is not read
    _pkg(tmp_path, "bad", {}, export='<nodelet plugin="${prefix}/../drv/plugins.xml"/>')
    assert plugin_classes(tmp_path / "bad") == {}


def test_a_nodelet_loaded_twice_is_two_nodes_named_by_the_launch_file(tmp_path: Path) -> None:
    _pkg(tmp_path, "drv", {
        "CMakeLists.txt": "project(drv)\nadd_library(drv_nodelets src/echo.cpp)\n",
        "plugins.xml": '<library path="lib/libdrv_nodelets"><class name="drv/Echo" type="drv::Echo" '
                       'base_class_type="nodelet::Nodelet"/></library>',
        "src/echo.cpp": "#include <nodelet/nodelet.h>\nnamespace drv {\nclass Echo : public nodelet::Nodelet {\n"
                        "  void onInit() {\n    ros::NodeHandle nh = getNodeHandle();\n"
                        "    pub_ = getPrivateNodeHandle().advertise<std_msgs::String>(\"out\", 1);\n"
                        "    sub_ = nh.subscribe(\"in\", 1, &Echo::cb, this);\n"
                        "    name_pub_ = nh.advertise<std_msgs::String>(getName() + \"/alive\", 1);\n  }\n"
                        "  void cb(const std_msgs::String::ConstPtr& m) {}\n};\n}\n"
                        "PLUGINLIB_EXPORT_CLASS(drv::Echo, nodelet::Nodelet)\n",
        "launch/two.launch": '<launch>\n<node pkg="nodelet" type="nodelet" name="mgr" args="manager"/>\n'
                             '<node pkg="nodelet" type="nodelet" name="a" ns="left" args="load drv/Echo /mgr">\n'
                             '  <remap from="in" to="chatter"/>\n</node>\n'
                             '<node pkg="nodelet" type="nodelet" name="b" args="standalone drv/Echo"/>\n</launch>\n'},
         export='<nodelet plugin="${prefix}/plugins.xml"/>')
    g = scan([tmp_path], [tmp_path / "drv" / "launch" / "two.launch"], base=tmp_path, standard=False).graph
    assert _edges(g) == {
        ("/left/a", "pub", "/left/a/out", "std_msgs/msg/String", "echo.cpp:6"),
        ("/left/a", "sub", "/left/chatter", "std_msgs/msg/String", "echo.cpp:7"),
        ("/left/a", "pub", "/left/a/alive", "std_msgs/msg/String", "echo.cpp:8"),
        ("/b", "pub", "/b/out", "std_msgs/msg/String", "echo.cpp:6"),
        ("/b", "sub", "/in", "std_msgs/msg/String", "echo.cpp:7"),
        ("/b", "pub", "/b/alive", "std_msgs/msg/String", "echo.cpp:8")}
    assert g.nodes["/b"].executable == "drv/Echo" and "/mgr" not in g.nodes
    assert not [n for n in g.notes if "mgr" in n.message or "nodelet" in n.message]


# -- helpers of drivers -----------------------------------------------------------------------
def test_diagnostics_reconfigure_self_test_and_realtime_publishers_in_cpp() -> None:
    r = scan_cpp(b'#include <ros/ros.h>\nvoid f(ros::NodeHandle nh, ros::NodeHandle pnh, boost::recursive_mutex m) {\n'
                 b'  diagnostic_updater::Updater updater;\n'
                 b'  dynamic_reconfigure::Server<pkg::Config> a;\n'
                 b'  dynamic_reconfigure::Server<pkg::Config> b(m, nh);\n'
                 b'  dynamic_reconfigure::Server<pkg::Config>::CallbackType cb;\n'
                 b'  dynamic_reconfigure::Client<pkg::Config> c("/driver");\n'
                 b'  self_test::TestRunner t;\n'
                 b'  realtime_tools::RealtimePublisher<std_msgs::Float64> rt(pnh, "effort", 4);\n'
                 b'  realtime_tools::RealtimePublisher<std_msgs::Float64> wrapped(existing_publisher);\n}\n', "x.cpp")
    pending = {(e.kind, e.src.line) for e in r["endpoints"] if e.pending is not None}
    assert pending == {("service_servers", 5), ("pub", 5), ("pub", 9)}  # through handle parameters
    rec = "dynamic_reconfigure/"
    assert _eps(r) >= {("pub", "/diagnostics", "diagnostic_msgs/msg/DiagnosticArray", ()),
                       ("service_servers", "set_parameters", rec + "srv/Reconfigure", ("~",)),
                       ("pub", "parameter_descriptions", rec + "msg/ConfigDescription", ("~",)),
                       ("pub", "parameter_updates", rec + "msg/Config", ("~",)),
                       ("service_clients", "/driver/set_parameters", rec + "srv/Reconfigure", ()),
                       ("sub", "/driver/parameter_updates", rec + "msg/Config", ()),
                       ("service_servers", "self_test", "diagnostic_msgs/srv/SelfTest", ("~",))}
    assert not [e for e in r["endpoints"] if e.src.line in (6, 10)]  # a nested type; a wrapped publisher


def test_diagnostics_and_reconfigure_in_python() -> None:
    r = scan_python("import rospy, diagnostic_updater\nfrom dynamic_reconfigure.server import Server\n"
                    "from dynamic_reconfigure.client import Client\nfrom interactive_markers.interactive_marker_server"
                    " import *\nrospy.init_node('n')\nu = diagnostic_updater.Updater()\n"
                    "s = Server(Cfg, cb)\na = Server(Cfg, cb, namespace='arm')\nt = Server(Cfg, cb, namespace='/abs')\n"
                    "c = Client('other')\nm = InteractiveMarkerServer('marks')\n", "x.py")
    got = {(e.kind, e.topic, e.src.line) for e in r["endpoints"]}
    assert {("pub", "/diagnostics", 6), ("service_servers", "~set_parameters", 7), ("pub", "~parameter_updates", 7),
            ("service_servers", "~arm/set_parameters", 8), ("service_servers", "/abs/set_parameters", 9),
            ("service_clients", "other/set_parameters", 10), ("sub", "other/parameter_descriptions", 10),
            ("pub", "marks/update", 11), ("sub", "marks/feedback", 11)} <= got


def test_helpers_as_base_class_and_through_another_files_typedef(tmp_path: Path) -> None:
    _pkg(tmp_path, "mon", {
        "CMakeLists.txt": "project(mon)\nadd_executable(mon src/main.cpp src/monitor.cpp)\n",
        "include/mon/monitor.h": "namespace mon {\ntypedef dynamic_reconfigure::Server<mon::Cfg> Srv;\n"
                                 "class Monitor : public diagnostic_updater::Updater {\n public:\n"
                                 "  explicit Monitor(ros::NodeHandle nh);\n  boost::shared_ptr<Srv> srv_;\n};\n}\n",
        "src/monitor.cpp": "#include \"mon/monitor.h\"\nusing namespace mon;\nMonitor::Monitor(ros::NodeHandle nh)\n"
                           "  : Updater(nh) {\n  srv_.reset(new Srv(nh));\n}\n",
        "src/main.cpp": "#include \"mon/monitor.h\"\nint main(int argc, char** argv) {\n"
                        "  ros::init(argc, argv, \"mon\");\n  ros::NodeHandle nh(\"~\");\n  mon::Monitor m(nh);\n}\n"})
    g = scan([tmp_path], base=tmp_path, standard=False).graph
    assert {(role, t, at) for _n, role, t, _ty, at in _edges(g)} == {
        ("pub", "/diagnostics", "monitor.cpp:4"), ("service_servers", "/mon/set_parameters", "monitor.cpp:5"),
        ("pub", "/mon/parameter_descriptions", "monitor.cpp:5"), ("pub", "/mon/parameter_updates", "monitor.cpp:5")}


# -- names ----------------------------------------------------------------------------------
@pytest.mark.parametrize("code", [
    'char t[] = "range00";\n  snprintf(t, sizeof(t), "range%02d", i);',
    'std::string t = "range";\n  t += std::to_string(i);',
    'std::string t = "range";\n  t.append("_raw");'])
def test_a_string_changed_in_place_is_not_read_as_its_first_value(code: str) -> None:
    r = scan_cpp(f"void f(int i) {{\n  ros::NodeHandle nh;\n  {code}\n  nh.advertise<std_msgs::Int32>(t, 1);\n}}\n"
                 .encode(), "x.cpp")
    assert r["endpoints"] == [] and [n.message for n in r["notes"]] == [
        "publisher topic name is 't', not a string literal: not resolved statically"]


def test_classes_defined_out_of_line_through_using_and_typedef(tmp_path: Path) -> None:
    hdr = "namespace bot {{\nclass {c} : public rclcpp::Node {{\n public:\n  explicit {c}(int x);\n}};\n}}\n"
    body = "{u}\n{c}::{c}(int x)\n: Node(\"{n}\") {{\n  create_publisher<std_msgs::msg::Int32>(\"{n}_out\", 1);\n}}\n"
    files = {"CMakeLists.txt": "project(p)\nadd_library(l src/a.cpp src/b.cpp src/c.cpp)\n"
                               "add_executable(e src/main.cpp)\ntarget_link_libraries(e l)\n",
             "src/main.cpp": "#include \"p/a.hpp\"\n#include \"p/b.hpp\"\n#include \"p/c.hpp\"\n"
                             "int main() {\n  auto a = std::make_shared<bot::A>(1);\n"
                             "  auto b = std::make_shared<bot::B>(2);\n  auto c = std::make_shared<bot::C>(3);\n}\n"}
    for c, u in (("A", "using bot::A;"), ("B", "typedef bot::B B;"), ("C", "using namespace bot;")):
        files[f"include/p/{c.lower()}.hpp"] = hdr.format(c=c)
        files[f"src/{c.lower()}.cpp"] = f"#include \"p/{c.lower()}.hpp\"\n" + body.format(u=u, c=c, n=c.lower())
    _pkg(tmp_path, "p", files, ros2=True)
    g = scan([tmp_path], base=tmp_path, standard=False).graph
    assert _edges(g) == {(f"/{n}", "pub", f"/{n}_out", "std_msgs/msg/Int32", f"{n}.cpp:5") for n in "abc"}


# -- lifecycle ------------------------------------------------------------------------------
def test_lifecycle_nodes_are_marked_and_their_management_interface_counts_as_served() -> None:
    g = scan([CORPUS / "idioms4"], base=CORPUS, standard=False).graph
    assert {n.name for n in g.nodes.values() if n.lifecycle} == {"/brake", "/pump"}
    assert g.nodes["/brake"].to_json()["lifecycle"] is True and "lifecycle" not in g.nodes["/odometer"].to_json()
    # not edges of the code ...
    assert not [e for n in g.nodes.values() for e in n.service_servers if "change_state" in e.topic]
    # ... but served and published for the grounding
    served = servers(g.nodes, "service")
    assert {"/brake/change_state", "/brake/get_state", "/pump/get_available_transitions"} <= set(served)
    assert [e.topic for e in implicit(g.nodes["/brake"], "pub")] == ["/brake/transition_event"]
    assert implicit(GraphNode("/x", "/", None, None, declared_at=Src("f", 1)), "service_servers") == []
    assert len(MANAGEMENT) == 6


# -- noise ----------------------------------------------------------------------------------
def test_qt_access_specifiers_are_no_syntax_error() -> None:
    code = b"class W : public QWidget {\n  Q_OBJECT\n public:\n  W();\n private slots:\n  void tick();\n" \
           b"signals:\n  void changed();\n public Q_SLOTS:\n  void f();\n};\n"
    assert len(prepare(code)) == len(code)
    assert scan_cpp(code, "w.cpp")["notes"] == []


@pytest.mark.skipif(not Path("/usr/share/std_srvs/srv").is_dir(), reason="Debian's ros-std-srvs is not installed")
def test_a_ros2_scan_knows_std_srvs_but_keeps_ros2_messages(tmp_path: Path) -> None:
    _pkg(tmp_path, "p", {"CMakeLists.txt": "project(p)\nadd_executable(n src/n.cpp)\n",
                         "src/n.cpp": "class N : public rclcpp::Node {\n public:\n  N() : Node(\"n\") {\n"
                                      "    create_service<std_srvs::srv::SetBool>(\"enable\", cb);\n  }\n};\n"},
         ros2=True)
    res = scan([tmp_path], base=tmp_path)
    assert res.table.get("std_srvs/srv/SetBool_Request") is not None
    header = res.table.get("std_msgs/msg/Header")
    assert header is not None and "seq" not in [f[0] for f in header.fields]  # ROS 2's Header


def test_camera_info_manager_serves_set_camera_info_through_its_handle() -> None:
    r = scan_cpp(b'void f() {\n  ros::NodeHandle pnh("~");\n'
                 b'  camera_info_manager::CameraInfoManager cim(pnh, "cam", "file:///c.yaml");\n}\n', "x.cpp")
    assert _eps(r) == {("service_servers", "set_camera_info", "sensor_msgs/srv/SetCameraInfo", ("~",))}


def test_a_header_no_program_includes_is_not_reported_for_its_callers_names(tmp_path: Path) -> None:
    _pkg(tmp_path, "lib", {
        "CMakeLists.txt": "project(lib)\nadd_executable(n src/n.cpp)\n",
        "src/n.cpp": "int main(int argc, char** argv) {\n  ros::init(argc, argv, \"n\");\n}\n",
        "include/lib/relay.hpp": "class Relay {\n public:\n  Relay(ros::NodeHandle nh, const std::string& topic)\n"
                                 "  { pub_ = nh.advertise<std_msgs::String>(topic, 1); }\n  ros::Publisher pub_;\n};\n"})
    g = scan([tmp_path], base=tmp_path, standard=False).graph
    assert not [n for n in g.notes if "not a string literal" in n.message] and _edges(g) == set()


@pytest.mark.parametrize("py2", [False, True])
def test_percent_formatting_of_read_names_in_both_python_readers(py2: bool) -> None:
    src = ("print 'legacy'\n" if py2 else "") + (
        "import rospy\nROBOT = 'rover'\nrospy.init_node('n')\n"
        "a = rospy.Publisher('/%s/cmd_vel' % ROBOT, T)\n"
        "b = rospy.Publisher('%s/%s/scan' % (ROBOT, 'front'), T)\n"
        "c = rospy.Publisher('%d/x' % 3, T)\n"
        "d = rospy.Publisher('/%s/pose' % rospy.get_param('~turtle'), T)\n")
    r = scan_python(src, "x.py")
    assert [e.topic for e in r["endpoints"]] == ["/rover/cmd_vel", "rover/front/scan", ""]
    assert r["endpoints"][2].param == "~turtle" and r["endpoints"][2].affix == ("/", "/pose")
    assert len([n for n in r["notes"] if "not a string literal" in n.message]) == 1


def test_a_name_built_around_a_parameter_takes_each_launch_value(tmp_path: Path) -> None:
    _pkg(tmp_path, "tt", {
        "CMakeLists.txt": "project(tt)\ncatkin_install_python(PROGRAMS nodes/follow.py DESTINATION bin)\n",
        "nodes/follow.py": "import rospy\nfrom turtlesim.msg import Pose\nrospy.init_node('follow')\n"
                           "name = rospy.get_param('~turtle')\n"
                           "rospy.Subscriber('/%s/pose' % name, Pose, cb)\n"
                           "rospy.Publisher(rospy.get_param('~leader', 'turtle1') + '/cmd_vel', Pose)\n",
        "launch/two.launch": '<launch>\n<node pkg="tt" type="follow.py" name="a"><param name="turtle" value="t1"/>'
                             '</node>\n<node pkg="tt" type="follow.py" name="b"><param name="turtle" value="t2"/>'
                             '<param name="leader" value="t1"/></node>\n</launch>\n'})
    g = scan([tmp_path], [tmp_path / "tt" / "launch" / "two.launch"], base=tmp_path, standard=False).graph
    # the code's default alone is not taken for a name built around the parameter
    assert {(n, t) for n, _r, t, _ty, _at in _edges(g)} == {("/a", "/t1/pose"), ("/b", "/t2/pose"),
                                                           ("/b", "/t1/cmd_vel")}
    assert [e.param for e in g.nodes["/b"].subscribes] == ["/b/turtle"]
    assert [n.message for n in g.notes if n.src.line == 6] == [
        "publisher topic name is 'rospy.get_param('~leader', 'turtle1') + '/cmd_vel'', not a string literal: "
        "not resolved statically"]


def test_a_node_class_made_through_a_factory_is_each_node_with_the_class_endpoints(tmp_path: Path) -> None:
    _pkg(tmp_path, "fac", {"CMakeLists.txt": "project(fac)\nadd_executable(f src/main.cpp)\n",
                           "src/main.cpp": "class Wheel : public rclcpp::Node {\n public:\n"
                                           "  explicit Wheel(const std::string & name) : Node(name) {\n"
                                           "    create_publisher<std_msgs::msg::Float64>(\"~/speed\", 10);\n  }\n};\n"
                                           "std::shared_ptr<Wheel> make(const std::string & n) "
                                           "{ return std::make_shared<Wheel>(n); }\n"
                                           "int main() {\n  auto a = make(\"left\");\n  auto b = make(\"right\");\n}\n"},
         ros2=True)
    g = scan([tmp_path], base=tmp_path, standard=False).graph
    assert _edges(g) == {("/left", "pub", "/left/speed", "std_msgs/msg/Float64", "main.cpp:4"),
                         ("/right", "pub", "/right/speed", "std_msgs/msg/Float64", "main.cpp:4")}


def test_an_actionlib_client_through_a_typedef_under_using_namespace(tmp_path: Path) -> None:
    _pkg(tmp_path, "at", {"CMakeLists.txt": "project(at)\nadd_executable(c src/c.cpp)\n",
                          "src/c.cpp": "#include <actionlib/client/simple_action_client.h>\nusing namespace std;\n"
                                       "using namespace at_msgs;\n"
                                       "typedef actionlib::SimpleActionClient<DockAction> Client;\n"
                                       "int main(int argc, char** argv) {\n  ros::init(argc, argv, \"docker\");\n"
                                       "  Client ac(\"dock\", true);\n}\n"})
    g = scan([tmp_path], base=tmp_path, standard=False).graph
    assert _edges(g) == {("/docker", "action_clients", "/dock", "at_msgs/action/Dock", "c.cpp:7")}
