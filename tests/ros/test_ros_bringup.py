"""A bringup read whole (issue 97): the idioms of a large ROS 2 stack's own
launch files and servers, on the project's own tree
(tests/data/ros_corpus/bringup), its graph counted by hand:

* ``remappings``, ``parameters``, ``name`` bound to a variable (in the
  function or at module level), lists joined with ``+``: read, never the
  node dropped;
* a standalone branch and a composed branch (``LoadComposableNodes``) chosen
  by a launch argument through ``IfCondition(PythonExpression([...]))``;
  a map server chosen by ``EqualsSubstitution`` / ``NotEqualsSubstitution``;
* action servers made through a node's member template that forwards the
  name to a free factory, ``make_shared`` of a class template, a delegating
  constructor and a member: each named where the server's code writes the
  literal, typed by that call's template argument;
* a template parameter named like another class's ``using`` alias;
* a header of another package installed from a scoped directory
  (``#include <rover/core/pose_relay.hpp>`` of ``rover_core/include/rover/core/``);
* two helper classes each with its own ``using Request = ...`` (a service),
  used in their ``.cpp`` files, beside the server's ``using Charge =
  sensor_msgs::msg::BatteryState``: each client typed by its own class's
  alias, never by the other's nor by an alias of its last name part.

By hand, with the launch arguments' defaults: two launch files start three
nodes, ``/rover/drive_server`` (publishes ``/rover/cmd_vel_raw``, subscribes
``/rover/odom`` (its ``TransformListener(*tf_buffer_)``, given no node,
subscribes ``/tf`` and ``/tf_static`` on tf2's own node, a note), serves action
``/rover/drive_to`` of ``rover_msgs/action/DriveTo``, calls action
``/rover/dock`` of ``rover_msgs/action/Dock``), ``/rover/dock`` (serves
``/rover/dock`` of ``Dock`` and ``/rover/undock`` of ``Undock``, subscribes
``/rover/battery``, calls services ``/rover/charge`` of ``rover_msgs/srv/Charge``
and ``/rover/lamp`` of ``std_srvs/srv/SetBool``) and
``/rover/map_server`` (publishes ``/rover/map`` and, through the pose relay,
``/rover/map_origin``; subscribes ``/rover/initialpose``)."""
from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from rclverify.ros.extract.launch import Unresolved, evaluate
from rclverify.ros.graph.scan import scan

WS = Path(__file__).parent.parent / "data" / "ros_corpus" / "bringup"
LAUNCH = WS / "src" / "rover_bringup" / "launch"
NAV, LOC = LAUNCH / "navigation.launch.py", LAUNCH / "localization.launch.py"

DRIVE = {("pub", "/rover/cmd_vel_raw", "geometry_msgs/msg/Twist"), ("sub", "/rover/odom", "nav_msgs/msg/Odometry"),
         ("action_servers", "/rover/drive_to", "rover_msgs/action/DriveTo"),
         ("action_clients", "/rover/dock", "rover_msgs/action/Dock")}
DOCK = {("action_servers", "/rover/dock", "rover_msgs/action/Dock"),
        ("action_servers", "/rover/undock", "rover_msgs/action/Undock"),
        ("sub", "/rover/battery", "sensor_msgs/msg/BatteryState"),
        ("service_clients", "/rover/charge", "rover_msgs/srv/Charge"),
        ("service_clients", "/rover/lamp", "std_srvs/srv/SetBool")}
POSE = "geometry_msgs/msg/PoseStamped"
# the pose relay's header is included as <rover/core/pose_relay.hpp>, from rover_core's include/rover/core/
MAP = {("pub", "/rover/map", "nav_msgs/msg/OccupancyGrid"), ("pub", "/rover/map_origin", POSE),
       ("sub", "/rover/initialpose", POSE)}
ROLES = ("publishes", "subscribes", "service_servers", "service_clients", "action_servers", "action_clients")
SHORT = {"publishes": "pub", "subscribes": "sub"}


