"""Issue 35, the hostile tester's reproductions: each one a located error
(``file:line:col: error: ...``) or a bounded, surviving server instead of a
traceback, a dropped connection or memory that grows without bound.

* 10: a 5,001-digit numeral; a Doorstop item symlinked outside the
  workspace; a monitor mapping with ``fields: 5``; an evidence record that
  is ``[]`` or ``null``; an oracle event nested 100,000 deep;
* 11: an oracle client that sends and never reads;
* 12: ``--horizon nan`` and a NaN horizon in the plan.
"""
from __future__ import annotations

import asyncio
import json
import os
import shutil
import socket
import subprocess
import sys
import threading
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator

import pytest

from rclverify.cli.commands import main

REPO = Path(__file__).resolve().parents[2]
STOP = REPO / "tests" / "data" / "requirements" / "stop"


def _env() -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": str(REPO / "src") + os.pathsep + os.environ.get("PYTHONPATH", "")}


def _doit(ws: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "doit", "verify"], cwd=ws, env=_env(), capture_output=True,
                          text=True, timeout=300)


def _error_lines(text: str) -> list[str]:
    return [line for line in text.splitlines() if line.strip()]


# --------------------------------------------------------------------------- 10: numerals


@pytest.fixture()
def init_ws(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    ws = tmp_path / "w"
    assert main(["init", str(ws), "--nodes", "Camera,Planner"]) == 0
    monkeypatch.chdir(ws)
    return ws


def _set_bound(ws: Path, numeral: str) -> tuple[int, int]:
    """Put ``numeral`` as Camera's upper input bound; returns its line and column."""
    rcl = ws / "contracts/camera.rcl"
    text = rcl.read_text()
    assert "in.reading <= 100 )" in text
    rcl.write_text(text.replace("in.reading <= 100 )", f"in.reading <= {numeral} )"))
    for i, line in enumerate(rcl.read_text().splitlines(), 1):
        if numeral in line:
            return i, line.index(numeral) + 1
    raise AssertionError(numeral)


def test_a_numeral_past_the_digit_limit_is_one_located_error_in_every_command(
        init_ws: Path, capsys: pytest.CaptureFixture[str]) -> None:
    line, col = _set_bound(init_ws, "1" + "0" * 5000)  # 5,001 digits: Python prints at most 4,300
    want = f"contracts/camera.rcl:{line}:{col}: error: numeral too long: 5001 digits (limit 1000)"
    capsys.readouterr()
    assert main(["check", "contracts/camera.rcl", "contracts/planner.rcl"]) == 1
    assert _error_lines(capsys.readouterr().err) == [want]
    assert main(["requirements", "-w", "."]) == 1
    assert _error_lines(capsys.readouterr().err) == [want]
    r = _doit(init_ws)
    assert r.returncode != 0 and want in r.stdout + r.stderr, r.stdout + r.stderr
    assert "Traceback" not in r.stdout + r.stderr and "Exceeds the limit" not in r.stdout + r.stderr


def test_a_huge_exponent_is_refused_and_numerals_within_the_limits_work_everywhere(
        init_ws: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rcl = init_ws / "contracts/camera.rcl"
    original = rcl.read_text()
    line, col = _set_bound(init_ws, "1e5000")
    capsys.readouterr()
    assert main(["check", "contracts/camera.rcl"]) == 1
    assert _error_lines(capsys.readouterr().err) == [
        f"contracts/camera.rcl:{line}:{col}: error: numeral's exponent too large (limit 1000 in magnitude)"]
    rcl.write_text(original)
    _set_bound(init_ws, "9" * 1000 + ".5")  # 1,001 digits: one too many
    assert main(["check", "contracts/camera.rcl"]) == 1
    assert "numeral too long: 1001 digits" in capsys.readouterr().err
    rcl.write_text(original)
    _set_bound(init_ws, "9" * 999 + "e1000")  # at both limits: a 1,999-digit integer
    assert main(["check", "contracts/camera.rcl", "contracts/planner.rcl"]) == 0
    assert main(["requirements", "-w", "."]) == 0  # Z3, the report text and JSON handle its value
    r = _doit(init_ws)
    assert r.returncode == 0, r.stdout + r.stderr
    report = json.loads((init_ws / "reports/assurance.json").read_text())
    assert any("9" * 999 in json.dumps(n) for n in report["nodes"])


# --------------------------------------------------------------------------- 10: Doorstop


def test_a_doorstop_item_symlinked_outside_the_workspace_is_a_located_error(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ws = tmp_path / "ws"
    shutil.copytree(STOP, ws)
    outside = tmp_path / "elsewhere"
    outside.mkdir()
    (ws / "reqs/SYS002.yml").rename(outside / "SYS002.yml")
    (ws / "reqs/SYS002.yml").symlink_to(outside / "SYS002.yml")
    capsys.readouterr()
    assert main(["requirements", "-w", str(ws), "--plan", "contracts/plan_doorstop.yaml"]) == 1
    err = _error_lines(capsys.readouterr().err)
    assert len(err) == 1 and err[0].startswith("reqs/SYS002.yml:1:1: error: requirements_from: the Doorstop "
                                               "item file 'reqs/SYS002.yml' resolves to "), err
    assert "outside the workspace (through a symbolic link)" in err[0]


# --------------------------------------------------------------------------- 10: trace mapping


@pytest.fixture()
def rover(tmp_path: Path) -> Path:
    ws = tmp_path / "rover"
    for rel in ("contracts", "backends"):
        shutil.copytree(REPO / rel, ws / rel)
    shutil.copy(REPO / "dodo.py", ws / "dodo.py")
    return ws


def _edit(path: Path, old: str, new: str) -> tuple[int, int]:
    text = path.read_text()
    assert old in text, old
    path.write_text(text.replace(old, new, 1))
    for i, line in enumerate(path.read_text().splitlines(), 1):
        if new in line:
            return i, line.index(new) + 1
    raise AssertionError(new)


@pytest.mark.parametrize("old, new, key, message", [
    ("  r: {fields: [value]}", "  r: {fields: 5}", "5", "topic r: fields must be a list of message field names, "
                                                          "or map each variable to its list ({x: [x], y: [y]}), "
                                                          "not 5"),
    # a mapping under fields: is one list per variable (two variables on one topic, docs/monitors.md)
    ("  r: {fields: [value]}", "  r: {fields: {a: 1}}", "1", "topic r (variable a): fields must be a list of "
                                                              "message field names, or map each variable to its "
                                                              "list ({x: [x], y: [y]}), not 1"),
    ("  at: {fields: [posx, posy], update: replace}", "  at: {fields: [posx, posy], update: 3}", "3",
     "topic at: update must be accumulate or replace, not 3"),
    ("msg_dirs: [backends/monitors/msg]", "msg_dirs: 7", "7", "msg_dirs must be a list of directories, not 7"),
])
def test_a_malformed_mapping_is_one_error_located_in_the_mapping_file(
        rover: Path, capsys: pytest.CaptureFixture[str], old: str, new: str, key: str, message: str) -> None:
    line, col = _edit(rover / "backends/monitors/mapping.yaml", old, new)
    col += new.index(key)
    want = f"backends/monitors/mapping.yaml:{line}:{col}: error: {message}"
    capsys.readouterr()
    assert main(["monitor", "-w", str(rover), str(rover / "backends/monitors/traces/nominal.jsonl")]) != 0
    assert _error_lines(capsys.readouterr().err) == [want]
    assert main(["compose", "-w", str(rover)]) == 1  # the plan's two monitors entries: reported once
    assert _error_lines(capsys.readouterr().err) == [want]


# --------------------------------------------------------------------------- 10: evidence records


def test_an_evidence_record_holding_a_list_or_null_is_produced_again_not_a_crash(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from rclverify.records.store import EvidenceStore
    ws = tmp_path / "ws"
    shutil.copytree(STOP, ws)
    assert _doit(ws).returncode == 0
    records = sorted((ws / "artifacts/evidence").glob("*.json"))
    assert len(records) >= 2
    records[0].write_text("[]\n")
    records[1].write_text("null\n")
    store = EvidenceStore(ws)
    for rec in records[:2]:
        ev, problem = store.read(rec.stem)
        assert ev is None and "altered outside rclverify" in problem
    assert main(["report", "-w", str(ws)]) in (0, 1)
    report = json.loads((ws / "reports/assurance.json").read_text())
    status = {o["id"]: o["status"] for o in report["obligations"]}
    assert status[records[0].stem] == status[records[1].stem] == "error"
    for _ in range(2):  # the up-to-date check read them on every run: it must not fail the run
        r = _doit(ws)
        assert r.returncode == 0 and "Traceback" not in r.stdout + r.stderr, r.stdout + r.stderr
    for rec in records[:2]:
        ev, problem = store.read(rec.stem)
        assert ev is not None and problem == "" and ev.status == "discharged"


# --------------------------------------------------------------------------- oracle (10, 11)


@contextmanager
def _oracle(limits: Any = None) -> Iterator[tuple[int, Any]]:
    """The oracle over the case study's RadiationSensor, served on 127.0.0.1
    by a thread of this process (so the test reads its counters)."""
    from rclverify.backends.monitors.config import load_mapping
    from rclverify.runtime.oracle import OracleStats, serve
    from rclverify.runtime.ros1 import free_port
    from rclverify.lang.typecheck import load
    checked = load([REPO / "contracts" / "remote_inspection.rcl"])
    cfg = load_mapping(REPO, "backends/monitors/mapping.yaml", 2.0)
    stats, port = OracleStats(), free_port()
    ready, box = threading.Event(), {}

    def run() -> None:
        async def go() -> None:
            box["loop"], box["stop"] = asyncio.get_running_loop(), asyncio.Event()
            started = asyncio.Event()
            task = asyncio.create_task(serve(checked, [checked.nodes["RadiationSensor"]], cfg.rules, cfg.horizon,
                                             port, ready=started, stop=box["stop"], limits=limits, stats=stats))
            await started.wait()
            ready.set()
            await task
        asyncio.run(go())
    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    assert ready.wait(20)
    try:
        yield port, stats
    finally:
        box["loop"].call_soon_threadsafe(box["stop"].set)
        thread.join(20)
        assert not thread.is_alive()


def test_a_deeply_nested_oracle_event_is_answered_unknown_and_the_connection_survives() -> None:
    from websockets.sync.client import connect
    with _oracle() as (port, stats), connect(f"ws://127.0.0.1:{port}", open_timeout=10) as ws:
        ws.send("[" * 100_000 + "]" * 100_000)
        reply = json.loads(ws.recv(timeout=10))
        assert reply["verdict"] == "unknown" and "nests deeper than 64 levels" in reply["error"]
        ws.send('{"topic": "r", "time": 1.0, "value": ' + "[" * 5000 + "]" * 5000 + "}")
        assert "limit 64" in json.loads(ws.recv(timeout=10))["error"]
        ws.send('{"topic": "r", "time": 1' + "0" * 5000 + ', "value": 3}')  # an integer Python cannot read
        reply = json.loads(ws.recv(timeout=10))
        assert reply["verdict"] == "unknown" and reply["error"].startswith("not JSON")
        ws.send(json.dumps({"topic": "radiationStatus", "time": 1.0, "level": "green"}))
        assert json.loads(ws.recv(timeout=10))["verdict"] in ("currently_true", "currently_false")
    assert stats.answered == 4


def test_a_client_that_sends_and_never_reads_is_throttled_then_dropped_and_its_state_freed() -> None:
    from websockets.client import ClientProtocol
    from websockets.sync.client import connect
    from websockets.uri import parse_uri

    from rclverify.runtime.oracle import OracleLimits
    limits = OracleLimits(inbox=32, inbox_bytes=1 << 20, stall_s=1.0)
    with _oracle(limits) as (port, stats):
        sock = socket.create_connection(("127.0.0.1", port), timeout=10)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        proto = ClientProtocol(parse_uri(f"ws://127.0.0.1:{port}"))
        proto.send_request(proto.connect())
        sock.sendall(b"".join(proto.data_to_send()))
        while not proto.events_received():  # the handshake's answer; from here on nothing is read
            proto.receive_data(sock.recv(4096))
        event = json.dumps({"topic": "r", "time": 1.0, "value": 5, "pad": "x" * 200}).encode()
        sock.settimeout(1)
        sent, pending, dropped_by = 0, b"", None
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not stats.dropped:  # send until the server drops us (bounded: 60 s)
            if not pending:
                proto.send_text(event)
                pending = b"".join(proto.data_to_send())
                sent += 1
            try:
                pending = pending[sock.send(pending):]
            except socket.timeout:  # the server does not read: our send waits (TCP flow control)
                continue
            except OSError as exc:  # reset or broken pipe: the server dropped the connection
                dropped_by = exc
                break
        # the client sees the reset, or (its receive buffer full, TCP backing off on loopback) the server says
        # it dropped it: before the server looked for replies left unread in the socket's send queue, it
        # waited forever for events that TCP no longer delivered
        assert dropped_by is not None or stats.dropped == 1, f"{sent} events sent in 60 s, never dropped: {stats}"
        # the server held at most its limit of unanswered events, dropped the connection and freed it
        assert stats.peak_inbox <= limits.inbox, stats
        end = time.monotonic() + 20
        while stats.connections and time.monotonic() < end:
            time.sleep(0.05)
        assert stats.dropped == 1 and stats.connections == 0, stats
        assert stats.answered < sent  # it did not keep answering into a buffer nobody reads
        sock.close()
        # the server goes on serving
        with connect(f"ws://127.0.0.1:{port}", open_timeout=10) as ws:
            ws.send(json.dumps({"topic": "radiationStatus", "time": 1.0, "level": "green"}))
            assert json.loads(ws.recv(timeout=10))["verdict"] in ("currently_true", "currently_false")
        end = time.monotonic() + 20
        while stats.connections and time.monotonic() < end:
            time.sleep(0.05)
        assert stats.connections == 0 and stats.dropped == 1


# --------------------------------------------------------------------------- 12: horizon


@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "-1", "NaN"])
@pytest.mark.parametrize("command", ["monitor", "oracle"])
def test_a_horizon_that_is_not_a_finite_number_of_seconds_is_a_usage_error(rover: Path, value: str,
                                                                           command: str) -> None:
    # a subprocess, bounded in time: an oracle that accepted the horizon would serve until killed
    extra = [str(rover / "backends/monitors/traces/nominal.jsonl")] if command == "monitor" else ["--port", "0"]
    r = subprocess.run([sys.executable, "-m", "rclverify.cli.commands", command, "-w", str(rover), f"--horizon={value}",
                        *extra], env=_env(), capture_output=True, text=True, timeout=60)
    assert r.returncode == 2, r.stdout + r.stderr
    assert f"rclverify {command}: error: argument --horizon: '{value}' is not a finite number of seconds >= 0" \
        in r.stderr
    assert "None:" not in r.stderr and "Traceback" not in r.stderr


def test_a_nan_horizon_in_the_plan_or_the_mapping_is_located(rover: Path, capsys: pytest.CaptureFixture[str]) -> None:
    line, col = _edit(rover / "contracts/plan.yaml", "horizon: 2.0", "horizon: .nan")
    col += len("horizon: ")
    capsys.readouterr()
    assert main(["compose", "-w", str(rover)]) == 1
    assert _error_lines(capsys.readouterr().err) == [
        f"contracts/plan.yaml:{line}:{col}: error: horizon must be a finite number of seconds >= 0, not nan"]
    r = _doit(rover)
    assert r.returncode != 0 and f"contracts/plan.yaml:{line}:{col}: error: horizon must be" in r.stdout + r.stderr
    # the mapping file's horizon, used when neither the plan entry nor --horizon gives one
    _edit(rover / "contracts/plan.yaml", "horizon: .nan", "horizon: 2.0")
    line, col = _edit(rover / "backends/monitors/mapping.yaml", "horizon: 2.0", "horizon: .inf")
    col += len("horizon: ")
    assert main(["monitor", "-w", str(rover), str(rover / "backends/monitors/traces/nominal.jsonl")]) != 0
    assert _error_lines(capsys.readouterr().err) == [
        f"backends/monitors/mapping.yaml:{line}:{col}: error: horizon must be a finite number of seconds >= 0, "
        "not inf"]
