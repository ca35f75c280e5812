"""``rclverify ros diff --master`` against a live ROS 1 system (docs/ros.md,
"Expected against observed").

roscore on 127.0.0.1 (a free port), and real rospy processes: two of the
three nodes tests/data/ros/diff_ws's launch file promises (``sensor`` and
``planner``; ``logger`` is left out), the sensor also publishing a debug
topic whose name its code takes from a parameter; and the safety-stop
example's ``base`` (serves std_srvs/SetBool ``/estop``) and ``mover`` (the
``move`` action server on actionlib's topics), nodes the workspace does not
have.  Every process is stopped (its process group) in the fixture's
``finally``; skipped, with the reason, only when roscore, rospy or rosgraph
is not installed.
"""
from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import time
from pathlib import Path
from typing import Iterator

import pytest

from rclverify.cli.commands import main
from rclverify.ros.live.master import MasterError, read_master

from test_ros_live import SYSTEM_PY, _free_port, _have_ros1, _stop

HERE = Path(__file__).parent.parent
WS = HERE / "data" / "ros" / "diff_ws"
LAUNCH = WS / "src" / "diff_demo" / "launch" / "demo.launch"
SCRIPTS = WS / "src" / "diff_demo" / "scripts"
REPO = HERE.parent
EXAMPLE = REPO / "examples" / "safety_stop"

@pytest.fixture(scope="module", autouse=True)
def _ros1() -> None:
    """Skips the module, with the reason, where ROS 1 cannot run (asked only when its tests run)."""
    reason = _have_ros1()
    if reason is not None:
        pytest.skip(reason)


def _settled(uri: str, deadline: float) -> None:
    """Wait until the master shows what the fixture started (bounded): every node, and each
    one's registrations the tests read (a node shows on the master, by its ``/rosout``, before
    it registers its service)."""
    while True:
        try:
            g = read_master(uri, service_types=False)
            nodes = set(g.nodes)
            if {"/sensor", "/planner"} <= nodes \
                    and any(n.startswith("/base") and any(e.topic == "/estop" for e in g.nodes[n].service_servers)
                            for n in nodes) \
                    and any(n.startswith("/mover") and g.nodes[n].action_servers for n in nodes) \
                    and any(e.topic == "/sensor_debug" for e in g.nodes["/sensor"].publishes) \
                    and any(e.topic == "/range" for e in g.nodes["/planner"].subscribes):
                return
        except MasterError:
            pass
        assert time.monotonic() < deadline, "the live system did not come up within the time allowed"
        time.sleep(0.3)


@pytest.fixture(scope="module")
def master(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    tmp = tmp_path_factory.mktemp("rosdiff")
    port = _free_port()
    uri = f"http://127.0.0.1:{port}"
    env = dict(os.environ, ROS_MASTER_URI=uri, ROS_IP="127.0.0.1", ROS_HOSTNAME="127.0.0.1",
               ROS_HOME=str(tmp / "ros_home"), ROS_LOG_DIR=str(tmp / "log"), PYTHONPATH="")
    procs: list[subprocess.Popen[bytes]] = []

    def start(cmd: list[str], e: dict[str, str]) -> None:
        procs.append(subprocess.Popen(cmd, env=e, start_new_session=True, cwd=tmp,
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
    try:
        start(["roscore", "-p", str(port)], env)
        deadline = time.monotonic() + 30
        while True:
            try:
                read_master(uri, service_types=False)
                break
            except MasterError:
                assert time.monotonic() < deadline, "roscore did not come up within 30 s"
                time.sleep(0.3)
        for s in ("sensor.py", "planner.py"):
            start([SYSTEM_PY, str(SCRIPTS / s)], env)
        ex_env = dict(env, PYTHONPATH=str(REPO / "src"))
        start([sys.executable, str(EXAMPLE / "nodes" / "ros1_nodes.py"), "base", "--serve", "/estop"], ex_env)
        start([sys.executable, str(EXAMPLE / "nodes" / "ros1_nodes.py"), "mover"], ex_env)
        _settled(uri, time.monotonic() + 60)
        yield uri
    finally:
        for p in reversed(procs):
            _stop(p)


def test_master_reads_services_and_actions(master: str) -> None:
    g = read_master(master)
    for _ in range(2):  # a service's type is probed from the live node, within 5 s: on a machine whose cores
        if not g.notes:  # other test workers hold, a probe may time out (a note says so); ask again, bounded
            break
        g = read_master(master)
    base = next(n for k, n in g.nodes.items() if k.startswith("/base"))
    assert [(e.topic, e.msg_type) for e in base.service_servers] == [("/estop", "std_srvs/srv/SetBool")]
    mover = next(n for k, n in g.nodes.items() if k.startswith("/mover"))
    assert [(e.topic, e.msg_type) for e in mover.action_servers] == [("/move", "rclverify_examples/action/Move")]
    assert not [e for e in mover.publishes + mover.subscribes if e.topic.startswith("/move/")]
    every = [e.topic for n in g.nodes.values() for e in n.service_servers]
    assert not [s for s in every if s.endswith(("/get_loggers", "/set_logger_level"))]
    assert "/rosout" not in g.nodes and not g.notes


def test_ros_diff_against_the_master(master: str, tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                    monkeypatch: pytest.MonkeyPatch) -> None:
    out = tmp_path / "diff.json"
    monkeypatch.chdir(WS)  # locations are shown relative to the current directory
    launch = "src/diff_demo/launch/demo.launch"
    rc = main(["ros", "diff", ".", "--launch", launch, "--master", master, "--json", str(out)])
    text = capsys.readouterr().out
    assert rc == 1
    data = json.loads(out.read_text())
    assert data["observed"] == {"kind": "master", "source": master} and data["equal"] is False
    assert [(i["category"], i["name"], i["at"]) for i in data["missing"]] == [
        ("node", "/logger", {"file": launch, "line": 4, "col": 1})]
    assert "node /logger is not running (its code subscribes to /cmd)" in data["missing"][0]["message"]
    extra = [(i["category"], re.sub(r"_\d+(_\d+)*$", "_N", i["name"]), i["node"], i["observed_type"], i["at"],
              i["observed"]) for i in data["extra"]]
    assert sorted(extra) == sorted([
        ("node", "/base_N", None, None, None, master),
        ("node", "/mover_N", None, None, None, master),
        ("publisher", "/sensor_debug", "/sensor", "std_msgs/msg/String", None, master),
    ])
    base = next(i for i in data["extra"] if i["name"].startswith("/base"))
    assert "serves /estop" in base["message"]
    mover = next(i for i in data["extra"] if i["name"].startswith("/mover"))
    assert "serves action /move" in mover["message"]
    assert f"{launch}:4:1: node /logger is not running" in text
    assert f"{master}: /sensor publishes /sensor_debug (std_msgs/String) in the running system, not in the code; " \
           f"the code names /sensor_debug nowhere" in text
