"""The live monitor against a real ROS 1 master on 127.0.0.1 (issue 23).

The test starts ``rosmaster`` on a free loopback port, the bundled Python
Radiation Sensor as a rospy node with the ``sensor_fault`` fault injected
(a reading of 300 reported ``orange``), a listener on the verdict topic,
``rclverify monitor --live`` as its own process, and a replay of the
``sensor_fault`` run's other messages; everything is stopped in a
``finally``.  Skipped, with the reason, only where ROS 1 cannot be
installed.
"""
from __future__ import annotations

import hashlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest
from _procs import stop, wait_for, wait_logged

from rclverify.backends.monitors.check import check_trace
from rclverify.backends.monitors.config import load_mapping
from rclverify.runtime.live import VERDICT_LOG_TOPIC
from rclverify.runtime.ros1 import LocalMaster, RosUnavailable, import_rospy
from rclverify.cli.commands import main
from rclverify.lang.typecheck import load
from rclverify.traces import read_trace

REPO = Path(__file__).resolve().parents[2]
SCRIPT = REPO / "scripts" / "ros1_case_study.py"
HORIZON = 1.0
RATE = 4.0  # the recorded times divided by 4: a loaded machine (CI runs two test workers) still lets
#            the sensor answer a reading before the next one arrives (an answer comes after its question)

try:
    import_rospy()
    REASON = ""
except RosUnavailable as exc:
    REASON = str(exc)
pytestmark = pytest.mark.skipif(bool(REASON), reason=f"ROS 1 unavailable: {REASON}")


def _start(args: list[str], env: dict[str, str], out: Path) -> subprocess.Popen[bytes]:
    return subprocess.Popen([sys.executable, *args], env=env, cwd=REPO, stdout=out.open("wb"),
                            stderr=subprocess.STDOUT, start_new_session=True)


@pytest.fixture(scope="module")
def live_run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    tmp = tmp_path_factory.mktemp("live")
    env_py = dict(PYTHONPATH=str(REPO / "src") + os.pathsep + os.environ.get("PYTHONPATH", ""))
    procs: list[subprocess.Popen[bytes]] = []
    with LocalMaster(tmp / "ros") as env:
        env = {**env, **env_py}
        try:
            listener = _start([str(SCRIPT), "listen", "/rclverify/verdict", "--out", str(tmp / "topic.jsonl")],
                              env, tmp / "listener.out")
            procs.append(listener)
            sensor = _start([str(SCRIPT), "sensor", "--misclassify", "--heard-by", "1"], env, tmp / "sensor.out")
            procs.append(sensor)
            monitor = _start(["-m", "rclverify.cli.commands", "monitor", "--live", "-w", str(REPO), "--horizon", str(HORIZON),
                              "--log", str(tmp / "live.jsonl"), "--evidence", str(tmp / "evidence.json"),
                              "--status", "0.5", "--duration", "60"], env, tmp / "monitor.out")
            procs.append(monitor)
            for p, name, text in ((listener, "listener.out", "listening"), (sensor, "sensor.out", "ready"),
                                  (monitor, "monitor.out", "monitoring")):
                wait_for(tmp / name, text, 20)
            # the monitor's links to the sensor's outputs are made after it said "monitoring": an answer sent
            # before its link is up is never heard (ROS 1 keeps no history for a late subscriber)
            wait_for(tmp / "sensor.out", "outputs heard by 1", 20)
            replay = subprocess.run([sys.executable, str(SCRIPT), "replay",
                                     str(REPO / "backends/monitors/traces/sensor_fault.jsonl"), "--rate", str(RATE),
                                     "--skip", "radiationStatus", "inspected", "--wait-for", "1",
                                     "--need", "r=2", "command=2"], env=env, cwd=REPO, capture_output=True,
                                    text=True, timeout=60)
            assert replay.returncode == 0, replay.stderr
            # a late subscriber to the latched last verdict, while the timer resolves what is still waiting
            late = _start([str(SCRIPT), "listen", "/rclverify/RadiationSensor/last_verdict",
                           "--out", str(tmp / "last.jsonl"), "--count", "1"], env, tmp / "late.out")
            procs.append(late)
            # the sensor's answers to the six readings heard, and the monitor's timer past the horizon of the last
            # message (what was still waiting then decided), whatever the load
            wait_logged(tmp / "live.jsonl", _resolved, 30)
            assert late.wait(20) == 0
            stop(monitor, signal.SIGINT)  # the monitor's own stop: evidence written
            rc = monitor.returncode
            # the listener reads what the monitor published up to its exit, which may be quicker than the
            # listener: wait (bounded) until it has every verdict the log holds before it is stopped
            until = time.monotonic() + 10
            while time.monotonic() < until and len(_topic_verdicts(tmp / "topic.jsonl")) < \
                    len(_live_verdicts(tmp / "live.jsonl")):
                time.sleep(0.05)
        finally:
            for p in procs:
                stop(p)
    return {"tmp": tmp, "rc": rc, "monitor_out": (tmp / "monitor.out").read_text()}


def _resolved(log: list[dict[str, Any]]) -> bool:
    """The sensor's answer (``radiationStatus``, ``inspected``) to each of the replay's six readings is in
    the monitor's ``log``, and a verdict decided by its timer at least the horizon after the last message."""
    heard = [x for x in log if x["topic"] != VERDICT_LOG_TOPIC]
    count = {t: sum(x["topic"] == t for x in heard) for t in ("r", "radiationStatus", "inspected")}
    return min(count.values()) >= 6 and any(x["verdict"].get("decided_at", 0) >= heard[-1]["time"] + HORIZON
                                            for x in log if x["topic"] == VERDICT_LOG_TOPIC)