def _edges(g: Any, node: str) -> set[tuple[str, str, str | None]]:
    n = g.nodes[node]
    return {(SHORT.get(r, r), e.topic, e.msg_type) for r in ROLES for e in getattr(n, r)}


def _said(g: Any) -> list[str]:
    return [n.message for n in g.notes]


@pytest.fixture(scope="module")
def default() -> Any:
    return scan([WS], [NAV, LOC]).graph


def test_the_bringup_counted_by_hand(default: Any) -> None:
    g = default
    assert sorted(g.nodes) == ["/rover/dock", "/rover/drive_server", "/rover/map_server"]
    assert _edges(g, "/rover/drive_server") == DRIVE
    assert _edges(g, "/rover/dock") == DOCK
    assert _edges(g, "/rover/map_server") == MAP
    said = _said(g)
    assert not [m for m in said if "action skipped" in m or "not a string literal" in m], said
    # the parameter file is a relative path (ros2 launch opens it where it runs): said once where it is
    # bound, the rest of the node read
    assert [m for m in said if "parameter file" in m] == [
        "<param>: parameter file 'rover.yaml' is a relative path, read from the directory ros2 launch runs in: "
        "not known statically; its parameters are not read; element skipped"]
    # the standalone branch ran: the nodes are the executables', not the components'
    assert g.nodes["/rover/drive_server"].executable == "drive_server"
    assert g.nodes["/rover/dock"].executable == "rover_dock"


def test_the_composed_branch_chosen_by_its_argument_gives_the_same_graph() -> None:
    g = scan([WS], [NAV, LOC], {"use_composition": "True"}).graph
    assert sorted(g.nodes) == ["/rover/dock", "/rover/drive_server", "/rover/map_server"]
    assert _edges(g, "/rover/drive_server") == DRIVE
    assert _edges(g, "/rover/dock") == DOCK
    assert g.nodes["/rover/drive_server"].executable is None  # a component in a container


def test_a_condition_on_a_launch_argument_picks_one_map_server() -> None:
    g = scan([WS], [LOC], {"map": "/maps/yard.yaml", "namespace": "r2"}).graph
    assert sorted(g.nodes) == ["/r2/map_server"]
    assert _edges(g, "/r2/map_server") == {("pub", "/r2/map_loaded", "nav_msgs/msg/OccupancyGrid"),
                                           ("pub", "/r2/map_origin", POSE), ("sub", "/r2/initialpose", POSE)}
    assert not [m for m in _said(g) if "started twice" in m]


def test_an_unreadable_condition_keeps_both_branches_as_alternatives(tmp_path: Path) -> None:
    lf = tmp_path / "pick.launch.py"
    lf.write_text(
        "from launch import LaunchDescription\nfrom launch.actions import GroupAction\n"
        "from launch.conditions import IfCondition, UnlessCondition\nfrom launch_ros.actions import Node\n"
        "from rover_bringup.subst import AsBool\n\n\n"
        "def generate_launch_description():\n"
        "    flag = AsBool('use_sim')\n"
        "    return LaunchDescription([\n"
        "        GroupAction(condition=UnlessCondition(flag), actions=[\n"
        "            Node(package='rover_map', executable='map_server', name='map_server')]),\n"
        "        GroupAction(condition=IfCondition(flag), actions=[\n"
        "            Node(package='rover_map', executable='map_server', name='map_server',\n"
        "                 remappings=[('map', 'sim_map')])]),\n"
        "    ])\n")
    g = scan([WS], [lf]).graph
    assert ("pub", "/map", "nav_msgs/msg/OccupancyGrid") in _edges(g, "/map_server")  # the first kept
    said = _said(g)
    assert sum("condition 'AsBool('use_sim')' (not a literal or a known substitution) cannot be read statically; "
               "the action is read as if it held" in m for m in said) == 2
    assert [m for m in said if "also started" in m] == [
        f"node /map_server is also started at {lf}:12:13, under a condition not evaluated statically "
        f"({lf}:13:9): taken as alternatives, the first is kept"]
    # control: the same two nodes with no condition at all are two starts, the last kept
    plain = tmp_path / "both.launch.py"
    plain.write_text(lf.read_text().replace("condition=UnlessCondition(flag), ", "")
                     .replace("condition=IfCondition(flag), ", ""))
    g = scan([WS], [plain]).graph
    assert ("pub", "/sim_map", "nav_msgs/msg/OccupancyGrid") in _edges(g, "/map_server")
    assert [m for m in _said(g) if "started twice" in m]


