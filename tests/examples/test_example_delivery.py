"""The delivery example (examples/delivery, docs/delivery.md): issue 48's six defects, each one row.

A nine-node ROS 2 delivery robot (a service, an action, nested messages,
units, deadlines, an MCAP recording) with six seeded defects.  The pipeline
runs once on a copy of the seeded workspace, then once per fix of
``examples/delivery/fixes/`` applied cumulatively (``git apply``; the run
rebuilt from the fixed node code by the simulator ``nodes/record_run.py``,
no ROS 2 needed), the last one with ``--strict``: seven pipeline runs, six of them incremental ``doit``
runs of the same copy (the last fix edits a hop off the deadline's named
path, which the incremental run must decide again, as a clean one does:
docs/integrity.md).

(a) each defect is one problem row with the right culprit and, where the
    contract is at fault, a safe first repair that is the edit its fix
    makes: the degrees for radians a unit problem with the factor 180/pi
    blaming the driver, the stale wheel command named at its time stamp
    (1.513 s into the run) with every violated event of the run listed, the route longer
    than the buffer tightened to the named constant ``RouteBuffer``, the
    stop number off by one blamed on the producer read by two consumers
    (one row, not one per victim), the property test's failure at the
    implementation's line with the boundary value, the deadline refuted
    along the worst path;
(b) each fix removes its row and no row appears;
(c) the recorded run raises no false alarm: no node's run fails but the
    stale command's;
(d) with all six fixed, ``--strict`` passes: nothing is left outstanding;
(e) the counterexamples read well (inputs within their assumptions or the
    note saying why not, short values, no more than the cone);
(f) the committed run is the live monitor's recording of real rclpy nodes
    (``nodes/record_live.py``; checked, not recorded again): the plan's bag
    is what ``make_trace`` makes of the monitor's bag and log, and its
    messages are the simulator's, topic by topic.
Real Z3, Hypothesis, rosbags and doit; nothing of the example is edited in place.
"""
from __future__ import annotations

import contextlib
import importlib.util
import io
import json
import runpy
import shutil
import subprocess
import sys
from fractions import Fraction
from pathlib import Path
from typing import Any

import pytest

from _example_report import changed as _changed, diag as _diag, first_repair as _first_repair, monitoring, \
    rows as _rows, verify as _verify

from rclverify.cli.commands import main

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "delivery"
FIXES = sorted((EXAMPLE / "fixes").glob("*.diff"))
RUN = "backends/monitors/traces/run"
#: The row each fix removes (its root-cause key in reports/assurance.json's ``problems``).
ROWS = {
    "01-degrees.diff": ("guarantee:GnssDriver:1",),
    "02-stale-command.diff": ("guarantee:WheelController:1",),
    "03-route-buffer.diff": ("assumption:Navigator:3", "guarantee:RouteServer:1"),
    "04-stop-number.diff": ("assumption:LockerController:1", "assumption:Navigator:1", "guarantee:MissionPlanner:1"),
    "05-slow-zone.diff": ("guarantee:SpeedGovernor:2",),
    "06-deadline.diff": ("deadline:STOP",),
}
#: The fixes of a failed side condition: the derived properties behind them are one more row until the last.
SIDE_CONDITION_FIXES = ("01-degrees.diff", "03-route-buffer.diff", "04-stop-number.diff")


def _record(ws: Path) -> None:
    """Record the run again from the node code as it now is: ``nodes/record_run.py`` run in this process
    (rosbags is imported once), the node modules imported afresh and taken away again."""
    names = [p.stem for p in (ws / "nodes").glob("*.py")]
    saved_path, saved = list(sys.path), {n: sys.modules.pop(n) for n in names if n in sys.modules}
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            runpy.run_path(str(ws / "nodes" / "record_run.py"), run_name="__main__")
    finally:
        for n in names:
            sys.modules.pop(n, None)
        sys.modules.update(saved)
        sys.path[:] = saved_path


