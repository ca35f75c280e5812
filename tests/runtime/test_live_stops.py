"""Stopping the live ROS 2 monitor, and a run that discovers nobody (issue 106; docs/monitors.md,
"Stopping"; docs/ros2.md, "A run that discovers nobody").

One rclpy system publishes two topics at about 1 kHz each (the load): ``/basic``
(``test_msgs/BasicTypes``, a type the workspace has no definition of: the rclpy source reads and
records it as its ROS 2 Python describes it) and ``/level`` (``std_msgs/Float32``), values 0.15f and
0.75 in turn, against ``<= 0.5`` and against ``<= LOW`` with the context's ``LOW = 0.15`` (the float32
boundary of docs/monitors.md, "Widths live and offline": satisfied live and offline).  The monitor is
started :data:`STOPS` times per source, each time with ``--record``: the rclpy source on ``/basic``,
the DDS source on ``/level``, beside a CPU burner; once it has judged messages it is sent SIGINT (SIGTERM every other time).  Each run ends within a second of the signal,
exit 1 (the violations), and leaves a log whose every line reads as JSON and a bag, and ``rclverify
monitor`` of the log and of the bag gives the counts the live evidence holds.  The runs that heard the
robot say nothing of discovery (the control of the last test): a DDS-source run in a domain where no
one runs says, in one line on its output and in its evidence's warnings, that no publisher was
discovered and what to check, and exits 0 as a run that heard nothing does."""
from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest
from _procs import stop, wait_for
from _ros2 import rclverify, ros2_env, ros2_python, start_node

from rclverify.cli.commands import main

#: starts (and stops) of the monitor per source: each start costs seconds (the suite's time); the race
#: itself is shown on its own, many signals over many waits, by tests/runtime/test_stop_flag.py
STOPS = 3
#: the longest a stopped run may take to exit, from the signal (s): measured 0.1-0.6 s beside a CPU burner at a
#: load of 11-14 on two cores (the process ends once its files are written: runtime/stopping.py, end_bounded)
STOP_LIMIT_S = 1.0

BASIC = """\
node Basic {
  inputs( )
  outputs( v : REAL )
  topics( test_msgs/BasicTypes basic matches(out.v) )
  assume( TRUE )
  guarantee( out.v <= 0.5 )
}
"""
#: the DDS source's contract compares the float32 field with a named constant at the value's boundary:
#: 0.15f (0.15000000596...) is within LOW read at the field's width, as offline (docs/monitors.md,
#: "Widths live and offline"); live without the width every 0.15f would read violated, unlike the log
LEVEL = "context {\n  LOW : REAL = 0.15 ;\n}\n" + BASIC.replace("node Basic", "node Level").replace(
    "test_msgs/BasicTypes basic", "std_msgs/Float32 level").replace("out.v <= 0.5", "out.v <= LOW")
MAPPING = {"basic": "topics:\n  basic: {fields: [float32_value]}\n", "level": "topics: {}\n"}
SYSTEM = """\
import time
import rclpy
from rclpy.node import Node
from std_msgs.msg import Float32
from test_msgs.msg import BasicTypes

rclpy.init()
n = Node("tank")
basic = n.create_publisher(BasicTypes, "basic", 100)
level = n.create_publisher(Float32, "level", 100)
print("ready", flush=True)
k = 0
try:
    while True:
        v = [0.15, 0.75][k % 2]
        basic.publish(BasicTypes(float32_value=v))
        level.publish(Float32(data=v))
        k += 1
        time.sleep(0.001)
except Exception:  # the context shut down by the test's SIGTERM
    pass
"""


def _workspace(tmp: Path, name: str) -> Path:
    ws = tmp / f"ws_{name}"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/c.rcl").write_text(BASIC if name == "basic" else LEVEL)
    (ws / "contracts/plan.yaml").write_text("contracts: [contracts/c.rcl]\n")
    (ws / "mapping.yaml").write_text(MAPPING[name])
    return ws


@pytest.fixture(scope="module")
def system(tmp_path_factory: pytest.TempPathFactory) -> Any:
    ros2_python()
    tmp = tmp_path_factory.mktemp("stops")
    env = ros2_env(tmp)
    p = start_node(tmp, "system", SYSTEM, env)
    burner = subprocess.Popen([sys.executable, "-c", "while True: pass"], start_new_session=True)  # beside a full core
    try:
        yield tmp, env
    finally:
        stop(burner, signal.SIGKILL)
        stop(p)