def test_what_cannot_be_read_drops_only_that_attribute(tmp_path: Path) -> None:
    lf = tmp_path / "loose.launch.py"
    lf.write_text(
        "from launch import LaunchDescription\nfrom launch_ros.actions import Node\n"
        "from rover_bringup.names import remaps_for, name_of\n\n\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([\n"
        "        Node(package='rover_map', executable='map_server', name=name_of('map'),\n"
        "             remappings=remaps_for('map')),\n"
        "        Node(package='rover_drive', executable='drive_server', namespace='r',\n"
        "             remappings=[('odom', 'wheel_odom'), (topic_of('cmd'), 'cmd')]),\n"
        "    ])\n")
    g = scan([WS], [lf]).graph
    assert sorted(g.nodes) == ["/map_server", "/r/drive_server"]  # the code's own name, no remapping
    assert ("pub", "/map", "nav_msgs/msg/OccupancyGrid") in _edges(g, "/map_server")
    assert ("sub", "/r/wheel_odom", "nav_msgs/msg/Odometry") in _edges(g, "/r/drive_server")
    said = _said(g)
    assert "Node(...): name 'name_of('map')' (not a literal or a known substitution) cannot be read statically; " \
           "the name the code gives is kept" in said
    assert "Node(...): remappings 'remaps_for('map')' cannot be read statically; the node is read without " \
           "them" in said
    assert "Node(...): remapping 'topic_of('cmd')' (not a literal or a known substitution) cannot be read " \
           "statically; remapping left out" in said
    assert not [m for m in said if "action skipped" in m]


def test_a_template_parameter_is_no_alias_of_the_class_calling_it(default: Any) -> None:
    """DriveServer has ``using ActionT = DriveTo``; the client member template's own
    parameter is also ``ActionT``: the dock client is a ``Dock`` client, never a
    ``DriveTo`` one (C++ [temp.local])."""
    clients = {(e.topic, e.msg_type) for e in default.nodes["/rover/drive_server"].action_clients}
    assert clients == {("/rover/dock", "rover_msgs/action/Dock")}


@pytest.mark.parametrize("expr,want", [("not False", "True"), ("not True", "False"), ("'' == ''", "True"),
                                        ("'a.yaml' != ''", "True"), ("'x' in ('x', 'y') and not False", "True"),
                                        ("False or 'a' == 'b'", "False")])
def test_eval_of_literals(expr: str, want: str) -> None:
    assert evaluate(expr) == want


@pytest.mark.parametrize("expr", ["not false", "__import__('os')", "1 + 1", "x == 'y'", "'a' in 3", "not"])
def test_eval_refuses_what_it_cannot_know(expr: str) -> None:
    with pytest.raises(Unresolved):
        evaluate(expr)


def _many(tmp_path: Path, loose: int) -> Path:
    """A launch file with three nodes whose package is not read (dropped) and
    ``loose`` nodes whose remappings are not read (kept, a warning each)."""
    lf = tmp_path / f"many{loose}.launch.py"
    body = "".join(f"        Node(package=pkg_of({i}), executable='x'),\n" for i in range(3))
    body += "".join(f"        Node(package='rover_map', executable='map_server', name='m{i}', "
                    f"remappings=remaps_for({i})),\n" for i in range(loose))
    lf.write_text("from launch import LaunchDescription\nfrom launch_ros.actions import Node\n\n\n"
                  "def generate_launch_description():\n    return LaunchDescription([\n" + body + "    ])\n")
    return lf


