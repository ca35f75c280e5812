"""ROS 2 pluginlib plugins (issue 53, idiom 5), and field paths kept per
contract (the grounding bug docs/ros.md notes in "Held-out recall").

A class exported in a plugin description that package.xml's <export> names,
whose endpoints are made on the handle its loader gives it, belongs to the
node whose parameter file lists it; a plugin no node is found to load is a
located note, never an edge.  The workspace is the project's own
(tests/data/ros_corpus/idioms8), its expected graph written by hand
(expected/idioms8_sources.json); each test below failed on main 9637a4d (the
plugins' endpoints were lost, with a note about a file naming no node; the
skeleton wrote one topic's field paths for two message types)."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

import _idioms

from rclverify.ros.graph.scan import scan
from rclverify.ros.extract.model import Src
from rclverify.ros.extract.plugins import described, instances

CORPUS, ROLES = _idioms.CORPUS, _idioms.ROLES
WS = CORPUS / "idioms8"
EXPECTED = _idioms.expected("idioms8")
graph = _idioms.graph_fixture("idioms8")
_edges = _idioms.edges


def _want(node: str) -> set[tuple[str, str, str | None, str]]:
    return _idioms.want(EXPECTED, node)


def test_plugin_endpoints_belong_to_the_node_whose_parameter_file_loads_them(graph) -> None:  # type: ignore[no-untyped-def]
    assert set(graph.nodes) == {"/mapper"}  # a plugin is no node of its own
    assert _edges(graph, "/mapper") == _want("/mapper")
    assert "idioms8/src/rig_layers/src/range_layer.cpp" in graph.nodes["/mapper"].sources


def test_each_instance_reads_its_own_topic_parameter_of_the_loading_node(graph) -> None:  # type: ignore[no-untyped-def]
    # RangeLayer is loaded twice: name + ".topic" is front_range.topic (set in the file)
    # and rear_range.topic (not set: the default the plugin declares)
    subs = {e.topic: e for e in graph.nodes["/mapper"].edges_of("sub")}
    front, rear = subs["/front/range"], subs["/range"]
    assert (front.param, str(front.param_set_at)) == ("/mapper/front_range.topic",
                                                      "idioms8/src/rig_mapper/config/mapper.yaml:7:14")
    assert (rear.param, rear.param_set_at) == ("/mapper/rear_range.topic", None)
    assert front.src == rear.src  # one call site, two instances


def test_a_plugin_no_node_loads_is_a_located_note_naming_it(graph) -> None:  # type: ignore[no-untyped-def]
    [at] = EXPECTED["unresolved"]
    said = [n for n in graph.notes if f"{n.src.file}:{n.src.line}" == at]
    assert len(said) == 1
    assert "plugin rig_layers::SonarLayer" in said[0].message and "loaded at run time" in said[0].message
    assert "idioms8/src/rig_layers/layers.xml:8" in said[0].message
    assert not any(e.topic == "/sonar" for n in graph.nodes.values() for r in ROLES for e in n.edges_of(r))
    # nothing else is said: no 'file names no node' nor 'not a string literal' about the plugins
    assert [str(n.src) for n in graph.notes] == ["idioms8/src/rig_layers/src/sonar_layer.cpp:19:12"]


def test_a_layer_the_list_leaves_out_is_not_loaded(tmp_path: Path) -> None:
    ws = tmp_path / "idioms8"
    shutil.copytree(WS, ws)
    cfg = ws / "src" / "rig_mapper" / "config" / "mapper.yaml"
    cfg.write_text(cfg.read_text().replace('["front_range", "rear_range", "bumper"]', '["bumper"]'))
    g = scan([ws], [], base=tmp_path, standard=False).graph
    assert {e.topic for e in g.nodes["/mapper"].edges_of("sub")} == {"/bumper"}
    assert sorted(f"{n.src.file}:{n.src.line}" for n in g.notes) == [
        "idioms8/src/rig_layers/src/range_layer.cpp:22", "idioms8/src/rig_layers/src/sonar_layer.cpp:19"]


def test_initialize_with_a_node_handle_and_an_unknown_plugin_class(tmp_path: Path) -> None:
    # another base (initialize(rclcpp::Node::SharedPtr node)), a lookup name given by
    # <class name=...> in <class_libraries>, a plugin: value no package exports, and an
    # exported class no source defines
    ws = tmp_path / "idioms8"
    shutil.copytree(WS, ws)
    pkg = ws / "src" / "rig_layers"
    (pkg / "src" / "probe.cpp").write_text(
        '#include "rclcpp/rclcpp.hpp"\n#include "std_msgs/msg/string.hpp"\nnamespace rig_layers {\n'
        'class Probe : public rig_core::Check {\npublic:\n  void initialize(rclcpp::Node::SharedPtr node) override\n'
        '  {\n    pub_ = node->create_publisher<std_msgs::msg::String>("probe_state", 1);\n  }\n'
        'private:\n  rclcpp::Publisher<std_msgs::msg::String>::SharedPtr pub_;\n};\n}\n')
    (pkg / "checks.xml").write_text(
        '<class_libraries><library path="lib/librig_checks">\n'
        '  <class name="rig_layers/Probe" type="rig_layers::Probe" base_class_type="rig_core::Check"/>\n'
        '  <class type="rig_layers::Missing" base_class_type="rig_core::Check"/>\n'
        '</library></class_libraries>\n')
    manifest = pkg / "package.xml"
    manifest.write_text(manifest.read_text().replace(
        '<rig_core plugin="${prefix}/layers.xml"/>',
        '<rig_core plugin="${prefix}/layers.xml"/>\n  <rig_core plugin="${prefix}/checks.xml"/>'))
    cmake = pkg / "CMakeLists.txt"
    cmake.write_text(cmake.read_text().replace("pluginlib_export", "add_library(rig_checks SHARED src/probe.cpp)\n"
                                                                  "pluginlib_export"))
    cfg = ws / "src" / "rig_mapper" / "config" / "mapper.yaml"
    cfg.write_text(cfg.read_text().replace('"bumper"]', '"bumper", "probe", "ghost", "missing"]') +
                   '    probe:\n      plugin: "rig_layers/Probe"\n    ghost:\n      plugin: "rig_layers::Ghost"\n'
                   '    missing:\n      plugin: "rig_layers::Missing"\n')
    g = scan([ws], [], base=tmp_path, standard=False).graph
    pubs = {(e.topic, f"{e.src.file}:{e.src.line}") for e in g.nodes["/mapper"].edges_of("pub")}
    assert ("/probe_state", "idioms8/src/rig_layers/src/probe.cpp:8") in pubs
    [ghost] = [n for n in g.notes if "Ghost" in n.message]
    assert str(ghost.src) == "idioms8/src/rig_mapper/config/mapper.yaml:16:15"
    assert "parameter /mapper/ghost.plugin names plugin 'rig_layers::Ghost', which no scanned package exports" \
        in ghost.message
    [missing] = [n for n in g.notes if "Missing" in n.message]  # exported, defined nowhere
    assert str(missing.src) == "idioms8/src/rig_mapper/config/mapper.yaml:18:15"
    assert "no scanned C++ source defines the class: its endpoints are unknown" in missing.message


def test_descriptions_read_from_the_export_and_nodelets_left_to_their_reader(tmp_path: Path) -> None:
    (tmp_path / "package.xml").write_text(
        '<package format="3"><name>p</name><export><nodelet plugin="${prefix}/nodelets.xml"/>'
        '<base_pkg plugin="${prefix}/plugins.xml"/><other plugin="${prefix}/missing.xml"/></export></package>')
    (tmp_path / "nodelets.xml").write_text('<library path="lib/libn"><class type="p::N" '
                                           'base_class_type="nodelet::Nodelet"/></library>')
    (tmp_path / "plugins.xml").write_text('<library path="p_plugins">\n<class type="::p::A" '
                                          'base_class_type="base::Iface"/>\n<class name="p/B" type="p::B" '
                                          'base_class_type="base::Iface"/></library>')
    got, notes = described(tmp_path)
    assert [(c.type, c.base, c.lookup, c.library, c.line) for c in got] == [
        ("p::A", "base::Iface", "p::A", "p_plugins", 2), ("p::B", "base::Iface", "p/B", "p_plugins", 3)]
    assert [(n.src.file, n.code) for n in notes] == [("package.xml", "ROS-PARSE")]
    assert "missing.xml" in notes[0].message


def test_instances_follow_the_nodes_list() -> None:
    got, _ = described(WS / "src" / "rig_layers")
    classes = {k: c for c in got for k in (c.type, c.lookup)}
    at = Src("params.yaml", 1, 1)
    values = {"/m/layers": (("a",), at), "/m/a.plugin": ("rig_layers::RangeLayer", at),
              "/m/b.plugin": ("rig_layers::BumperLayer", at), "/m/c.plugin": ("not a class", at),
              "/other/d.plugin": ("rig_layers::SonarLayer", at)}
    found, notes = instances(values, "/m", classes)
    assert [(i, c.type) for i, c, _at in found] == [("a", "rig_layers::RangeLayer")] and notes == []
    del values["/m/layers"]  # no list: every plugin entry of the node is its (the code's default list)
    found, notes = instances(values, "/m", classes)
    assert [(i, c.type) for i, c, _at in found] == [("a", "rig_layers::RangeLayer"), ("b", "rig_layers::BumperLayer")]
    assert notes == []  # "not a class" is some other parameter called plugin


def _pkg(root: Path, name: str, build: str, extra: str = "") -> Path:
    (root / name).mkdir(parents=True)
    (root / name / "package.xml").write_text(
        f'<?xml version="1.0"?>\n<package format="3"><name>{name}</name><version>0.1.0</version>'
        f'<description>d</description><maintainer email="dev@example.org">dev</maintainer><license>MIT</license>'
        f'<buildtool_depend>{build}</buildtool_depend>{extra}<export><build_type>{build}</build_type></export>'
        f'</package>\n')
    return root / name


def test_field_paths_are_kept_per_contract_when_one_topic_carries_two_types(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # the grounding bug of docs/ros.md "Held-out recall": one topic name, a message in one
    # node and an array of it in another; the first contract's field paths were written
    # under the topic's name and looked up in the other contract's array type
    from rclverify.cli.commands import main
    src = tmp_path / "pads" / "src"
    msgs = _pkg(src, "pad_msgs", "ament_cmake", "<member_of_group>rosidl_interface_packages</member_of_group>")
    (msgs / "msg").mkdir()
    (msgs / "msg" / "Feedback.msg").write_text("uint8 kind\nfloat32 intensity\n")
    (msgs / "msg" / "FeedbackArray.msg").write_text("Feedback[] array\n")
    (msgs / "CMakeLists.txt").write_text('cmake_minimum_required(VERSION 3.8)\nproject(pad_msgs)\n'
                                         'rosidl_generate_interfaces(${PROJECT_NAME} "msg/Feedback.msg" '
                                         '"msg/FeedbackArray.msg")\nament_package()\n')
    nodes = _pkg(src, "pad_nodes", "ament_python")
    (nodes / "scripts").mkdir()
    (nodes / "scripts" / "pad.py").write_text(
        "import rclpy\nfrom pad_msgs.msg import Feedback\nrclpy.init()\nn = rclpy.create_node('pad')\n"
        "n.create_subscription(Feedback, 'set_feedback', lambda m: None, 1)\n")
    (nodes / "scripts" / "rumble.py").write_text(
        "import rclpy\nfrom pad_msgs.msg import FeedbackArray\nrclpy.init()\nn = rclpy.create_node('rumble')\n"
        "n.create_publisher(FeedbackArray, 'set_feedback', 1)\n")
    ws = tmp_path / "ws"
    assert main(["init", str(ws), "--from-ros", str(tmp_path / "pads")]) == 0
    plan = (ws / "contracts/plan.yaml").read_text()
    assert "    Pad.set_feedback: [kind, intensity]\n" in plan and "    set_feedback:" not in plan
    capsys.readouterr()
    out = tmp_path / "ground.json"
    main(["ros", "check", "-w", str(ws), "--json", str(out)])
    codes = [f["code"] for f in json.loads(out.read_text())["findings"]]
    assert "ROS-FIELD-MISSING" not in codes and "ROS-FIELD-TYPE" not in codes
    # the code disagrees with itself: that stays said, naming both programs, each contract matching its own code
    assert "ROS-TYPE-CLASH" in codes and "ROS-TYPE-DIFFERS" not in codes
    # the grounding reads the contract's own entry (Contract.topic): a path Rumble's array lacks
    (ws / "contracts/plan.yaml").write_text(plan + "    Rumble.set_feedback: [kind]\n")
    main(["ros", "check", "-w", str(ws), "--json", str(out)])
    missing = [f for f in json.loads(out.read_text())["findings"] if f["code"] == "ROS-FIELD-MISSING"]
    assert [(f["node"], f["topic"]) for f in missing] == [("Rumble", "set_feedback")]


def test_a_node_in_a_plugin_library_is_still_a_node(tmp_path: Path) -> None:
    ws = tmp_path / "idioms8"
    shutil.copytree(WS, ws)
    pkg = ws / "src" / "rig_layers"
    (pkg / "src" / "probe_node.cpp").write_text(
        '#include "rclcpp/rclcpp.hpp"\n#include "std_msgs/msg/bool.hpp"\n'
        'class ProbeNode : public rclcpp::Node {\npublic:\n  ProbeNode() : Node("layer_probe")\n'
        '  {\n    pub_ = create_publisher<std_msgs::msg::Bool>("probe", 1);\n  }\n'
        '  rclcpp::Publisher<std_msgs::msg::Bool>::SharedPtr pub_;\n};\n')
    cmake = pkg / "CMakeLists.txt"
    cmake.write_text(cmake.read_text().replace("src/sonar_layer.cpp)", "src/sonar_layer.cpp src/probe_node.cpp)"))
    g = scan([ws], [], base=tmp_path, standard=False).graph
    assert set(g.nodes) == {"/mapper", "/layer_probe"}
    assert [e.topic for e in g.nodes["/layer_probe"].publishes] == ["/probe"]
