"""A service server restarted under the DDS source (docs/ros2.md, "Every endpoint of a call accounted for").

One rclpy process on Fast DDS serves ``/rs`` (std_srvs/SetBool; the contract ``in.req -> out.ok``) from a
server node publishing contents introspection events, its client none.  The server answers one call right,
is destroyed and made again under its name (new DDS endpoints), then answers two calls wrongly.  The live
monitor hears it through the DDS source (``--strict``), which reads the request and reply topics on the
wire and needs no introspection.  Two runs:

* the server made again **without introspection**: its wrong answers are never green: the DDS source pairs
  them on the wire and finds them (``Rs`` failed, two ``violated``); never ``discharged``, ``--strict``
  exits 1, live and from the run's log.  The order pairs them: the client's request writer was matched at
  the start, and the one request the order did not hear (the first call, paired by the events) was written
  more than the horizon (1 s) before (:meth:`~rclverify.runtime.dds.order.OrderPairer.again`);
* the control, made again **with contents events**: the two wrong answers found, ``violated``.
"""
from __future__ import annotations

import contextlib
import io
import json
import signal
from pathlib import Path
from typing import Any, Iterator

import pytest
from _procs import calls_judged, stop, wait_for, wait_logged
from _ros2 import live_workspace, rclverify, ros2_env, ros2_python, start_node

pytestmark = [pytest.mark.live, pytest.mark.slow]

RCL = """\
node Rs {
  inputs( req : BOOL )
  outputs( ok : BOOL )
  services( std_srvs/SetBool rs serves(in.req, out.ok) )
  assume( TRUE )
  guarantee( in.req -> out.ok )
}
"""

SYSTEM = """\
import time
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import qos_profile_services_default
from rclpy.service_introspection import ServiceIntrospectionState as S
from std_srvs.srv import SetBool

rclpy.init()
ex = SingleThreadedExecutor()
nodes = {}

def node(name):
    nodes[name] = n = Node(name)
    ex.add_node(n)
    return n

def serve(right, level):
    def answer(req, resp):
        resp.success = req.data if right else not req.data
        return resp
    n = node("rs_s")
    srv = n.create_service(SetBool, "rs", answer)
    if level is not None:
        srv.configure_introspection(n.get_clock(), qos_profile_services_default, level)

def spin(seconds):
    until = time.monotonic() + seconds
    while time.monotonic() < until:
        ex.spin_once(timeout_sec=0.02)

def done(fut, timeout=10.0):
    until = time.monotonic() + timeout
    while time.monotonic() < until and not fut.done():
        ex.spin_once(timeout_sec=0.01)
    return fut.result().success if fut.done() else None

watch = node("watch")
serve(True, S.CONTENTS)
c = node("rs_c").create_client(SetBool, "rs")

def taps_made():  # the monitor's verdict topic, its readers of the request topic and of the events
    return (watch.count_publishers("/rs_mon/verdict") >= 1
            and len(watch.get_subscriptions_info_by_topic("rq/rsRequest", True)) >= 2
            and len(watch.get_subscriptions_info_by_topic("/rs/_service_event", False)) >= 1)

until = time.monotonic() + 20
while time.monotonic() < until and not c.service_is_ready():
    ex.spin_once(timeout_sec=0.05)
print("ready", flush=True)
until = time.monotonic() + 60
while time.monotonic() < until and not taps_made():
    ex.spin_once(timeout_sec=0.05)
taps = taps_made()
spin(2.5)  # the DDS source's horizon (1 s) after it began to hear the request writer, and the graph read
print("matched", taps, flush=True)
print("rs", done(c.call_async(SetBool.Request(data=True))), flush=True)
spin(1.5)  # its events delivered before the writer goes
old = nodes.pop("rs_s")
ex.remove_node(old)
old.destroy_node()
serve(False, LEVEL)  # the same node made again, wrong
spin(0.5)
until = time.monotonic() + 20
while time.monotonic() < until and not c.service_is_ready():
    ex.spin_once(timeout_sec=0.05)
spin(2.5)  # the new server's endpoints matched by the monitor's readers, the graph read again
answers = []
for _ in range(2):
    answers.append(done(c.call_async(SetBool.Request(data=True))))
    spin(0.3)
print("rs again", answers, flush=True)
spin(3.0)
print("done", flush=True)
while True:
    ex.spin_once(timeout_sec=0.1)
"""


