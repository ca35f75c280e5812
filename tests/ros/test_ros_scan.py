"""``rclverify ros scan``: the exact graphs of the test workspaces
(tests/data/ros, written for this project; docs/ros.md)."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from rclverify.cli.commands import main
from rclverify.ros.graph.scan import scan
from rclverify.ros.extract.interfaces import field_path
from rclverify.ros.extract.launch import read_yaml
from rclverify.ros.extract.sources_cpp import scan_cpp
from rclverify.ros.extract.sources_py import scan_python

DATA = Path(__file__).parent.parent / "data" / "ros"
CATKIN = DATA / "catkin_ws"
AMENT = DATA / "ament_ws"
ROVER_LAUNCH = CATKIN / "src/rover_control/launch/rover.launch"
ARM_LAUNCH = AMENT / "src/arm_planner/launch/arm.launch.py"


def test_catkin_workspace_exact_graph() -> None:
    g = scan([CATKIN], [ROVER_LAUNCH], base=DATA).graph
    assert g.edges() == {
        ("/rover/sensor", "pub", "/rover/radiation", "rover_msgs/msg/Reading"),
        ("/rover/sensor", "sub", "/odometry/filtered", "nav_msgs/msg/Odometry"),       # group remap
        ("/rover/controller", "sub", "/rover/radiation", "rover_msgs/msg/Reading"),    # type from the callback
        ("/rover/controller", "pub", "/rover/status", "rover_msgs/msg/Status"),
        ("/rover/controller", "pub", "/mobile_base/cmd_vel", "geometry_msgs/msg/Twist"),  # include arg -> remap
    }
    ctl = g.nodes["/rover/controller"]
    assert (ctl.package, ctl.executable, ctl.namespace) == ("rover_control", "controller", "/rover")
    assert ctl.sources == ["catkin_ws/src/rover_control/src/controller.cpp"]
    assert str(ctl.declared_at) == "catkin_ws/src/rover_control/launch/control.launch:3:1"
    cmd = next(e for e in ctl.publishes if e.topic == "/mobile_base/cmd_vel")
    assert str(cmd.src) == "catkin_ws/src/rover_control/src/controller.cpp:25:13"
    assert str(cmd.remapped_at) == "catkin_ws/src/rover_control/launch/control.launch:4:1"
    # the `if="$(arg use_sim)"` node is not started (use_sim defaults to false)
    assert set(g.nodes) == {"/rover/sensor", "/rover/controller"}
    assert {k: (v["version"], v["build_type"], v["ros"]) for k, v in g.packages.items()} == {
        "rover_msgs": ("0.3.1", "catkin", 1), "rover_sensing": ("0.3.1", "catkin", 1),
        "rover_control": ("1.2.0", "catkin", 1)}
    # the parameter-held topic is reported, located, never guessed
    assert [str(n) for n in g.notes] == [
        "catkin_ws/src/rover_sensing/scripts/sensor.py:14:38: warning: publisher topic name is 'debug_topic', "
        "not a string literal: not resolved statically"]


def test_catkin_launch_arguments_change_the_graph() -> None:
    g = scan([CATKIN], [ROVER_LAUNCH], {"robot": "r2", "use_sim": "true"}, base=DATA).graph
    assert set(g.nodes) == {"/r2/sensor", "/r2/controller", "/sim_sensor"}
    assert ("/sim_sensor", "sub", "/odom", "nav_msgs/msg/Odometry") in g.edges()
    assert ("/r2/controller", "pub", "/r2/status", "rover_msgs/msg/Status") in g.edges()


def test_ament_workspace_exact_graph_from_python_launch_including_xml() -> None:
    g = scan([AMENT], [ARM_LAUNCH], base=DATA).graph
    assert g.edges() == {
        ("/arm/planner", "pub", "/arm/joint_goal", "arm_interfaces/msg/JointGoal"),
        ("/arm/planner", "sub", "/robot/joint_states", "sensor_msgs/msg/JointState"),
        ("/arm/driver", "sub", "/arm/joint_goal", "arm_interfaces/msg/JointGoal"),
        ("/arm/driver", "pub", "/robot/joint_states", "sensor_msgs/msg/JointState"),
    }
    assert g.nodes["/arm/planner"].sources == ["ament_ws/src/arm_planner/arm_planner/planner.py"]
    assert str(g.nodes["/arm/planner"].declared_at) == "ament_ws/src/arm_planner/launch/arm.launch.py:17:13"
    assert str(g.nodes["/arm/driver"].declared_at) == "ament_ws/src/arm_driver/launch/driver.launch.xml:3:1"
    assert g.notes == []
    assert {k: v["build_type"] for k, v in g.packages.items()} == {
        "arm_interfaces": "ament_cmake", "arm_planner": "ament_python", "arm_driver": "ament_cmake"}
    # ROS 2 workspace: standard types from rosbags' ROS 2 store (no seq in Header)
    assert g.types["std_msgs/msg/Header"]["origin"] == "rosbags"
    assert [f["name"] for f in g.types["std_msgs/msg/Header"]["fields"]] == ["stamp", "frame_id"]


def test_ament_yaml_launch_and_sources_alone() -> None:
    g = scan([AMENT], [AMENT / "src/arm_driver/launch/driver.launch.yaml"], base=DATA).graph
    assert g.edges() == {("/arm/driver", "sub", "/arm/joint_goal", "arm_interfaces/msg/JointGoal"),
                         ("/arm/driver", "pub", "/arm/joint_states", "sensor_msgs/msg/JointState")}
    g = scan([AMENT], base=DATA).graph  # no launch file: one node per source that names its node
    assert g.edges() == {("/planner", "pub", "/joint_goal", "arm_interfaces/msg/JointGoal"),
                         ("/planner", "sub", "/joint_states", "sensor_msgs/msg/JointState"),
                         ("/driver", "sub", "/joint_goal", "arm_interfaces/msg/JointGoal"),
                         ("/driver", "pub", "/joint_states", "sensor_msgs/msg/JointState")}
    assert {n.origin for n in g.nodes.values()} == {"source"}


def test_message_definitions_nested_and_across_packages() -> None:
    r = scan([CATKIN, AMENT], base=DATA)
    t = r.graph.types
    reading = t["rover_msgs/msg/Reading"]
    assert [(f["name"], f["type"], f["array"], f.get("line")) for f in reading["fields"]] == [
        ("header", "std_msgs/msg/Header", None, 2), ("position", "geometry_msgs/msg/Point", None, 3),
        ("value", "float32", None, 4)]
    assert reading["file"] == "catkin_ws/src/rover_msgs/msg/Reading.msg"
    status = t["rover_msgs/msg/Status"]
    assert [(c["name"], c["value"]) for c in status["constants"]] == [("GREEN", 0), ("ORANGE", 1), ("RED", 2)]
    assert ("readings", "rover_msgs/msg/Reading", "[]") in [(f["name"], f["type"], f["array"]) for f in status["fields"]]
    assert "arm_interfaces/srv/Home_Request" in t and "arm_interfaces/srv/Home_Response" in t
    tab = r.table
    assert field_path(tab, "rover_msgs/msg/Status", "readings[].position.x") == ("float64", None, False)
    assert field_path(tab, "rover_msgs/msg/Status", "readings") == ("rover_msgs/msg/Reading", None, True)
    assert field_path(tab, "arm_interfaces/msg/JointGoal", "tolerance.upper") == ("float64", None, False)
    typ, err, _ = field_path(tab, "rover_msgs/msg/Reading", "position.w")
    assert typ is None and err == "geometry_msgs/msg/Point has no field 'w' (it has: x, y, z)"


def test_python_and_cpp_sources_unresolved_are_located() -> None:
    py = scan_python("import rospy\nfrom std_msgs.msg import String\nt = input()\n"
                     "rospy.Publisher(t, String)\nrospy.Subscriber('/abs', String, cb)\n", "n.py")
    assert [(e.kind, e.topic, e.msg_type, str(e.src)) for e in py["endpoints"]] == [
        ("sub", "/abs", "std_msgs/msg/String", "n.py:5:1")]
    assert [str(n) for n in py["notes"]] == [
        "n.py:4:17: warning: publisher topic name is 't', not a string literal: not resolved statically"]
    cpp = scan_cpp(b'void f(){ auto p = n.advertise<std_msgs::String>(topic_name, 1);\n'
                   b'  auto q = node->create_publisher<std_msgs::msg::Bool>("~/ok", 1); }\n', "n.cpp")
    assert [(e.topic, e.msg_type, str(e.src)) for e in cpp["endpoints"]] == [("~/ok", "std_msgs/msg/Bool", "n.cpp:2:12")]
    assert [str(n) for n in cpp["notes"]] == [
        "n.cpp:1:50: warning: publisher topic name is 'topic_name', not a string literal: not resolved statically"]


def test_cli_scan_writes_json_matching_the_schema(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    import jsonschema
    monkeypatch.chdir(DATA)
    out = tmp_path / "graph.json"
    rc = main(["ros", "scan", "catkin_ws", "--launch", str(ROVER_LAUNCH.relative_to(DATA)), "--json", str(out),
               "--cache", str(tmp_path / "cache")])
    assert rc == 0
    data = json.loads(out.read_text())
    schema = json.loads((Path(__file__).parents[2] / "docs" / "ros-graph.schema.json").read_text())
    jsonschema.validate(data, schema)
    assert [n["name"] for n in data["nodes"]] == ["/rover/controller", "/rover/sensor"]
    radiation = next(t for t in data["topics"] if t["name"] == "/rover/radiation")
    assert radiation == {"name": "/rover/radiation", "types": ["rover_msgs/msg/Reading"],
                         "publishers": ["/rover/sensor"], "subscribers": ["/rover/controller"]}
    assert {f["path"] for f in data["files"]} >= {"catkin_ws/src/rover_control/src/controller.cpp",
                                                  "catkin_ws/src/rover_control/launch/control.launch"}
    err = capsys.readouterr().err
    assert "3 package(s), 2 node(s), 4 topic(s)" in err
    assert main(["ros", "scan", "no/such/dir"]) == 2


def test_incremental_rescan_parses_only_changed_files(tmp_path: Path) -> None:
    import shutil
    ws = tmp_path / "ws"
    shutil.copytree(CATKIN, ws)
    cache = tmp_path / "cache.pickle"
    first = scan([ws], [ws / "src/rover_control/launch/rover.launch"], cache_path=cache, base=tmp_path)
    assert first.cache_hits == 0 and first.cache_misses > 0
    again = scan([ws], [ws / "src/rover_control/launch/rover.launch"], cache_path=cache, base=tmp_path)
    assert again.cache_misses == 0 and again.graph.edges() == first.graph.edges()
    src = ws / "src/rover_control/src/controller.cpp"
    src.write_text(src.read_text().replace('"status"', '"state"'))
    third = scan([ws], [ws / "src/rover_control/launch/rover.launch"], cache_path=cache, base=tmp_path)
    assert third.cache_misses == 1
    assert ("/rover/controller", "pub", "/rover/state", "rover_msgs/msg/Status") in third.graph.edges()


def test_yaml_launch_errors_are_located(tmp_path: Path) -> None:
    f = tmp_path / "bad.launch.yaml"
    f.write_text("launch:\n  - node: {pkg: [\n")
    root, notes = read_yaml(f, "bad.launch.yaml")
    assert root is None and notes[0].severity == "error" and str(notes[0]).startswith("bad.launch.yaml:3:")