def _offline(ws: Path, trace: Path, capsys: pytest.CaptureFixture[str]) -> dict[str, int]:
    """The counts ``rclverify monitor --json TRACE`` gives its one node."""
    capsys.readouterr()
    main(["monitor", "-w", str(ws), "--mapping", "mapping.yaml", "--json", str(trace)])
    out = capsys.readouterr().out
    (entry,) = json.loads(out)  # one node, judged on its topic alone
    return {k: v for k, v in entry["counts"].items() if v}


def _stop_once(tmp: Path, env: dict[str, str], source: str, k: int, capsys: pytest.CaptureFixture[str]) -> None:
    name = "basic" if source == "rclpy" else "level"
    ws = tmp / f"ws_{name}"
    run = tmp / f"{source}{k}"
    run.mkdir()
    log, bag, evidence, out = run / "live.jsonl", run / "bag", run / "live.json", run / "monitor.out"
    monitor = rclverify(["monitor", "-w", str(ws), "--live", "--ros2", "--mapping", "mapping.yaml", "--status", "0",
                         "--source", source, "--ros2-python", str(ros2_python()), "--log", str(log),
                         "--record", str(bag), "--evidence", str(evidence), "--duration", "60"], env, tmp, out)
    sig = signal.SIGINT if k % 2 == 0 else signal.SIGTERM
    try:
        wait_for(out, "monitoring ", 60)
        deadline = time.monotonic() + 30
        while (sum(1 for _ in log.open()) if log.exists() else 0) < 20:  # judging messages: under load
            assert time.monotonic() < deadline and monitor.poll() is None, out.read_text()
            time.sleep(0.02)
        t0 = time.monotonic()
        monitor.send_signal(sig)
        code = monitor.wait(10)
        took = time.monotonic() - t0
    finally:
        stop(monitor)
    text = out.read_text()
    assert took <= STOP_LIMIT_S and code == 1, (source, k, sig, round(took, 3), code, text)
    assert "no publisher was discovered" not in text, text  # the control of the silent run below
    lines = [json.loads(line) for line in log.read_text().splitlines()]  # every line reads
    record = json.loads(evidence.read_text())
    live = {c: v for c, v in record["nodes"][0]["counts"].items() if v}
    assert live.get("violated", 0) >= 1 and live.get("satisfied", 0) >= 1, live
    assert record["bag"]["messages"] >= 1 and "failed" not in record["bag"], record
    assert len(lines) >= 20
    assert _offline(ws, log, capsys) == live, (source, k)
    assert _offline(ws, bag, capsys) == live, (source, k)


@pytest.mark.parametrize("source", ["rclpy", "dds"])
def test_a_signal_ends_every_run_within_a_second_its_log_and_bag_readable(
        system: Any, source: str, capsys: pytest.CaptureFixture[str]) -> None:
    tmp, env = system
    _workspace(tmp, "basic" if source == "rclpy" else "level")
    for k in range(STOPS):
        _stop_once(tmp, env, source, k, capsys)


def test_a_run_that_discovers_nobody_says_so(tmp_path: Path) -> None:
    ros2_python()
    env = ros2_env(tmp_path)  # a domain of its own, where no one runs
    ws = _workspace(tmp_path, "level")
    out = tmp_path / "monitor.out"
    monitor = rclverify(["monitor", "-w", str(ws), "--live", "--ros2", "--mapping", "mapping.yaml", "--status", "0",
                         "--source", "dds", "--log", str(tmp_path / "live.jsonl"), "--evidence",
                         str(tmp_path / "live.json"), "--duration", "1.5"], env, tmp_path, out)
    try:
        code = monitor.wait(60)
    finally:
        stop(monitor)
    text = out.read_text()
    lines = [line for line in text.splitlines() if "no publisher was discovered" in line]
    assert code == 0 and len(lines) == 1, text
    assert "on any of the 1 watched topic(s)" in lines[0] and "no other DDS participant was discovered" in lines[0]
    assert "ROS_DOMAIN_ID" in lines[0] and "CYCLONEDDS_URI" in lines[0]
    assert "not judged: topic /level (Level): nothing heard" in text
    assert lines[0] in json.loads((tmp_path / "live.json").read_text())["warnings"]
