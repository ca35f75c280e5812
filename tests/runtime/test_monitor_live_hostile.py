"""``rclverify monitor --live`` against a ROS 1 master that hangs on
``registerPublisher``: SIGTERM and SIGINT stop it within seconds, with one
message and exit 2, not after minutes (runtime/ros1.py, "A
master is an external peer").

The master is a tiny threaded XML-RPC server on 127.0.0.1 and an ephemeral
port, in this process: it answers ``getPid`` and the parameter calls, and
holds every ``registerPublisher`` call until the test ends.  The monitor
runs as its own process (its own process group), killed in ``finally``.
Skipped, with the reason, where rospy cannot be imported."""
from __future__ import annotations

import functools
import os
import signal
import socketserver
import subprocess
import sys
import threading
import time
import xmlrpc.server
from pathlib import Path
from typing import Any, Iterator

import pytest

REPO = Path(__file__).resolve().parents[2]


@functools.cache
def _no_rospy() -> str | None:
    """Why rospy cannot be imported, or None: asked once, when the module's tests run."""
    r = subprocess.run([sys.executable, "-c", "from rclverify.runtime.ros1 import import_rospy; "
                        "import_rospy()"], capture_output=True, text=True,
                       env=dict(os.environ, PYTHONPATH=str(REPO / "src")))
    return None if r.returncode == 0 else f"rospy cannot be imported: {r.stderr.strip()[-200:]}"


@pytest.fixture(scope="module", autouse=True)
def _rospy() -> None:
    reason = _no_rospy()
    if reason is not None:
        pytest.skip(reason)


class _Server(socketserver.ThreadingMixIn, xmlrpc.server.SimpleXMLRPCServer):
    daemon_threads = True


class _Quiet(xmlrpc.server.SimpleXMLRPCRequestHandler):
    def log_message(self, *args: Any) -> None:
        pass


class HangingMaster:
    """Answers like a master, except that registerPublisher never returns."""

    def __init__(self) -> None:
        self.asked = threading.Event()
        self.release = threading.Event()
        self.server = _Server(("127.0.0.1", 0), requestHandler=_Quiet, logRequests=False, allow_none=True)
        self.server.register_instance(self)
        self.uri = f"http://127.0.0.1:{self.server.server_address[1]}"

    def _dispatch(self, method: str, params: Any) -> Any:
        if method == "registerPublisher":
            self.asked.set()
            self.release.wait(120)
            return [1, "", []]
        if method == "getPid":
            return [1, "", os.getpid()]
        if method == "getUri":
            return [1, "", self.uri]
        if method in ("getParam", "searchParam"):
            return [-1, "parameter not set", 0]
        if method == "hasParam":
            return [1, "", False]
        return [1, "", []]


@pytest.fixture()
def master() -> Iterator[HangingMaster]:
    m = HangingMaster()
    t = threading.Thread(target=m.server.serve_forever, kwargs={"poll_interval": 0.05}, daemon=True)
    t.start()
    try:
        yield m
    finally:
        m.release.set()
        m.server.shutdown()
        m.server.server_close()


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_a_signal_stops_the_monitor_while_the_master_hangs(master: HangingMaster, tmp_path: Path, sig: int) -> None:
    env = dict(os.environ, ROS_MASTER_URI=master.uri, ROS_IP="127.0.0.1", ROS_HOSTNAME="127.0.0.1",
               ROS_HOME=str(tmp_path / "ros_home"), ROS_LOG_DIR=str(tmp_path / "log"),
               PYTHONPATH=str(REPO / "src") + os.pathsep + os.environ.get("PYTHONPATH", ""))
    p = subprocess.Popen([sys.executable, "-m", "rclverify.cli.commands", "monitor", "--live", "-w", str(REPO),
                          "--node", "RadiationSensor", "--log", str(tmp_path / "live.jsonl")],
                         env=env, cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         start_new_session=True)
    try:
        assert master.asked.wait(30), "the monitor never asked the master to register a publisher"
        time.sleep(0.3)  # inside the registration call now
        t0 = time.monotonic()
        p.send_signal(sig)
        out, err = p.communicate(timeout=10)
        took = time.monotonic() - t0
    finally:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait(10)
    text = err.decode()
    assert p.returncode == 2, (out, text)
    assert took < 8, took
    assert f"rclverify monitor --live: error: stopped by a signal while registering with the master at " \
           f"{master.uri}; nothing was monitored" in text
    assert "Traceback" not in text
