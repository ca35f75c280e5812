"""Every endpoint of a call accounted for (docs/ros2.md, "Every endpoint of a
call accounted for"; docs/monitors.md, "Services and actions over DDS").

The rclpy source hears a service's calls through introspection events only.
One ROS 2 system (one rclpy process on Fast DDS, tests/_ros2.py) runs once
for the module, watched by two monitors through the rclpy source: one of
every contract (``--strict``, ``--record``), one of the control alone
(``--node Ctl --strict``).  Its services (std_srvs/SetBool; every contract
is ``in.req -> out.ok``):

* ``/ctl``, the control: its server publishes contents events, its two
  clients none: every call is heard, judged and right: discharged, and the
  control's monitor exits 0 under ``--strict`` (live, its log, its bag);
* ``/two``: two servers, ``two_ok`` publishing contents events and answering
  right, ``two_bad`` publishing none and answering wrong: not judged for
  ``server /two_bad``, never discharged;
* ``/both``: the same two servers, both publishing contents events: the
  wrong server's answers are judged, violated (each server's handling of a
  request is a call of its own);
* ``/meta``: two clients, ``meta_good`` publishing contents, ``meta_bad``
  metadata only, whose three calls are answered wrong; the server publishes
  none: not judged for ``client /meta_bad`` (METADATA);
* ``/half``: two clients, one publishing contents events, one none, the
  server none: not judged for ``client /half_b``; the run's ``--record`` bag
  says the same, so its check is never greener than the live run;
* ``/rs``: a server publishing contents events, restarted (the node
  destroyed and made again, same name) without introspection, its two
  answers then wrong: not judged for ``server /rs_s``;
* ``/early``: a request made before the monitors started, answered wrong
  once they run, then a right call: the wrong answer is named undecided
  (its client gid and sequence number), never discharged.
"""
from __future__ import annotations

import contextlib
import io
import json
import signal
from pathlib import Path
from typing import Any, Callable

import pytest
from _procs import calls_judged, stop, wait_for, wait_logged
from _ros2 import live_workspace, rclverify, ros2_env, ros2_python, start_node

SERVICES = ("ctl", "two", "both", "meta", "half", "rs", "early")
RCL = "".join(f"""\
node {s.capitalize()} {{
  inputs( req : BOOL )
  outputs( ok : BOOL )
  services( std_srvs/SetBool {s} serves(in.req, out.ok) )
  assume( TRUE )
  guarantee( in.req -> out.ok )
}}

""" for s in SERVICES)