def _events(ws: Path) -> list[tuple[float, str, dict[str, Any]]]:
    from rclverify.traces import read_trace
    return [(e.time, e.topic, dict(e.fields)) for e in read_trace(ws / RUN)]


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    ws = tmp_path_factory.mktemp("delivery") / "ws"
    shutil.copytree(EXAMPLE, ws, ignore=shutil.ignore_patterns("artifacts", "reports", ".doit*", "__pycache__",
                                                               ".ros2"))
    out: dict[str, Any] = {"ws": ws}
    out["seeded_events"] = _events(ws)  # the committed run, recorded live
    out["seeded"] = _verify(ws)[1]
    for n in (1, 10):  # `rclverify explain` reaches every violation of the run, the first and the last
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            out[f"explain#{n}"] = (main(["explain", "-w", str(ws), f"WheelController.g0.monitors.run#{n}"]),
                                   buf.getvalue())
    _record(ws)
    out["simulated_events"] = _events(ws)
    for diff in FIXES:
        subprocess.run(["git", "apply", str(diff)], cwd=ws, check=True, capture_output=True, timeout=60)
        if "+++ b/nodes/" in diff.read_text(encoding="utf-8"):  # the node code changed: record the run again
            _record(ws)
        res = _verify(ws, *(["--strict"] if diff == FIXES[-1] else []))
        out[diff.name] = res[1]
    out["strict"] = res
    return out


def _derived(report: dict[str, Any]) -> set[tuple[str, ...]]:
    """The row of the derived properties not derived (behind the failed side conditions)."""
    return {k for k, g in _rows(report).items() if all(m["id"].endswith(".derived") for m in g["members"])}


def _members(report: dict[str, Any], key: tuple[str, ...]) -> list[str]:
    return [m["id"] for m in _rows(report)[key]["members"]]


def _culprits(report: dict[str, Any], key: tuple[str, ...]) -> list[tuple[str, str]]:
    return [(c["what"], c["source"]) for c in _rows(report)[key]["culprits"]]


def test_the_example_is_as_shipped(runs: dict[str, Any]) -> None:
    """The committed MCAP bag is read with its nested messages and the service's and action's parts;
    every fix is a patch of the seeded files."""
    assert [f.name for f in FIXES] == sorted(ROWS)
    events = runs["seeded_events"]
    assert (EXAMPLE / RUN / "run.mcap").is_file()
    topics = {t for _, t, _ in events}
    assert {"get_route/request", "get_route/response", "deliver/goal", "deliver/feedback", "deliver/result",
            "cmd_vel", "safe_cmd", "wheel_cmd"} <= topics
    goal = next(f for _, t, f in events if t == "deliver/goal")
    assert goal["goal"] == {"dest_id": 42}
    assert next(f for _, t, f in events if t == "cmd_vel")["linear"]["x"] == 0.8


