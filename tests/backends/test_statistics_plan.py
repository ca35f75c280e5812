"""Targets in the plan over monitored runs (issue 68; docs/statistics.md): small workspaces whose run files are
written here, checked by the monitors backend through the plan's entries."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.backend import MonitorsBackend
from rclverify.cli.commands import main
from rclverify.model.plan.errors import PlanError
from rclverify.stages.workspace import Workspace

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
    """One run of Clamp: three questions and their answers (the last 31 when ``bad``); ``k`` makes it unique
    (its values: a run's identity takes its times relative to its first, so a later start alone is no new run)."""
    t0 = 1000.0 + k
    lines = []
    for j, x in enumerate([5.0, 31.0 if bad else 20.0]):
        lines.append({"topic": "a", "time": t0 + 0.1 * j, "data": float(j + k)})
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


def test_100_runs_fall_short_with_the_runs_still_needed_and_one_violation_among_1000_answers(tmp_path: Path) -> None:
    ws = _ws(tmp_path / "a", [], {"runs": [False] * 100})
    (tmp_path / "a/contracts/plan.yaml").write_text(json.dumps({"contracts": ["contracts/sys.rcl"], "nodes": {
        "Clamp": {"evidence": [_entry(tmp_path / "a", "runs")]}}}))
    _, ev, _ = _runset(Workspace(tmp_path / "a"))
    d = ev.details["statistics"]["decision"]
    assert ev.status == "pending" and d["runs_needed"] == 199 and "199 further clean run(s)" in ev.explanation
    assert d["sprt"]["decision"] == "continue"
    # one violation among 1000 judged answers, counted per answer: one long run of 1000 questions
    lines = []
    for j in range(1000):
        lines.append({"topic": "a", "time": 5000.0 + 0.1 * j, "data": 1.0})
        lines.append({"topic": "x", "time": 5000.0 + 0.1 * j + 0.01, "data": 31.0 if j == 417 else 20.0})
    _ws(tmp_path / "b", [], {"long": []})
    (tmp_path / "b/long/run.jsonl").write_text("".join(json.dumps(x) + "\n" for x in lines))
    entry = {"backend": "monitors", "traces": ["long/run.jsonl"],
             "target": "violation probability <= 1e-2 at 95 % per answer"}
    (tmp_path / "b/contracts/plan.yaml").write_text(json.dumps({"contracts": ["contracts/sys.rcl"], "nodes": {
        "Clamp": {"evidence": [entry]}}}))
    ws = Workspace(tmp_path / "b")
    _, ev, obligations = _runset(ws)
    s = ev.details["statistics"]
    assert ev.status == "discharged", ev.explanation
    assert (s["counts"]["runs"], s["counts"]["answers"], s["counts"]["violations"]) == (1, 1000, 1)
    assert s["decision"]["bound"] == pytest.approx(0.004735, abs=1e-6)
    # the run's own record still fails: a violation is counter-evidence for the guarantee itself
    (own,) = [o for o in obligations if o.data.get("run_set") is None]
    assert MonitorsBackend().run(own, ws.target("Clamp", 0)).status == "failed"


def test_two_environments_are_kept_apart_and_a_run_given_twice_counts_once(tmp_path: Path) -> None:
    _ws(tmp_path, [], {"day": [False] * 60, "rain": [False] * 20})
    rain = _traces(tmp_path, "rain")
    (tmp_path / "rain/copy.jsonl").write_bytes((tmp_path / rain[0]).read_bytes())  # the same run under another name
    five = "violation probability <= 5 % at 95 % per run"  # 59 clean runs meet it: the day's do, the rain's do not
    entries = [_entry(tmp_path, "day", environment="day", target=five),
               {**_entry(tmp_path, "rain", environment="rain", target=five), "traces": rain + ["rain/copy.jsonl"]}]
    (tmp_path / "contracts/plan.yaml").write_text(json.dumps({"contracts": ["contracts/sys.rcl"],
                                                              "nodes": {"Clamp": {"evidence": entries}}}))
    ws = Workspace(tmp_path)
    _, day, _ = _runset(ws, 0)
    _, wet, _ = _runset(ws, 1)
    assert day.status == "discharged" and day.details["statistics"]["counts"]["runs"] == 60
    c = wet.details["statistics"]["counts"]
    assert wet.status == "pending" and (c["runs"], c["duplicates"]) == (20, 1)
    assert "repeat a run already counted" in wet.explanation


def test_harness_runs_never_count_and_bad_targets_are_located(tmp_path: Path) -> None:
    _ws(tmp_path, [], {"runs": [False] * 5})
    (tmp_path / "contracts/plan.yaml").write_text(json.dumps({"contracts": ["contracts/sys.rcl"], "nodes": {
        "Clamp": {"evidence": [_entry(tmp_path, "runs", origin="harness")]}}}))
    _, ev, _ = _runset(Workspace(tmp_path))
    assert ev.status == "pending" and ev.details["statistics"]["counts"]["runs"] == 0 and "not operation" in ev.explanation
    (tmp_path / "contracts/plan.yaml").write_text(json.dumps({"contracts": ["contracts/sys.rcl"], "nodes": {
        "Clamp": {"evidence": [{"backend": "monitors", "traces": [], "target": TARGET}]}}}))
    target = Workspace(tmp_path).target("Clamp", 0)
    (ob,) = MonitorsBackend().export(target)  # a target without runs: its obligation, pending, never dropped
    ev = MonitorsBackend().run(ob, target)
    assert ev.status == "pending" and "no judged run yet: 299 clean run(s)" in ev.explanation
    assert ob.source.file == "contracts/sys.rcl"
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


def test_an_experiment_target_counts_trials_and_leaves_the_criterion_alone(tmp_path: Path) -> None:
    from rclverify.backends.experiment.backend import ExperimentBackend
    _ws(tmp_path, [], {})
    rows = [18.0] * 120
    rows[33] = 27.0  # one trial beyond the tolerance
    (tmp_path / "trials.csv").write_text("trial,err\n" + "".join(f"{i},{v}\n" for i, v in enumerate(rows, 1)))
    entry = {"backend": "experiment", "guarantee": 1, "data": "trials.csv", "column": "err", "unit": "cm",
             "constants": {"tol": "25 cm"}, "criterion": "err <= tol", "answers": "out.x <= 30",
             "environment": "track", "target": "violation probability <= 5 % at 95 %"}
    (tmp_path / "contracts/plan.yaml").write_text(json.dumps({"contracts": ["contracts/sys.rcl"],
                                                              "nodes": {"Clamp": {"evidence": [entry]}}}))
    target, backend = Workspace(tmp_path).target("Clamp", 0), ExperimentBackend()
    criterion, stat = backend.export(target)
    assert stat.id == "Clamp.g1.experiment.e0_target" and "under track" in stat.statement
    assert backend.run(criterion, target).status == "failed"  # trial 34 misses the criterion: a counterexample
    ev = backend.run(stat, target)
    c = ev.details["statistics"]["counts"]
    assert (c["runs"], c["violating_runs"]) == (120, 1) and ev.details["statistics"]["failing_trials"] == [34]
    # 1 of 120 gives an upper bound of 3.9 %: within 5 %
    assert ev.status == "discharged" and ev.details["statistics"]["decision"]["bound"] == pytest.approx(0.0389, abs=1e-3)


def test_the_live_monitor_counts_as_it_goes_and_its_log_counts_as_a_live_run(tmp_path: Path) -> None:
    from rclverify.backends.monitors.config import load_mapping
    from rclverify.runtime.live import LiveRun
    ws = _ws(tmp_path, [], {})
    cfg = load_mapping(tmp_path, None, 1.0)
    log = tmp_path / "live/run.jsonl"
    live = LiveRun(ws.checked, [ws.checked.nodes["Clamp"]], cfg.rules, cfg.horizon, log, reorder_window=0.0)
    for j in range(40):
        t = 1.0 + 0.1 * j
        live.tick(t)
        live.push("a", {"data": 1.0}, t)
        live.push("x", {"data": 20.0}, t + 0.01)
        if j == 19:  # half way: the counts so far, and their bound
            assert "answer(s) counted, 95 % bound" in live.status_line()
    live.tick(6.0)
    record = live.stop()
    (node,) = record["nodes"]
    s = node["statistics"]
    assert (s["recorded"], s["answers"], s["violations"]) == ("live", 40, 0) and s["sha256"] == record["sha256"]
    assert "40 answer(s) counted, 95 % bound 0.0722 per answer" in live.status_line()
    # the log in the plan: recorded live, counted once however often it is named
    (tmp_path / "live/again.jsonl").write_bytes(log.read_bytes())
    entry = {"backend": "monitors", "traces": ["live/run.jsonl", "live/again.jsonl"], "environment": "lab",
             "target": "violation probability <= 1e-1 at 95 % per answer"}
    (tmp_path / "contracts/plan.yaml").write_text(json.dumps({"contracts": ["contracts/sys.rcl"],
                                                              "nodes": {"Clamp": {"evidence": [entry]}}}))
    _, ev, _ = _runset(Workspace(tmp_path))
    st = ev.details["statistics"]
    assert ev.status == "discharged" and st["counts"]["runs"] == 1 and st["counts"]["duplicates"] == 1
    assert {r["recorded"] for r in st["runs"]} == {"live"} and st["counts"]["answers"] == 40


def test_every_bad_key_of_a_counting_entry_is_one_located_error(tmp_path: Path) -> None:
    _ws(tmp_path, [], {})
    (tmp_path / "contracts/plan.yaml").write_text(
        "contracts: [contracts/sys.rcl]\nnodes:\n  Clamp:\n    evidence:\n      - backend: monitors\n"
        "        target: 0.05\n        environment: two words\n        origin: field\n")
    with pytest.raises(PlanError) as exc:
        _ = Workspace(tmp_path).checked
    text = str(exc.value)
    assert "plan.yaml:6:17: error: a target is a text such as" in text and "not 0.05" in text
    assert "plan.yaml:7:22: error: an environment tag is a name" in text
    assert "plan.yaml:8:17: error: a run set's origin is one of operation, simulation, harness, not 'field'" in text


def test_a_target_of_one_guarantee_counts_that_guarantee_alone(tmp_path: Path) -> None:
    _ws(tmp_path, [], {})
    (tmp_path / "contracts/sys.rcl").write_text(RCL.replace("guarantee( out.x <= 30 )",
                                                            "guarantee( out.x <= 30 )\n  guarantee( out.x >= 0 )"))
    (tmp_path / "runs").mkdir()
    for i in range(60):
        lines = [{"topic": "a", "time": 10.0 + i, "data": 1.0 + i},  # its own value: a run of its own
                 {"topic": "x", "time": 10.01 + i, "data": -1.0 if i == 7 else 5.0}]  # run 7 breaks guarantee 2
        (tmp_path / f"runs/r{i:02d}.jsonl").write_text("".join(json.dumps(x) + "\n" for x in lines))
    traces = _traces(tmp_path, "runs")
    five = "violation probability <= 5 % at 95 % per run"
    entries = [{"backend": "monitors", "traces": traces, "environment": "e", "target": f"{five} of guarantee 1"},
               {"backend": "monitors", "traces": traces, "environment": "f", "target": f"{five} of guarantee 2"}]
    (tmp_path / "contracts/plan.yaml").write_text(json.dumps({"contracts": ["contracts/sys.rcl"],
                                                              "nodes": {"Clamp": {"evidence": entries}}}))
    ws = Workspace(tmp_path)
    one, ev1, _ = _runset(ws, 0)
    two, ev2, _ = _runset(ws, 1)
    assert (one.id, one.guarantee, two.id) == ("Clamp.g1.monitors.runs_e_e0", 1, "Clamp.g2.monitors.runs_f_e1")
    assert ev1.status == "discharged" and ev1.details["statistics"]["decision"]["k"] == 0
    assert ev2.status == "pending" and ev2.details["statistics"]["decision"]["k"] == 1
    entries[0]["target"] = f"{five} of guarantee 3"
    (tmp_path / "contracts/plan.yaml").write_text(json.dumps({"contracts": ["contracts/sys.rcl"],
                                                              "nodes": {"Clamp": {"evidence": entries}}}))
    with pytest.raises(PlanError, match="Clamp has 2 guarantee.s.; there is no guarantee 3"):
        _ = Workspace(tmp_path).checked
