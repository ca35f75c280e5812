"""A FIFO (or device) in a recorded run is never opened (traces/guard.py):
a bag whose reader would open it is one located error, any other such
entry of a bag directory is skipped with a warning.  ``monitor``, ``ros
check`` (the grounding scan) and the monitors backend of ``doit verify``
run in a subprocess with a timeout, so a regression (a blocking read)
fails instead of hanging."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from rclverify.traces.files import trace_files
from rclverify.traces import TraceError, read_trace
from rclverify.traces.guard import check_trace_path

pytestmark = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")

REPO = Path(__file__).resolve().parents[2]
BAG = "backends/monitors/traces/nominal_bag"
CLI = "import sys; from rclverify.cli.commands import main; sys.exit(main(sys.argv[1:]))"


def _case(tmp_path: Path) -> Path:
    ws = tmp_path / "case"
    for item in ("contracts", "ros", "backends"):
        shutil.copytree(REPO / item, ws / item, ignore=shutil.ignore_patterns("__pycache__"))
    return ws


def _run(ws: Path, *args: str) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ, PYTHONPATH=str(REPO / "src") + os.pathsep + os.environ.get("PYTHONPATH", ""))
    return subprocess.run([sys.executable, "-c", CLI, *args], cwd=ws, capture_output=True, text=True, timeout=120,
                          env=env)


def _fifo_metadata(ws: Path) -> Path:
    meta = ws / BAG / "metadata.yaml"
    meta.unlink()
    os.mkfifo(meta)
    return meta


def test_a_fifo_the_bag_reader_would_open_is_a_located_error(tmp_path: Path) -> None:
    ws = _case(tmp_path)
    meta = _fifo_metadata(ws)
    with pytest.raises(TraceError) as exc:
        check_trace_path(ws / BAG)
    assert str(exc.value).startswith(f"{meta}: error: a FIFO, not a regular file: the bag reader would open it")
    with pytest.raises(TraceError):
        read_trace(ws / BAG)
    assert f"{BAG}/metadata.yaml" not in trace_files(ws, BAG)


def test_another_fifo_in_a_bag_is_skipped_with_a_warning(tmp_path: Path) -> None:
    ws = _case(tmp_path)
    os.mkfifo(ws / BAG / "notes")
    os.symlink("/dev/null", ws / BAG / "null")
    warnings: list[str] = []
    events = list(read_trace(ws / BAG, [ws / "backends/monitors/msg"], on_warning=warnings.append))
    assert len(events) == 63
    assert warnings == [f"{ws / BAG / 'notes'}: warning: a FIFO, not a regular file: skipped",
                        f"{ws / BAG / 'null'}: warning: a device, not a regular file: skipped"]


def test_a_trace_that_is_a_fifo_is_refused_unless_a_stream_was_asked_for(tmp_path: Path) -> None:
    fifo = tmp_path / "run.jsonl"
    os.mkfifo(fifo)
    with pytest.raises(TraceError, match="a FIFO, not a recorded run"):
        read_trace(fifo)
    assert trace_files(tmp_path, "run.jsonl") == []

    def write() -> None:
        with fifo.open("w") as fh:
            fh.write('{"topic": "r", "time": 1.0, "value": 5.0}\n')
    t = threading.Thread(target=write, daemon=True)
    t.start()
    assert [e.topic for e in read_trace(fifo, streams=True)] == ["r"]
    t.join(5)


def test_monitor_and_ros_check_end_with_a_located_error(tmp_path: Path) -> None:
    ws = _case(tmp_path)
    _fifo_metadata(ws)
    r = _run(ws, "monitor", BAG)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert f"{BAG}/metadata.yaml: error: a FIFO, not a regular file" in r.stderr
    r = _run(ws, "ros", "check", "--json", "findings.json")
    assert "Traceback" not in r.stderr
    assert "metadata.yaml" in r.stdout + r.stderr + (ws / "findings.json").read_text()


BACKEND = """
import json
from pathlib import Path
from rclverify.backends.base import NodeTarget
from rclverify.backends.monitors.backend import MonitorsBackend
from rclverify.lang.typecheck import load
root = Path(".")
checked = load([root / "contracts/remote_inspection.rcl"])
t = NodeTarget(root=root, checked=checked, node=checked.nodes["RadiationSensor"],
               config={"backend": "monitors", "mapping": "backends/monitors/mapping.yaml", "horizon": 2.0,
                       "traces": ["backends/monitors/traces/nominal.jsonl", "backends/monitors/traces/nominal_bag"]},
               contract_files=("contracts/remote_inspection.rcl",), plan_file="contracts/plan.yaml",
               artifacts=root / "artifacts/monitors/RadiationSensor")
b = MonitorsBackend()
print(json.dumps({o.instance: [e.status, e.explanation] for o in b.export(t) for e in [b.run(o, t)]}))
"""


def test_the_monitors_backend_records_an_error(tmp_path: Path) -> None:
    """doit verify's evidence for the bag holding the FIFO: error, located; the log's untouched."""
    ws = _case(tmp_path)
    _fifo_metadata(ws)
    r = subprocess.run([sys.executable, "-c", BACKEND], cwd=ws, capture_output=True, text=True, timeout=120,
                       env=dict(os.environ, PYTHONPATH=str(REPO / "src")))
    assert r.returncode == 0, r.stderr
    got = json.loads(r.stdout)
    assert got["nominal_bag"][0] == "error" and "metadata.yaml: error: a FIFO" in got["nominal_bag"][1]
    assert got["nominal_jsonl"][0] == "discharged"


def test_a_fifo_message_definition_is_refused_not_read(tmp_path: Path) -> None:
    ws = _case(tmp_path)
    fifo = ws / "backends/monitors/msg/gazebo_radiation_plugin/msg/Other.msg"
    os.mkfifo(fifo)
    with pytest.raises(TraceError, match="Other.msg:1: error: not a regular file"):
        list(read_trace(ws / BAG, [ws / "backends/monitors/msg"]))
    from rclverify.backends.monitors.config import load_mapping
    cfg = load_mapping(ws, "backends/monitors/mapping.yaml")
    assert all(not f.endswith("Other.msg") for f in cfg.msg_files(ws))