def test_each_defect_is_one_row_with_the_right_culprit(runs: dict[str, Any]) -> None:
    report = runs["seeded"]
    rows = _rows(report)
    derived = _derived(report)
    assert len(derived) == 1 and set(rows) == {*ROWS.values(), *derived}
    # (a) degrees for radians: a unit problem, 180/pi, blaming the driver; the side condition, the
    # missing-unit warning, the scale hint and the run's assumption violations are its findings
    deg = ROWS["01-degrees.diff"]
    assert _culprits(report, deg) == [("guarantee 1 of GnssDriver", "contracts/gnss_driver.rcl:15:3")]
    assert _members(report, deg)[0] == "GnssDriver.out.heading.unit"
    assert {"Localiser.sc2", "Localiser.sc2.scale", "Localiser.g0.monitors.run",
            "contracts/gnss_driver.rcl:9:12"} <= set(_members(report, deg))
    sentence = rows[deg]["sentence"]
    assert sentence.startswith("Unit mismatch: GnssDriver publishes GnssDriver.out.heading in [deg]")
    assert "a factor of 180/pi" in sentence and "Localiser reads Localiser.in.heading in [rad]" in sentence
    # (b) the stale wheel command: the event at its time stamp, every violated event listed
    stale = ROWS["02-stale-command.diff"]
    assert _culprits(report, stale) == [("guarantee 1 of WheelController", "contracts/wheel_controller.rcl:14:3")]
    t = float(rows[stale]["sentence"].split("(t = ", 1)[1].split(" s)")[0])
    assert 1.50 <= t - runs["seeded_events"][0][0] <= 1.53  # the watchdog's tick 1.513 s into the run
    # (c) the route longer than the buffer: one row for the side condition and the requirement
    route = ROWS["03-route-buffer.diff"]
    assert _members(report, route) == ["Navigator.sc4", "ROUTE"]
    assert _culprits(report, route) == [("guarantee 1 of RouteServer", "contracts/route_server.rcl:13:3"),
                                        ("assumption 3 of Navigator", "contracts/navigator.rcl:22:3")]
    # (d) the stop number off by one: one row for both consumers, the producer its culprit guarantee
    stop = ROWS["04-stop-number.diff"]
    assert _members(report, stop) == ["Navigator.sc1", "LockerController.sc1"]
    assert [w for w, _ in _culprits(report, stop)] == [  # the producer first, then the assumptions it fails
        "guarantee 1 of MissionPlanner", "assumption 1 of LockerController", "assumption 1 of Navigator"]
    from rclverify.report.culprits import culprit_nodes
    blamed = culprit_nodes(report["problems"])
    assert {"GnssDriver", "MissionPlanner", "RouteServer", "WheelController", "SpeedGovernor"} <= blamed
    assert not {"Localiser", "LockerController"} & blamed  # victims only
    # (e) the property test: the implementation's line with the slip (`clearance < SLOW_ZONE`), the boundary first
    slow = ROWS["05-slow-zone.diff"]
    assert "the implementation line where the failing example goes wrong is nodes/speed_governor.py:16" in rows[slow]["sentence"]
    ev = next(e for e in report["evidence"] if e["obligation"] == "SpeedGovernor.g2.property_tests.e0")
    cex = ev["counterexample"]
    assert (cex["cause"], cex["boundary"], cex["in.clearance"]) == ("nodes/speed_governor.py:16", "in.clearance", "2.0")
    assert len(cex["in.cmd_vel"]) <= 4 and Fraction(cex["in.cmd_vel"]) > Fraction(1, 2)  # a short value past 0.5
    from rclverify.report.sarif import sarif_log
    res = next(r for r in sarif_log(report)["runs"][0]["results"]
               if r["ruleId"] == "RCL-OBL-FAILED" and "SpeedGovernor.g2" in json.dumps(r))
    loc = res["locations"][0]["physicalLocation"]
    assert (loc["artifactLocation"]["uri"], loc["region"]["startLine"]) == ("nodes/speed_governor.py", 16)
    # (f) the deadline: refuted along the worst path, through the Navigator, not the path named
    dl = ROWS["06-deadline.diff"]
    assert [w for w, _ in _culprits(report, dl)] == [
        "guarantee 1 of ObstacleDetector: within 20 ms", "guarantee 4 of Navigator: within 60 ms",
        "guarantee 4 of SpeedGovernor: within 20 ms", "guarantee 1 of WheelController: within 30 ms"]
    d = _diag(report, "STOP.deadline")["sentence"]
    assert "sums to 130 ms, 30 ms over the budget" in d and "along ObstacleDetector -> SpeedGovernor -> WheelController" in d


def test_every_violation_of_the_run_is_listed_and_explained(runs: dict[str, Any]) -> None:
    report = runs["seeded"]
    ev = next(e for e in report["evidence"] if e["obligation"] == "WheelController.g0.monitors.run")
    viol = ev["monitoring"]["violations"]
    assert ev["monitoring"]["counts"]["violated"] == len(viol) == 10 and ev["monitoring"]["violations_dropped"] == 0
    assert 1.50 <= viol[0]["time"] - runs["seeded_events"][0][0] <= 1.53
    assert viol[0]["values"] == {"in.safe_cmd": "0.0", "out.wheel_cmd": "0.8"}
    assert [v["time"] for v in viol] == sorted(v["time"] for v in viol)
    rc, text = runs["explain#1"]
    assert rc == 0 and "violation WheelController.g0.monitors.run#1 of 10" in text
    assert f"(t = {viol[0]['time']} s)" in text
    assert "out.wheel_cmd = 0.8" in text and "in.safe_cmd = 0.0" in text
    rc, text = runs["explain#10"]
    assert rc == 0 and "#10 of 10" in text and f"(t = {viol[-1]['time']} s)" in text


