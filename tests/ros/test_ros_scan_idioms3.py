"""Real ROS 2 code, round three (issue 53): node bases of a helper package
written with its namespace, endpoints made by another package's helper
classes, names from parameters read into variables through out-parameters
and computed keys, names from the node's own name, type adapters, bond's
heartbeat, and located notes for names only known at run time.

The workspace is the project's own (tests/data/ros_corpus/idioms5), its
expected graph written by hand (expected/idioms5_sources.json); each test
below failed before issue 53's change and passes after."""
from __future__ import annotations

from pathlib import Path

import _idioms

from rclverify.ros.graph.scan import scan
from rclverify.ros.extract.sources_cpp import scan_cpp

CORPUS, ROLES = _idioms.CORPUS, _idioms.ROLES
WS = CORPUS / "idioms5"
EXPECTED = _idioms.expected("idioms5")
graph = _idioms.graph_fixture("idioms5")
_edges = _idioms.edges


def _want(node: str) -> set[tuple[str, str, str | None, str]]:
    return _idioms.want(EXPECTED, node)


def test_node_base_of_a_helper_package_written_with_its_namespace(graph) -> None:  # type: ignore[no-untyped-def]
    # class Guard : public rig_util::LifecycleNode, Guard() : rig_util::LifecycleNode("guard", "", options)
    assert graph.nodes["/guard"].lifecycle
    assert _edges(graph, "/guard") == _want("/guard")
    # the one note: TransformListener(*tf_buffer_) subscribes on tf2's own node, not /guard
    assert [(n.code, n.src.line) for n in graph.notes if "guard" in n.src.file or "rig_util" in n.src.file] == \
        [("ROS-TF-OWN-NODE", 17)]


def test_namespaced_node_base_whose_package_is_not_scanned() -> None:
    src = (b'#include "rclcpp/rclcpp.hpp"\n#include "std_msgs/msg/bool.hpp"\n'
           b'class Monitor : public ext_util::LifecycleNode {\npublic:\n'
           b'  explicit Monitor(const rclcpp::NodeOptions & o)\n'
           b'  : ext_util::LifecycleNode("collision_monitor", "", o) {\n'
           b'    pub_ = create_publisher<std_msgs::msg::Bool>("stopped", 1);\n  }\n'
           b'  std::shared_ptr<void> pub_;\n};\n')
    r = scan_cpp(src, "monitor.cpp")
    assert [n for n, _at in r["nodes"]] == ["collision_monitor"]
    assert r["node_names"][0][5] == "lifecycle"
    # a member named Node in a file that is no ROS 2 code is not a node
    plain = b"struct Graph : public geo::Node {\n  Graph() : geo::Node(\"vertex\") {}\n};\n"
    assert scan_cpp(plain, "graph.cpp")["nodes"] == []


def test_endpoints_made_by_another_packages_helper_classes_with_the_callers_names(graph) -> None:  # type: ignore[no-untyped-def]
    # TwistSubscriber/TwistPublisher (header-only) and OdomSmoother (its header's default
    # argument, its source's subscription) are rig_util's; the names are rig_relay's
    assert _edges(graph, "/relay") == _want("/relay")
    # the helper library is no program of its own: nothing said about its open names
    assert not [n for n in graph.notes if "rig_util" in n.src.file]


def test_names_from_the_node_own_name_and_from_parameters_through_out_parameters(graph) -> None:  # type: ignore[no-untyped-def]
    assert _edges(graph, "/rig_manager") == _want("/rig_manager")
    assert not [n for n in graph.notes if "rig_manager" in n.src.file]


def test_a_computed_parameter_key_takes_the_launch_value_of_each_source(tmp_path: Path) -> None:
    lf = tmp_path / "manager.launch.py"
    lf.write_text("from launch import LaunchDescription\nfrom launch_ros.actions import Node\n\n\n"
                  "def generate_launch_description():\n    return LaunchDescription([\n"
                  "        Node(package='rig_manager', executable='manager',\n"
                  "             parameters=[{'front.topic': 'front/scan'}]),\n    ])\n")
    g = scan([WS], [lf], standard=False).graph
    subs = {(e.topic, e.param, e.param_set_at is not None) for e in g.nodes["/rig_manager"].subscribes}
    assert subs == {("/front/scan", "/rig_manager/front.topic", True), ("/scan", "/rig_manager/rear.topic", False)}


