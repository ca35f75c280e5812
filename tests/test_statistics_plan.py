"""Targets in the plan over monitored runs (issue 68; docs/statistics.md): small workspaces whose run files are
written here, checked by the monitors backend through the plan's entries."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.backend import MonitorsBackend
from rclverify.cli import main
from rclverify.plan.errors import PlanError
from rclverify.workspace import Workspace

RCL = """
node Clamp {
  inputs( a : REAL )
  outputs( x : REAL )
  topics( std_msgs/Float64 a matches(in.a), std_msgs/Float64 x matches(out.x) )
  assume( in.a >= 0 )
  guarantee( out.x <= 30 )
}
"""
TARGET = "violation probability <= 1e-2 at 95 % per run"


def _run(path: Path, k: int, bad: bool = False) -> str:
    """One run of Clamp: three questions and their answers (the last 31 when ``bad``); ``k`` makes it unique."""
    t0 = 1000.0 + k
    lines = []
    for j, x in enumerate([5.0, 31.0 if bad else 20.0]):
        lines.append({"topic": "a", "time": t0 + 0.1 * j, "data": float(j + k % 7)})
        lines.append({"topic": "x", "time": t0 + 0.1 * j + 0.01, "data": x})
    path.write_text("".join(json.dumps(x) + "\n" for x in lines))
    return path.as_posix()


def _ws(tmp: Path, entries: list[dict[str, Any]], runs: dict[str, list[bool]]) -> Workspace:
    """A workspace with the ``runs`` (folder -> one flag per run: violates) and the plan ``entries``."""
    (tmp / "contracts").mkdir(parents=True, exist_ok=True)
    (tmp / "contracts/sys.rcl").write_text(RCL)
    k = 0
    for folder, flags in runs.items():
        (tmp / folder).mkdir(parents=True, exist_ok=True)
        for i, bad in enumerate(flags):
            _run(tmp / folder / f"run{i:04d}.jsonl", k, bad)
            k += 1
    (tmp / "contracts/plan.yaml").write_text(json.dumps({"contracts": ["contracts/sys.rcl"],
                                                         "nodes": {"Clamp": {"evidence": entries}}}))
    return Workspace(tmp)


def _traces(tmp: Path, folder: str) -> list[str]:
    return sorted(p.relative_to(tmp).as_posix() for p in (tmp / folder).glob("*.jsonl"))


def _runset(ws: Workspace, index: int = 0) -> tuple[Any, Any, list[Any]]:
    """The run-set obligation of entry ``index``, its evidence and the entry's obligations."""
    target = ws.target("Clamp", index)
    backend = MonitorsBackend()
    obligations = backend.export(target)
    (ob,) = [o for o in obligations if o.data.get("run_set") is not None]
    assert len(obligations) == len(ob.data["run_set"]) + 1  # every run keeps its own obligation
    return ob, backend.run(ob, target), obligations


def _entry(tmp: Path, folder: str, **kw: Any) -> dict[str, Any]:
    return {"backend": "monitors", "traces": _traces(tmp, folder), "target": TARGET, **kw}


def test_299_clean_runs_meet_a_one_percent_target_at_95(tmp_path: Path) -> None:
    ws = _ws(tmp_path, [], {"runs": [False] * 299})
    (tmp_path / "contracts/plan.yaml").write_text(json.dumps({"contracts": ["contracts/sys.rcl"], "nodes": {
        "Clamp": {"evidence": [_entry(tmp_path, "runs", environment="lab")]}}}))
    ob, ev, _ = _runset(Workspace(tmp_path))
    s = ev.details["statistics"]
    assert ev.status == "discharged", ev.explanation
    assert (s["counts"]["runs"], s["counts"]["answers"], s["counts"]["violating_runs"]) == (299, 598, 0)
    assert s["decision"]["bound"] <= 0.01 and s["environment"] == "lab"
    assert s["counts"]["seconds"] == pytest.approx(299 * 0.11)
    assert {r["recorded"] for r in s["runs"]} == {"log"}
    assert ob.id == "Clamp.g0.monitors.runs_lab_e0"