def test_each_first_repair_is_safe_and_is_what_the_fix_does(runs: dict[str, Any]) -> None:
    report = runs["seeded"]
    contract = {n: k for n, k in ROWS.items() if n not in ("02-stale-command.diff", "05-slow-zone.diff")}
    first = {name: _first_repair(report, key) for name, key in contract.items()}
    assert {n: r["kind"] for n, r in first.items()} == {
        "01-degrees.diff": "convert-unit", "03-route-buffer.diff": "strengthen-producer",
        "04-stop-number.diff": "strengthen-producer", "06-deadline.diff": "tighten-hop"}
    edits = {n: (r["edit"]["deleted"], r["edit"]["inserted"]) for n, r in first.items()}
    assert edits == {"01-degrees.diff": ("in.cog", "in.cog * 0.017453292519943295 [rad/deg]"),
                     "03-route-buffer.diff": ("64", "RouteBuffer"), "04-stop-number.diff": ("501", "500"),
                     "06-deadline.diff": ("within 60 ms", "within 30 ms")}
    assert "multiply by pi/180" in first["01-degrees.diff"]["summary"]
    for name, rep in first.items():
        assert rep["checked_by"].startswith("z3") and rep["proves"], name
        fix = (EXAMPLE / "fixes" / name).read_text(encoding="utf-8")
        assert all(line in _changed(fix) for line in _changed(rep["diff"])), (name, rep["diff"])
    # the contract is right where the code is wrong: no contract edit is offered for those rows; a repair
    # offered there is a checked one-token edit of the node's code, the one the fix makes (the slow zone's
    # `<` for `<=`); the stale command needs two lines changed, which no one-token edit is
    offered = {}
    for name in ("02-stale-command.diff", "05-slow-zone.diff"):
        reps = [_diag(report, r["diagnosis"])["repairs"][r["index"]] for r in _rows(report)[ROWS[name]]["repairs"]]
        assert all(r["kind"] == "code" for r in reps), (name, reps)
        fix = (EXAMPLE / "fixes" / name).read_text(encoding="utf-8")
        assert "contracts/" not in fix and "nodes/" in fix
        for r in reps:
            assert all(line in _changed(fix) for line in _changed(r["diff"])), (name, r["diff"])
        offered[name] = len(reps)
    assert offered == {"02-stale-command.diff": 0, "05-slow-zone.diff": 1}
    for g in report["problems"]:  # never a widened consumer assumption first
        reps = [_diag(report, r["diagnosis"])["repairs"][r["index"]] for r in g["repairs"]]
        assert not reps or reps[0]["kind"] != "weaken-consumer"


def test_each_fix_removes_its_row_and_no_other_appears(runs: dict[str, Any]) -> None:
    """Applied one after the other: each fix takes its own row away and leaves the others.  The derived
    properties not derived are findings behind the failed side conditions (their own row, or the row of
    the last one left) until the last of those is fixed."""
    before = runs["seeded"]
    for diff in FIXES:
        after = runs[diff.name]
        b, a = set(_rows(before)) - _derived(before), set(_rows(after)) - _derived(after)
        assert b - a == {ROWS[diff.name]} and a <= b, (diff.name, b - a, a - b)
        derived = [m for g in after["problems"] for m in g["members"] if m["id"].endswith(".derived")]
        fixed = [f.name for f in FIXES[:FIXES.index(diff) + 1]]
        assert bool(derived) == (not set(SIDE_CONDITION_FIXES) <= set(fixed)), (diff.name, derived)
        before = after


NODES = ["GnssDriver", "Localiser", "MissionPlanner", "RouteServer", "ObstacleDetector", "Navigator",
         "SpeedGovernor", "WheelController", "LockerController"]


def test_the_recorded_run_raises_no_false_alarm(runs: dict[str, Any]) -> None:
    report = runs["seeded"]
    failed = {n for n in NODES if _monitoring(report, n)["status"] == "failed"}
    assert failed == {"WheelController"}
    # the degrees reach the localiser: its assumption violated, blamed on the driver, the localiser not at fault
    loc = _monitoring(report, "Localiser")
    assert loc["status"] == "pending" and loc["first_assumption_violation"]["blame"] == "upstream node(s) GnssDriver"
    # the Twist's linear.x and the action's and service's parts are read and answered
    for n in ("Navigator", "SpeedGovernor", "RouteServer", "MissionPlanner"):
        m = _monitoring(report, n)
        assert m["status"] == "discharged" and m["counts"]["satisfied"] >= 1, (n, m["counts"])


