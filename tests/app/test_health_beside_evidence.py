"""A node's health checks run beside the other nodes' evidence (app/task_table.py, ``task_health``;
docs/decisions.md).

The evidence tasks are created once every ``node`` task ran.  While the health checks were a stage of
``node:<Node>``, one node with long health checks (the case study's Agent: 4-9 s) kept every evidence
task waiting while the other core had nothing to do.  Here, in ``rclverify verify -n 2``, the health
checks of ``N0`` do not finish until an evidence record of ``N1`` exists: they end only when the
evidence ran beside them (with the health checks inside the node task, they wait in vain and fail
after 30 s).  The run's verdicts are a serial run's, and each stage's provenance is written whole.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from _chain import write_chain_with_evidence as _workspace

ROOT = Path(__file__).resolve().parents[2]

#: Runs ``rclverify verify -n 2`` in-process with ``N0``'s health checks held until an evidence
#: record exists (doit forks its workers: they run the held function).
HELD = """\
import sys, time
from pathlib import Path
import rclverify.app.pipeline as pipeline
ws = Path(sys.argv[1])
checks = pipeline.stage_health


def held(w, node):
    if node == "N0":
        end = time.monotonic() + 30
        while not any((ws / "artifacts" / "evidence").glob("N1.*.json")):
            if time.monotonic() > end:
                raise SystemExit("no evidence ran beside the health checks of N0")
            time.sleep(0.05)
        (ws / "beside").write_text("N0's health checks ended after N1's evidence")
    return checks(w, node)


pipeline.stage_health = held
from rclverify.cli.commands import main
raise SystemExit(main(["verify", "-n", "2", "-w", str(ws)]))
"""

def _summary(root: Path) -> dict[str, object]:
    report = json.loads((root / "reports" / "assurance.json").read_text())
    return {"summary": report["summary"]["headline"],
            "evidence": sorted((o["id"], o["status"]) for o in report["obligations"])}


def test_health_checks_run_beside_the_evidence_in_two_processes(tmp_path: Path) -> None:
    ws = _workspace(tmp_path / "ws")
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    r = subprocess.run([sys.executable, "-c", HELD, str(ws)], env=env, capture_output=True, text=True, timeout=240)
    assert r.returncode == 0, r.stdout + r.stderr
    assert (ws / "beside").is_file()
    assert "N0: health" in r.stdout and "N0: compose, export" in r.stdout
    for stage in ("compose", "health"):  # one provenance file a stage, each written whole
        for n in ("N0", "N1"):
            rec = json.loads((ws / "artifacts" / "provenance" / stage / f"{n}.json").read_text())
            assert f"artifacts/contracts/{n}.json" in rec[stage]
    # the same verdicts as a serial run of the same inputs
    serial = _workspace(tmp_path / "serial")
    r = subprocess.run([sys.executable, "-m", "rclverify.cli.commands", "verify", "-n", "1", "-w", str(serial)],
                       env=env, capture_output=True, text=True, timeout=240)
    assert r.returncode == 0, r.stdout + r.stderr
    assert _summary(ws) == _summary(serial)
    assert [o for o in _summary(ws)["evidence"] if o[0].startswith("N1.")]  # type: ignore[union-attr]
