"""The warehouse example (examples/warehouse, docs/warehouse.md): the advice is right.

A seven-node warehouse robot with five seeded defects.  The pipeline runs
once on a copy of the seeded workspace, then once per fix of
``examples/warehouse/fixes/`` applied to the copy (``git apply``; the run
rebuilt from the fixed node code by the simulator ``nodes/record_run.py``,
no ROS 2 needed; the previous fix undone first), then with all five applied: each run is an
incremental ``doit`` run of the same copy, which must equal a clean one
(docs/integrity.md).  About 17 s of CPU in all: seven pipeline runs, six of
them incremental.

(a) each defect is its own problem row with the right culprit and a safe
    first repair, which is the edit the fix makes;
(b) each fix removes its row and no row appears;
(c) the recorded run raises no false alarm: no node's run is failed, the
    node computing ``1000 * range`` is discharged (exactly on the committed
    run, whose ``sensor_msgs/Range`` carries a float32; in double arithmetic
    on the simulator's ``1.2``), the Twist's ``linear.x`` is read, and a
    service response outside the client's assumption is caught, blamed on
    the server through the service;
(e) the committed run is the live monitor's recording of real rclpy nodes
    (``nodes/record_live.py``; checked, not recorded again): the plan's
    trace is what ``trace_of`` makes of the monitor's log, and its messages
    are the simulator's, in the same order but for same-time ties, up to
    the float32 of the ranges.
(d) with all five fixed, no problem row is left and ``--strict`` passes:
    ARRIVE is met, its proof needing none of the three ``initially``
    declarations (traced, not needed: no run can show them, each node's
    first message answering an input), every progress declaration judged
    on the run, and the Planner's initial result, which the node holds,
    shown true by its property tests.
Real Z3, Hypothesis and doit; nothing of the example is edited in place.
"""
from __future__ import annotations

import importlib.util
import json
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from _example_report import changed as _changed, diag as _diag, first_repair as _first_repair, monitoring, \
    rows as _rows, verify as _verify

from rclverify.cli.commands import main

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "warehouse"
FIXES = sorted((EXAMPLE / "fixes").glob("*.diff"))
#: The row each fix removes (its root-cause key in reports/assurance.json's ``problems``).
ROWS = {
    "01-deadline.diff": ("deadline:STOP",),
    "02-service-range.diff": ("assumption:Controller:3", "guarantee:Base:2"),
    "03-progress.diff": ("contract:Planner",),
    "04-threshold.diff": ("guarantee:BatteryMonitor:1",),
    "05-millimetres.diff": ("assumption:Controller:1", "guarantee:LidarDriver:1"),
}
#: The derived properties of Controller and Base, not derived while either side condition fails: one
#: row behind both, which either fix empties into the other's row.
DERIVED = ("assumption:Controller:1", "assumption:Controller:3", "guarantee:Base:2", "guarantee:LidarDriver:1")


def _record(ws: Path) -> None:
    """Record the run again from the node code as it now is (a subprocess: the node modules are
    imported afresh)."""
    subprocess.run([sys.executable, "nodes/record_run.py"], cwd=ws, check=True, capture_output=True, timeout=60)


def _apply(ws: Path, diff: Path, reverse: bool = False) -> None:
    subprocess.run(["git", "apply", *(["-R"] if reverse else []), str(diff)], cwd=ws, check=True,
                   capture_output=True, timeout=60)
    _record(ws)


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    ws = tmp_path_factory.mktemp("warehouse") / "ws"
    shutil.copytree(EXAMPLE, ws, ignore=shutil.ignore_patterns("artifacts", "reports", ".doit*", "__pycache__",
                                                               ".ros2"))
    out: dict[str, Any] = {"ws": ws}
    out["seeded"] = _verify(ws)[1]  # on the committed run, recorded live
    _record(ws)
    out["simulated"] = _lines(ws / "backends/monitors/traces/run.jsonl")
    for diff in FIXES:
        _apply(ws, diff)
        out[diff.name] = _verify(ws)[1]
        _apply(ws, diff, reverse=True)
    for diff in FIXES:
        _apply(ws, diff)
    out["strict"] = _verify(ws, "--strict")
    return out


