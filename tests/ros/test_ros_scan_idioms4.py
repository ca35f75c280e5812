"""Real ROS 2 code, round three, the rest (issue 53): programs that take one
node name kept apart without a launch file, the package's parameter YAML,
lists of sources from a string-array parameter, pluginlib plugins, located
notes saying where a run-time name comes from, and skeletons of a driver
whose messages share constant names.

The workspace is the project's own (tests/data/ros_corpus/idioms6), its
expected graph written by hand (expected/idioms6_sources.json); each test
below failed before its change and passes after."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

import _idioms

from rclverify.cli.commands import main
from rclverify.ros.graph.scan import scan

CORPUS, ROLES = _idioms.CORPUS, _idioms.ROLES
WS = CORPUS / "idioms6"
EXPECTED = _idioms.expected("idioms6")
graph = _idioms.graph_fixture("idioms6")
_edges = _idioms.edges


def _want(node: str) -> set[tuple[str, str, str | None, str]]:
    return _idioms.want(EXPECTED, node)


def test_programs_taking_one_node_name_without_launch_files_stay_apart(graph) -> None:  # type: ignore[no-untyped-def]
    talkers = sorted(k for k in graph.nodes if k.startswith("/talker"))
    assert talkers == ["/talker@chat_cpp.talker", "/talker@chat_cpp.talker_best_effort", "/talker@chat_py.talker"]
    for k in talkers:
        assert _edges(graph, k) == _want(k), k
        assert graph.nodes[k].namespace == "/"
    # a private name resolves with the node's ROS name, not the graph's
    assert ("pub", "/talker/dropped") in {(r, t) for r, t, _ty, _at in _edges(graph, talkers[1])}
    said = sorted(str(n) for n in graph.notes if n.code == "ROS-LAUNCH")
    assert said == [
        "idioms6/src/chat_cpp/src/talker_best_effort.cpp:12:5: warning: node /talker is also named at "
        "idioms6/src/chat_cpp/src/talker.cpp:11:5; no launch file starts these programs together: kept apart as "
        "/talker@chat_cpp.talker_best_effort (and /talker@chat_cpp.talker)",
        "idioms6/src/chat_py/chat_py/talker.py:10:9: warning: node /talker is also named at "
        "idioms6/src/chat_cpp/src/talker.cpp:11:5; no launch file starts these programs together: kept apart as "
        "/talker@chat_py.talker (and /talker@chat_cpp.talker, /talker@chat_cpp.talker_best_effort)"]


def test_a_launch_file_starting_those_programs_decides(tmp_path: Path) -> None:
    lf = tmp_path / "chat.launch.py"
    lf.write_text("from launch import LaunchDescription\nfrom launch_ros.actions import Node\n\n\n"
                  "def generate_launch_description():\n    return LaunchDescription([\n"
                  "        Node(package='chat_cpp', executable='talker_best_effort'),\n"
                  "        Node(package='chat_py', executable='talker', name='py_talker'),\n    ])\n")
    g = scan([WS], [lf], standard=False).graph
    assert {k for k in g.nodes if "talker" in k} == {"/talker", "/py_talker"}
    assert {e.topic for e in g.nodes["/talker"].publishes} == {"/chatter", "/talker/dropped"}
    assert not [n for n in g.notes if "also named" in n.message]


@pytest.fixture(scope="module")
def skeletons(tmp_path_factory):  # type: ignore[no-untyped-def]
    ws = tmp_path_factory.mktemp("init") / "rig"
    assert main(["init", str(ws), "--from-ros", str(WS)]) == 0
    return ws, {p.name: p.read_text() for p in (ws / "contracts").glob("*.rcl")}


def test_skeletons_keep_programs_apart(skeletons) -> None:  # type: ignore[no-untyped-def]
    _ws, rcl = skeletons
    nodes = sorted(line.split()[1] for text in rcl.values() for line in text.splitlines() if line.startswith("node "))
    assert nodes == ["ArgvListener", "Base", "RangeFusion", "Relay", "TalkerChatCppTalker",
                     "TalkerChatCppTalkerBestEffort", "TalkerChatPyTalker"]
    assert "outputs( chatter : STRING, dropped : NATURAL )" in rcl["talker_chat_cpp_talker_best_effort.rcl"]


def test_skeletons_of_a_driver_check_and_ground(skeletons, tmp_path: Path,  # type: ignore[no-untyped-def]
                                                capsys: pytest.CaptureFixture[str]) -> None:
    ws, rcl = skeletons
    py = rcl["talker_chat_py_talker.rcl"]
    assert "outputs( chatter : STRING, heartbeat : {} )" in py  # std_msgs/Empty: the empty type, not NATURAL
    base = rcl["base.rcl"]
    assert "inputs( reset : {} )" in base and "parameter_events" not in base.split("node Base")[1]
    assert "subscribes to /parameter_events (rcl_interfaces/ParameterEvent)" in base  # listed apart (issue 65)
    # two messages' ON/OFF constants: the later enumeration's values are qualified with its type
    assert "  MotorPowerState : {off, on} ;\n  SoundValue : {soundValueOff, soundValueOn, beep} ;" in \
        rcl["ros_types.rcl"]
    assert "parameter_events" not in (ws / "contracts/plan.yaml").read_text()
    capsys.readouterr()
    files = [str(p) for p in sorted((ws / "contracts").glob("*.rcl"))]
    assert main(["check", "-w", str(ws), *files]) == 0
    assert "0 errors" in capsys.readouterr().out
    out = tmp_path / "ground.json"
    assert main(["ros", "check", "-w", str(ws), "--strict", "--json", str(out)]) == 0
    findings = json.loads(out.read_text())
    got = findings["findings"] if isinstance(findings, dict) else findings
    # every contract is matched to its graph node (its enumerations read from the constants,
    # /parameter_events the library's): nothing but the scan's own located notes
    assert {f["code"] for f in got} == {"ROS-SCAN"}
    assert len(got) == 5  # two programs kept apart, three run-time names


def test_the_packages_parameter_file_gives_values_and_lists_of_sources(graph) -> None:  # type: ignore[no-untyped-def]
    assert _edges(graph, "/range_fusion") == _want("/range_fusion")
    sets = {(e.topic, e.param, f"{e.param_set_at.file}:{e.param_set_at.line}")
            for e in graph.nodes["/range_fusion"].publishes + graph.nodes["/range_fusion"].subscribes}
    yaml = "idioms6/src/rig_sensing/config/range_fusion.yaml"
    assert sets == {("/fused_range", "/range_fusion/output_topic", f"{yaml}:5"),
                    ("/front/range", "/range_fusion/front.topic", f"{yaml}:8"),
                    ("/rear/range", "/range_fusion/rear.topic", f"{yaml}:10")}
    assert not [n for n in graph.notes if "range_fusion" in n.src.file]


def test_without_the_parameter_file_the_code_default_and_a_located_note(tmp_path: Path) -> None:
    import shutil
    ws = tmp_path / "ws"
    shutil.copytree(WS / "src" / "rig_sensing", ws / "rig_sensing")
    shutil.rmtree(ws / "rig_sensing" / "config")
    g = scan([ws], [], base=tmp_path, standard=False).graph
    assert [e.topic for e in g.nodes["/range_fusion"].publishes] == ["/range"]
    assert g.nodes["/range_fusion"].subscribes == []
    [note] = [str(n) for n in g.notes]
    assert note == ("ws/rig_sensing/src/range_fusion.cpp:26:23: warning: name of sub comes from parameter "
                    "~<source>.topic of each source listed in parameter ~observation_sources, which has no list "
                    "value in the launch files or the package's parameter files: not resolved statically")


def test_parameter_files_two_files_disagreeing_and_wildcards(tmp_path: Path) -> None:
    from rclverify.ros.extract.param_yaml import PackageParams, matches, read_file
    assert [matches(p, "/rig/range_fusion") for p in ("/**", "**", "/rig/range_fusion", "range_fusion",
                                                      "/*/range_fusion", "/**/range_fusion", "/other")] == [
        True, True, True, False, True, True, False]
    got, notes = read_file("/**:\n  ros__parameters:\n    a: {b: x, n: 3}\n    l: [p, q]\n", "p.yaml")
    assert (got, notes) == ([("/**", "~a.b", "x", got[0][3]), ("/**", "~l", ("p", "q"), got[1][3])], [])
    assert read_file("a: [\n", "bad.yaml")[1][0].code == "ROS-PARSE"  # never raises
    cfg = tmp_path / "pkg" / "config"
    cfg.mkdir(parents=True)
    (cfg / "a.yaml").write_text("n:\n  ros__parameters:\n    topic: one\n    same: s\n")
    (cfg / "b.yaml").write_text("/n:\n  ros__parameters:\n    topic: two\n    same: s\n")
    vals, said = PackageParams({"pkg": tmp_path / "pkg"}, lambda p: p.relative_to(tmp_path).as_posix()).for_node(
        "pkg", "/n")
    assert {k: v[0] for k, v in vals.items()} == {"/n/same": "s"}
    assert [str(n) for n in said] == ["pkg/config/b.yaml:3:12: warning: parameter /n/topic has different values in "
                                      "pkg/config/a.yaml:3:12 and pkg/config/b.yaml:3:12; which file runs is a "
                                      "launch file's choice: not used"]


def test_run_time_names_say_where_they_come_from(graph) -> None:  # type: ignore[no-untyped-def]
    said = sorted(str(n) for n in graph.notes if n.code == "ROS-UNRESOLVED")
    assert said == [
        "idioms6/src/chat_cpp/src/listener_argv.cpp:12:5: warning: subscriber topic name is 'argv[1]', from argv: "
        "not resolved statically",
        "idioms6/src/chat_py/chat_py/relay.py:15:41: warning: publisher topic name is 'args.out_topic', from "
        "argparse option --out-topic: not resolved statically",
        "idioms6/src/chat_py/chat_py/relay.py:16:38: warning: subscriber topic name is 'sys.argv[1]', from argv: "
        "not resolved statically"]
    assert {f"{n.src.file}:{n.src.line}" for n in graph.notes if n.code == "ROS-UNRESOLVED"} == \
        set(EXPECTED["unresolved"])
    # round three's tools: a positional argparse argument, a name from the graph at run time
    g5 = scan([CORPUS / "idioms5"], [], base=CORPUS, standard=False).graph
    assert sorted(n.message for n in g5.notes if n.code == "ROS-UNRESOLVED") == [
        "subscriber topic name is 'name', discovered at run time (get_topic_names_and_types()): not resolved "
        "statically",
        "subscriber topic name is 'topic', from argparse argument topic: not resolved statically"]


def test_whole_workspace_is_the_hand_written_graph(graph) -> None:  # type: ignore[no-untyped-def]
    assert set(graph.nodes) == set(EXPECTED["nodes"])
    for node in EXPECTED["nodes"]:
        assert _edges(graph, node) == _want(node), node