def test_100_runs_fall_short_with_the_runs_still_needed_and_a_violation_among_1000(tmp_path: Path) -> None:
    ws = _ws(tmp_path / "a", [], {"runs": [False] * 100})
    (tmp_path / "a/contracts/plan.yaml").write_text(json.dumps({"contracts": ["contracts/sys.rcl"], "nodes": {
        "Clamp": {"evidence": [_entry(tmp_path / "a", "runs")]}}}))
    _, ev, _ = _runset(Workspace(tmp_path / "a"))
    d = ev.details["statistics"]["decision"]
    assert ev.status == "pending" and d["runs_needed"] == 199 and "199 further clean run(s)" in ev.explanation
    assert d["sprt"]["decision"] == "continue"
    flags = [False] * 1000
    flags[417] = True
    _ws(tmp_path / "b", [], {"runs": flags})
    (tmp_path / "b/contracts/plan.yaml").write_text(json.dumps({"contracts": ["contracts/sys.rcl"], "nodes": {
        "Clamp": {"evidence": [_entry(tmp_path / "b", "runs")]}}}))
    ws = Workspace(tmp_path / "b")
    _, ev, obligations = _runset(ws)
    s = ev.details["statistics"]
    assert ev.status == "discharged" and (s["counts"]["runs"], s["counts"]["violating_runs"]) == (1000, 1)
    assert s["decision"]["bound"] == pytest.approx(0.004735, abs=1e-6)
    # the violating run's own record still fails: counter-evidence for the guarantee itself
    bad = [o for o in obligations if o.data.get("trace", "").endswith("run0417.jsonl")]
    assert MonitorsBackend().run(bad[0], ws.target("Clamp", 0)).status == "failed"


def test_two_environments_are_kept_apart_and_a_run_given_twice_counts_once(tmp_path: Path) -> None:
    _ws(tmp_path, [], {"day": [False] * 300, "rain": [False] * 20})
    rain = _traces(tmp_path, "rain")
    (tmp_path / "rain/copy.jsonl").write_bytes((tmp_path / rain[0]).read_bytes())  # the same run under another name
    entries = [_entry(tmp_path, "day", environment="day"),
               {**_entry(tmp_path, "rain", environment="rain"), "traces": rain + ["rain/copy.jsonl"]}]
    (tmp_path / "contracts/plan.yaml").write_text(json.dumps({"contracts": ["contracts/sys.rcl"],
                                                              "nodes": {"Clamp": {"evidence": entries}}}))
    ws = Workspace(tmp_path)
    _, day, _ = _runset(ws, 0)
    _, wet, _ = _runset(ws, 1)
    assert day.status == "discharged" and day.details["statistics"]["counts"]["runs"] == 300
    c = wet.details["statistics"]["counts"]
    assert wet.status == "pending" and (c["runs"], c["duplicates"]) == (20, 1)
    assert "repeat a run already counted" in wet.explanation


def test_harness_runs_never_count_and_bad_targets_are_located(tmp_path: Path) -> None:
    _ws(tmp_path, [], {"runs": [False] * 5})
    (tmp_path / "contracts/plan.yaml").write_text(json.dumps({"contracts": ["contracts/sys.rcl"], "nodes": {
        "Clamp": {"evidence": [_entry(tmp_path, "runs", origin="harness")]}}}))
    _, ev, _ = _runset(Workspace(tmp_path))
    assert ev.status == "pending" and ev.details["statistics"]["counts"]["runs"] == 0 and "not operation" in ev.explanation
    plan = (f"contracts: [contracts/sys.rcl]\nnodes:\n  Clamp:\n    evidence:\n      - backend: monitors\n"
            f"        traces: [runs/run0000.jsonl]\n        target: violation probability <= 2 at 95 %\n"
            f"        environment: day\n")
    (tmp_path / "contracts/plan.yaml").write_text(plan)
    with pytest.raises(PlanError, match=r"plan.yaml:7:17: error: .*between 0 and 1"):
        _ = Workspace(tmp_path).checked
    (tmp_path / "contracts/plan.yaml").write_text(
        "contracts: [contracts/sys.rcl]\nrequirements:\n  - id: R1\n    text: t\n"
        "    target: violation probability <= 1e-3 at 95 % per answer\n")
    with pytest.raises(PlanError, match=r"plan.yaml:5:13: error: a requirement's target counts per run"):
        _ = Workspace(tmp_path).plan