def _lines(path: Path) -> list[dict[str, Any]]:
    return [json.loads(x) for x in path.read_text(encoding="utf-8").splitlines() if x.strip()]


def test_the_example_is_as_shipped(runs: dict[str, Any]) -> None:
    """Every fix is a patch of the seeded files."""
    assert [f.name for f in FIXES] == sorted(ROWS)


def _values(line: dict[str, Any]) -> list[Any]:
    """The values a line carries for the plan, whatever else its message has (a Range's header)."""
    if line["topic"] == "scan":
        return [line["range"]]
    if "linear" in line:
        return [line["linear"]["x"]]
    body = {k: v for k, v in line.items() if k not in ("topic", "time")}
    return [v for b in body.values() for v in (b.values() if isinstance(b, dict) else [b])]


def test_the_committed_run_was_recorded_live_from_rclpy_nodes(runs: dict[str, Any]) -> None:
    spec = importlib.util.spec_from_file_location("warehouse_record_live", EXAMPLE / "nodes" / "record_live.py")
    assert spec is not None and spec.loader is not None
    record_live = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(record_live)
    log = _lines(EXAMPLE / "backends/monitors/live/monitor.jsonl")
    trace = _lines(EXAMPLE / "backends/monitors/traces/run.jsonl")
    # the monitor's log: its verdicts, the calls it paired, wall-clock receive times
    verdicts = [x["verdict"] for x in log if x["topic"] == "rclverify/verdict"]
    calls = [x for x in log if x["topic"] == "rclverify/call" and "index" in x]
    assert len(verdicts) >= 40 and {c["link"] for c in calls} == {"get_limits", "navigate"} and len(calls) == 14
    assert all(x["time"] > 1.6e9 for x in log)
    assert not any(v["verdict"] == "violated" for v in verdicts)
    # the plan's trace is the program's reading of that log, nothing edited
    assert trace == json.loads(json.dumps(record_live.trace_of(log, record_live.ACTIONS)))
    # the simulator's messages, same topics and values (float32 ranges), same order but for same-time ties
    sim = runs["simulated"]
    assert sorted(x["topic"] for x in trace) == sorted(x["topic"] for x in sim) and len(trace) == 62
    for topic in {x["topic"] for x in sim}:
        live_values = [v for x in trace if x["topic"] == topic for v in _values(x)]
        sim_values = [v for x in sim if x["topic"] == topic for v in _values(x)]
        assert len(live_values) == len(sim_values) and all(
            a == b if isinstance(b, bool) else abs(a - b) <= 1e-7 * abs(b) for a, b in zip(live_values, sim_values)), \
            (topic, live_values, sim_values)
    # each node waited its latency: the odometry 40 ms after each velocity command at least
    cmd, odom = ([x["time"] for x in trace if x["topic"] == t] for t in ("cmd_vel", "odom"))
    assert len(cmd) == len(odom) == 7 and all(0.040 <= b - a < 0.1 for a, b in zip(cmd, odom))


