"""A live ROS 1 system: roscore started by the test on 127.0.0.1 (a free
port, bounded in time, stopped in a finally), two rospy nodes from
tests/data/ros/live_ws; the graph read from the master through rosgraph
equals the graph read from the nodes' sources (docs/ros.md)."""
from __future__ import annotations

import functools
import os
import shutil
import signal
import socket
import subprocess
import time
from pathlib import Path

import pytest

from rclverify.ros.graph.scan import scan
from rclverify.ros.live.master import MasterError, import_rosgraph, read_master

LIVE = Path(__file__).parent.parent / "data" / "ros" / "live_ws"
SYSTEM_PY = "/usr/bin/python3"  # Debian's python3-rospy is installed for Debian's interpreter


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@functools.cache
def _have_ros1() -> str | None:
    """Why ROS 1 cannot run here, or None.  Asked once per process, and only when a live test is about to
    run: every pytest worker imports every test module, and this starts a Python of its own."""
    if shutil.which("roscore") is None:
        return "roscore is not installed (apt-get install ros-core)"
    if subprocess.run([SYSTEM_PY, "-c", "import rospy"], capture_output=True).returncode != 0:
        return "rospy is not installed (apt-get install python3-rospy)"
    try:
        import_rosgraph()
    except MasterError as exc:
        return str(exc)
    return None


def _stop(p: subprocess.Popen[bytes]) -> None:
    if p.poll() is None:
        os.killpg(p.pid, signal.SIGINT)
        try:
            p.wait(timeout=10)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait(timeout=5)


@pytest.fixture()
def ros1() -> None:
    """Skips, with the reason, where ROS 1 cannot run."""
    reason = _have_ros1()
    if reason is not None:
        pytest.skip(reason)


def test_graph_from_master_equals_graph_from_sources(tmp_path: Path, ros1: None) -> None:
    port = _free_port()
    uri = f"http://127.0.0.1:{port}"
    env = dict(os.environ, ROS_MASTER_URI=uri, ROS_IP="127.0.0.1", ROS_HOSTNAME="127.0.0.1",
               ROS_HOME=str(tmp_path / "ros_home"), ROS_LOG_DIR=str(tmp_path / "log"), PYTHONPATH="")
    procs: list[subprocess.Popen[bytes]] = []
    try:
        procs.append(subprocess.Popen(["roscore", "-p", str(port)], env=env, start_new_session=True,
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        scripts = LIVE / "src/live_demo/scripts"
        deadline = time.monotonic() + 30
        while True:  # wait for the master
            try:
                read_master(uri)
                break
            except MasterError:
                assert time.monotonic() < deadline, "roscore did not come up within 30 s"
                time.sleep(0.3)
        for s in ("talker.py", "listener.py"):
            procs.append(subprocess.Popen([SYSTEM_PY, str(scripts / s)], env=env, start_new_session=True,
                                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        expected = scan([LIVE], base=LIVE).graph.edges()
        assert expected == {("/talker", "pub", "/chatter", "std_msgs/msg/String"),
                            ("/talker", "sub", "/ack", "std_msgs/msg/Int32"),
                            ("/listener", "pub", "/ack", "std_msgs/msg/Int32"),
                            ("/listener", "sub", "/chatter", "std_msgs/msg/String")}
        got: set[tuple[str, str, str, str | None]] = set()
        while got != expected and time.monotonic() < deadline + 30:
            got = read_master(uri).edges()
            time.sleep(0.3)
        assert got == expected
    finally:
        for p in reversed(procs):
            _stop(p)
