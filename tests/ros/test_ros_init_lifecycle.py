"""``init --from-ros`` on a Nav2-like bringup of lifecycle servers (tests/data/ros_corpus/bringup:
``/rover/drive_server``, ``/rover/dock``, ``/rover/map_server``, each an ``rclcpp_lifecycle`` node
under the launch file's namespace) writes each skeleton as a lifecycle node (issue 110): its transition
topic named as the skeleton's other names (relative, ``dock/transition_event``, resolved in the node's
namespace) and its guarantee scoped ``while active``; the skeletons check with no error and no
``W-lifecycle-unscoped`` warning and ground against the code with no error.  The control: a plain rclpy
node's skeleton names no transition topic and no scope."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from rclverify.cli.commands import main

BRINGUP = Path(__file__).parent.parent / "data" / "ros_corpus" / "bringup" / "src"
LAUNCH = BRINGUP / "rover_bringup" / "launch"


def test_the_bringups_lifecycle_servers_get_scoped_skeletons(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ws = tmp_path / "ws"
    assert main(["init", str(ws), "--from-ros", str(BRINGUP), "--launch", str(LAUNCH / "navigation.launch.py"),
                 "--launch", str(LAUNCH / "localization.launch.py")]) == 0
    for stem, name in (("dock", "dock"), ("drive_server", "drive_server"), ("map_server", "map_server")):
        text = (ws / "contracts" / f"{stem}.rcl").read_text(encoding="utf-8")
        assert f"lifecycle_msgs/TransitionEvent {name}/transition_event )" in text, text
        assert "  guarantee( TRUE ) while active\n" in text, text
    capsys.readouterr()
    assert main(["check", "-w", str(ws), *map(str, sorted((ws / "contracts").glob("*.rcl")))]) == 0
    out = capsys.readouterr()
    assert "0 errors" in out.out + out.err and "W-lifecycle-unscoped" not in out.out + out.err
    assert "is a lifecycle node" not in out.out + out.err
    # control: the scope taken away, the lint names the lifecycle node at its guarantee
    dock = ws / "contracts" / "dock.rcl"
    dock.write_text(dock.read_text(encoding="utf-8").replace(" while active\n", "\n"), encoding="utf-8")
    assert main(["check", "-w", str(ws), *map(str, sorted((ws / "contracts").glob("*.rcl")))]) == 0
    said = capsys.readouterr()
    assert "guarantee 1 of Dock: Dock is a lifecycle node (it names its transition topic dock/transition_event)" \
        in said.out + said.err
    dock.write_text(dock.read_text(encoding="utf-8").replace("guarantee( TRUE )\n", "guarantee( TRUE ) while active\n"),
                    encoding="utf-8")
    found = tmp_path / "ground.json"
    main(["ros", "check", "-w", str(ws), "--json", str(found)])
    errors = [f for f in json.loads(found.read_text())["findings"] if f["severity"] == "error"]
    assert errors == [], errors  # each transition topic resolves to the node's own ~/transition_event


def test_a_plain_nodes_skeleton_names_no_lifecycle(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    pkg = tmp_path / "src" / "pilot"
    (pkg / "scripts").mkdir(parents=True)
    (pkg / "package.xml").write_text(
        '<?xml version="1.0"?>\n<package format="3"><name>pilot</name><version>0.1.0</version><description>d'
        '</description><maintainer email="dev@example.org">dev</maintainer><license>MIT</license>'
        '<exec_depend>rclpy</exec_depend><export><build_type>ament_python</build_type></export></package>\n')
    (pkg / "scripts" / "pilot.py").write_text(
        "#!/usr/bin/env python3\nimport rclpy\nfrom std_msgs.msg import Float64\n"
        "rclpy.init()\nn = rclpy.create_node('pilot')\npub = n.create_publisher(Float64, 'cmd', 1)\n")
    ws = tmp_path / "ws"
    assert main(["init", str(ws), "--from-ros", str(tmp_path / "src")]) == 0
    capsys.readouterr()
    text = next((ws / "contracts").glob("pilot*.rcl")).read_text(encoding="utf-8")
    assert "transition_event" not in text and "while active" not in text and "  guarantee( TRUE )\n" in text
