"""The ROS scan on code as real packages write it (issue 32): Python 2 scripts,
C++ components behind export macros and CMake wrappers, launch composable
nodes, parameter-held names, services and actions.  The corpus is the
project's own (tests/data/ros_corpus), its expected graphs written by hand."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from rclverify.ros.extract.cmake import expand
from rclverify.ros.graph.scan import scan
from rclverify.ros.extract.model import SERVICE_ROLES
from rclverify.ros.extract.sources_cpp import scan_cpp
from rclverify.ros.extract.sources_py import scan_python

CORPUS = Path(__file__).parent.parent / "data" / "ros_corpus"
CASES = sorted((CORPUS / "expected").glob("*.json"))


def _graph(case: str):  # type: ignore[no-untyped-def]
    exp = json.loads((CORPUS / "expected" / f"{case}.json").read_text())
    ws = CORPUS / exp["workspace"]
    return exp, scan([ws], [ws / lf for lf in exp["launch"]], base=CORPUS, standard=False).graph


@pytest.mark.parametrize("case", [c.stem for c in CASES])
def test_corpus_graph_is_exactly_the_hand_written_one(case: str) -> None:
    exp, g = _graph(case)
    want = {(n, role, name, typ) for n, spec in exp["nodes"].items()
            for role in ("pub", "sub") + SERVICE_ROLES for name, typ, *_at in spec.get(role, [])}
    assert set(g.nodes) == set(exp["nodes"])
    assert g.edges(with_services=True) == want
    # every call site is its own edge, at its line
    sites = {(n, role, name, typ, at[0]) for n, spec in exp["nodes"].items()
             for role in ("pub", "sub") + SERVICE_ROLES for name, typ, *at in spec.get(role, []) if at}
    got = {(n.name, role, e.topic, e.msg_type, f"{e.src.file}:{e.src.line}")
           for n in g.nodes.values() for role in ("pub", "sub") + SERVICE_ROLES for e in n.edges_of(role)}
    assert sites <= got
    if sites:
        assert len(sites) == sum(len(n.edges_of(r)) for n in g.nodes.values() for r in ("pub", "sub") + SERVICE_ROLES)
    assert {n: g.nodes[n].package for n in g.nodes} == {n: s["package"] for n, s in exp["nodes"].items()}


def test_python2_script_rospy_calls_recovered_and_unread_lines_noted() -> None:
    text = ("import rospy\nfrom std_msgs.msg import String\nfrom std_srvs.srv import Empty\n"
            "print 'starting'\n"
            "rospy.init_node('old')\n"
            "pub = rospy.Publisher('out', String, queue_size=1)\n"
            "def f(:\n"
            "    pass\n"
            "srv = rospy.Service('~clear', Empty, lambda r: None)\n")
    r = scan_python(text, "old.py")
    assert r["nodes"] == [("old", r["nodes"][0][1])]
    assert [(e.kind, e.topic, e.msg_type, e.src.line) for e in r["endpoints"]] == [
        ("pub", "out", "std_msgs/msg/String", 6), ("service_servers", "~clear", "std_srvs/srv/Empty", 9)]
    note = r["notes"][0]
    assert (note.src.line, note.code, note.severity) == (4, "ROS-PARSE", "warning")
    assert "read with the tolerant reader (tree-sitter-python); line 7 not read" in note.message


def test_python2_corpus_script_is_read_whole() -> None:
    _, g = _graph("ros1_robot")
    [note] = g.notes
    assert str(note).startswith("ros1/src/legacy_py/scripts/beacon:25:9: warning: Python source is not Python 3")
    assert note.message.endswith("every line read")


def test_component_nodes_linked_to_launch_and_cmake_wrapper() -> None:
    _, g = _graph("ros2_composed")
    relay = g.nodes["/demo/relay"]  # a ComposableNode(plugin='comp_demo::Relay') of the container
    assert str(relay.declared_at) == "ros2/src/comp_demo/launch/composed.launch.py:13:13"
    assert (relay.sources, relay.executable) == (["ros2/src/comp_demo/src/relay.cpp"], None)
    gauge = g.nodes["/demo/gauge"]  # exe 'gauge': rclcpp_components_register_node inside a CMake function
    assert (gauge.sources, gauge.executable) == (["ros2/src/comp_demo/src/gauge.cpp"], "gauge")
    _, g2 = _graph("ros2_tools")  # XML node_container / composable_node
    assert g2.nodes["/demo/relay_b"].sources == ["ros2/src/comp_demo/src/relay.cpp"]


def test_parameterised_topic_takes_the_launch_value_else_the_default() -> None:
    _, g = _graph("ros2_composed")
    out = g.nodes["/demo/relay"].publishes[0]
    assert (out.topic, out.written, out.param) == ("/demo/chatter_out", "chatter_out", "/demo/relay/output")
    assert str(out.param_set_at) == "ros2/src/comp_demo/launch/composed.launch.py:18:40"
    battery = g.nodes["/demo/gauge"].publishes[0]  # not set by the launch file: the declared default
    assert (battery.topic, battery.param, battery.param_set_at) == ("/demo/battery", "/demo/gauge/battery_topic", None)
    _, g1 = _graph("ros1_robot")  # a <param> in a group scope reaches a relative parameter
    level = next(e for e in g1.nodes["/scout/beacon"].subscribes if e.param)
    assert (level.topic, level.param) == ("/scout/power/level", "/scout/level_topic")


def test_parameter_without_default_or_launch_value_is_noted(tmp_path: Path) -> None:
    pkg = tmp_path / "p"
    (pkg / "scripts").mkdir(parents=True)
    (pkg / "package.xml").write_text('<package format="2"><name>p</name><version>1.0.0</version>'
                                     '<description>d</description><maintainer email="dev@example.org">m</maintainer>'
                                     '<license>MIT</license><buildtool_depend>catkin</buildtool_depend></package>')
    (pkg / "scripts" / "n.py").write_text("import rospy\nfrom std_msgs.msg import String\n"
                                          "rospy.init_node('n')\nrospy.Publisher(rospy.get_param('~t'), String)\n")
    g = scan([tmp_path], base=tmp_path, standard=False).graph
    assert g.nodes["/n"].publishes == []
    assert [str(n) for n in g.notes] == [
        "p/scripts/n.py:4:1: warning: name of pub comes from parameter /n/t, which has no default in the code "
        "and no value in the launch files: not resolved statically"]


def test_cpp_export_macro_members_and_receivers() -> None:
    code = (b"namespace a { namespace b {\n"
            b"class A_B_EXPORT Cam final : public rclcpp::Node {\n"
            b" public:\n"
            b"  Cam() : Node(\"cam\") { img_ = this->create_publisher<sensor_msgs::msg::Image>(\"image\", 1); }\n"
            b"  void later() { s_ = shared_from_this()->create_service<std_srvs::srv::Empty>(\"snap\", cb); }\n"
            b"  rclcpp::Publisher<sensor_msgs::msg::Image>::SharedPtr img_;\n"
            b"};\n}}\n")
    r = scan_cpp(code, "cam.cpp")
    assert r["notes"] == []
    assert list(r["classes"]) == ["a::b::Cam"]
    assert [(e.kind, e.topic, e.msg_type) for e in r["classes"]["a::b::Cam"]["endpoints"]] == [
        ("pub", "image", "sensor_msgs/msg/Image"), ("service_servers", "snap", "std_srvs/srv/Empty")]
    assert [n for n, _ in r["classes"]["a::b::Cam"]["nodes"]] == ["cam"]


def test_cmake_wrappers_traced_with_arguments() -> None:
    text = ("project(p)\nset(SRCS a.cpp b.cpp)  # a comment (\n"
            "function(add_comp target cls)\n  rclcpp_components_register_node(${target} PLUGIN \"${cls}\" "
            "EXECUTABLE ${target}_exe)\nendfunction()\n"
            "macro(kw)\n  cmake_parse_arguments(K \"\" \"NAME;CLASS\" \"SOURCES\" ${ARGN})\n"
            "  add_executable(${K_NAME} ${K_SOURCES})\n  add_comp(${K_NAME} ${K_CLASS})\nendmacro()\n"
            "kw(NAME cam CLASS ns::Cam SOURCES ${SRCS})\n")
    assert expand(text, "p") == [
        ("add_executable", ["cam", "a.cpp", "b.cpp"], 11),
        ("rclcpp_components_register_node", ["cam", "PLUGIN", "ns::Cam", "EXECUTABLE", "cam_exe"], 11)]


def test_source_mode_makes_one_node_per_node_class() -> None:
    g = scan([CORPUS / "ros2"], base=CORPUS, standard=False).graph
    assert set(g.nodes) == {"/relay", "/gauge", "/probe", "/watchdog"}
    assert ("/relay", "service_servers", "/relay/flush", "std_srvs/srv/Trigger") in g.edges(with_services=True)


def test_yaml_launch_composable_node_with_parameter(tmp_path: Path) -> None:
    import shutil
    ws = tmp_path / "ws"
    shutil.copytree(CORPUS / "ros2", ws)
    lf = ws / "src" / "comp_demo" / "launch" / "one.launch.yaml"
    lf.write_text("launch:\n- node_container:\n    pkg: rclcpp_components\n    exec: component_container\n"
                  "    name: c\n    namespace: ''\n    composable_node:\n    - pkg: comp_demo\n"
                  "      plugin: comp_demo::Relay\n      name: yrelay\n      namespace: y\n"
                  "      param:\n      - name: output\n        value: /shared/out\n")
    g = scan([ws], [lf], base=tmp_path, standard=False).graph
    assert set(g.nodes) == {"/y/yrelay"}
    assert ("/y/yrelay", "pub", "/shared/out", "std_msgs/msg/String") in g.edges()
    assert ("/y/yrelay", "action_servers", "/y/sweep", "corpus_interfaces/action/Sweep") in g.edges(True)


def test_programs_taking_one_node_name_without_launch_are_kept_apart() -> None:
    # Published packages ship several test scripts that call init_node with the
    # same name; nothing starts them together, so each is a node of its own
    # (issue 53: merged, they mixed into one contract), none dropped.
    _, g = _graph("loose_sources")
    linear, spin = g.nodes["/rig_jogger@bench_tools.jog_linear.py"], g.nodes["/rig_jogger@bench_tools.jog_spin.py"]
    assert "/rig_jogger" not in g.nodes
    assert (linear.sources, spin.sources) == (["loose/src/bench_tools/scripts/jog_linear.py"],
                                              ["loose/src/bench_tools/scripts/jog_spin.py"])
    assert ({e.topic for e in linear.service_clients}, {e.topic for e in spin.service_clients}) == (
        {"/rig/home"}, {"/rig/stop"})
    [note] = [n for n in g.notes if n.code == "ROS-LAUNCH"]
    assert str(note) == ("loose/src/bench_tools/scripts/jog_spin.py:7:1: warning: node /rig_jogger is also named "
                         "at loose/src/bench_tools/scripts/jog_linear.py:10:9; no launch file starts these "
                         "programs together: kept apart as /rig_jogger@bench_tools.jog_spin.py (and "
                         "/rig_jogger@bench_tools.jog_linear.py)")


def test_nodes_named_alike_are_merged_only_without_launch_files() -> None:
    _, g = _graph("ros1_robot")  # launched: no merging note
    assert not any("also named" in n.message for n in g.notes)


@pytest.mark.parametrize("py2", [False, True])
def test_python_node_classes_own_the_endpoints_written_in_them(py2: bool) -> None:
    text = ("import rclpy\nfrom rclpy.node import Node\nfrom std_msgs.msg import String\n"
            "class A(Node):\n"
            "    def __init__(self):\n"
            "        super().__init__('a')\n"
            "        self.p = self.create_publisher(String, 'x', 1)\n"
            "class B(Node):\n"
            "    def __init__(self):\n"
            "        super().__init__('b')\n"
            "        self.s = self.create_subscription(String, 'x', None, 1)\n"
            "def main():\n"
            "    n = rclpy.create_node('c')\n"
            "    n.create_publisher(String, 'y', 1)\n"
            + ("    print 'py2'\n" if py2 else ""))
    r = scan_python(text, "two.py")
    assert [n for n, _ in r["nodes"]] == ["a", "b", "c"]
    assert [(r["nodes"][o][0], e.topic) for o, e in zip(r["owners"], r["endpoints"])] == [
        ("a", "x"), ("b", "x"), ("c", "y")]
    assert bool(r["notes"]) is py2  # the tolerant reader gives the same classes


def test_one_node_file_has_no_owners() -> None:
    r = scan_python("import rospy\nrospy.init_node('n')\nclass K(object):\n    pass\n", "one.py")
    assert r["owners"] == []