def _topic_verdicts(path: Path) -> list[dict[str, Any]]:
    """The verdicts the listener heard on the verdict topic (a silence note, node "", is no verdict)."""
    got = [json.loads(line) for line in path.read_text().splitlines()] if path.exists() else []
    return [g for g in got if g["data"].get("node")]


def _live_verdicts(log: Path) -> list[dict[str, Any]]:
    rows = [json.loads(line) for line in log.read_text().splitlines()]
    return [r["verdict"] for r in rows if r["topic"] == VERDICT_LOG_TOPIC]


def _key(v: dict[str, Any]) -> tuple[Any, ...]:
    return (v["node"], v["verdict"], v["guarantee"], v["topic"], round(v["time"], 6))


def test_live_verdicts_equal_the_offline_verdicts_for_the_same_messages(live_run: dict[str, Any]) -> None:
    log = live_run["tmp"] / "live.jsonl"
    live = _live_verdicts(log)
    checked = load([REPO / "contracts" / "remote_inspection.rcl"])
    cfg = load_mapping(REPO, "backends/monitors/mapping.yaml", HORIZON)
    offline: list[Any] = []
    check_trace(checked, list(checked.nodes.values()), read_trace(log), cfg.rules, cfg.horizon, offline.append)
    assert len(live) > 40
    assert sorted(map(_key, live)) == sorted(_key(v.to_json()) for v in offline)


def test_the_injected_fault_is_reported_online_at_once(live_run: dict[str, Any]) -> None:
    got = [json.loads(line) for line in (live_run["tmp"] / "topic.jsonl").read_text().splitlines()]
    # the injected fault (r = 300 classified orange); on a loaded machine the live sensor may also
    # answer another reading after the response time, which the monitor rightly reports as well.  When the
    # answer's callback ran before the reading's (a race of two TCPROS links: docs/semantics.md, "Transport
    # skew"), the answer is right for the reading before and wrong for 300: inconclusive, never left green
    raced = [g for g in got if g["data"]["node"] == "RadiationSensor" and g["data"]["verdict"] == "inconclusive"
             and g["data"]["values"].get("in.r") == "300.0" and "transport skew" in g["data"]["reason"]]
    if raced:
        assert raced[0]["data"]["values"]["out.radiationStatus"] == "orange"
        return
    bad = [g for g in got if g["data"]["node"] == "RadiationSensor" and g["data"]["verdict"] == "violated"]
    assert bad, got[-5:]
    fault = [g for g in bad if g["data"]["values"].get("in.r") == "300.0"]
    assert fault, [g["data"]["values"] for g in bad]
    first = fault[0]
    assert first["data"]["guarantee"] == 1
    assert first["data"]["values"]["out.radiationStatus"] == "orange"
    # a wrong answer is violated whatever comes later (docs/semantics.md): reported once the transport skew
    # passed, not at the next message or at the end.  Judged in the monitor's own order of events, not by
    # the wall clock: on a loaded machine (CI) a process may wait a second for a core, which delays the
    # listener's copy but not the order in which the monitor logged what it heard and what it decided
    rows = [json.loads(line) for line in (live_run["tmp"] / "live.jsonl").read_text().splitlines()]
    decided = next(i for i, r in enumerate(rows) if r["topic"] == VERDICT_LOG_TOPIC and r["verdict"] == first["data"])
    heard = next(i for i, r in enumerate(rows) if r["topic"] == "r" and r["value"] == 300.0)
    following = [i for i, r in enumerate(rows) if r["topic"] == "r" and i > heard]
    assert following, "the replay's next reading after 300 was not heard"
    assert heard < decided < following[0], (heard, decided, following[0])
    assert first["data"]["decided_at"] < rows[following[0]]["time"]
    # every verdict the log records was published on the topic (a topic silent past --silence on a loaded
    # machine adds a silence note, which is no verdict)
    assert len(_topic_verdicts(live_run["tmp"] / "topic.jsonl")) == len(_live_verdicts(live_run["tmp"] / "live.jsonl"))


def test_the_last_verdict_is_latched_and_the_stop_writes_evidence(live_run: dict[str, Any],
                                                                  capsys: pytest.CaptureFixture[str]) -> None:
    [last] = [json.loads(line) for line in (live_run["tmp"] / "last.jsonl").read_text().splitlines()]
    assert last["data"]["node"] == "RadiationSensor"
    assert live_run["rc"] == 1  # a contract was violated (the Agent's, whatever the race)
    ev = json.loads((live_run["tmp"] / "evidence.json").read_text())
    log = live_run["tmp"] / "live.jsonl"
    assert ev["sha256"] == hashlib.sha256(log.read_bytes()).hexdigest()
    sensor = {n["node"]: n for n in ev["nodes"]}["RadiationSensor"]
    # failed; inconclusive when the fault's answer raced its reading (the test above), never discharged
    assert sensor["status"] == "failed" and sensor["first_violation"]["guarantee"] == 1 or (
        sensor["status"] == "inconclusive" and "transport skew" in json.dumps(sensor))
    assert ev["late_events"] == 0 and ev["decode_errors"] == {}
    assert "RadiationSensor:" in live_run["monitor_out"]  # the status line
    # the log re-checks offline with the command
    assert main(["monitor", "-w", str(REPO), "--horizon", str(HORIZON), "--json", str(log)]) == 1
    counts = {e["node"]: e["counts"] for e in json.loads(capsys.readouterr().out)}
    assert counts == {n["node"]: n["counts"] for n in ev["nodes"]}