def test_the_first_screen_names_what_dropped_nodes_first(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from rclverify.cli.commands import main
    lf = _many(tmp_path, 30)
    assert main(["ros", "scan", str(WS), "--launch", str(lf), "--json", str(tmp_path / "g.json")]) == 0
    err = capsys.readouterr().err.splitlines()
    assert len(err) <= 20 and err[-1].endswith("0 error(s), 34 warning(s)"), err
    assert err[0] == "34 warning(s) by cause (each located in the JSON's \"unresolved\"; --verbose lists them here):"
    assert err[1].startswith(f"    3  launch nodes dropped (not started in the graph): {lf}:7:9, {lf}:8:9, {lf}:9:9")
    assert err[2].startswith(f"   30  launch attributes not read (parameter files, conditions, remappings): {lf}:10:")
    assert err[2].endswith("(+27 more)")  # the launch file lies in no scanned package: no package named
    # --verbose: every warning, one a line
    assert main(["ros", "scan", str(WS), "--launch", str(lf), "--json", str(tmp_path / "g.json"), "--verbose"]) == 0
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 35 and sum("action skipped" in x for x in err) == 3
    # control: a few warnings are listed one a line, as they always were
    few = _many(tmp_path, 2)
    assert main(["ros", "scan", str(WS), "--launch", str(few), "--json", str(tmp_path / "g.json")]) == 0
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 7 and err[0] == f"{few}:7:9: warning: Node(...): package 'pkg_of(0)' (not a literal or a " \
                                       f"known substitution) cannot be read statically; action skipped", err


def test_each_helper_class_types_its_client_by_its_own_alias(default: Any) -> None:
    """ChargerClient's ``Request`` is ``rover_msgs::srv::Charge``, LampClient's
    ``std_srvs::srv::SetBool``, the dock server's ``Charge`` a message: before,
    both clients were typed ``sensor_msgs/msg/BatteryState``, silently."""
    clients = {(e.topic, e.msg_type) for e in default.nodes["/rover/dock"].service_clients}
    assert clients == {("/rover/charge", "rover_msgs/srv/Charge"), ("/rover/lamp", "std_srvs/srv/SetBool")}


def test_an_alias_is_looked_up_in_its_scope() -> None:
    from rclverify.ros.extract.cpp_types import alias_of, message_type
    aliases = {"a::Helper::Request": "other_msgs::srv::Charge", "a::Node::Charge": "geometry_msgs::msg::Point",
               "Charge": "geometry_msgs::msg::Point", "ns::Twist": "geometry_msgs::msg::Twist"}
    assert alias_of("Request", aliases, ["a::Helper", "a"]) == "other_msgs::srv::Charge"
    assert alias_of("Request", aliases, ["a::Node", "a"]) is None  # not the helper's in another class
    assert alias_of("other_msgs::srv::Charge", aliases) is None  # a namespace's name: no class's alias
    assert alias_of("Helper::Request", aliases) == "other_msgs::srv::Charge"
    assert alias_of("ns::Twist", aliases) == "geometry_msgs::msg::Twist"
    assert alias_of("Node::Charge", aliases) == "geometry_msgs::msg::Point"
    # control: a bare name still reads its one alias
    assert alias_of("Charge", aliases) == "geometry_msgs::msg::Point"
    assert message_type("other_msgs::msg::Charge", aliases) == "other_msgs/msg/Charge"


def test_a_class_the_package_re_exports_is_followed_to_its_module() -> None:
    """``from rover_tools import Beacon``, where ``rover_tools/__init__.py`` says
    ``from .beacon import Beacon``: the beacon's publisher, named at the call site,
    is the node's (before: 'names no node ...: not in the graph')."""
    g = scan([WS / "src" / "rover_tools"]).graph
    assert _edges(g, "/beacon_node") == {("pub", "/rover_beacon", "std_msgs/msg/String")}
    assert not _said(g)


def test_a_child_node_is_its_class_and_a_reference_member_makes_nothing() -> None:
    """OdomServer makes ``Odometer("wheel_odometer", ...)`` and lends it to a
    helper holding ``Odometer & odometer_``: two nodes, the odometer's publisher
    its own.  Before: ``odometer_(odometer)`` was read as a construction through
    Odometer's one-argument constructor (a third node, ``/odometer``), and every
    node named through the shared base class's constructor got every endpoint."""
    g = scan([WS / "src" / "rover_odom", WS / "src" / "rover_core"]).graph
    assert sorted(g.nodes) == ["/odom_server", "/wheel_odometer"]
    assert _edges(g, "/wheel_odometer") == {("pub", "/odom", "nav_msgs/msg/Odometry")}
    assert _edges(g, "/odom_server") == set()


def test_a_type_the_code_chooses_at_run_time_grounds_as_the_contract_says(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A node publishing ``cmd`` as ``TwistStamped`` or ``Twist`` by a parameter (Nav2's
    twist publisher): its own skeleton grounds with a warning, not an error; a
    contract type the node's code never makes stays an error."""
    import json

    from rclverify.cli.commands import main
    pkg = tmp_path / "src" / "pilot"
    (pkg / "scripts").mkdir(parents=True)
    (pkg / "package.xml").write_text(
        '<?xml version="1.0"?>\n<package format="3"><name>pilot</name><version>0.1.0</version><description>d'
        '</description><maintainer email="dev@example.org">dev</maintainer><license>MIT</license>'
        '<exec_depend>rclpy</exec_depend><export><build_type>ament_python</build_type></export></package>\n')
    (pkg / "scripts" / "pilot.py").write_text(
        "#!/usr/bin/env python3\nimport rclpy\nfrom geometry_msgs.msg import Twist, TwistStamped\n"
        "rclpy.init()\nn = rclpy.create_node('pilot')\n"
        "if n.declare_parameter('stamped', True).value:\n"
        "    pub = n.create_publisher(TwistStamped, 'cmd', 1)\n"
        "else:\n"
        "    pub = n.create_publisher(Twist, 'cmd', 1)\n")
    ws = tmp_path / "ws"
    assert main(["init", str(ws), "--from-ros", str(tmp_path / "src")]) == 0
    capsys.readouterr()
    out = tmp_path / "ground.json"

    def codes() -> list[str]:
        main(["ros", "check", "-w", str(ws), "--json", str(out)])
        return [f["code"] for f in json.loads(out.read_text())["findings"]]
    got = codes()
    assert "ROS-TYPE-ALTERNATIVE" in got and "ROS-TYPE-DIFFERS" not in got, got
    rcl = next((ws / "contracts").glob("pilot*.rcl"))
    text = rcl.read_text()
    for t in ("geometry_msgs/TwistStamped", "geometry_msgs/Twist"):
        if t in text:  # control: a type the code never makes is an error
            rcl.write_text(text.replace(t, "geometry_msgs/Vector3"))
            break
    got = codes()
    assert "ROS-TYPE-DIFFERS" in got, got


def test_the_node_name_inside_a_name_is_not_read_as_tilde() -> None:
    """``std::string("get_cost_") + get_name()`` is ``get_cost_<node name>``: not
    ``/get_cost_~`` (a wrong name, silently, before); ``get_name() + "/x"`` stays
    the private ``~x``."""
    from rclverify.ros.extract import symbols
    assert symbols.text(symbols.cat([symbols.lit("get_cost_"), symbols.NODE])) is None
    assert symbols.text(symbols.cat([symbols.NODE, symbols.lit("/x")])) == "~x"  # private x


def test_a_library_of_a_source_directory_is_its_component() -> None:
    """``ament_auto_add_library(lights_component SHARED DIRECTORY src)`` registered
    as ``rover_lights::Lights`` with executable ``lights_node``: its sources are
    those under ``src/`` (before: none, and the component was said to be in no
    node of the graph)."""
    g = scan([WS / "src" / "rover_lights"]).graph
    assert _edges(g, "/lights") == {("sub", "/headlights", "std_msgs/msg/Bool")}
    assert g.nodes["/lights"].executable == "lights_node"
    assert [(p["name"], p["nodes"], p["unaccounted"]) for p in g.programs] == [
        ("rover_lights::Lights", ["/lights"], None)]
    assert not _said(g)


def test_a_component_registered_by_another_packages_cmake_macro() -> None:
    """``rover_register_node(horn_component PLUGIN "rover_horn::Horn" EXECUTABLE
    horn_node)``, a macro rover_core exports (``cmake/*.cmake``, ``CONFIG_EXTRAS``):
    the component and its executable are declared (before: no program, a node of no
    executable)."""
    g = scan([WS / "src" / "rover_horn", WS / "src" / "rover_core"]).graph
    assert _edges(g, "/horn") == {("sub", "/honk", "std_msgs/msg/Empty")}
    assert g.nodes["/horn"].executable == "horn_node"
    assert [(p["name"], p["kind"], p["nodes"], p["unaccounted"]) for p in g.programs] == [
        ("rover_horn::Horn", "component", ["/horn"], None)]


def test_a_script_and_an_executable_of_one_name_are_two_programs() -> None:
    """``beeper`` (C++) and ``scripts/beeper.py`` (Python, also called ``beeper``):
    the executable's account holds its own node only (before: both nodes)."""
    g = scan([WS / "src" / "rover_beeper"]).graph
    assert _edges(g, "/beeper") == {("pub", "/beep", "std_msgs/msg/Empty")}
    assert _edges(g, "/beeper_py") == {("pub", "/beep_text", "std_msgs/msg/String")}
    assert [(p["name"], p["nodes"]) for p in g.programs] == [("beeper", ["/beeper"])]


def test_a_warm_scan_links_again_what_changed(tmp_path: Path) -> None:
    """Linked programs are kept in the parse cache (the second scan reads the
    same graph from it); a change in a program's own file, or in another
    package's header it takes in, is read on the next scan."""
    import shutil
    ws = tmp_path / "ws"
    shutil.copytree(WS, ws)
    nav = [ws / "src/rover_bringup/launch/navigation.launch.py", ws / "src/rover_bringup/launch/localization.launch.py"]
    cache = tmp_path / "cache.pickle"
    first = scan([ws], nav, cache_path=cache, base=tmp_path).graph
    again = scan([ws], nav, cache_path=cache, base=tmp_path)
    assert again.cache_misses == 0 and again.link_misses == 0 and again.link_hits > 0
    assert again.graph.to_json() == first.to_json()
    drive = ws / "src/rover_drive/src/drive_server.cpp"
    drive.write_text(drive.read_text().replace('"drive_to"', '"drive_home"'))
    relay = ws / "src/rover_core/include/rover/core/pose_relay.hpp"
    relay.write_text(relay.read_text().replace("create_publisher<geometry_msgs::msg::PoseStamped>(to, 1)",
                                               'create_publisher<geometry_msgs::msg::PoseStamped>("relayed/" + to, 1)'))
    g = scan([ws], nav, cache_path=cache, base=tmp_path).graph
    assert ("action_servers", "/rover/drive_home", "rover_msgs/action/DriveTo") in _edges(g, "/rover/drive_server")
    assert ("pub", "/rover/relayed/map_origin", POSE) in _edges(g, "/rover/map_server")


def test_init_from_ros_summarises_the_scans_warnings(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``init --from-ros`` on a launch file with three dropped nodes and thirty
    loose ones: the first lines are the summary, what dropped nodes first."""
    from rclverify.cli.commands import main
    lf = _many(tmp_path, 30)
    assert main(["init", str(tmp_path / "ws"), "--from-ros", str(WS), "--launch", str(lf)]) == 0
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith("34 warning(s) by cause (`rclverify ros scan ") and "--verbose` lists each one" in err[0]
    assert err[1].startswith("    3  launch nodes dropped (not started in the graph): ") and \
        "many30.launch.py:7:9, " in err[1]
    assert not [x for x in err if "cannot be read statically; the node is read without them" in x]
