"""examples/contracts_first: the contracts, the tree `rclverify generate ros2` made from them and
the hand-written logic; `doit verify` finds the seeded bug in TempSensor's logic, by its property
tests and by the monitor on the run record_run.py recorded from that logic, and discharges
HeaterControl's; the fixed logic, its run recorded again, is discharged (docs/generate.md,
"Contracts first: an example")."""
from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

from rclverify.cli import main

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "contracts_first"


def _verify(ws: Path) -> dict:
    subprocess.run([sys.executable, "-m", "doit", "verify"], cwd=ws, capture_output=True, text=True, timeout=600)
    report = json.loads((ws / "reports" / "assurance.json").read_text())
    return {o["id"]: o["status"] for o in report["obligations"]}


def test_doit_verify_finds_the_seeded_bug_and_discharges_the_fix(tmp_path: Path, capsys) -> None:
    ws = tmp_path / "ws"
    shutil.copytree(EXAMPLE, ws, ignore=shutil.ignore_patterns("artifacts", "reports", ".doit.*", "__pycache__"))
    # the committed tree is what the command writes today, and the hand-written logic is kept
    assert main(["generate", "ros2", "-w", str(ws), "-o", str(ws / "gen"), "--system", "contracts_first"]) == 0
    assert "0 generated file(s) written" in capsys.readouterr().out
    fragment = (ws / "gen" / "rclverify_plan.yaml").read_text().split("nodes:\n", 1)[1]
    plan = (ws / "contracts" / "plan.yaml").read_text().split("nodes:\n", 1)[1]
    strip = lambda t: [ln for ln in t.splitlines() if ln.strip() and not ln.strip().startswith("#")]  # noqa: E731
    # the plan's entries are the generated fragment's, with the recorded run under `traces`
    assert strip(plan) == strip(fragment.replace("traces: []", "traces:\n          - runs/run.jsonl"))
    # the committed run is the one record_run.py records from the committed logic
    run = (ws / "runs" / "run.jsonl").read_text()
    subprocess.run([sys.executable, "record_run.py"], cwd=ws, check=True, capture_output=True)
    assert (ws / "runs" / "run.jsonl").read_text() == run

    assert _verify(ws) == {"TempSensor.g1.property_tests.e0": "failed", "TempSensor.g0.monitors.run_jsonl": "failed",
                           "HeaterControl.g1.property_tests.e0": "discharged",
                           "HeaterControl.g0.monitors.run_jsonl": "discharged"}
    logic = ws / "gen" / "temp_sensor" / "temp_sensor" / "logic.py"
    logic.write_text(logic.read_text().replace("kelvin - 273}", "kelvin - 273.15}"))
    subprocess.run([sys.executable, "record_run.py"], cwd=ws, check=True, capture_output=True)
    assert _verify(ws) == {"TempSensor.g1.property_tests.e0": "discharged",
                           "TempSensor.g0.monitors.run_jsonl": "discharged",
                           "HeaterControl.g1.property_tests.e0": "discharged",
                           "HeaterControl.g0.monitors.run_jsonl": "discharged"}