@pytest.fixture(scope="module", params=["off", "contents"], ids=["restarted without introspection",
                                                                 "control: restarted with contents events"])
def run(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    """The system watched by the DDS source's live monitor; the offline check of its log."""
    ros2_python()  # skips, with the reason, without a ROS 2 Python
    tmp = tmp_path_factory.mktemp(f"restart-{request.param}")
    ws = live_workspace(tmp, RCL, setbool=True)
    env = ros2_env(tmp)
    level = "None" if request.param == "off" else "S.CONTENTS"
    system = monitor = None
    try:
        system = start_node(tmp, "system", SYSTEM.replace("LEVEL", level), env)
        monitor = rclverify(["monitor", "-w", str(ws), "--live", "--ros2", "--interfaces", "interfaces",
                             "--horizon", "1.0", "--reorder-window", "0.3", "--status", "0", "--duration", "90",
                             "--strict", "--log", str(tmp / "live.jsonl"), "--evidence", str(tmp / "live.json"),
                             "--verdict-topic", "/rs_mon/verdict"], env, tmp, tmp / "monitor.out")
        wait_for(tmp / "monitor.out", "monitoring", 60)
        wait_for(tmp / "system.log", "done", 90)
        # every call judged, or the restarted server said not judged
        wait_logged(tmp / "live.jsonl", lambda log: calls_judged(log, {"Rs": 3}) or any(
            x.get("part") == "unjudged" for x in log), 30)
        stop(monitor, signal.SIGINT)
        from rclverify.cli.commands import main
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(["monitor", "-w", str(ws), "--horizon", "1.0", "--json", "--strict", str(tmp / "live.jsonl")])
        yield {"level": request.param, "code": monitor.returncode, "out": (tmp / "monitor.out").read_text(),
               "system": (tmp / "system.log").read_text(), "record": json.loads((tmp / "live.json").read_text()),
               "log": [json.loads(x) for x in (tmp / "live.jsonl").read_text().splitlines()],
               "offline": {"code": code, "report": json.loads(out.getvalue()), "err": err.getvalue()}}
    finally:
        for p in (system, monitor):
            if p is not None:
                stop(p)


def _rs(rec: dict[str, Any]) -> dict[str, Any]:
    (got,) = [n for n in rec["calls"]["nodes"] if n["node"] == "Rs"]
    return dict(got)


def test_the_server_answered_right_then_wrong_twice(run: dict[str, Any]) -> None:
    s = run["system"]
    assert "matched True" in s and "rs True" in s and "rs again [False, False]" in s and "done" in s, s
    assert run["record"]["source"] == "dds", run["out"]


def test_the_wrong_answers_of_the_restarted_server_are_never_green(run: dict[str, Any]) -> None:
    """Live: ``Rs`` failed, ``--strict`` exits 1; its wrong answers paired on the wire and violated (with
    contents events or without); the offline check of the log gives the live status."""
    rs = _rs(run["record"])
    assert rs["status"] == "failed" and run["code"] == 1, (rs, run["out"])
    assert rs["counts"]["violated"] == 2 and rs["counts"]["inconclusive"] == 0, rs
    assert rs["counts"].get("satisfied", 0) >= 1, rs  # the call before the restart, judged right
    off = run["offline"]
    assert off["code"] == 1 and [e["status"] for e in off["report"] if e.get("node") == "Rs" and "calls" in e] == [
        rs["status"]], (off, rs)


@pytest.mark.parametrize("run", ["contents"], indirect=True)  # the control's run only
def test_the_control_with_contents_events_finds_both_wrong_answers(run: dict[str, Any]) -> None:
    assert run["level"] == "contents"
    rs = _rs(run["record"])
    assert rs["status"] == "failed" and rs["counts"]["violated"] == 2 and rs["counts"]["satisfied"] == 1, rs
