"""A hostile or broken ROS 1 master: ``ros diff`` and ``ros scan --master``
end within a bounded time with one located message and a non-zero exit,
never a traceback or a hang (ros/live/master_rpc.py).

The masters here are tiny XML-RPC servers in a thread on 127.0.0.1 and an
ephemeral port: one answers malformed structures, one accepts and never
answers.  Each is shut down by the test that starts it."""
from __future__ import annotations

import socket
import subprocess
import sys
import threading
import time
import xmlrpc.server
from pathlib import Path
from typing import Any, Iterator

import pytest

from rclverify.ros.live.master import read_master
from rclverify.ros.live.master_rpc import MasterError, call, probe_service_type

REPO = Path(__file__).resolve().parents[2]
WS = Path(__file__).parent.parent / "data" / "ros" / "diff_ws"
OK_STATE = [[["/a", ["/n"]]], [], []]

#: getSystemState / getTopicTypes answers that are not the Master API's shape
MALFORMED: list[tuple[str, Any, Any]] = [
    ("not a triple", "nonsense", [1, "", []]),
    ("two lists", [1, "", [[], []]], [1, "", []]),
    ("topic not a string", [1, "", [[[5, ["/n"]]], [], []]], [1, "", []]),
    ("nodes not a list", [1, "", [[["/t", "/n"]], [], []]], [1, "", []]),
    ("node not a string", [1, "", [[["/t", [7]]], [], []]], [1, "", []]),
    ("services not a list", [1, "", [[], [], 3]], [1, "", []]),
    ("topic a list", [1, "", [[[["/t"], ["/n"]]], [], []]], [1, "", []]),
    ("types entry short", [1, "", OK_STATE], [1, "", [["/a"]]]),
    ("type not a string", [1, "", OK_STATE], [1, "", [["/a", 5]]]),
    ("types a mapping", [1, "", OK_STATE], [1, "", {"a": "b"}]),
    ("code refused", [-1, "go away", []], [1, "", []]),
    ("code not an int", ["1", "", OK_STATE], [1, "", []]),
]


class _Quiet(xmlrpc.server.SimpleXMLRPCRequestHandler):
    def log_message(self, *args: Any) -> None:
        pass


def _serve(functions: dict[str, Any]) -> tuple[str, Any]:
    server = xmlrpc.server.SimpleXMLRPCServer(("127.0.0.1", 0), requestHandler=_Quiet, logRequests=False,
                                              allow_none=True)
    for name, fn in functions.items():
        server.register_function(fn, name)
    threading.Thread(target=server.serve_forever, kwargs={"poll_interval": 0.05}, daemon=True).start()
    return f"http://127.0.0.1:{server.server_address[1]}", server


@pytest.fixture()
def silent() -> Iterator[str]:
    """A 'master' that accepts connections and never answers."""
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    s.listen(8)
    held: list[socket.socket] = []
    stop = threading.Event()

    def accept() -> None:
        s.settimeout(0.1)
        while not stop.is_set():
            try:
                held.append(s.accept()[0])
            except OSError:
                continue

    t = threading.Thread(target=accept, daemon=True)
    t.start()
    try:
        yield f"http://127.0.0.1:{s.getsockname()[1]}"
    finally:
        stop.set()
        t.join(2)
        for c in held:
            c.close()
        s.close()


def _diff(uri: str, *extra: str, timeout: float = 30) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "rclverify.cli.commands", "ros", "diff", str(WS), "--master", uri, *extra],
                          capture_output=True, text=True, timeout=timeout, cwd=REPO)


@pytest.mark.parametrize("label,state,types", MALFORMED, ids=[m[0] for m in MALFORMED])
def test_a_malformed_answer_is_one_located_error(label: str, state: Any, types: Any) -> None:
    uri, server = _serve({"getSystemState": lambda caller: state, "getTopicTypes": lambda caller: types})
    try:
        with pytest.raises(MasterError) as exc:
            read_master(uri, service_types=False, timeout=5)
        assert str(exc.value).startswith(f"cannot read the master at {uri}: get")
    finally:
        server.shutdown()
        server.server_close()


def test_ros_diff_on_a_malformed_master_exits_1_with_one_line() -> None:
    uri, server = _serve({"getSystemState": lambda caller: [1, "", [[[5, ["/n"]]], [], []]],
                          "getTopicTypes": lambda caller: [1, "", []]})
    try:
        r = _diff(uri)
    finally:
        server.shutdown()
        server.server_close()
    assert r.returncode == 1 and "Traceback" not in r.stderr
    errors = [line for line in r.stderr.splitlines() if ": error: " in line]
    assert errors == [f"{uri}: error: cannot read the master at {uri}: getSystemState: publishers entry 0 is "
                      "[5, ['/n']], not [name, [node, ...]]"]


def test_ros_diff_on_a_master_that_never_answers_ends_within_its_limit(silent: str) -> None:
    t0 = time.monotonic()
    r = _diff(silent, "--timeout", "1")
    took = time.monotonic() - t0
    assert r.returncode == 1 and "Traceback" not in r.stderr
    assert f"{silent}: error: cannot read the master at {silent}: getSystemState: no answer within the time " \
           "limit of 1 s" in r.stderr
    assert took < 15, took


def test_a_bad_timeout_is_a_usage_error() -> None:
    r = _diff("http://127.0.0.1:1", "--timeout", "nan")
    assert r.returncode == 2 and "expected a finite number of seconds > 0" in r.stderr


def test_a_call_that_hangs_is_cut_at_its_limit(silent: str) -> None:
    t0 = time.monotonic()
    with pytest.raises(MasterError, match="no answer within the time limit of 0.5 s"):
        call(silent, "getPid", "/x", timeout=0.5)
    assert time.monotonic() - t0 < 3


def test_a_service_probe_that_hangs_is_cut_at_its_limit(silent: str) -> None:
    port = silent.rsplit(":", 1)[1]
    t0 = time.monotonic()
    with pytest.raises(MasterError, match="no probe answer within the time limit of 0.5 s"):
        probe_service_type("/s", f"rosrpc://127.0.0.1:{port}", timeout=0.5)
    assert time.monotonic() - t0 < 3
    with pytest.raises(MasterError, match="not a rosrpc://HOST:PORT URI"):
        probe_service_type("/s", "http://127.0.0.1:1")


def test_not_a_master_uri() -> None:
    with pytest.raises(MasterError, match="is not a master URI"):
        read_master("ftp://x", service_types=False)
