"""``rclverify oracle``: the contracts answering ROSMonitoring's WebSocket
events, with a real client on 127.0.0.1 (issue 23)."""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest
from websockets.sync.client import connect

from rclverify.backends.monitors.check import check_trace
from rclverify.backends.monitors.config import load_mapping
from rclverify.runtime.oracle import ORACLE_VERDICTS
from rclverify.runtime.ros1 import free_port
from rclverify.lang.typecheck import load
from rclverify.traces import read_trace

REPO = Path(__file__).resolve().parents[2]
TRACES = REPO / "backends" / "monitors" / "traces"


@pytest.fixture(scope="module")
def oracle(tmp_path_factory: pytest.TempPathFactory) -> Any:
    port = free_port()
    out = tmp_path_factory.mktemp("oracle") / "oracle.out"
    env = dict(os.environ, PYTHONPATH=str(REPO / "src") + os.pathsep + os.environ.get("PYTHONPATH", ""))
    p = subprocess.Popen([sys.executable, "-m", "rclverify.cli.commands", "oracle", "-w", str(REPO), "--port", str(port),
                          "--node", "RadiationSensor", "--horizon", "2.0"], env=env, cwd=REPO,
                         stdout=out.open("wb"), stderr=subprocess.STDOUT, start_new_session=True)
    try:
        deadline = time.monotonic() + 20
        while "oracle for" not in out.read_text():
            assert p.poll() is None and time.monotonic() < deadline, out.read_text()
            time.sleep(0.05)
        yield f"ws://127.0.0.1:{port}", port
    finally:
        os.killpg(p.pid, signal.SIGTERM)
        try:
            assert p.wait(10) == 0, out.read_text()
        finally:
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGKILL)


def _send_run(url: str, run: str) -> list[dict[str, Any]]:
    """The run's lines sent as ROSMonitoring sends events: topic, time, fields flattened."""
    answers = []
    with connect(url, open_timeout=10, close_timeout=5) as ws:
        for line in (TRACES / run).read_text().splitlines():
            ws.send(line)
            answers.append(json.loads(ws.recv(timeout=10)))
    return answers


def _offline(run: str) -> list[tuple[Any, ...]]:
    checked = load([REPO / "contracts" / "remote_inspection.rcl"])
    cfg = load_mapping(REPO, "backends/monitors/mapping.yaml", 2.0)
    seen: list[Any] = []
    check_trace(checked, [checked.nodes["RadiationSensor"]], read_trace(TRACES / run), cfg.rules, cfg.horizon,
                seen.append)
    return [(v.verdict, v.guarantee, v.time) for v in seen if v.verdict != "open"]


def test_nominal_run_is_never_false_and_its_verdicts_are_the_offline_ones(oracle: Any) -> None:
    url, _ = oracle
    answers = _send_run(url, "nominal.jsonl")
    assert {a["verdict"] for a in answers} <= {"currently_true", "currently_false", "unknown"}
    assert "currently_false" in {a["verdict"] for a in answers}  # an inspection waiting for the sensor
    # inspect(i) arrives with the last waypoint's reading, and the new reading comes
    # before any answer: the command's question is superseded, the answer judged
    # against the new reading (docs/semantics.md), so nothing is unknown
    assert [a["verdict"] for a in answers].count("unknown") == 0
    got = [(v["verdict"], v["guarantee"], v["time"]) for a in answers for v in a["rclverify"]]
    offline = _offline("nominal.jsonl")  # the run's last outputs are judged when it ends, past the skew
    assert got == offline[:len(got)] and len(offline) - len(got) <= 2


def test_fault_run_turns_false_at_the_violation_and_stays_false(oracle: Any) -> None:
    url, _ = oracle
    answers = _send_run(url, "sensor_fault.jsonl")
    assert all(a["verdict"] in ORACLE_VERDICTS for a in answers)
    first = next(k for k, a in enumerate(answers) if a["verdict"] == "false")
    [v] = [v for v in answers[first]["rclverify"] if v["verdict"] == "violated"]
    assert v["node"] == "RadiationSensor" and v["guarantee"] == 1
    assert v["values"]["in.r"] == "300.0" and v["values"]["out.radiationStatus"] == "orange"
    assert all(a["verdict"] == "false" for a in answers[first:])
    assert all(a["verdict"] != "false" for a in answers[:first])
    got = [(v["verdict"], v["guarantee"], v["time"]) for a in answers for v in a["rclverify"]]
    offline = _offline("sensor_fault.jsonl")  # the run's last outputs are judged when it ends, past the skew
    assert got == offline[:len(got)] and len(offline) - len(got) <= 2


def test_malformed_events_are_unknown_with_the_reason_and_the_run_goes_on(oracle: Any) -> None:
    url, _ = oracle
    with connect(url, open_timeout=10) as ws:
        for bad, why in (("{", "not JSON"), ("[1]", "not a JSON object"), ('{"time": 1}', "'topic'"),
                         ('{"topic": "r", "time": NaN}', "'time'")):
            ws.send(bad)
            a = json.loads(ws.recv(timeout=10))
            assert a["verdict"] == "unknown" and why in a["error"]
        ws.send(json.dumps({"topic": "r", "time": 1.0, "value": 40.0}))
        assert json.loads(ws.recv(timeout=10))["verdict"] == "currently_true"


def test_a_busy_port_is_one_located_error(oracle: Any) -> None:
    _, port = oracle
    r = subprocess.run([sys.executable, "-m", "rclverify.cli.commands", "oracle", "-w", str(REPO), "--port", str(port)],
                       cwd=REPO, capture_output=True, text=True, timeout=60,
                       env=dict(os.environ, PYTHONPATH=str(REPO / "src")))
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert r.stderr.startswith(f"rclverify oracle: error: cannot listen on 127.0.0.1:{port}")


def test_pipelined_events_get_the_answers_of_one_at_a_time_in_order(oracle: Any) -> None:
    """A monitor that does not wait for each verdict: the events that arrive
    together are answered together (one socket write), each in its own text
    frame, in order, with the same answers as one at a time."""
    url, _ = oracle
    one_by_one = _send_run(url, "sensor_fault.jsonl")
    lines = (TRACES / "sensor_fault.jsonl").read_text().splitlines() * 20
    with connect(url, open_timeout=10, close_timeout=5) as ws:
        for line in lines:  # all sent before any answer is read
            ws.send(line)
        frames = [ws.recv(timeout=10) for _ in lines]
    assert all(isinstance(f, str) for f in frames)  # text frames, as ROSMonitoring reads them
    answers = [json.loads(f) for f in frames]
    assert answers[:len(one_by_one)] == one_by_one
    assert {a["verdict"] for a in answers[len(one_by_one):]} == {"false"}  # the repeated run stays false