SYSTEM = """\
import time
import rclpy
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from rclpy.qos import qos_profile_services_default
from rclpy.service_introspection import ServiceIntrospectionState as S
from std_srvs.srv import SetBool

t0 = time.monotonic()
rclpy.init()
ex = MultiThreadedExecutor(num_threads=4)
nodes = {}

def node(name):
    nodes[name] = n = Node(name)
    ex.add_node(n)
    return n

def serve(name, service, right, level=None, before=None):
    def answer(req, resp):
        if before is not None:
            before()
        resp.success = req.data if right else not req.data
        return resp
    n = node(name)
    srv = n.create_service(SetBool, service, answer, callback_group=ReentrantCallbackGroup())
    if level is not None:
        srv.configure_introspection(n.get_clock(), qos_profile_services_default, level)
    return srv

def client(name, service, level=None):
    n = node(name)
    c = n.create_client(SetBool, service)
    if level is not None:
        c.configure_introspection(n.get_clock(), qos_profile_services_default, level)
    return c

def spin(seconds):
    until = time.monotonic() + seconds
    while time.monotonic() < until:
        ex.spin_once(timeout_sec=0.02)

def done(*futs, timeout=10.0):
    until = time.monotonic() + timeout
    while time.monotonic() < until and not all(f.done() for f in futs):
        ex.spin_once(timeout_sec=0.01)
    return [f.result().success if f.done() else None for f in futs]

watch = node("watch")

def monitors_up():
    return all(watch.count_publishers(t) >= 1 for t in VERDICT_TOPICS)

# once the monitors' readers are in the graph: their own side of each match, and the DDS source's horizon
# (1 s) after it began to hear a request writer, within which a reply is undecided (runtime/dds/order.py)
SETTLE = 2.5

def taps_made():  # the readers of the system's topics the monitors made, in the graph (a DDS name is raw)
    return all(len(watch.get_subscriptions_info_by_topic(t, not t.startswith("/"))) >= n
               for t, n in READERS.items())

held = [True]  # the first request only: the later ones come after the monitors' taps are made

def after_the_monitors():  # the early request's answer: once the monitors run
    if not held:
        return
    held.clear()
    until = time.monotonic() + 60
    while time.monotonic() < until and not (monitors_up() and taps_made()):
        time.sleep(0.05)
    time.sleep(SETTLE)

serve("early_s", "early", False, S.CONTENTS, after_the_monitors)
early = client("early_c", "early")
serve("ctl_s", "ctl", True, S.CONTENTS)
ctl = [client("ctl_a", "ctl"), client("ctl_b", "ctl")]
serve("two_ok", "two", True, S.CONTENTS)
serve("two_bad", "two", False)
two = client("two_c", "two")
serve("both_ok", "both", True, S.CONTENTS)
serve("both_bad", "both", False, S.CONTENTS)
both = client("both_c", "both")
serve("meta_s", "meta", False)
meta_good, meta_bad = client("meta_good", "meta", S.CONTENTS), client("meta_bad", "meta", S.METADATA)
serve("half_s", "half", True)
half = [client("half_a", "half", S.CONTENTS), client("half_b", "half")]
rs = serve("rs_s", "rs", True, S.CONTENTS)
rs_c = client("rs_c", "rs")
until = time.monotonic() + 20
while time.monotonic() < until and not early.service_is_ready():
    ex.spin_once(timeout_sec=0.05)
pending = early.call_async(SetBool.Request(data=True))  # before any monitor runs
spin(0.5)
print("ready", flush=True)
until = time.monotonic() + 40
while time.monotonic() < until and not (monitors_up() and taps_made()):  # taps made once they hear the publishers
    ex.spin_once(timeout_sec=0.05)
taps = taps_made()  # False: the wait ran out (the calls are made anyway: what is unheard is said so)
spin(SETTLE)
print("matched", round(time.monotonic() - t0, 2), taps, flush=True)
print("early", done(pending), done(early.call_async(SetBool.Request(data=False))), flush=True)
print("ctl", [done(c.call_async(SetBool.Request(data=d)))[0] for c in ctl for d in (True, False)], flush=True)
def paced(c):  # one call, then both servers' replies written before the next call (paired by order on the wire)
    answer = done(c.call_async(SetBool.Request(data=True)))[0]
    spin(0.3)
    return answer

print("two", [paced(two) for _ in range(3)], flush=True)
print("both", [paced(both) for _ in range(3)], flush=True)
print("meta", [done(meta_good.call_async(SetBool.Request(data=False)))[0] for _ in range(2)],
      [done(meta_bad.call_async(SetBool.Request(data=True)))[0] for _ in range(3)], flush=True)
print("half", [done(c.call_async(SetBool.Request(data=True)))[0] for c in half for _ in range(3)], flush=True)
print("rs", done(rs_c.call_async(SetBool.Request(data=True))), flush=True)
spin(1.5)  # its events delivered (a reliable writer destroyed at once drops what no reader acknowledged yet)
old = nodes.pop("rs_s")
ex.remove_node(old)
old.destroy_node()
serve("rs_s", "rs", False)  # the same node made again, without introspection, now wrong
until = time.monotonic() + 20
spin(0.5)
while time.monotonic() < until and not rs_c.service_is_ready():
    ex.spin_once(timeout_sec=0.05)
print("rs again", [done(rs_c.call_async(SetBool.Request(data=True)))[0] for _ in range(2)], flush=True)
spin(3.0)  # the graph read again, the grace passed
print("done", round(time.monotonic() - t0, 2), flush=True)
while True:
    ex.spin_once(timeout_sec=0.1)
"""


def _workspace(tmp: Path) -> Path:
    return live_workspace(tmp, RCL, setbool=True)


