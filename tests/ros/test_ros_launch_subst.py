"""Substitution classes of other packages than launch itself, each read as
what it does (docs/ros.md, "Other packages' substitutions"), with its control:

* launch's ``NotSubstitution``, ``AndSubstitution``, ``OrSubstitution``,
  ``IfElseSubstitution`` evaluated (control: the other value);
* nav2_common's ``HasNodeParams(source_file, node_name)`` reads the YAML
  file's top-level keys (control: a file without the node's key); of a
  ``RewrittenYaml`` (keys decided at run time) it is said, the node kept;
* ``ParameterFile(RewrittenYaml(...))`` given to an include is a value (the
  include reads it), while a class nobody knows is said at its line;
* ``HasNodeParams`` of a file the YAML guard refuses (an alias bomb) or a FIFO
  is said and the node kept;
* ``Command``, ``FindExecutable``, launch_ros' ``Parameter`` are named as
  known only at run time, the node kept without the attribute, a cause of
  their own on the first screen (control: a literal there is read).

Packages are written into a temporary directory and read by the scan.
"""
from __future__ import annotations

import os
from pathlib import Path

import pytest
from test_ros_launch_args import _graph, _include, _said, ws  # noqa: F401  (the fixture)
from test_ros_launch_run import PY_HEAD

from rclverify.ros.graph import summary

HEAD = PY_HEAD + ("from launch.actions import IncludeLaunchDescription\n"
                  "from launch.conditions import IfCondition\n"
                  "from launch.launch_description_sources import PythonLaunchDescriptionSource\n"
                  "from launch.substitutions import AndSubstitution, Command, FindExecutable, "
                  "IfElseSubstitution, NotSubstitution, OrSubstitution\n"
                  "from launch_ros.descriptions import ParameterFile\n"
                  "from launch_ros.substitutions import FindPackageShare, Parameter\n"
                  "from nav2_common.launch import HasNodeParams, RewrittenYaml\n\n\n")


def _py(ws: Path, name: str, body: str) -> Path:
    f = ws / "ws" / "demo" / "launch" / name
    f.parent.mkdir(exist_ok=True)
    f.write_text(HEAD + "def generate_launch_description():\n"
                 "    params = os.path.join(FindPackageShare('demo').perform(None), 'config', 'p.yaml')\n"
                 "    return LaunchDescription([\n"
                 + "".join(f"        {line}\n" for line in body.strip().splitlines()) + "    ])\n")
    return f


SIM = "DeclareLaunchArgument('sim', default_value='{sim}'),\nDeclareLaunchArgument('log', default_value='{log}'),\n"


@pytest.mark.parametrize("sim, log, cond, started", [
    ("true", "false", "NotSubstitution(LaunchConfiguration('sim'))", False),
    ("false", "false", "NotSubstitution(LaunchConfiguration('sim'))", True),
    ("True", "1", "AndSubstitution(LaunchConfiguration('sim'), LaunchConfiguration('log'))", True),
    ("true", "0", "AndSubstitution(LaunchConfiguration('sim'), LaunchConfiguration('log'))", False),
    ("false", "1", "OrSubstitution(LaunchConfiguration('sim'), LaunchConfiguration('log'))", True),
    ("false", "FALSE", "OrSubstitution(LaunchConfiguration('sim'), LaunchConfiguration('log'))", False),
])
def test_logic_substitutions_are_evaluated(ws: Path, sim: str, log: str, cond: str, started: bool) -> None:
    g = _graph(ws, _py(ws, "logic.launch.py", SIM.format(sim=sim, log=log)
                       + f"Node(package='demo', executable='talker', condition=IfCondition({cond})),"))
    assert sorted(g.nodes) == (["/talker"] if started else []) and _said(g) == []


def test_if_else_substitution_picks_its_value(ws: Path) -> None:
    body = SIM + ("Node(package='demo', executable='talker',\n"
                  "     namespace=IfElseSubstitution(LaunchConfiguration('sim'), 'sim', 'real')),")
    assert sorted(_graph(ws, _py(ws, "ifelse.launch.py", body.format(sim="true", log="0"))).nodes) == ["/sim/talker"]
    assert sorted(_graph(ws, _py(ws, "ifelse.launch.py", body.format(sim="0", log="0"))).nodes) == ["/real/talker"]
    picked = body.replace("'sim', 'real'", "LaunchConfiguration('log'), 'real'")
    assert sorted(_graph(ws, _py(ws, "ifelse.launch.py", picked.format(sim="1", log="x1"))).nodes) == ["/x1/talker"]
    # control: an operand that is no bool is said, the node kept without the namespace
    g = _graph(ws, _py(ws, "ifelse.launch.py", body.format(sim="maybe", log="0")))
    assert sorted(g.nodes) == ["/talker"] and "'maybe' is not true, false, 1 or 0" in " ".join(_said(g))


