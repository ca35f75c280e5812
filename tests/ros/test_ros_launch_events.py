"""Launch files as ``ros2 launch`` runs them, every miss said (issue 108, third
part), and the code shapes three published trees counted by hand showed
(docs/grounding.md, "heldout-e").  Each idiom with a control:

* the launch event handlers: ``OnShutdown``'s nodes are never started (launch
  starts no process once shutting down) and are said at their lines;
  ``OnProcessStart``, ``OnExecutionComplete``, ``OnStateTransition`` and
  ``ROSTimer`` start theirs; ``OnProcessIO``'s are functions, said;
* node-scoped remaps ``node:from:=to`` (``remappings``, ``ros_arguments``,
  XML) rename only the node of that name, as rcl applies them;
* an ``if`` of a test known from the file and the environment runs its branch
  (a list of actions grown inside it, ``add_action`` under it); one not known
  is read as holding and said;
* an include argument that cannot be read is said and the include kept;
* a workspace's method named ``create_subscription`` called without template
  arguments is followed into its body (rclcpp's needs the message type);
* a ``tf2_ros::TransformListener`` member initialised with a buffer alone
  subscribes on tf2's own node;
* ``rclcpp_components_register_nodes`` with a class in no namespace.

Packages are written into a temporary directory and read by the scan.
"""
from __future__ import annotations

from pathlib import Path

import pytest
from test_ros_launch_run import CMAKE, LISTENER, PKG, PY_HEAD, TALKER, _write

from rclverify.ros.extract.model import Graph
from rclverify.ros.graph import summary
from rclverify.ros.graph.scan import scan

DUO = """#include <rclcpp/rclcpp.hpp>
#include <std_msgs/msg/int32.hpp>
class Ear : public rclcpp::Node
{
public:
  explicit Ear(const std::string & name) : Node(name)
  {
    sub_ = create_subscription<std_msgs::msg::Int32>("heard", 10, [](std_msgs::msg::Int32::SharedPtr) {});
  }
  rclcpp::Subscription<std_msgs::msg::Int32>::SharedPtr sub_;
};
int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  rclcpp::executors::SingleThreadedExecutor ex;
  auto left = std::make_shared<Ear>("left");
  auto right = std::make_shared<Ear>("right");
  ex.add_node(left);
  ex.add_node(right);
  ex.spin();
}
"""
HEAD = PY_HEAD + ("from launch.actions import TimerAction\n"
                  "from launch.event_handlers import OnExecutionComplete, OnProcessIO, OnProcessStart, OnShutdown\n"
                  "from launch_ros.actions import ROSTimer\nfrom launch_ros.event_handlers import OnStateTransition\n"
                  "from launch_ros.actions import LifecycleTransition\n\n\n")