def _args(ws: Path, tmp: Path, name: str, *extra: str, source: str = "rclpy") -> list[str]:
    """A monitor's arguments; a 300 ms lateness bound: the calls at their writers' source times (with none, at
    their receipt, in the order heard, which a loaded machine's delivery may change)."""
    via = ["--source", "rclpy", "--ros2-python", str(ros2_python())] if source == "rclpy" else []
    return ["monitor", "-w", str(ws), "--live", "--ros2", *via,
            "--interfaces", "interfaces", "--horizon", "1.0", "--reorder-window", "0.3", "--status", "0",
            "--duration", "90", "--strict", "--log", str(tmp / f"{name}.jsonl"), "--evidence",
            str(tmp / f"{name}.json"), "--verdict-topic", f"/{name}/verdict", *extra]


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """The system watched through the rclpy source by a monitor of every contract and one of the control."""
    ros2_python()  # skips, with the reason, without a ROS 2 Python
    tmp = tmp_path_factory.mktemp("endpoints")
    ws = _workspace(tmp)
    return _watched(tmp, ws, {"all": _args(ws, tmp, "all", "--record", str(tmp / "bag")),
                              "ctl": _args(ws, tmp, "ctl", "--node", "Ctl", "--record", str(tmp / "ctl_bag"))},
                    {**{f"/{s}/_service_event": 1 for s in SERVICES}, "/ctl/_service_event": 2},
                    # the last call heard (/rs's, before its server's restart) judged, the restarted server named
                    {"all": lambda log: calls_judged(log, {"Rs": 1, "Ctl": 6}) and any(
                        x.get("part") == "unjudged" and x.get("endpoint") == "server /rs_s" for x in log),
                     "ctl": lambda log: calls_judged(log, {"Ctl": 6})})  # four calls: a request of False is judged too


@pytest.fixture(scope="module")
def dds(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """The same system in a domain of its own, watched by the DDS source (a Cyclone DDS reader on an
    introspection event topic beside the rclpy source's Fast DDS one: docs/ros2.md, "Not covered")."""
    ros2_python()
    tmp = tmp_path_factory.mktemp("endpoints-dds")
    ws = _workspace(tmp)
    # the DDS source reads /two's and /both's request topics on the wire, beside their two servers
    return _watched(tmp, ws, {"all": _args(ws, tmp, "all", source="dds")},
                    {"/ctl/_service_event": 1, "rq/twoRequest": 3, "rq/bothRequest": 3},
                    {"all": lambda log: calls_judged(log, {"Rs": 3})})  # /rs's last calls, on the wire, judged


def _watched(tmp: Path, ws: Path, monitors: dict[str, list[str]], readers: dict[str, int],
             done: dict[str, Callable[[list[dict[str, Any]]], bool]]) -> dict[str, Any]:
    """The system started first (its early request made before any monitor), then the monitors; stopped
    once the system is done and each monitor's log holds what ``done[name]`` waits for (its run's last calls
    judged); per monitor its exit code, output, log and record.  ``readers``: topic (a ROS name, or a raw DDS
    one) -> the readers, the monitors' with the system's own, it waits for before its calls."""
    env = ros2_env(tmp)
    procs: dict[str, Any] = {}
    system = None
    try:
        system = start_node(tmp, "system", SYSTEM.replace("VERDICT_TOPICS", repr([f"/{n}/verdict" for n in monitors]))
                            .replace("READERS", repr(readers)), env)
        for name, args in monitors.items():
            procs[name] = rclverify(args, env, tmp, tmp / f"{name}.out")
        for name in monitors:
            wait_for(tmp / f"{name}.out", "monitoring", 60)
        wait_for(tmp / "system.log", "done", 90)
        for name in monitors:  # whatever the load, not a fixed horizon and settle
            wait_logged(tmp / f"{name}.jsonl", done[name], 30)
        for p in procs.values():
            stop(p, signal.SIGINT)
        codes = {name: p.returncode for name, p in procs.items()}
    finally:
        if system is not None:
            stop(system)
        for p in procs.values():
            stop(p)
    out: dict[str, Any] = {"tmp": tmp, "ws": ws, "system": (tmp / "system.log").read_text()}
    for name in monitors:
        out[name] = {"code": codes[name], "out": (tmp / f"{name}.out").read_text(),
                     "log": [json.loads(x) for x in (tmp / f"{name}.jsonl").read_text().splitlines()],
                     "record": json.loads((tmp / f"{name}.json").read_text())}
    return out


def _offline(run: dict[str, Any], trace: Path, *extra: str) -> tuple[int, list[dict[str, Any]], str]:
    """``rclverify monitor TRACE --strict --json`` (in this process): exit code, report, stderr."""
    from rclverify.cli.commands import main
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["monitor", "-w", str(run["ws"]), "--horizon", "1.0", "--json", "--strict", *extra, str(trace)])
    return code, json.loads(out.getvalue()), err.getvalue()


def _calls(rec: dict[str, Any]) -> dict[str, dict[str, Any]]:
    return {n["node"]: n for n in rec["calls"]["nodes"]}


