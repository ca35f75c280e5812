"""A type clash blames the side that differs (issue 108): on the test rover,
the sensor's code publishes ``radiation`` with another type than the one its
contract and the controller (code and contract) use.  The sensor's contract
no longer matches its own code (``ROS-TYPE-DIFFERS``, located at the sensor's
contract); the controller's contract matches its own code, so it is not
blamed: ``ROS-TYPE-CLASH`` names both programs.  Control: the rover as
written has neither."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

from rclverify.cli.commands import main

WS = Path(__file__).parent.parent / "data" / "ros" / "catkin_ws"


def _findings(tmp_path: Path, clash: bool) -> list[tuple[str, str, str, str]]:
    ws = tmp_path / "ws"
    shutil.copytree(WS, ws)
    if clash:
        sensor = ws / "src/rover_sensing/scripts/sensor.py"
        text = sensor.read_text()
        sensor.write_text(text.replace("from rover_msgs.msg import Reading\n", "from rover_msgs.msg import Reading, "
                                       "Status\n").replace("Publisher('radiation', Reading,", "Publisher('radiation', "
                                                                                              "Status,"))
    out = ws / "findings.json"
    main(["ros", "check", "-w", str(ws), "--json", str(out)])
    data = json.loads(out.read_text())
    loc = lambda d: f"{d['file']}:{d['line']}" if d else "-"  # noqa: E731
    return [(f["code"], loc(f["rcl"]), loc(f["ros"]), f["message"]) for f in data["findings"]
            if f["code"].startswith("ROS-TYPE")]


def test_a_type_clash_names_both_programs_and_blames_only_the_contract_its_code_differs_from(tmp_path: Path) -> None:
    fs = _findings(tmp_path, clash=True)
    assert fs == [
        ("ROS-TYPE-DIFFERS", "contracts/rover.rcl:11", "src/rover_sensing/scripts/sensor.py:11",
         "topic 'radiation' carries rover_msgs/Status in the code, the contract says rover_msgs/Reading"),
        ("ROS-TYPE-CLASH", "contracts/rover.rcl:18", "src/rover_sensing/scripts/sensor.py:11",
         "topic /rover/radiation is made with rover_msgs/Status by /rover/sensor "
         "(src/rover_sensing/scripts/sensor.py:11:20) and with rover_msgs/Reading by /rover/controller "
         "(src/rover_control/src/controller.cpp:23:25), as Controller's contract says: the two programs differ, "
         "not the contract")], fs


def test_the_rover_as_written_has_no_type_finding(tmp_path: Path) -> None:
    assert _findings(tmp_path, clash=False) == []
