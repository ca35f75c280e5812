"""examples/contracts_first: the contracts, the tree `rclverify generate ros2` made from them and
the hand-written logic; `doit verify` finds the seeded bug in TempSensor's logic, by its property
tests and by the monitor on the run recorded from that logic running as rclpy nodes on ROS 2
(record_live.py: the committed run is the live monitor's log, checked here without re-recording),
and discharges HeaterControl's; the fixed logic, its run rebuilt by the simulator record_run.py
(no ROS 2 needed), is discharged (docs/generate.md, "Contracts first: an example")."""
from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

from rclverify.cli.commands import main

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "contracts_first"


def _verify(ws: Path, *extra: str) -> dict:
    p = subprocess.run([sys.executable, "-m", "doit", "verify", *extra], cwd=ws, capture_output=True, text=True,
                       timeout=600)
    report = json.loads((ws / "reports" / "assurance.json").read_text())
    from _report_schema import check_report
    check_report(report, "contracts_first")  # docs/assurance.schema.json and the status vocabulary
    return {**{o["id"]: o["status"] for o in report["obligations"]}, "exit": p.returncode}


def test_doit_verify_finds_the_seeded_bug_and_discharges_the_fix(tmp_path: Path, capsys) -> None:
    ws = tmp_path / "ws"
    shutil.copytree(EXAMPLE, ws, ignore=shutil.ignore_patterns("artifacts", "reports", ".doit.*", "__pycache__", ".ros2"))
    # the committed tree is what the command writes today, and the hand-written logic is kept
    assert main(["generate", "ros2", "-w", str(ws), "-o", str(ws / "gen"), "--system", "contracts_first"]) == 0
    assert "0 generated file(s) written" in capsys.readouterr().out
    fragment = (ws / "gen" / "rclverify_plan.yaml").read_text().split("nodes:\n", 1)[1]
    plan = (ws / "contracts" / "plan.yaml").read_text().split("nodes:\n", 1)[1]
    strip = lambda t: [ln for ln in t.splitlines() if ln.strip() and not ln.strip().startswith("#")]  # noqa: E731
    # the plan's entries are the generated fragment's, with the recorded run under `traces`
    assert strip(plan) == strip(fragment.replace("traces: []", "traces:\n          - runs/run.jsonl"))

    assert _verify(ws) == {"TempSensor.g1.property_tests.e0": "failed", "TempSensor.g0.monitors.run_jsonl": "failed",
                           "HeaterControl.g1.property_tests.e0": "discharged",
                           "HeaterControl.g0.monitors.run_jsonl": "discharged", "exit": 0}
    logic = ws / "gen" / "temp_sensor" / "temp_sensor" / "logic.py"
    logic.write_text(logic.read_text().replace("kelvin - 273}", "kelvin - 273.15}"))
    subprocess.run([sys.executable, "record_run.py"], cwd=ws, check=True, capture_output=True)
    # the fixed thermostat is a correct system: green under --strict (issue 64)
    assert _verify(ws, "--strict") == {"TempSensor.g1.property_tests.e0": "discharged",
                                       "TempSensor.g0.monitors.run_jsonl": "discharged",
                                       "HeaterControl.g1.property_tests.e0": "discharged",
                                       "HeaterControl.g0.monitors.run_jsonl": "discharged", "exit": 0}


def _messages(path: Path) -> list[dict]:
    return [json.loads(x) for x in path.read_text().splitlines() if x.strip()]


def test_the_committed_run_was_recorded_by_the_live_monitor(tmp_path: Path) -> None:
    """runs/run.jsonl is `rclverify monitor --live --ros2`'s log of the rclpy nodes (record_live.py), not the
    simulator's: it carries the monitor's verdict lines and wall-clock receive times; its messages are the
    ones the simulator computes from the same logic and readings, in the same order, each answer published
    at least the node's latency after its input (the nodes wait it), and the live verdicts are the 14
    violations of TempSensor's guarantee 1 and HeaterControl's 14 satisfied answers."""
    live = _messages(EXAMPLE / "runs" / "run.jsonl")
    verdicts = [x["verdict"] for x in live if x["topic"] == "rclverify/verdict"]
    messages = [x for x in live if not x["topic"].startswith("rclverify/")]
    assert len(messages) == 42 and all(x["time"] > 1.6e9 for x in messages)  # Unix time, not a simulated clock
    assert sorted((v["node"], v["verdict"]) for v in verdicts) == \
        [("HeaterControl", "satisfied")] * 14 + [("TempSensor", "violated")] * 14
    ws = tmp_path / "ws"
    shutil.copytree(EXAMPLE, ws, ignore=shutil.ignore_patterns("artifacts", "reports", ".doit.*", "__pycache__",
                                                               ".ros2"))
    subprocess.run([sys.executable, "record_run.py"], cwd=ws, check=True, capture_output=True, timeout=60)
    simulated = _messages(ws / "runs" / "run.jsonl")
    drop_time = lambda m: {k: v for k, v in m.items() if k != "time"}  # noqa: E731
    assert [drop_time(m) for m in messages] == [drop_time(m) for m in simulated]
    for k in range(0, 42, 3):  # probe, temperature, heat: 4 ms, then 2 ms at least
        assert messages[k + 1]["time"] - messages[k]["time"] >= 0.004
        assert messages[k + 2]["time"] - messages[k + 1]["time"] >= 0.002
