"""Launch files as ``ros2 launch`` runs them, and only code that is built
(issue 108).  Each idiom a user met, read by the project's evaluator over the
launch file's own syntax (never run), with a control showing the other side:

* ``LifecycleNode`` / ``<lifecycle_node>`` / YAML ``lifecycle_node`` are nodes
  (before: launch files read as empty, ``init`` said "no ROS node found");
* ``SetRemap``, ``<set_remap>``, ``ros_arguments`` and ``--ros-args -r`` in
  ``arguments`` remap the node's names, so a type clash behind the remap is
  one topic with two types (before: ignored without a note);
* ROS 1 nodelets and ``ros::init`` programs no target of an ament package
  builds are listed apart as not built, never nodes (before: nodes, and
  contracts from ``init``);
* ``DeclareLaunchArgument`` defaulting to ``EnvironmentVariable(...,
  default_value=)`` or ``TextSubstitution`` gives its value; what cannot be
  known drops the attribute, never the node (before: the node skipped);
* ``OpaqueFunction``, list comprehensions and ``RegisterEventHandler(
  OnProcessExit(on_exit=[...]))`` start their nodes, or a note says why not
  (before: dropped with no note);
* a YAML ``group:`` written as a list (before: dropped silently);
* C++ under ``#if 0`` is not read (before: read as live).

The workspace is written by the tests into a temporary directory: package
``demo`` (ament_cmake) has a ``talker`` publishing ``chatter``
(``std_msgs/msg/String``) and a ``listener`` subscribing ``heard``
(``std_msgs/msg/Int32``).
"""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.cli.commands import main
from rclverify.ros.extract.model import Graph
from rclverify.ros.extract.sources_cpp import scan_cpp
from rclverify.ros.graph import summary
from rclverify.ros.graph.scan import scan

PKG = ('<?xml version="1.0"?>\n<package format="3"><name>{name}</name><version>0.1.0</version>'
       '<description>d</description><maintainer email="dev@example.org">a</maintainer><license>MIT</license>'
       '<buildtool_depend>{tool}</buildtool_depend><depend>rclcpp</depend><depend>std_msgs</depend>'
       '<export><build_type>{tool}</build_type>{export}</export></package>\n')
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
LISTENER = """#include <rclcpp/rclcpp.hpp>
#include <std_msgs/msg/int32.hpp>
class Listener : public rclcpp::Node
{
public:
  Listener() : Node("listener")
  {
    sub_ = create_subscription<std_msgs::msg::Int32>("heard", 10, [](std_msgs::msg::Int32::SharedPtr) {});
  }
  rclcpp::Subscription<std_msgs::msg::Int32>::SharedPtr sub_;
};
int main(int argc, char ** argv) { rclcpp::init(argc, argv); rclcpp::spin(std::make_shared<Listener>()); }
"""
CMAKE = "cmake_minimum_required(VERSION 3.8)\nproject({name})\nfind_package(rclcpp REQUIRED)\n"
PY_HEAD = ("import os\nfrom launch import LaunchDescription\n"
           "from launch.actions import DeclareLaunchArgument, ExecuteProcess, GroupAction, OpaqueFunction, "
           "RegisterEventHandler\n"
           "from launch.event_handlers import OnProcessExit\n"
           "from launch.substitutions import EnvironmentVariable, LaunchConfiguration, TextSubstitution\n"
           "from launch_ros.actions import LifecycleNode, Node, SetRemap\n\n\n")


def _write(root: Path, files: dict[str, str]) -> None:
    for rel, text in files.items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(text)