def test_each_defect_is_its_own_row_with_the_right_culprit(runs: dict[str, Any]) -> None:
    report = runs["seeded"]
    rows = _rows(report)
    assert set(rows) == {*ROWS.values(), DERIVED}
    members = {k: [m["id"] for m in g["members"]] for k, g in rows.items()}
    culprits = {k: [(c["what"], c["source"]) for c in g["culprits"]] for k, g in rows.items()}
    # (1) the deadline: its chain's hops, each with its bound, and the budget in the sentence
    assert members[ROWS["01-deadline.diff"]] == ["STOP.deadline", "STOP"]
    assert culprits[ROWS["01-deadline.diff"]] == [
        ("guarantee 1 of LidarDriver: within 20 ms", "contracts/lidar_driver.rcl:15:3"),
        ("guarantee 1 of Controller: within 50 ms", "contracts/controller.rcl:22:3"),
        ("guarantee 1 of Base: within 100 ms", "contracts/base.rcl:16:3")]
    assert "sums to 170 ms, 20 ms over the budget" in _diag(report, "STOP.deadline")["sentence"]
    # (2) the service: the server's response guarantee and the client's assumption on the response
    assert members[ROWS["02-service-range.diff"]] == ["Controller.sc6"]
    assert culprits[ROWS["02-service-range.diff"]] == [("guarantee 2 of Base", "contracts/base.rcl:19:3"),
                                                        ("assumption 3 of Controller", "contracts/controller.rcl:20:3")]
    # (3) liveness: the node that should answer (Planner), not the one whose input the goal reads
    assert members[ROWS["03-progress.diff"]] == ["ARRIVE"]
    assert culprits[ROWS["03-progress.diff"]] == [("the contract of Planner", "contracts/planner.rcl:8:1")]
    assert "Planner never answers in the loop" in _diag(report, "ARRIVE")["sentence"]
    # (4) the off-by-one: the threshold guarantee
    assert members[ROWS["04-threshold.diff"]] == ["DOCK"]
    assert culprits[ROWS["04-threshold.diff"]] == [("guarantee 1 of BatteryMonitor",
                                                    "contracts/battery_monitor.rcl:14:3")]
    # (5) millimetres: the producer's scale, and the probable scale mismatch without declared units
    # the Controller's run, whose assumption the millimetres violate (blamed on LidarDriver): a consequence (issue 64)
    assert members[ROWS["05-millimetres.diff"]] == ["Controller.sc2", "Controller.g0.monitors.run_jsonl"]
    assert ("guarantee 1 of LidarDriver", "contracts/lidar_driver.rcl:15:3") in culprits[ROWS["05-millimetres.diff"]]
    [scale] = [f for f in report["findings"] if f["check"] == "probable-scale-mismatch"]
    assert (scale["id"], scale["status"]) == ("Controller.sc2.scale", "warning")
    assert "a factor of 1000" in scale["message"] and "LidarDriver.out.obstacle ranges over [0, 30000]" in scale["message"]
    # the derived properties: one row behind both failed side conditions
    assert members[DERIVED] == ["Base.derived", "Controller.derived"]


def test_each_first_repair_is_safe_and_is_what_the_fix_does(runs: dict[str, Any]) -> None:
    """The first repair of every row: never a widened consumer assumption, never a coefficient
    rewritten as a bound; each checked by Z3; and its changed lines are the fix's."""
    report = runs["seeded"]
    first = {name: _first_repair(report, key) for name, key in ROWS.items()}
    assert {n: r["kind"] for n, r in first.items()} == {
        "01-deadline.diff": "tighten-hop", "02-service-range.diff": "strengthen-producer",
        "03-progress.diff": "declare-progress", "04-threshold.diff": "move-threshold",
        "05-millimetres.diff": "rescale-producer"}
    assert (first["01-deadline.diff"]["edit"]["deleted"], first["01-deadline.diff"]["edit"]["inserted"]) == \
        ("within 100 ms", "within 80 ms")
    assert (first["02-service-range.diff"]["edit"]["deleted"], first["02-service-range.diff"]["edit"]["inserted"]) == \
        ("2.0", "1.5")
    assert first["03-progress.diff"]["edit"]["inserted"] == "  progress( within 3 steps )\n"
    assert (first["04-threshold.diff"]["edit"]["deleted"], first["04-threshold.diff"]["edit"]["inserted"]) == ("<", "<=")
    assert (first["05-millimetres.diff"]["edit"]["deleted"], first["05-millimetres.diff"]["edit"]["inserted"]) == \
        ("1000 * in.range", "in.range")
    assert "unit conversion, not a bound" in first["05-millimetres.diff"]["summary"]
    for name, rep in first.items():
        assert rep["checked_by"].startswith("z3") and rep["proves"] and rep["not_shown"]
        fix = (EXAMPLE / "fixes" / name).read_text(encoding="utf-8")
        assert all(line in _changed(fix) for line in _changed(rep["diff"])), (name, rep["diff"])
    for g in report["problems"]:
        reps = [_diag(report, r["diagnosis"])["repairs"][r["index"]] for r in g["repairs"]]
        assert not reps or reps[0]["kind"] != "weaken-consumer"
        for r in reps:  # a coefficient or a scale factor is never rewritten as a bound
            assert not (r["kind"] == "tighten-bound" and r["edit"]["deleted"] == "1000")
    # the widened assumption comes last, said to be probably unsafe, naming what it invalidates
    mm = _diag(report, "Controller.sc2")["repairs"]
    assert mm[-1]["kind"] == "weaken-consumer" and "Probably unsafe" in mm[-1]["summary"]
    assert "must be established again" in mm[-1]["summary"]


