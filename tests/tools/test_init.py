"""`rclverify init`: a new workspace that type-checks and verifies at once."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from rclverify.cli.commands import main
from rclverify.tools.scaffold import plan_nodes

SRC = Path(__file__).resolve().parents[2] / "src"


def _env() -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": str(SRC) + os.pathsep + os.environ.get("PYTHONPATH", "")}


def test_init_then_doit_verify_works_in_a_fresh_directory(tmp_path: Path) -> None:
    ws = tmp_path / "rover"
    assert main(["init", str(ws), "--nodes", "Camera,Planner,MotorDriver"]) == 0
    assert sorted(p.name for p in (ws / "contracts").iterdir()) == ["camera.rcl", "motor_driver.rcl", "plan.yaml",
                                                                       "planner.rcl"]
    assert (ws / "dodo.py").is_file()
    assert all((ws / d).is_dir() and not any((ws / d).iterdir()) for d in ("backends", "artifacts", "reports"))
    # the example contracts type-check without warnings
    assert main(["check", *(str(p) for p in sorted((ws / "contracts").glob("*.rcl")))]) == 0
    r = subprocess.run([sys.executable, "-m", "doit", "verify"], cwd=ws, env=_env(), capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    # not a terminal: doit's task lines, no progress line, the summary table in plain ASCII
    assert ".  node:Planner" in r.stdout and "\x1b[" not in r.stdout and "obligations  running" not in r.stdout
    assert "| total " in r.stdout and r.stdout.rstrip().endswith("report: reports/assurance.html")
    report = json.loads((ws / "reports" / "assurance.json").read_text())
    assert report["meta"]["workspace"] == "rover" and not report["lint"]
    # each link of the chain gives side conditions, all proved by Z3 (rule R1)
    scs = {sc["node"] for sc in report["side_conditions"]}
    assert scs == {"Planner", "MotorDriver"}
    assert all(sc["status"] == "discharged" and sc["rule"] == "R1" for sc in report["side_conditions"])
    assert report["findings"] and all(f["status"] == "ok" for f in report["findings"])
    # without evidence entries nothing reads as verified
    # no evidence entry yet: every guarantee is unverified (no obligation covers it), each listed
    assert all(g["status"] == "unverified" for n in report["nodes"] for g in n["guarantees"])
    assert {u["id"] for u in report["unverified"]} == {f"{n['name']}.g{g['index']}" for n in report["nodes"]
                                                      for g in n["guarantees"]}
    assert (ws / "reports" / "assurance.sarif").is_file() and (ws / "reports" / "assurance.junit.xml").is_file()
    # --strict does not pass a system whose guarantees have no evidence yet
    assert report["meta"]["strict_ok"] is False


def test_init_defaults_and_refuses_to_overwrite(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["init", str(tmp_path / "w")]) == 0
    assert sorted(p.stem for p in (tmp_path / "w" / "contracts").glob("*.rcl")) == ["actuator", "controller", "sensor"]
    capsys.readouterr()
    before = (tmp_path / "w" / "dodo.py").read_text()
    assert main(["init", str(tmp_path / "w")]) == 1
    assert "error: exists and is not an empty directory" in capsys.readouterr().err
    assert (tmp_path / "w" / "dodo.py").read_text() == before


@pytest.mark.parametrize("nodes", ["", "A,A", "9x", "A,node", "A b"])
def test_init_rejects_unusable_node_names(tmp_path: Path, nodes: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["init", str(tmp_path / "w"), "--nodes", nodes]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"{tmp_path / 'w'}: error: ") and "Traceback" not in err
    assert not (tmp_path / "w").exists()


def test_chain_links_each_output_to_the_next_input() -> None:
    a, b = plan_nodes(["RadiationSensor", "Agent"])
    assert (a.input, a.output, a.file) == ("reading", "radiation_sensor_value", "contracts/radiation_sensor.rcl")
    assert (b.input, b.producer, a.consumer) == (a.output, "RadiationSensor", "Agent")