def test_with_all_six_fixed_strict_passes(runs: dict[str, Any]) -> None:
    rc, report = runs["strict"]
    assert rc == 0 and report["problems"] == []
    assert {q["id"]: q["verdict"] for q in report["requirements"]} == {"STOP": "met", "SLOW": "met", "ROUTE": "met"}
    assert all(o["status"] == "discharged" for o in report["obligations"])
    assert all(sc["status"] == "discharged" for sc in report["side_conditions"])
    assert not report["lint"] and not [f for f in report["findings"] if f["status"] != "ok"]
    assert {n: _monitoring(report, n)["status"] for n in NODES} == dict.fromkeys(NODES, "discharged")
    assert report["summary"]["status"] == "discharged"


def test_the_delivery_counterexamples_read_well(runs: dict[str, Any]) -> None:
    """Issue 48's readability check on this example's counterexamples: each side condition's values
    short and of the nodes it involves; each refuted requirement's inputs within their assumptions
    (or the note saying why not) and short; the property test's example at the boundary."""
    from _readable import assert_readable
    report = runs["seeded"]
    assert assert_readable(report) >= 4
    refuted = [q for q in report["requirements"] if q["verdict"] == "refuted"]
    assert {q["id"] for q in refuted} == {"STOP", "ROUTE"}
    route = next(q for q in refuted if q["id"] == "ROUTE")["check"]  # 51 waypoints need an input outside Navigator
    assert "needs an input outside Navigator: in.n_waypoints <= RouteBuffer" in route["counterexample_note"]


def test_the_committed_run_was_recorded_live_from_rclpy_nodes(runs: dict[str, Any], tmp_path: Path) -> None:
    """The plan's bag is made by program from what ``rclverify monitor --live --ros2 --record`` wrote of
    real rclpy nodes (its bag: the topics; its log: verdicts and the calls, which it does not record in
    a bag), and carries the simulator's messages; each node waited its latency."""
    live = EXAMPLE / "backends/monitors/live"
    log = [json.loads(x) for x in (live / "monitor.jsonl").read_text(encoding="utf-8").splitlines() if x.strip()]
    verdicts = [x["verdict"] for x in log if x["topic"] == "rclverify/verdict"]
    calls = [x for x in log if x["topic"] == "rclverify/call" and "index" in x]
    assert sorted(c["part"] for c in calls) == ["feedback", "goal", "request", "response", "result"]
    assert sum(v["verdict"] == "violated" and v["node"] == "WheelController" for v in verdicts) == 10
    assert all(x["time"] > 1.6e9 for x in log)  # the monitor's clock, not a simulated one
    spec = importlib.util.spec_from_file_location("delivery_record_live", EXAMPLE / "nodes" / "record_live.py")
    assert spec is not None and spec.loader is not None
    record_live = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(record_live)
    saved = list(sys.path)
    try:
        record_live.make_trace(live / "run", log, tmp_path / "run")
    finally:
        sys.path[:] = saved
        sys.modules.pop("record_run", None)
    from rclverify.traces import read_trace
    remade = [(e.time, e.topic, dict(e.fields)) for e in read_trace(tmp_path / "run", [EXAMPLE / "interfaces"])]
    assert remade == runs["seeded_events"] and len(remade) == 90
    strip = lambda f: {k: v for k, v in f.items() if k not in ("header", "goal_id")}  # noqa: E731
    sim = runs["simulated_events"]
    for topic in {t for _, t, _ in sim}:
        assert [strip(f) for _, t, f in remade if t == topic] == [strip(f) for _, t, f in sim if t == topic], topic
    safe, wheel = ([e for e in remade if e[1] == t] for t in ("safe_cmd", "wheel_cmd"))
    assert all(any(0.025 <= w[0] - s[0] < 0.06 for w in wheel) for s in safe)  # answered after its 25 ms


def _monitoring(report: dict[str, Any], node: str) -> dict[str, Any]:
    return monitoring(report, node, "run")


def test_every_report_of_the_example_matches_the_published_schema(runs: dict[str, Any]) -> None:
    """Each report the fixture built (as shipped, after each fix, under --strict) against
    docs/assurance.schema.json and the status vocabulary (tests/_report_schema.py)."""
    from _report_schema import check_report
    reports = {k: v for k, v in runs.items() if isinstance(v, dict) and "meta" in v}
    assert len(reports) > 2, sorted(reports)
    for label, report in {**reports, "strict": runs["strict"][1]}.items():
        check_report(report, label)