@pytest.mark.parametrize("name", sorted(ROWS))
def test_each_fix_removes_its_row_and_no_other_appears(runs: dict[str, Any], name: str) -> None:
    before, after = set(_rows(runs["seeded"])), set(_rows(runs[name]))
    assert ROWS[name] in before and ROWS[name] not in after
    assert after <= before, after - before
    # only its own row goes, and the derived properties' row when one of its two side conditions is fixed
    assert before - after == {ROWS[name]} | ({DERIVED} if name in ("02-service-range.diff", "05-millimetres.diff")
                                              else set())


def test_the_recorded_run_raises_no_false_alarm(runs: dict[str, Any]) -> None:
    report = runs["seeded"]
    nodes = ["LidarDriver", "Localiser", "BatteryMonitor", "MissionManager", "Planner", "Controller", "Base"]
    for node in nodes:
        m = _monitoring(report, node)
        assert m["counts"]["violated"] == 0 and m["status"] != "failed", (node, m)
    # the recorded sensor_msgs/Range carries a float32: 1000 * range is exact in double, satisfied exactly
    lidar = _monitoring(report, "LidarDriver")
    assert lidar["status"] == "discharged" and lidar["counts"]["satisfied"] == 4
    assert not lidar["semantics"].get("double") and not lidar.get("first_inexact"), lidar
    # the simulator's 1.2 (fix 1 alone leaves the driver as seeded): 1000 * 1.2 published as 1200.0,
    # satisfied in the node's double arithmetic, said so
    lidar = _monitoring(runs["01-deadline.diff"], "LidarDriver")
    assert lidar["status"] == "discharged" and lidar["semantics"]["double"] >= 1
    inexact = lidar["first_inexact"]
    assert inexact["values"] == {"in.range": "1.2", "out.obstacle": "1200.0"} and inexact["semantics"] == "double"
    # the Twist's linear.x (cmd_vel, odom) is read: every velocity command the base accepted is answered
    base = _monitoring(report, "Base")
    assert base["status"] == "discharged" and base["counts"]["satisfied"] >= 7
    # the run sees defect 5 too: the controller's input in millimetres violates its assumption, blamed
    # on the lidar driver (not a violation of the controller, which is not at fault)
    ctl = _monitoring(report, "Controller")
    assert ctl["first_assumption_violation"]["blame"] == "upstream node(s) LidarDriver"
    # with the driver publishing metres (fix 5 alone), the base's limit 2.0 is the service response outside
    # the client's assumption: caught on the run, blamed on the server through the service
    ctl5 = _monitoring(runs["05-millimetres.diff"], "Controller")
    a = ctl5["first_assumption_violation"]
    assert a["assumption"] == "0 < in.max_speed and in.max_speed <= 1.5" and a["values"]["in.max_speed"] == "2.0"
    assert a["blame"] == "upstream node(s) Base (through service get_limits)"


