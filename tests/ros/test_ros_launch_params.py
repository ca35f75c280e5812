"""Parameter files a ROS 2 launch file gives a node (issue 108; docs/ros.md, "Parameter files a launch file
gives"): Python ``parameters=[path]`` (``ParameterFile``, a launch argument whose default is the path), XML
``<param from="..."/>`` and YAML ``param: [{from: ...}]``, read as rcl reads them (``ros__parameters`` under
``/**``, the node's name, its full name) so that a topic the code takes from a parameter is found.

The code is tests/data/ros_corpus/idioms5's ``rig_manager``, whose subscription's topic is parameter
``front.topic`` (``/scan`` by default).  Each form is tried with a file whose key names the node (the topic is
``/front/scan``, set at the file's line) and, as its control, with the same file keyed for another node (the
default topic).  A relative path (read from where ``ros2 launch`` runs), a file that is missing and a file that
is not YAML are each one located note, the node kept."""
from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from rclverify.ros.graph.scan import scan

WS = Path(__file__).parent.parent / "data" / "ros_corpus" / "idioms5"

PY_HEAD = ("from launch import LaunchDescription\nfrom launch.actions import DeclareLaunchArgument\n"
           "from launch.substitutions import LaunchConfiguration, PathJoinSubstitution, ThisLaunchFileDir\n"
           "from launch_ros.actions import Node\nfrom launch_ros.descriptions import ParameterFile\n\n\n"
           "def generate_launch_description():\n")
FORMS = {
    "python ParameterFile": ("a.launch.py", PY_HEAD + "    return LaunchDescription([\n"
                             "        Node(package='rig_manager', executable='manager', parameters=[\n"
                             "            ParameterFile(PathJoinSubstitution([ThisLaunchFileDir(), 'params.yaml']))]),\n"
                             "    ])\n"),
    "python launch argument": ("b.launch.py", PY_HEAD + "    params = LaunchConfiguration('params_file')\n"
                               "    return LaunchDescription([\n"
                               "        DeclareLaunchArgument('params_file', default_value=PathJoinSubstitution(\n"
                               "            [ThisLaunchFileDir(), 'params.yaml'])),\n"
                               "        Node(package='rig_manager', executable='manager', name='rig_manager',\n"
                               "             parameters=[params, {'rear.topic': 'rear/scan'}]),\n    ])\n"),
    "xml param from": ("c.launch.xml", '<launch>\n  <node pkg="rig_manager" exec="manager" name="rig_manager">\n'
                       '    <param from="$(dirname)/params.yaml"/>\n  </node>\n</launch>\n'),
    "yaml param from": ("d.launch.yaml", "launch:\n- node:\n    pkg: rig_manager\n    exec: manager\n"
                        "    name: rig_manager\n    param:\n    - from: $(dirname)/params.yaml\n"),
}
KEYS = {"python ParameterFile": "/**", "python launch argument": "rig_manager", "xml param from": "/rig_manager",
        "yaml param from": "/**/rig_manager"}


def _params(key: str) -> str:
    return f"{key}:\n  ros__parameters:\n    front:\n      topic: front/scan\n"


def _front(tmp_path: Path, form: str, key: str) -> tuple[str, Any, list[str]]:
    """The topic of rig_manager's front subscription with the file keyed ``key``, where it was set, the notes."""
    name, text = FORMS[form]
    (tmp_path / "params.yaml").write_text(_params(key), encoding="utf-8")
    launch = tmp_path / name
    launch.write_text(text, encoding="utf-8")
    g = scan([WS], [launch], standard=False).graph
    [front] = [e for e in g.nodes["/rig_manager"].subscribes if e.param == "/rig_manager/front.topic"]
    return front.topic, front.param_set_at, [n.message for n in g.notes if str(tmp_path) in n.src.file]


@pytest.mark.parametrize("form", FORMS)
def test_a_parameter_file_the_launch_file_gives_names_the_topic(tmp_path: Path, form: str) -> None:
    topic, at, notes = _front(tmp_path, form, KEYS[form])
    assert topic == "/front/scan" and (Path(at.file).name, at.line) == ("params.yaml", 4), (form, notes)
    assert notes == []
    topic, at, _ = _front(tmp_path, form, "other_node")  # the control: the file is another node's
    assert topic == "/scan" and at is None


def test_a_relative_missing_or_broken_file_is_said_and_the_node_kept(tmp_path: Path) -> None:
    _, text = FORMS["xml param from"]
    launch = tmp_path / "e.launch.xml"
    for frm, said in (("params.yaml", "is a relative path, read from the directory ros2 launch runs in"),
                      ("$(dirname)/none.yaml", "cannot read parameter file"),
                      ("$(dirname)/broken.yaml", "parameter file is not valid YAML")):
        (tmp_path / "broken.yaml").write_text("/**: [unclosed\n", encoding="utf-8")
        launch.write_text(text.replace("$(dirname)/params.yaml", frm), encoding="utf-8")
        g = scan([WS], [launch], standard=False).graph
        assert "/rig_manager" in g.nodes
        notes = [n for n in g.notes if said in n.message]
        assert len(notes) == 1, [n.message for n in g.notes]


def test_a_node_the_launch_file_does_not_name_takes_the_keys_of_its_codes_name(tmp_path: Path) -> None:
    """Node(package=..., executable=...) with no name= runs with the name its code gives (rig_manager): the
    file's ``rig_manager:`` key applies to it once the graph knows that name; ``other_node:`` (the control) does
    not."""
    topic, at, notes = _front(tmp_path, "python ParameterFile", "rig_manager")
    assert topic == "/front/scan" and at.line == 4 and notes == []
    topic, at, _ = _front(tmp_path, "python ParameterFile", "other_node")
    assert topic == "/scan" and at is None