@pytest.fixture(scope="module")
def ws(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("launchevents")
    _write(root / "ws" / "demo", {
        "package.xml": PKG.format(name="demo", tool="ament_cmake", export=""),
        "CMakeLists.txt": CMAKE.format(name="demo") + "add_executable(talker src/talker.cpp)\n"
                                                      "add_executable(listener src/listener.cpp)\n"
                                                      "add_executable(duo src/duo.cpp)\n",
        "src/talker.cpp": TALKER, "src/listener.cpp": LISTENER, "src/duo.cpp": DUO})
    return root


def _file(ws: Path, name: str, text: str) -> Path:
    f = ws / "ws" / "demo" / "launch" / name
    f.parent.mkdir(exist_ok=True)
    f.write_text(text)
    return f


def _py(ws: Path, name: str, body: str, before: str = "") -> Path:
    return _file(ws, name, HEAD + before + "def generate_launch_description():\n    return LaunchDescription([\n"
                 + "".join(f"        {line}\n" for line in body.strip().splitlines()) + "    ])\n")


def _graph(ws: Path, lf: Path) -> Graph:
    return scan([ws / "ws"], [lf], base=ws, standard=False).graph


def _subs(g: Graph, node: str) -> set[str]:
    return {e.topic for e in g.nodes[node].subscribes}


def _said(g: Graph) -> list[str]:
    return [str(n) for n in g.notes]


# -- event handlers --------------------------------------------------------------

def test_nodes_of_an_on_shutdown_handler_are_said_never_started(ws: Path) -> None:
    lf = _py(ws, "shutdown.launch.py", "Node(package='demo', executable='talker'),\n"
                                       "RegisterEventHandler(OnShutdown(on_shutdown=[\n"
                                       "    Node(package='demo', executable='listener', name='late'),\n"
                                       "    OpaqueFunction(function=lambda _: os.remove('/tmp/x.sdf'))])),")
    g = _graph(ws, lf)
    assert sorted(g.nodes) == ["/talker"]  # and the OpaqueFunction run at shutdown starts nothing: not said
    assert _said(g) == ["ws/demo/launch/shutdown.launch.py:20:13: warning: node 'listener' is started by OnShutdown "
                        "(ws/demo/launch/shutdown.launch.py:19:9): launch starts no process once it is shutting "
                        "down; not a node of the graph"]
    assert summary.cause_of("ROS-LAUNCH", g.notes[0].message).key == "nodes-at-shutdown"
    # control: the same node started when a process exits is a node
    lf = _py(ws, "exit.launch.py", "Node(package='demo', executable='talker'),\n"
                                   "RegisterEventHandler(OnProcessExit(on_exit=[\n"
                                   "    Node(package='demo', executable='listener', name='late')])),")
    g = _graph(ws, lf)
    assert sorted(g.nodes) == ["/late", "/talker"] and _said(g) == []


@pytest.mark.parametrize("handler", ["OnProcessStart(on_start=[ACT])", "OnExecutionComplete(on_completion=[ACT])",
                                     "OnStateTransition(entities=[ACT], goal_state='active')"])
def test_the_other_event_handlers_start_their_nodes(ws: Path, handler: str) -> None:
    act = "Node(package='demo', executable='listener', name='after')"
    lf = _py(ws, "handler.launch.py", f"RegisterEventHandler({handler.replace('ACT', act)}),")
    g = _graph(ws, lf)
    assert sorted(g.nodes) == ["/after"] and _said(g) == []


def test_timers_start_their_nodes_and_output_handlers_are_said(ws: Path) -> None:
    lf = _py(ws, "timers.launch.py", "ROSTimer(period=2.0, actions=[Node(package='demo', executable='talker')]),\n"
                                     "TimerAction(period=1.0, actions=[Node(package='demo', executable='listener')]),\n"
                                     "LifecycleTransition(lifecycle_node_names=['x'], transition_ids=[1]),")
    g = _graph(ws, lf)
    assert sorted(g.nodes) == ["/listener", "/talker"] and _said(g) == []
    # control: OnProcessIO's actions are functions of the process's output, run at the event
    lf = _py(ws, "io.launch.py", "RegisterEventHandler(OnProcessIO(on_stderr=lambda info: [Node(package='demo', "
                                 "executable='talker')])),")
    g = _graph(ws, lf)
    assert g.nodes == {}
    assert _said(g) == ["ws/demo/launch/io.launch.py:18:9: warning: RegisterEventHandler(...): the actions of "
                        "OnProcessIO, a function run at the event, cannot be read statically; action skipped"]


# -- node-scoped remaps ----------------------------------------------------------

@pytest.mark.parametrize("how", ["remappings=[('PREFIX:heard', 'chatter')]",
                                 "ros_arguments=['-r', 'PREFIX:heard:=chatter']",
                                 "arguments=['--ros-args', '--remap', 'PREFIX:rostopic://heard:=chatter']"])
def test_a_node_scoped_remap_renames_only_that_node(ws: Path, how: str) -> None:
    lf = _py(ws, "scoped.launch.py", f"Node(package='demo', executable='listener', {how.replace('PREFIX', 'listener')}),")
    g = _graph(ws, lf)
    assert _subs(g, "/listener") == {"/chatter"} and _said(g) == []
    # control: a rule for another node's name leaves this one as it is
    lf = _py(ws, "scoped.launch.py", f"Node(package='demo', executable='listener', {how.replace('PREFIX', 'talker')}),")
    assert _subs(_graph(ws, lf), "/listener") == {"/heard"}


def test_a_node_scoped_remap_matches_the_name_the_node_runs_with(ws: Path) -> None:
    # rcl matches the rule's node name against the node's name after the launch file renames it
    lf = _py(ws, "renamed.launch.py", "Node(package='demo', executable='listener', name='ears',\n"
                                      "     remappings=[('ears:heard', 'chatter'), ('listener:heard', 'other')]),")
    assert _subs(_graph(ws, lf), "/ears") == {"/chatter"}


def test_a_node_scoped_remap_renames_one_node_of_a_process(ws: Path) -> None:
    lf = _file(ws, "duo.launch.xml", '<launch>\n  <node pkg="demo" exec="duo">\n'
                                     '    <remap from="left:heard" to="/left_ear"/>\n  </node>\n</launch>\n')
    g = _graph(ws, lf)
    assert (_subs(g, "/left"), _subs(g, "/right")) == ({"/left_ear"}, {"/heard"})
    # control: the same rule without the node's name renames both nodes of the process
    lf = _file(ws, "duo.launch.xml", '<launch>\n  <node pkg="demo" exec="duo">\n'
                                     '    <remap from="heard" to="/left_ear"/>\n  </node>\n</launch>\n')
    g = _graph(ws, lf)
    assert (_subs(g, "/left"), _subs(g, "/right")) == ({"/left_ear"}, {"/left_ear"})


# -- if statements -----------------------------------------------------------------

def _bringup(ws: Path, name: str, default: str) -> Path:
    """turtlebot4's bringup form: a list of actions, appended to under an ``if``
    of an environment variable's value, then given to a GroupAction."""
    return _file(ws, name, HEAD + "def generate_launch_description():\n"
                 f"    diag = EnvironmentVariable('RCLVERIFY_TEST_DIAG', default_value='{default}')\n"
                 "    actions = [Node(package='demo', executable='talker')]\n"
                 "    if diag.perform(None) == '1':\n"
                 "        actions.append(Node(package='demo', executable='listener'))\n"
                 "    ld = LaunchDescription()\n"
                 "    ld.add_action(GroupAction(actions))\n"
                 "    if os.environ.get('RCLVERIFY_TEST_SERVER', '').strip(' ;'):\n"
                 "        ld.add_action(Node(package='demo', executable='duo'))\n"
                 "    return ld\n")


def test_an_if_of_a_known_test_runs_its_branch(ws: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("RCLVERIFY_TEST_DIAG", raising=False)
    monkeypatch.delenv("RCLVERIFY_TEST_SERVER", raising=False)
    g = _graph(ws, _bringup(ws, "branch.launch.py", "1"))
    assert sorted(g.nodes) == ["/listener", "/talker"] and _said(g) == []
    # controls: the other default, and the environment, choose the other branches
    g = _graph(ws, _bringup(ws, "branch.launch.py", "0"))
    assert sorted(g.nodes) == ["/talker"] and _said(g) == []
    monkeypatch.setenv("RCLVERIFY_TEST_SERVER", "localhost:11811")
    g = _graph(ws, _bringup(ws, "branch.launch.py", "0"))
    assert sorted(g.nodes) == ["/left", "/right", "/talker"] and _said(g) == []


def test_an_action_added_under_a_test_not_known_is_read_and_said(ws: Path) -> None:
    lf = _file(ws, "unknown_if.launch.py", HEAD + "def generate_launch_description():\n"
               "    ld = LaunchDescription()\n"
               "    if LaunchConfiguration('sim').perform(None) == 'true':\n"
               "        ld.add_action(Node(package='demo', executable='talker'))\n"
               "    return ld\n")
    g = _graph(ws, lf)
    assert sorted(g.nodes) == ["/talker"]
    assert _said(g) == ["ws/demo/launch/unknown_if.launch.py:19:9: warning: add_action(...) under 'if "
                        "LaunchConfiguration('sim').perform(None) == 'true'' (ws/demo/launch/unknown_if.launch.py:18:5), "
                        "a test not read statically: the actions are read as if it held"]


# -- includes ----------------------------------------------------------------------

def test_an_include_argument_not_read_is_said_and_the_include_kept(ws: Path) -> None:
    inner = _py(ws, "inner.launch.py", "DeclareLaunchArgument('who', default_value='dflt'),\n"
                                       "Node(package='demo', executable='talker', name=LaunchConfiguration('who')),")
    body = ("IncludeLaunchDescription(PythonLaunchDescriptionSource('{f}'), launch_arguments=[('who', WHO)]),"
            .format(f=inner.name))
    before = "from launch.actions import IncludeLaunchDescription\n" \
             "from launch.launch_description_sources import PythonLaunchDescriptionSource\n\n\n"
    g = _graph(ws, _py(ws, "outer.launch.py", body.replace("WHO", "Rewritten(source_file='p.yaml')"), before))
    assert sorted(g.nodes) == ["/talker"]  # kept, without the name the include gives; the default is not taken
    said = _said(g)
    assert said[0] == ("ws/demo/launch/outer.launch.py:22:110: warning: IncludeLaunchDescription(...): argument "
                       "'who' 'Rewritten(source_file='p.yaml')' (not a literal or a known substitution) cannot be "
                       "read statically; the included file reads it without a value")
    assert len(said) == 2 and "argument 'who' has no value read statically" in said[1]
    # control: a literal argument names the node
    g = _graph(ws, _py(ws, "outer.launch.py", body.replace("WHO", "'given'"), before))
    assert sorted(g.nodes) == ["/given"] and _said(g) == []


# -- C++ shapes ------------------------------------------------------------------

LEDS = """#include <map>
#include <rclcpp/rclcpp.hpp>
#include <std_msgs/msg/int32.hpp>
class Led
{
public:
  void create_subscription(rclcpp::Node::SharedPtr nh, std::string topic)
  {
    sub_ = nh->create_subscription<std_msgs::msg::Int32>(topic, 10, [](std_msgs::msg::Int32::SharedPtr) {});
  }
  rclcpp::Subscription<std_msgs::msg::Int32>::SharedPtr sub_;
};
class Board : public rclcpp::Node
{
public:
  Board() : Node("board"), buffer_(get_clock()), tf_(TF_ARGS)
  {
    auto self = std::shared_ptr<rclcpp::Node>(this, [](rclcpp::Node *) {});
    leds_[0] = std::make_shared<Led>();
    leds_[0]->create_subscription(self, "led/power");
    pub_ = create_publisher<std_msgs::msg::Int32>("level", 10);
  }
  std::map<int, std::shared_ptr<Led>> leds_;
  tf2_ros::Buffer buffer_;
  tf2_ros::TransformListener tf_;
  rclcpp::Publisher<std_msgs::msg::Int32>::SharedPtr pub_;
};
int main(int argc, char ** argv) { rclcpp::init(argc, argv); rclcpp::spin(std::make_shared<Board>()); }
"""


def _board(tmp: Path, tf_args: str, register: str = "") -> Graph:
    _write(tmp / "ws" / "hw", {
        "package.xml": PKG.format(name="hw", tool="ament_cmake", export=""),
        "CMakeLists.txt": CMAKE.format(name="hw") + "add_executable(board_node src/board.cpp)\n" + register,
        "src/board.cpp": LEDS.replace("TF_ARGS", tf_args)})
    return scan([tmp / "ws"], base=tmp, standard=False).graph


def test_a_method_named_like_rclcpps_without_template_arguments_is_followed(tmp_path: Path) -> None:
    g = _board(tmp_path, "buffer_, this, false")
    assert _subs(g, "/board") == {"/led/power", "/tf", "/tf_static"}
    assert not [n for n in _said(g) if "led" in n]
    # control: rclcpp's own method, given its message type, is an endpoint at its call
    assert {(e.topic, e.src.line) for e in g.nodes["/board"].publishes} == {("/level", 21)}


def test_a_transform_listener_member_given_a_buffer_alone_is_on_tf2s_own_node(tmp_path: Path) -> None:
    g = _board(tmp_path, "buffer_")
    assert _subs(g, "/board") == {"/led/power"}
    assert "ws/hw/src/board.cpp:16:50: warning: tf2_ros::TransformListener made without a node subscribes /tf " \
           "and /tf_static on tf2's own node (transform_listener_impl_...), not on this one" in _said(g)


@pytest.mark.parametrize("cls", ["Board", "hw::Board"])
def test_components_registered_in_no_namespace_are_programs(tmp_path: Path, cls: str) -> None:
    g = _board(tmp_path, "buffer_, this, false", f'add_library(board SHARED src/board.cpp)\n'
                                                  f'rclcpp_components_register_nodes(board "{cls}")\n')
    names = {p["name"] for p in g.programs}
    # a class in no namespace is registered; the namespaced name (control) names no class of the package
    assert ("Board" in names) == (cls == "Board") and "board_node" in names


# -- XML and YAML actions ----------------------------------------------------------

def test_xml_executables_and_timers_start_their_nodes(ws: Path) -> None:
    lf = _file(ws, "exec.launch.xml", '<launch>\n'
               '  <executable cmd="ros2 run demo listener --ros-args -r __node:=ears -r heard:=chatter"/>\n'
               '  <timer period="2.0">\n    <node pkg="demo" exec="talker"/>\n  </timer>\n'
               '  <set_env name="X" value="1"/>\n  <log message="up"/>\n</launch>\n')
    g = _graph(ws, lf)
    assert sorted(g.nodes) == ["/ears", "/talker"] and _subs(g, "/ears") == {"/chatter"} and _said(g) == []
    # control: another program, and an element the scan does not know, are said at their lines
    lf = _file(ws, "exec.launch.yaml", "launch:\n- executable:\n    cmd: gzserver --verbose\n"
                                       "- my_action:\n    name: x\n")
    g = _graph(ws, lf)
    assert g.nodes == {}
    assert _said(g) == ["ws/demo/launch/exec.launch.yaml:2:1: warning: <executable> runs 'gzserver --verbose', "
                        "not 'ros2 run PKG EXE': the nodes it starts, if any, are unknown",
                        "ws/demo/launch/exec.launch.yaml:4:1: warning: <my_action> is not an element the scan "
                        "reads: the nodes it starts, if any, are unknown"]


GAUGE = """#include <ros/ros.h>
#include <std_msgs/Int32.h>
int main(int argc, char ** argv)
{
  ros::init(argc, argv, "gauge");
  ros::NodeHandle nh, pnh("~");
  std::string topic;
  pnh.param<std::string>("out_topic", topic, "level");
  ros::Publisher pub = nh.advertise<std_msgs::Int32>(topic, 1);
  ros::spin();
}
"""


@pytest.mark.parametrize("rosparam", ['<rosparam command="load" file="$(find gauges)/config/gauge.yaml"/>',
                                      '<rosparam command="load" file="$(find gauges)/config/gauge.yaml" ns="io"/>',
                                      '<rosparam command="delete" param="out_topic"/>'])
def test_a_rosparam_file_gives_the_nodes_parameters(tmp_path: Path, rosparam: str) -> None:
    _write(tmp_path / "ws" / "gauges", {
        "package.xml": PKG.format(name="gauges", tool="catkin", export="").replace("rclcpp", "roscpp"),
        "CMakeLists.txt": "cmake_minimum_required(VERSION 3.0)\nproject(gauges)\nfind_package(catkin REQUIRED)\n"
                          "add_executable(gauge src/gauge.cpp)\n",
        "src/gauge.cpp": GAUGE, "config/gauge.yaml": "out_topic: tank/level\nrate: 10\n",
        "launch/gauge.launch": f'<launch>\n  <node pkg="gauges" type="gauge" name="gauge">\n    {rosparam}\n'
                               f'  </node>\n</launch>\n'})
    g = scan([tmp_path / "ws"], [tmp_path / "ws/gauges/launch/gauge.launch"], base=tmp_path, standard=False).graph
    # the file's out_topic names the topic; under ns="io" (control) it is io/out_topic, so the default holds
    want = "/level" if 'ns="io"' in rosparam or "delete" in rosparam else "/tank/level"
    assert {e.topic for e in g.nodes["/gauge"].publishes} == {want}
    said = [n for n in _said(g) if "rosparam" in n]
    assert said == ([] if "load" in rosparam else [
        'ws/gauges/launch/gauge.launch:3:1: warning: <rosparam>: <rosparam command="delete"> without a file: the '
        "parameters it loads are not read (a name the code takes from one keeps its default)"])


@pytest.mark.parametrize("model, started", [("standard", ["/listener", "/talker"]), ("lite", ["/talker"])])
def test_launch_configuration_equals_conditions_are_evaluated(ws: Path, model: str, started: list[str]) -> None:
    # turtlebot4's robot.launch.py: the base node only for the standard model (the other model: the control)
    lf = _py(ws, "model.launch.py", f"DeclareLaunchArgument('model', default_value='{model}'),\n"
                                    "Node(package='demo', executable='talker'),\n"
                                    "Node(package='demo', executable='listener',\n"
                                    "     condition=LaunchConfigurationEquals('model', 'standard')),\n"
                                    "Node(package='demo', executable='duo',\n"
                                    "     condition=LaunchConfigurationNotEquals('model', model_name)),",
             "from launch.conditions import LaunchConfigurationEquals, LaunchConfigurationNotEquals\n"
             f"model_name = '{model}'\n\n\n")
    g = _graph(ws, lf)
    assert sorted(g.nodes) == started and _said(g) == []


def test_a_hostile_rosparam_file_is_refused_and_said(tmp_path: Path) -> None:
    bomb = "a: &a [x, x, x, x, x, x, x, x, x, x]\n" + "".join(
        f"{c}: &{c} [{', '.join(['*' + p] * 10)}]\n" for p, c in zip("abcdefgh", "bcdefghi"))
    _write(tmp_path / "ws" / "gauges", {
        "package.xml": PKG.format(name="gauges", tool="catkin", export="").replace("rclcpp", "roscpp"),
        "CMakeLists.txt": "cmake_minimum_required(VERSION 3.0)\nproject(gauges)\nfind_package(catkin REQUIRED)\n"
                          "add_executable(gauge src/gauge.cpp)\n",
        "src/gauge.cpp": GAUGE, "config/gauge.yaml": bomb,
        "launch/gauge.launch": '<launch>\n  <node pkg="gauges" type="gauge" name="gauge">\n'
                               '    <rosparam command="load" file="$(find gauges)/config/gauge.yaml"/>\n'
                               '  </node>\n</launch>\n'})
    g = scan([tmp_path / "ws"], [tmp_path / "ws/gauges/launch/gauge.launch"], base=tmp_path, standard=False).graph
    assert {e.topic for e in g.nodes["/gauge"].publishes} == {"/level"}  # the code's default
    [said] = [n for n in _said(g) if "rosparam" in n]
    assert said.startswith("ws/gauges/launch/gauge.launch:3:1: warning: <rosparam>: ") and "cannot be read (" in said


def test_an_opaque_function_returning_in_a_known_branch_is_evaluated(ws: Path,
                                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("RCLVERIFY_TEST_SIM", raising=False)
    setup = ("def launch_setup(context):\n"
             "    if os.environ.get('RCLVERIFY_TEST_SIM', 'real') == 'sim':\n"
             "        return [Node(package='demo', executable='talker')]\n"
             "    else:\n"
             "        return [Node(package='demo', executable='listener')]\n\n\n")
    lf = _py(ws, "branchy.launch.py", "OpaqueFunction(function=launch_setup),", setup)
    g = _graph(ws, lf)
    assert sorted(g.nodes) == ["/listener"] and _said(g) == []
    monkeypatch.setenv("RCLVERIFY_TEST_SIM", "sim")
    assert sorted(_graph(ws, lf).nodes) == ["/talker"]
    # control: a test only running decides leaves two returns, said
    lf = _py(ws, "branchy.launch.py", "OpaqueFunction(function=launch_setup),",
             setup.replace("os.environ.get('RCLVERIFY_TEST_SIM', 'real')", "context.perform_substitution(x)"))
    g = _graph(ws, lf)
    assert g.nodes == {} and len(_said(g)) == 1 and "it has 2 return statements" in _said(g)[0]