def test_has_node_params_reads_the_files_keys(ws: Path) -> None:
    cfg = ws / "ws/demo/config/p.yaml"
    cfg.parent.mkdir(exist_ok=True)
    body = "Node(package='demo', executable='talker', condition=IfCondition(HasNodeParams(source_file=params, " \
           "node_name='talker'))),"
    cfg.write_text("talker:\n  ros__parameters:\n    rate: 2\n")
    g = _graph(ws, _py(ws, "has.launch.py", body))
    assert sorted(g.nodes) == ["/talker"] and _said(g) == []
    # control: a file without the node's key: the condition does not hold
    cfg.write_text("listener:\n  ros__parameters:\n    rate: 2\n")
    g = _graph(ws, _py(ws, "has.launch.py", body))
    assert sorted(g.nodes) == [] and _said(g) == []


def test_has_node_params_of_a_rewritten_file_is_said(ws: Path) -> None:
    g = _graph(ws, _py(ws, "has.launch.py", "Node(package='demo', executable='talker', condition=IfCondition(\n"
                                            "    HasNodeParams(source_file=RewrittenYaml(source_file=params, "
                                            "param_rewrites={}, root_key='r1'), node_name='talker'))),"))
    assert sorted(g.nodes) == ["/talker"]
    [said] = _said(g)
    assert "has.launch.py:" in said and "written when launched" in said and "as if the condition held" in said


def test_a_rewritten_parameter_file_is_a_value_an_include_passes(ws: Path) -> None:
    (ws / "ws/demo/launch/robot.launch.py").write_text(
        HEAD + "def generate_launch_description():\n    return LaunchDescription([\n"
        "        DeclareLaunchArgument('params_file'),\n"
        "        Node(package='demo', executable='talker', namespace='r1'),\n    ])\n")
    rewritten = "ParameterFile(RewrittenYaml(source_file=params, param_rewrites={}, root_key='r1'), " \
                "allow_substs=True)"
    g = _graph(ws, _py(ws, "top.launch.py", _include("robot.launch.py", f"'params_file': {rewritten}")))
    assert sorted(g.nodes) == ["/r1/talker"] and _said(g) == []
    # control: a class the scan does not know: the argument is said at its line, the include kept
    g = _graph(ws, _py(ws, "top.launch.py", _include("robot.launch.py", "'params_file': MyRewriter(params)")))
    assert sorted(g.nodes) == ["/r1/talker"]
    [said] = _said(g)
    assert said.startswith("ws/demo/launch/top.launch.py:") and "MyRewriter(params)" in said
    assert [summary.cause_of(n.code, n.message).key for n in g.notes] == ["launch-attributes"]


@pytest.mark.parametrize("sub, why", [
    ("Command(['xacro ', params])", "Command runs a program when launched"),
    ("FindExecutable(name='ros2')", "FindExecutable looks the program up"),
    ("Parameter('robot')", "Parameter reads a ROS parameter of the launch context"),
])
def test_run_time_substitutions_are_named_and_the_node_kept(ws: Path, sub: str, why: str) -> None:
    g = _graph(ws, _py(ws, "rt.launch.py", f"Node(package='demo', executable='talker', namespace={sub}),"))
    assert sorted(g.nodes) == ["/talker"]
    [said] = _said(g)
    assert said.startswith("ws/demo/launch/rt.launch.py:") and why in said and "known only at run time" in said
    assert [summary.cause_of(n.code, n.message).key for n in g.notes] == ["launch-run-time"]  # its own cause
    # control: a literal in its place is read
    assert sorted(_graph(ws, _py(ws, "rt.launch.py", "Node(package='demo', executable='talker', "
                                                     "namespace='r9'),")).nodes) == ["/r9/talker"]


BOMB = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"{c}: &{c} [{', '.join(['*' + p] * 9)}]\n" for p, c in zip("abcdefgh", "bcdefghi"))


@pytest.mark.parametrize("hostile", ["bomb", "fifo"])
def test_has_node_params_of_a_hostile_file_is_said_and_the_node_kept(ws: Path, hostile: str) -> None:
    cfg = ws / "ws/demo/config/p.yaml"
    cfg.parent.mkdir(exist_ok=True)
    cfg.unlink(missing_ok=True)
    if hostile == "fifo":
        os.mkfifo(cfg)  # never opened: the scan would block on it
    else:
        cfg.write_text(BOMB)
    try:
        g = _graph(ws, _py(ws, "has.launch.py", "Node(package='demo', executable='talker', condition=IfCondition("
                                                "HasNodeParams(source_file=params, node_name='talker'))),"))
    finally:
        cfg.unlink()
    assert sorted(g.nodes) == ["/talker"]
    [said] = _said(g)
    assert "has.launch.py:" in said and "HasNodeParams: p.yaml cannot be read" in said and "as if the condition held" in said
