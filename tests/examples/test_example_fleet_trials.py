"""examples/fleet_trials (issue 68; docs/statistics.md): two run sets of the speed governor, each with an
environment tag and a target; verified on a copy, with what the report, the confidence and the argument say."""
from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from rclverify.cli.commands import main

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "fleet_trials"


@pytest.fixture(scope="module")
def ws(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("fleet") / "fleet_trials"
    shutil.copytree(EXAMPLE, root, ignore=shutil.ignore_patterns("artifacts", "reports", ".doit*", "__pycache__"))
    assert main(["verify", "-w", str(root)]) == 0  # pending, not failed: the night's runs fall short
    return root


def _report(ws: Path) -> dict[str, Any]:
    return json.loads((ws / "reports/assurance.json").read_text())


def test_the_day_meets_the_target_and_the_night_says_how_many_runs_it_needs(ws: Path) -> None:
    r = _report(ws)
    targets = {s["environment"]: s for s in r["statistics"] if s["kind"] == "target"}
    day, night = targets["warehouse_day"], targets["loading_dock_night"]
    assert day["status"] == "discharged" and day["counts"]["runs"] == 60
    assert day["bound"] == pytest.approx(1 - 0.05 ** (1 / 60))
    assert night["status"] == "pending" and night["counts"]["runs"] == 25
    assert (night["runs_needed"], night["sprt"]) == (34, "continue")
    groups = {s["environment"]: s for s in r["statistics"] if s["kind"] == "runs"}
    assert set(groups) == {"warehouse_day", "loading_dock_night", "lab_bench"}  # never one bound over two tags
    assert groups["warehouse_day"]["recorded"] == {"log": 60} and groups["warehouse_day"]["origin"] == "simulation"
    bench = groups["lab_bench"]  # recorded live from real ROS 2 nodes (record_live.py): operation, no target
    assert (bench["recorded"], bench["origin"], bench["counts"]["answers"]) == ({"live": 10}, "operation", 200)
    assert bench["bound"] == pytest.approx(1 - 0.05 ** (1 / 10))
    run = next(e for e in r["evidence"] if e["obligation"].endswith("lab_bench_003_jsonl"))
    assert run["strength"]["kind"] == "observed" and run["strength"]["doubt"] == pytest.approx(bench["bound"])
    (g1,) = [g for n in r["nodes"] for g in n["guarantees"]]
    assert g1["strength"]["kind"] == "statistical" and g1["strength"]["doubt"] == pytest.approx(day["bound"])
    (req,) = r["requirements"]
    assert {s["environment"]: s["status"] for s in req["statistics"]} == {
        "warehouse_day": "discharged", "loading_dock_night": "pending", "lab_bench": "pending"}
    md = (ws / "reports/assurance.md").read_text()
    assert "### Runs counted and statistical guarantees" in md and "34 further clean run(s) needed" in md


def test_the_argument_has_a_target_goal_per_environment(ws: Path) -> None:
    a = json.loads((ws / "reports/argument.json").read_text())
    el = {e["id"]: e for e in a["elements"]}
    assert el["G-FLEET-SPEED.target.warehouse_day"]["status"] == "discharged"
    assert el["G-FLEET-SPEED.target.loading_dock_night"]["status"] == "pending"
    assert "J-statistics" in el["G-FLEET-SPEED.target.warehouse_day"]["in_context_of"]
    assert el["G-FLEET-SPEED"]["status"] == "pending"


def test_the_simulation_writes_the_committed_runs(tmp_path: Path) -> None:
    subprocess.run([sys.executable, str(EXAMPLE / "simulate_runs.py"), str(tmp_path)], check=True,
                   capture_output=True)
    for env in ("warehouse_day", "loading_dock_night"):
        ours = sorted(p.name for p in (EXAMPLE / "runs" / env).iterdir())
        assert ours == sorted(p.name for p in (tmp_path / env).iterdir())
        assert all((EXAMPLE / "runs" / env / n).read_bytes() == (tmp_path / env / n).read_bytes() for n in ours)


def test_an_edited_run_is_not_counted_until_checked_again(ws: Path) -> None:
    """Last in this module: it edits a run of the copy.  The report reads that run's record as stale: its counts
    leave the group's bound and the run set's record is stale too."""
    run = ws / "runs/warehouse_day/warehouse_day_007.jsonl"
    run.write_text(run.read_text() + '{"topic": "requested", "time": 1800007000.0, "data": 0.5}\n')
    assert main(["report", "-w", str(ws)]) == 0
    r = _report(ws)
    day = next(s for s in r["statistics"] if s["kind"] == "runs" and s["environment"] == "warehouse_day")
    assert day["counts"]["runs"] == 59
    target = next(s for s in r["statistics"] if s["kind"] == "target" and s["environment"] == "warehouse_day")
    assert target["status"] == "stale"


def test_the_report_matches_the_published_schema(ws: Path) -> None:
    """The statistics rows and the rest of the report against docs/assurance.schema.json and the status
    vocabulary (tests/_report_schema.py)."""
    from _report_schema import check_report
    check_report(_report(ws), "fleet_trials")