@pytest.fixture(scope="module")
def ws(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("launchrun")
    _write(root / "ws" / "demo", {
        "package.xml": PKG.format(name="demo", tool="ament_cmake", export=""),
        "CMakeLists.txt": CMAKE.format(name="demo") + "add_executable(talker src/talker.cpp)\n"
                                                      "add_executable(listener src/listener.cpp)\n",
        "src/talker.cpp": TALKER, "src/listener.cpp": LISTENER})
    return root


def _py(ws: Path, name: str, body: str, before: str = "") -> Path:
    """A Python launch file of package demo whose LaunchDescription lists ``body``."""
    f = ws / "ws" / "demo" / "launch" / name
    f.parent.mkdir(exist_ok=True)
    f.write_text(PY_HEAD + before + "def generate_launch_description():\n    return LaunchDescription([\n"
                 + "".join(f"        {line}\n" for line in body.strip().splitlines()) + "    ])\n")
    return f


def _launch(ws: Path, name: str, text: str) -> Path:
    f = ws / "ws" / "demo" / "launch" / name
    f.parent.mkdir(exist_ok=True)
    f.write_text(text)
    return f


def _graph(ws: Path, lf: Path, args: dict[str, str] | None = None) -> Graph:
    return scan([ws / "ws"], [lf], args, base=ws, standard=False).graph


def _subs(g: Graph, node: str) -> set[tuple[str, str | None]]:
    return {(e.topic, e.msg_type) for e in g.nodes[node].subscribes}


def _said(g: Graph) -> list[str]:
    return [str(n) for n in g.notes]


# -- LifecycleNode ---------------------------------------------------------------

def test_lifecycle_nodes_are_nodes_in_every_format(ws: Path) -> None:
    py = _py(ws, "lc.launch.py", "LifecycleNode(package='demo', executable='listener', name='lc', namespace='arm'),")
    xml = _launch(ws, "lc.launch.xml", '<launch>\n  <lifecycle_node pkg="demo" exec="listener" name="lc" '
                                       'namespace="arm"/>\n</launch>\n')
    yml = _launch(ws, "lc.launch.yaml", "launch:\n- lifecycle_node:\n    pkg: demo\n    exec: listener\n"
                                        "    name: lc\n    namespace: arm\n")
    for lf in (py, xml, yml):
        g = _graph(ws, lf)
        assert sorted(g.nodes) == ["/arm/lc"], lf.name
        assert _subs(g, "/arm/lc") == {("/arm/heard", "std_msgs/msg/Int32")}
        assert _said(g) == [], lf.name


def test_an_action_the_scan_does_not_know_is_named_at_its_line(ws: Path) -> None:
    # control: a workspace's own wrapper action is no node, and never a silent miss
    lf = _py(ws, "own.launch.py", "MyLifecycle(package='demo', executable='listener'),")
    g = _graph(ws, lf)
    assert g.nodes == {}
    assert _said(g) == ["ws/demo/launch/own.launch.py:11:9: warning: launch action MyLifecycle(...) is not one the "
                        "scan reads: the nodes it starts, if any, are unknown"]


def test_init_from_a_lifecycle_launch_file_writes_its_contract(ws: Path, tmp_path: Path,
                                                                capsys: pytest.CaptureFixture[str]) -> None:
    lf = _py(ws, "lc_init.launch.py", "LifecycleNode(package='demo', executable='listener', name='lc', "
                                      "namespace='arm'),")
    out = tmp_path / "rig"
    assert main(["init", str(out), "--from-ros", str(ws / "ws"), "--launch", str(lf)]) == 0
    assert "no ROS node found" not in capsys.readouterr().out
    rcl = "".join(p.read_text() for p in (out / "contracts").glob("*.rcl"))
    assert "node Lc" in rcl and "heard" in rcl


# -- remaps ------------------------------------------------------------------------

REMAPPED = {("/chatter", "std_msgs/msg/Int32")}
TALK = "Node(package='demo', executable='talker'),"


@pytest.mark.parametrize("how", [
    "SetRemap(src='heard', dst='chatter'),\nNode(package='demo', executable='listener'),",
    "GroupAction([SetRemap('heard', 'chatter'), Node(package='demo', executable='listener')]),",
    "Node(package='demo', executable='listener', ros_arguments=['-r', 'heard:=chatter']),",
    "Node(package='demo', executable='listener', arguments=['--verbose', '--ros-args', '-r', 'heard:=chatter']),",
    "Node(package='demo', executable='listener', arguments=['--ros-args', '--remap', 'listener:heard:=chatter']),",
])
def test_remaps_in_python_launch_files_rename_the_nodes_names(ws: Path, how: str) -> None:
    g = _graph(ws, _py(ws, "remap.launch.py", TALK + "\n" + how))
    assert _subs(g, "/listener") == REMAPPED
    # the type clash behind the remap is now one topic with two types
    assert g.topics()["/chatter"]["types"] == ["std_msgs/msg/Int32", "std_msgs/msg/String"]
    assert _said(g) == []


@pytest.mark.parametrize("how", [
    "Node(package='demo', executable='listener', arguments=['heard:=chatter']),",  # a program argument
    "GroupAction([SetRemap('heard', 'chatter')]),\nNode(package='demo', executable='listener'),",  # scoped
    "Node(package='demo', executable='listener', name='listener', arguments=['--ros-args', '-r', "
    "'other:heard:=chatter']),",  # a remap for another node
])
def test_what_is_no_remap_of_the_node_leaves_its_name(ws: Path, how: str) -> None:
    g = _graph(ws, _py(ws, "noremap.launch.py", TALK + "\n" + how))
    assert _subs(g, "/listener") == {("/heard", "std_msgs/msg/Int32")}


def test_remaps_in_xml_and_yaml_launch_files(ws: Path) -> None:
    # set_remap applies to the nodes after it in its scope (the node before it keeps its own remap)
    xml = _launch(ws, "remap.launch.xml", '<launch>\n'
                                          '  <node pkg="demo" exec="listener" name="two" ros_args="-r heard:=two_in"/>\n'
                                          '  <set_remap from="heard" to="chatter"/>\n'
                                          '  <node pkg="demo" exec="listener"/>\n'
                                          '  <node pkg="demo" exec="listener" name="three" '
                                          'args="--ros-args -r __ns:=/deck"/>\n</launch>\n')
    g = _graph(ws, xml)
    assert _subs(g, "/listener") == REMAPPED
    assert _subs(g, "/two") == {("/two_in", "std_msgs/msg/Int32")}
    assert sorted(g.nodes) == ["/deck/three", "/listener", "/two"]
    yml = _launch(ws, "remap.launch.yaml", "launch:\n- set_remap:\n    from: heard\n    to: chatter\n"
                                           "- node:\n    pkg: demo\n    exec: listener\n")
    assert _subs(_graph(ws, yml), "/listener") == REMAPPED


def test_a_remap_argument_that_cannot_be_read_is_said_and_the_node_kept(ws: Path) -> None:
    lf = _py(ws, "badargs.launch.py", "Node(package='demo', executable='listener', "
                                      "ros_arguments=['-r', os.environ['REMAP']]),")
    g = _graph(ws, lf)
    assert _subs(g, "/listener") == {("/heard", "std_msgs/msg/Int32")}
    [note] = _said(g)
    assert note.startswith("ws/demo/launch/badargs.launch.py:11:") and "its ROS arguments are left out" in note


# -- launch argument defaults ----------------------------------------------------

ARGS = """DeclareLaunchArgument('robot', default_value=EnvironmentVariable('RCLV_TEST_UNSET_ROBOT', default_value='rover')),
DeclareLaunchArgument('deck', default_value=TextSubstitution(text='upper')),
DeclareLaunchArgument('bare', default_value=EnvironmentVariable('RCLV_TEST_UNSET_BARE')),
Node(package='demo', executable='listener', name=LaunchConfiguration('robot'), namespace=LaunchConfiguration('deck')),
Node(package='demo', executable='talker', name=LaunchConfiguration('bare')),"""


def test_argument_defaults_from_environment_and_text_substitutions(ws: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("RCLV_TEST_UNSET_ROBOT", raising=False)
    monkeypatch.delenv("RCLV_TEST_UNSET_BARE", raising=False)
    lf = _py(ws, "args.launch.py", ARGS)
    g = _graph(ws, lf)
    # the unset variable without a default: its node is kept, without the name, said at its line
    assert sorted(g.nodes) == ["/talker", "/upper/rover"]
    assert _said(g) == ["ws/demo/launch/args.launch.py:13:9: warning: <arg> bare: $(env RCLV_TEST_UNSET_BARE): "
                        "not set; the argument has no value",
                        "ws/demo/launch/args.launch.py:15:9: warning: <node>: name: $(var bare): argument 'bare' "
                        "has no value; the node is kept without it"]
    # control: set, the variable gives the name; an argument given overrides the default
    monkeypatch.setenv("RCLV_TEST_UNSET_BARE", "speaker")
    monkeypatch.setenv("RCLV_TEST_UNSET_ROBOT", "crawler")
    g = _graph(ws, lf, {"deck": "lower"})
    assert sorted(g.nodes) == ["/lower/crawler", "/speaker"] and _said(g) == []


# -- OpaqueFunction, comprehensions, event handlers ------------------------------

SETUP = """def launch_setup(context, *args, **kwargs):
    robot = LaunchConfiguration('robot').perform(context)
    listener = Node(package='demo', executable='listener', name=robot + '_ears')
    return [listener, Node(package='demo', executable='talker', name=f'{robot}_mouth')]


"""
BRANCHED = """def launch_setup(context, *args, **kwargs):
    if LaunchConfiguration('sim').perform(context) == 'true':
        return [Node(package='demo', executable='talker', name='sim_talker')]
    return [Node(package='demo', executable='talker')]


"""


def test_an_opaque_function_built_from_literals_is_evaluated(ws: Path) -> None:
    lf = _py(ws, "opaque.launch.py", "DeclareLaunchArgument('robot', default_value='rover'),\n"
                                     "OpaqueFunction(function=launch_setup),", SETUP)
    g = _graph(ws, lf)
    assert sorted(g.nodes) == ["/rover_ears", "/rover_mouth"] and _said(g) == []


def test_what_an_opaque_function_pushes_stays_after_it_and_a_group_scopes_it(ws: Path) -> None:
    pushed = "def pushes(context):\n    return [PushRosNamespace('deck'), SetRemap('heard', 'chatter')]\n\n\n"
    lf = _py(ws, "pushes.launch.py", "OpaqueFunction(function=pushes),\nNode(package='demo', executable='listener'),",
             "from launch_ros.actions import PushRosNamespace\n\n\n" + pushed)
    g = _graph(ws, lf)
    assert _subs(g, "/deck/listener") == {("/deck/chatter", "std_msgs/msg/Int32")}
    # control: the same function inside a GroupAction, which scopes what it pushes
    lf = _py(ws, "pushes_grouped.launch.py", "GroupAction([OpaqueFunction(function=pushes)]),\n"
                                             "Node(package='demo', executable='listener'),",
             "from launch_ros.actions import PushRosNamespace\n\n\n" + pushed)
    assert _subs(_graph(ws, lf), "/listener") == {("/heard", "std_msgs/msg/Int32")}


def test_an_opaque_function_chosen_at_run_time_is_named_on_the_first_screen(ws: Path) -> None:
    lf = _py(ws, "branched.launch.py", "OpaqueFunction(function=launch_setup),", BRANCHED)
    g = _graph(ws, lf)
    assert g.nodes == {}
    assert _said(g) == ["ws/demo/launch/branched.launch.py:17:9: warning: OpaqueFunction launch_setup not "
                        "evaluated: it has 2 return statements (which one runs is chosen at run time); the nodes "
                        "it starts are unknown"]
    # past one screen of warnings, the cause line is the first and names the function
    many = g.notes + [g.notes[0].__class__(g.notes[0].src, f"name of pub comes from parameter ~p{i}, which has "
                                                             f"no default") for i in range(30)]
    lines = summary.report(many, {"ws/demo/package.xml": "demo"})
    assert lines[1].split(":", 1)[1].strip() .startswith("OpaqueFunction launch_setup at ws/demo/launch/branched")
    assert "launch actions not evaluated" in lines[1]


def test_list_comprehensions_over_known_lists_start_each_node(ws: Path) -> None:
    lf = _py(ws, "comp.launch.py",
             "*[Node(package='demo', executable='listener', name=f'{side}_ears', namespace=deck)\n"
             "  for side, deck in [('left', 'port'), ('right', 'starboard')]],\n"
             "*[Node(package='demo', executable='talker', name=n) for n in TALKERS if n != 'quiet'],",
             "TALKERS = ['one', 'two', 'quiet']\n\n\n")
    g = _graph(ws, lf)
    assert sorted(g.nodes) == ["/one", "/port/left_ears", "/starboard/right_ears", "/two"] and _said(g) == []
    # control: over what only running says (a directory listing), the comprehension is named, not guessed
    lf = _py(ws, "comp_dir.launch.py", "*[Node(package='demo', executable='talker', name=n) for n in os.listdir('.')],")
    g = _graph(ws, lf)
    assert g.nodes == {}
    [note] = _said(g)
    assert note.startswith("ws/demo/launch/comp_dir.launch.py:11:10: warning: launch actions built by a list "
                           "comprehension over 'os.listdir('.')'") and "the nodes it starts are unknown" in note


def test_nodes_started_by_an_event_handler_are_started(ws: Path) -> None:
    lf = _py(ws, "events.launch.py",
             "first,\nRegisterEventHandler(OnProcessExit(target_action=first, on_exit=[\n"
             "    Node(package='demo', executable='listener', name='after')])),",
             "first = Node(package='demo', executable='talker')\n\n\n")
    # `first` is bound at module level; the handler's node is started too
    g = _graph(ws, lf)
    assert sorted(g.nodes) == ["/after", "/talker"] and _said(g) == []
    # control: actions computed by a function run at the event cannot be read, and that is said
    lf = _py(ws, "events_fn.launch.py",
             "RegisterEventHandler(OnProcessExit(on_exit=lambda event, context: [Node(package='demo', "
             "executable='listener')])),")
    g = _graph(ws, lf)
    assert g.nodes == {}
    [note] = _said(g)
    assert note.startswith("ws/demo/launch/events_fn.launch.py:11:9: warning: RegisterEventHandler(...): the "
                           "actions of OnProcessExit, a function run at the event, cannot be read statically")


def _grow(ws: Path, name: str, grow: str) -> Path:
    f = ws / "ws" / "demo" / "launch" / name
    f.parent.mkdir(exist_ok=True)
    f.write_text(PY_HEAD + "def generate_launch_description():\n"
                 "    nodes = [Node(package='demo', executable='talker')]\n" + grow +
                 "    return LaunchDescription(nodes)\n")
    return f


def test_a_list_of_actions_grown_in_order_is_read_whole(ws: Path) -> None:
    lf = _grow(ws, "grow.launch.py", "    nodes.append(Node(package='demo', executable='listener'))\n"
                                     "    nodes += [Node(package='demo', executable='listener', name='two')]\n")
    g = _graph(ws, lf)
    assert sorted(g.nodes) == ["/listener", "/talker", "/two"] and _said(g) == []
    # control: grown under a condition only running decides, the list is named, not guessed
    lf = _grow(ws, "grow_if.launch.py", "    if os.environ.get('SIM'):\n"
                                        "        nodes.append(Node(package='demo', executable='listener'))\n")
    g = _graph(ws, lf)
    assert sorted(g.nodes) == ["/talker"]
    assert _said(g) == ["ws/demo/launch/grow_if.launch.py:13:30: warning: launch actions 'nodes' is grown at line "
                        "12 inside a block or a loop (chosen at run time): not resolved statically"]


def test_a_process_running_ros2_run_is_its_node(ws: Path) -> None:
    lf = _py(ws, "exec.launch.py", "ExecuteProcess(cmd=['ros2', 'run', 'demo', 'listener', '--ros-args', '-r', "
                                   "'__node:=ears', '-r', 'heard:=chatter']),")
    g = _graph(ws, lf)
    assert sorted(g.nodes) == ["/ears"] and _subs(g, "/ears") == REMAPPED and _said(g) == []
    # control: another program is no node read, and said so
    lf = _py(ws, "exec_other.launch.py", "ExecuteProcess(cmd=['gzserver', '--verbose']),")
    g = _graph(ws, lf)
    assert g.nodes == {}
    assert _said(g) == ["ws/demo/launch/exec_other.launch.py:11:9: warning: ExecuteProcess(...) runs 'gzserver "
                        "--verbose', not 'ros2 run PKG EXE': the nodes it starts, if any, are unknown"]


# -- YAML group as a list --------------------------------------------------------

def test_a_yaml_group_written_as_a_list(ws: Path) -> None:
    lf = _launch(ws, "group.launch.yaml", "launch:\n- group:\n  - push_ros_namespace:\n      namespace: g1\n"
                                          "  - node:\n      pkg: demo\n      exec: talker\n"
                                          "- node:\n    pkg: demo\n    exec: listener\n")
    g = _graph(ws, lf)
    assert sorted(g.nodes) == ["/g1/talker", "/listener"] and _said(g) == []
    # control: the mapping form with children keeps working, and the namespace stays inside the group
    lf = _launch(ws, "group_map.launch.yaml", "launch:\n- group:\n    children:\n    - push-ros-namespace:\n"
                                              "        namespace: g2\n    - node:\n        pkg: demo\n"
                                              "        exec: talker\n- node:\n    pkg: demo\n    exec: listener\n")
    assert sorted(_graph(ws, lf).nodes) == ["/g2/talker", "/listener"]


# -- only what is built ----------------------------------------------------------

NODELET = """#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.h>
#include <ros/ros.h>
#include <std_msgs/String.h>
namespace port {
class FilterNodelet : public nodelet::Nodelet {
  void onInit() override { pub_ = getNodeHandle().advertise<std_msgs::String>("filtered", 1); }
  ros::Publisher pub_;
};
}
PLUGINLIB_EXPORT_CLASS(port::FilterNodelet, nodelet::Nodelet)
"""
ROS1_MAIN = """#include <ros/ros.h>
#include <std_msgs/String.h>
int main(int argc, char ** argv)
{
  ros::init(argc, argv, "old_node");
  ros::NodeHandle nh;
  ros::Publisher p = nh.advertise<std_msgs::String>("out", 1);
  ros::spin();
}
"""
PLUGINS = ('<library path="lib/libport_nodelets">\n  <class name="port/Filter" type="port::FilterNodelet" '
           'base_class_type="nodelet::Nodelet"><description>f</description></class>\n</library>\n')


def _port(root: Path, tool: str, cmake_more: str) -> Path:
    _write(root / "port", {
        "package.xml": PKG.format(name="port", tool=tool, export='<nodelet plugin="${prefix}/nodelet_plugins.xml"/>'),
        "nodelet_plugins.xml": PLUGINS,
        "CMakeLists.txt": CMAKE.format(name="port") + "add_executable(relay src/talker.cpp)\n" + cmake_more,
        "src/talker.cpp": TALKER, "src/filter_nodelet.cpp": NODELET, "src/old_main.cpp": ROS1_MAIN})
    return root


def test_ros1_code_no_ament_target_builds_is_listed_apart(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ws = _port(tmp_path / "ws", "ament_cmake", "")
    g = scan([ws], [], base=tmp_path, standard=False).graph
    assert sorted(g.nodes) == ["/talker"]
    apart = sorted((p["kind"], p["name"], p["declared"]["line"], p["unaccounted"]) for p in g.programs
                   if p["kind"] == "not built")
    assert apart == [("not built", "old_main.cpp", 5, None), ("not built", "port/Filter", 11, None)]
    said = sorted((n.code, str(n.src)) for n in g.notes)
    assert said == [("ROS-NOT-BUILT", "ws/port/src/filter_nodelet.cpp:11:1"),
                    ("ROS-NOT-BUILT", "ws/port/src/old_main.cpp:5:3")]
    assert summary.cause_of("ROS-NOT-BUILT", g.notes[0].message).key == "not-built"  # not "launch attributes"
    out = tmp_path / "rig"
    assert main(["init", str(out), "--from-ros", str(ws)]) == 0
    capsys.readouterr()
    assert sorted(p.name for p in (out / "contracts").glob("*.rcl") if p.name != "ros_types.rcl") == ["talker.rcl"]
    # a ROS 1 launch file loading the nodelet is told it is not built
    lf = tmp_path / "filter.launch"
    lf.write_text('<launch>\n  <node pkg="nodelet" type="nodelet" name="filter" args="load port/Filter mgr"/>\n'
                  '</launch>\n')
    g = scan([ws], [lf], base=tmp_path, standard=False).graph
    assert "filter.launch:2:1: warning: nodelet 'port/Filter': package 'port' has it, not built (no target of its " \
           "CMakeLists.txt builds its sources); its topics are unknown" in _said(g)


@pytest.mark.parametrize("tool, more", [
    ("ament_cmake", "add_library(port_nodelets src/filter_nodelet.cpp)\nadd_executable(old src/old_main.cpp)\n"),
    ("catkin", ""),  # a catkin package is built by catkin: its ROS 1 code is read as before
])
def test_ros1_code_that_is_built_stays_nodes(tmp_path: Path, tool: str, more: str) -> None:
    ws = _port(tmp_path / "ws", tool, more)
    g = scan([ws], [], base=tmp_path, standard=False).graph
    assert {"/talker", "/old_node", "/Filter"} <= set(g.nodes)
    assert not [p for p in g.programs if p["kind"] == "not built"]


# -- #if 0 -----------------------------------------------------------------------

def test_code_under_if_0_is_not_read() -> None:
    src = TALKER.replace('    pub_ = create_publisher<std_msgs::msg::String>("chatter", 10);\n',
                         '#if 0\n    old_ = create_publisher<std_msgs::msg::String>("retired", 10);\n'
                         '#  if 1\n    x_ = create_publisher<std_msgs::msg::String>("nested", 10);\n#  endif\n'
                         '#else\n    pub_ = create_publisher<std_msgs::msg::String>("chatter", 10);\n#endif\n'
                         '#if 1\n    on_ = create_publisher<std_msgs::msg::String>("kept", 10);\n#endif\n')
    r = scan_cpp(src.encode(), "talker.cpp")
    assert sorted(e.topic for e in r["endpoints"]) == ["chatter", "kept"]
    assert [e.src.line for e in r["endpoints"] if e.topic == "chatter"] == [14]  # lines unchanged


DUAL = """cmake_minimum_required(VERSION 3.8)
project(dual)
if({cond})
  find_package(catkin REQUIRED COMPONENTS roscpp)
  catkin_package()
  add_executable(old_node src/old_main.cpp)
else()
  find_package(ament_cmake REQUIRED)
  add_executable(talker src/talker.cpp)
  ament_package()
endif()
"""


@pytest.mark.parametrize("cond, tool, apart_", [
    ('"$ENV{ROS_VERSION}" STREQUAL "1"', "ament_cmake", [("old_node", 6)]),
    ("catkin_FOUND", "ament_cmake", [("old_node", 6)]),
    ("NOT ament_cmake_FOUND", "ament_cmake", [("old_node", 6)]),
    ("NOT catkin_FOUND", "ament_cmake", [("talker", 9)]),  # control: the branches swapped
    ("catkin_FOUND", "catkin", []),  # control: a catkin package builds what it declares
])
def test_catkin_only_code_of_a_dual_build_is_not_built(tmp_path: Path, cond: str, tool: str,
                                                       apart_: list[tuple[str, int]]) -> None:
    _write(tmp_path / "ws" / "dual", {
        "package.xml": PKG.format(name="dual", tool=tool, export=""),
        "CMakeLists.txt": DUAL.format(cond=cond), "src/talker.cpp": TALKER, "src/old_main.cpp": ROS1_MAIN})
    g = scan([tmp_path / "ws"], [], base=tmp_path, standard=False).graph
    apart = [(p["name"], p["declared"]["line"]) for p in g.programs if p["kind"] == "not built"]
    assert apart == apart_
    assert sorted(g.nodes) == sorted({"/old_node", "/talker"} - {"/" + name for name, _line in apart_})
    assert not g.unaccounted()