def test_with_all_five_fixed_the_example_is_green_under_strict(runs: dict[str, Any]) -> None:
    rc, report = runs["strict"]
    assert report["problems"] == []
    verdicts = {q["id"]: q["verdict"] for q in report["requirements"]}
    assert verdicts == {"STOP": "met", "DOCK": "met", "SPEED": "met", "ARRIVE": "met"}
    record = json.loads((runs["ws"] / "artifacts/requirements/ARRIVE.json").read_text(encoding="utf-8"))
    # the proof holds without the initial values, which no run shows (each node's first message answers an
    # input): traced, not needed; the progress declarations it uses are judged on the run
    assert {p["label"] for p in record["traced_not_needed"]} == {
        "Localiser initially 1", "BatteryMonitor initially 1", "Planner initially 1"}
    assert {p["label"] for p in record["used"] if p["kind"] == "progress"} == {
        "Localiser progress", "BatteryMonitor progress", "MissionManager progress", "Planner progress"}
    # the Planner states the position it holds before its first result (nodes/planner.py): shown true
    planner = json.loads((runs["ws"] / "artifacts/evidence/Planner.g1.property_tests.e0.json").read_text())
    rows = {r["declaration"]: r for r in planner["details"]["declarations"]}
    assert rows["initially 1"]["verdict"] == "true", rows
    assert all(o["status"] == "discharged" for o in report["obligations"])
    assert not [f for f in report["findings"] if f["status"] not in ("ok",)]
    assert rc == 0
    assert report["summary"]["headline"].startswith("21 obligations: 21 discharged; 12/12 side conditions discharged")


def test_declaring_the_units_makes_it_a_located_error_at_both_ends(tmp_path: Path,
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    """Without units the mismatch is a probable scale mismatch (a hint); declared as the driver publishes
    it ([mm]) and as the controller reads it ([m]), it is a unit error at each end's declaration."""
    ws = tmp_path / "ws"
    shutil.copytree(EXAMPLE / "contracts", ws / "contracts")
    lidar, ctl = ws / "contracts/lidar_driver.rcl", ws / "contracts/controller.rcl"
    lidar.write_text(lidar.read_text().replace("outputs( obstacle : REAL )", "outputs( obstacle : REAL [mm] )")
                     .replace("1000 * in.range", "1000 [mm/m] * in.range"))
    ctl.write_text(ctl.read_text().replace("inputs( obstacle : REAL,", "inputs( obstacle : REAL [m],"))
    assert main(["check", "-w", str(ws), *[str(p) for p in sorted((ws / "contracts").glob("*.rcl"))]]) == 1
    err = capsys.readouterr()
    text = err.out + err.err
    lines = [x for x in text.splitlines() if "unit mismatch on the connection LidarDriver.out.obstacle" in x]
    assert len(lines) == 2
    assert any("lidar_driver.rcl:9:12: error:" in x for x in lines)
    assert any("controller.rcl:10:11: error:" in x for x in lines)
    assert all("a factor of 1000" in x for x in lines)


def test_sarif_puts_a_failed_side_condition_at_the_guarantee_to_repair(runs: dict[str, Any]) -> None:
    """Issue 48: the CI annotation of a failed side condition landed on the innocent consumer."""
    from rclverify.report.sarif import sarif_log
    results = sarif_log(runs["seeded"])["runs"][0]["results"]
    sc = next(r for r in results if r["ruleId"] == "RCL-SC-REFUTED"
              and r["properties"]["sideCondition"] == "Controller.sc2")
    assert sc["locations"][0]["physicalLocation"]["artifactLocation"]["uri"] == "contracts/lidar_driver.rcl"
    rel = sc["relatedLocations"][0]
    assert rel["physicalLocation"]["artifactLocation"]["uri"] == "contracts/controller.rcl"
    assert rel["message"]["text"] == "the assumption it fails"


def _monitoring(report: dict[str, Any], node: str) -> dict[str, Any]:
    return monitoring(report, node, "run_jsonl")


def test_every_report_of_the_example_matches_the_published_schema(runs: dict[str, Any]) -> None:
    """Each report the fixture built (as shipped, after each fix, under --strict) against
    docs/assurance.schema.json and the status vocabulary (tests/_report_schema.py)."""
    from _report_schema import check_report
    reports = {k: v for k, v in runs.items() if isinstance(v, dict) and "meta" in v}
    assert len(reports) > 2, sorted(reports)
    for label, report in {**reports, "strict": runs["strict"][1]}.items():
        check_report(report, label)