def _items(rec: dict[str, Any]) -> dict[str, tuple[str, str]]:
    return {i["name"]: (i["reason"], i["detail"]) for i in rec["not_judged"] if i["kind"] == "service"}


def _verdicts(rec: dict[str, Any], node: str) -> list[str]:
    return [x["verdict"]["verdict"] for x in rec["log"] if x.get("topic") == "rclverify/verdict"
            and "kind" not in x and x["verdict"].get("call") and x["verdict"]["node"] == node]


def test_the_system_made_every_call(run: dict[str, Any]) -> None:
    s = run["system"]
    for line in ("early [False] [True]", "ctl [True, False, True, False]", "two ", "both ",
                 "meta [True, True] [False, False, False]", "half [True, True, True, True, True, True]",
                 "rs [True]", "rs again [False, False]", "done"):
        assert line in s, s
    assert s.split("matched ")[1].split()[1] == "True", s  # the calls made once the monitors' taps were


def test_the_control_is_judged_and_green(run: dict[str, Any]) -> None:
    """Row 1-3's control: a server publishing contents events covers every client: its four calls judged,
    discharged, nothing not judged; the control's monitor exits 0 under --strict, and so do its log and bag."""
    ctl = run["ctl"]
    assert _calls(ctl["record"])["Ctl"]["status"] == "discharged", ctl["out"]
    counts = _calls(ctl["record"])["Ctl"]["counts"]
    assert counts["violated"] == counts["inconclusive"] == 0 and counts["satisfied"] >= 4, counts
    assert ctl["record"]["not_judged"] == [] and ctl["code"] == 0, ctl["out"]
    assert _calls(run["all"]["record"])["Ctl"]["status"] == "discharged"
    assert "/ctl" not in _items(run["all"]["record"])
    for trace in (run["tmp"] / "ctl.jsonl", run["tmp"] / "ctl_bag"):
        code, report, err = _offline(run, trace, "--node", "Ctl")
        assert code == 0, (trace, err, report)
        assert [e["status"] for e in report if "calls" in e] == ["discharged"], report


def test_a_server_without_introspection_is_not_judged(run: dict[str, Any]) -> None:
    """Row 1: ``two_bad`` publishes no events and answers wrong: /two is not judged for it, never discharged."""
    rec = run["all"]["record"]
    reason, detail = _items(rec)["/two"]
    assert reason == "endpoint not heard" and "server /two_bad publishes no introspection events" in detail, detail
    assert _calls(rec)["Two"]["status"] == "inconclusive", _calls(rec)["Two"]
    assert "server /two_bad publishes no introspection events" in _calls(rec)["Two"]["explanation"]
    assert _calls(rec)["Two"]["counts"]["violated"] == 0  # its wrong answers were never heard
    assert run["all"]["code"] == 1


def test_two_servers_publishing_contents_are_each_judged(run: dict[str, Any]) -> None:
    """The control of row 1: both servers of /both publish contents: the wrong one's answers are violated
    (each server's handling of a request is a call of its own), none is an orphan, nothing is unheard."""
    rec = run["all"]["record"]
    assert sorted(set(_verdicts(run["all"], "Both"))) == ["satisfied", "violated"], _verdicts(run["all"], "Both")
    assert _calls(rec)["Both"]["status"] == "failed" and _calls(rec)["Both"]["counts"]["violated"] == 3
    assert "/both" not in _items(rec), _items(rec)
    lines = [x for x in run["all"]["log"] if x.get("kind") == "call" and x.get("link") == "both"]
    assert not [x for x in lines if x.get("orphan")], lines


def test_a_metadata_client_is_not_judged(run: dict[str, Any]) -> None:
    """Row 1: ``meta_bad`` publishes metadata only: its three wrongly answered calls are never judged, and the
    link says so for that endpoint (the contents client's calls are judged)."""
    rec = run["all"]["record"]
    reason, detail = _items(rec)["/meta"]
    assert reason == "endpoint not heard" and "client /meta_bad publishes introspection events without " \
        "contents (METADATA)" in detail, detail
    meta = _calls(rec)["Meta"]
    assert meta["status"] == "inconclusive" and meta["counts"]["violated"] == 0 and meta["counts"]["satisfied"], meta