def test_type_adapters_give_the_ros_type(graph, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    assert _edges(graph, "/camera") == _want("/camera")
    # a custom type no adapter names is no message (never cv/msg/Mat): left unknown, said
    pkg = tmp_path / "ws" / "cam"
    (pkg / "src").mkdir(parents=True)
    (pkg / "package.xml").write_text('<package format="3"><name>cam</name><version>0.0.0</version>'
                                     '<description>d</description><maintainer email="dev@example.org">m</maintainer>'
                                     '<license>MIT</license><buildtool_depend>ament_cmake</buildtool_depend>'
                                     '<export><build_type>ament_cmake</build_type></export></package>')
    (pkg / "src" / "c.cpp").write_text('#include "rclcpp/rclcpp.hpp"\nclass C : public rclcpp::Node {\n public:\n'
                                       '  C() : Node("c") { p_ = create_publisher<cv::Mat>("frames", 1); }\n};\n')
    g = scan([tmp_path / "ws"], [], base=tmp_path, standard=False).graph
    assert [(e.topic, e.msg_type) for e in g.nodes["/c"].publishes] == [("/frames", None)]
    assert [(n.src.file, n.src.line) for n in g.notes if "type of publisher topic 'frames'" in n.message] == [
        ("ws/cam/src/c.cpp", 4)]


def test_bond_heartbeat_publishes_and_subscribes_its_topic() -> None:
    r = scan_cpp(b'#include "bondcpp/bond.hpp"\nvoid f(rclcpp::Node::SharedPtr node) {\n'
                 b'  auto b = std::make_unique<bond::Bond>(std::string("bond"), node->get_name(), node);\n}\n',
                 "b.cpp")
    assert sorted((e.kind, e.topic, e.msg_type, e.src.line) for e in r["endpoints"]) == [
        ("pub", "bond", "bond/msg/Status", 3), ("sub", "bond", "bond/msg/Status", 3)]


def test_whole_workspace_is_the_hand_written_graph_and_run_time_names_are_located(graph) -> None:  # type: ignore[no-untyped-def]
    assert set(graph.nodes) == set(EXPECTED["nodes"])
    for node in EXPECTED["nodes"]:
        assert _edges(graph, node) == _want(node), node
    notes = {f"{n.src.file}:{n.src.line}" for n in graph.notes if n.code == "ROS-UNRESOLVED"}
    assert notes == set(EXPECTED["unresolved"])


def test_a_stacks_free_factory_taking_the_node_first() -> None:
    # pkg::interfaces::create_service<T>(shared_from_this(), get_name() + "/is_active", cb)
    r = scan_cpp(b'#include "rclcpp/rclcpp.hpp"\n#include "std_srvs/srv/trigger.hpp"\n'
                 b'class M : public rclcpp::Node {\n public:\n  M() : Node("m") {}\n  void start() {\n'
                 b'    srv_ = rig::interfaces::create_service<std_srvs::srv::Trigger>(\n'
                 b'      shared_from_this(), get_name() + std::string("/is_active"), cb_);\n  }\n};\n', "m.cpp")
    assert [(e.kind, e.topic, e.msg_type, e.src.line) for e in r["endpoints"]] == [
        ("service_servers", "~is_active", "std_srvs/srv/Trigger", 7)]


def test_one_node_named_by_an_executable_and_its_component_is_said_once(tmp_path: Path) -> None:
    pkg = tmp_path / "ws" / "mon"
    (pkg / "src").mkdir(parents=True)
    (pkg / "package.xml").write_text('<package format="3"><name>mon</name><version>0.0.0</version>'
                                     '<description>d</description><maintainer email="dev@example.org">m'
                                     '</maintainer><license>MIT</license><buildtool_depend>ament_cmake'
                                     '</buildtool_depend><export><build_type>ament_cmake</build_type></export>'
                                     '</package>')
    (pkg / "CMakeLists.txt").write_text('project(mon)\nadd_library(mon_core SHARED src/mon.cpp)\n'
                                        'add_executable(mon src/main.cpp)\ntarget_link_libraries(mon mon_core)\n'
                                        'rclcpp_components_register_nodes(mon_core "mon::Monitor")\n')
    (pkg / "src" / "mon.cpp").write_text('#include "rclcpp/rclcpp.hpp"\n#include "std_msgs/msg/bool.hpp"\n'
                                         'namespace mon {\nclass Monitor : public rclcpp::Node {\n public:\n'
                                         '  Monitor() : Node("monitor") {\n'
                                         '    p_ = create_publisher<std_msgs::msg::Bool>("alarm", 1);\n  }\n};\n}\n')
    (pkg / "src" / "main.cpp").write_text('#include "rclcpp/rclcpp.hpp"\nint main(int argc, char ** argv) {\n'
                                          '  rclcpp::init(argc, argv);\n'
                                          '  rclcpp::spin(std::make_shared<mon::Monitor>());\n}\n')
    g = scan([tmp_path / "ws"], [], base=tmp_path, standard=False).graph
    assert [(e.topic, e.src.line) for e in g.nodes["/monitor"].publishes] == [("/alarm", 7)]
    assert not [n for n in g.notes if "also named" in n.message]