def test_a_client_without_events_is_not_judged_live_nor_in_the_bag(run: dict[str, Any]) -> None:
    """Rows 1 and 3: ``half_b`` publishes nothing: live, /half is not judged for it; the --record bag and the
    log say the same (never greener than the live run), --strict exits 1 on each."""
    rec = run["all"]["record"]
    reason, detail = _items(rec)["/half"]
    assert reason == "endpoint not heard" and "client /half_b publishes no introspection events" in detail, detail
    assert _calls(rec)["Half"]["status"] == "inconclusive"
    for trace in (run["tmp"] / "all.jsonl", run["tmp"] / "bag"):
        code, report, err = _offline(run, trace, "--node", "Half")
        assert code == 1, (trace, err, report)
        items = {i["name"]: i for e in report for i in e.get("not_judged", [])}
        assert items["/half"]["reason"] == "endpoint not heard", items
        assert [e["status"] for e in report if "calls" in e] == ["inconclusive"], report
    code, report, _err = _offline(run, run["tmp"] / "bag", "--node", "Half")
    detail = {i["name"]: i for e in report for i in e.get("not_judged", [])}["/half"]["detail"]
    assert "client /half_b" in detail, detail  # the bag names the endpoint with the live reason


def test_a_server_restarted_without_introspection_is_not_judged(run: dict[str, Any]) -> None:
    """Row 1: the graph read again: /rs_s made again without events answers wrong twice: not judged for it."""
    rec = run["all"]["record"]
    reason, detail = _items(rec)["/rs"]
    assert reason == "endpoint not heard" and "server /rs_s publishes no introspection events" in detail, detail
    rs = _calls(rec)["Rs"]
    assert rs["status"] == "inconclusive" and rs["counts"]["violated"] == 0 and rs["counts"]["satisfied"], rs


def test_an_answer_to_a_request_before_the_monitor_is_named_undecided(run: dict[str, Any]) -> None:
    """Row 2: the early request's wrong answer is named (client gid, sequence number 1), undecided, whatever
    else was judged (the later right call): never discharged, live and offline, --strict exits 1."""
    rec = run["all"]["record"]
    early = _calls(rec)["Early"]
    assert early["counts"]["satisfied"] and not early["counts"]["violated"], early
    assert early["status"] == "inconclusive", early
    assert "1 answer(s) of /early whose request the monitor did not hear" in early["explanation"], early
    orphan = [x for x in run["all"]["log"] if x.get("kind") == "call" and x.get("link") == "early"
              and x.get("orphan")]
    assert len(orphan) == 1 and orphan[0]["key"][0] == "ev" and orphan[0]["key"][2] == 1, orphan
    assert f"client gid {orphan[0]['key'][1]} seq 1" in early["explanation"]
    assert _items(rec)["/early"][0] == "not paired"
    for trace in (run["tmp"] / "all.jsonl", run["tmp"] / "bag"):
        code, report, err = _offline(run, trace, "--node", "Early")
        assert code == 1 and [e["status"] for e in report if "calls" in e] == ["inconclusive"], (trace, err, report)


def test_the_log_and_the_bag_are_never_greener_than_the_live_run(run: dict[str, Any]) -> None:
    """Row 3: the same call statuses per node and the same links not judged, live, from the log, from the bag."""
    rec = run["all"]["record"]
    live = {n: c["status"] for n, c in _calls(rec).items()}
    for trace in (run["tmp"] / "all.jsonl", run["tmp"] / "bag"):
        code, report, err = _offline(run, trace)
        assert {e["node"]: e["status"] for e in report if "calls" in e} == live, (trace, err)
        items = {(i["name"], i["reason"]) for e in report for i in e.get("not_judged", []) if i["kind"] == "service"}
        assert items == {(n, r) for n, (r, _d) in _items(rec).items()}, (trace, items)
        assert code == 1


def test_the_dds_source_hears_both_servers_on_the_wire(dds: dict[str, Any]) -> None:
    """Row 1 on the DDS source, which reads the request and reply topics: with one of /two's servers publishing
    no events it takes no introspection side and pairs the wire (both servers' replies heard), so ``two_bad``'s
    wrong answers are judged, never discharged; the control /ctl, whose one server publishes, is paired by its
    events and green."""
    rec = dds["all"]["record"]
    calls = _calls(rec)
    assert calls["Ctl"]["status"] == "discharged", (calls["Ctl"], dds["all"]["out"])
    assert calls["Two"]["status"] == "failed" and calls["Two"]["counts"]["violated"] >= 1, \
        (calls["Two"], dds["all"]["out"])
    assert "answered by node /two_bad" in calls["Two"]["explanation"], calls["Two"]
    assert calls["Both"]["status"] == "failed", calls["Both"]
    assert dds["all"]["code"] == 1
