"""The checked code repairs on seeded defects (issue 111, "Must show"; docs/diagnosis.md, "Seeded defects:
figures").

Every code defect the project's examples seed, and the slips of the two bench robots
(``bench/repair_robots/rover`` and ``arm``, each slip in ``slips.yaml``), is seeded alone in a temporary
copy of its workspace and the tool runs on it as the pipeline's property-tests stage and diagnosis run it,
in process:

1. every guarantee of the defect's node is run by the property-tests harness
   (:func:`rclverify.backends.property_tests.harness.run_guarantee`, the plan entry's seed and budget); the
   first that fails names its culprit line (``counterexample.cause``);
2. :func:`rclverify.diagnosis.code_repair.checked_repairs` offers the checked repairs of that failure, as
   the diagnosis stage does;
3. the first repair is compared with the seeded fix: **equal** when the repaired file's text is the fixed
   file's; else **equivalent** when the repaired workspace and the fixed one discharge the same property-test
   obligations (every node's, run again on each); else a **miss**;
4. the first repair **breaks** another obligation when a property-test obligation of any node that is
   discharged with the seeded fix is not discharged with the repair.  The other evidence (a recorded run, a
   Hoare program) does not read the edited Python file and is not run again.

The defects (:func:`defects`): the five patches of ``examples/ros2_robot/defects``, the delivery example's
slow zone (``fixes/05-slow-zone.diff``) and stale wheel command (``02-stale-command.diff``, found by the
recorded run; no property test fails), the contracts-first thermostat's 273 for 273.15, and the bench
robots' slips.  The failing line is **exact** when the line the diagnosis names first is the seeded line
(the first line the fix changes): the property test's culprit line, or the line the first checked repair
edits when that repair was found around it (:func:`rclverify.diagnosis.code_repair.repaired_line`, as
``diagnosis/build.py`` names it).

The manipulator's seven defects (``examples/manipulator/robot.py --defects NAME``) are found by its live
monitor, not by property tests (:func:`run_manipulator`, when a ROS 2 Python is there: ``.venv-ros2`` or
``RCLVERIFY_ROS2_PYTHON``):

1. the correct robot and each defect are run live once (``examples/manipulator/watch.py``: the robot under
   ``rclverify monitor --live --ros2``, :data:`ROUNDS` rounds, the rclpy source), each run's log kept;
2. on the defect's log, :func:`rclverify.diagnosis.run_repair.run_repairs` re-runs the defect's node
   (``robot.py``'s ``build([NAME])``) on its recorded questions, each candidate judged again by the monitors
   on the run, as the diagnosis of a monitor's violation does;
3. the first repair is **equivalent** to the seeded fix when the run judged again with it equals the run
   judged again with the node re-run as the correct robot (``build([])``), every node's verdicts and counts
   (the defects are seeded by a flag, so no repair's text is the fix's: none is **equal**); else a miss;
4. it **breaks** an obligation when a live run of the robot with the repair made (a copy of the example,
   ``--defects NAME``) gives any node another status than the correct robot's live run;
5. the seeded line is the line of ``robot.py`` that reads ``bad("NAME")``; the named line is the line the
   first checked repair edits, else the callback's first line.

Usage::

    python bench/repair_examples.py              # every defect, a table and the totals
    python bench/repair_examples.py --only battery_lt,odometer_minus
    python bench/repair_examples.py --only manipulator   # the manipulator's seven (live runs)

The figures are printed, not asserted (``tests/diagnosis/test_repair_examples.py`` asserts one defect).
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import difflib
import shutil
import subprocess
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
ROBOTS = Path(__file__).resolve().parent / "repair_robots"
IGNORE = shutil.ignore_patterns("artifacts", "reports", ".doit*", "__pycache__", ".ros2")


@dataclass
class Defect:
    """One seeded code defect: its ``robot`` (a workspace folder), ``name``, ``node``, the implementation
    ``file`` (workspace-relative) as ``slipped`` (the defect) and ``fixed`` (the seeded fix) texts."""

    robot: Path
    name: str
    node: str
    file: str
    slipped: str
    fixed: str

    @property
    def line(self) -> int:
        """The seeded line: the first line of ``slipped`` the fix changes (1-based)."""
        a, b = self.slipped.splitlines(), self.fixed.splitlines()
        for op, i1, _, _, _ in difflib.SequenceMatcher(a=a, b=b, autojunk=False).get_opcodes():
            if op != "equal":
                return i1 + 1
        return 0


def _patched(root: Path, rel: str, patch: Path, reverse: bool = False) -> str:
    """The text of ``root/rel`` with ``patch`` (``-p1``) applied (``reverse``: un-applied), in a copy."""
    with tempfile.TemporaryDirectory(prefix="rclverify-repair-examples-") as tmp:
        (Path(tmp) / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(root / rel, Path(tmp) / rel)
        subprocess.run(["patch", "-p1", "--forward", "-s", *(["-R"] if reverse else []), "-d", tmp, "-i",
                        str(patch)], check=True, capture_output=True, timeout=60)
        return (Path(tmp) / rel).read_text(encoding="utf-8")


def _patch_file(patch: Path) -> str:
    """The one file ``patch`` changes (its ``+++ b/`` line)."""
    return next(x[len("+++ b/"):].split("\t")[0] for x in patch.read_text().splitlines() if x.startswith("+++ b/"))


def defects() -> list[Defect]:
    """Every seeded code defect of the examples and the bench robots (module docstring)."""
    out: list[Defect] = []
    ros2 = EXAMPLES / "ros2_robot"
    nodes = {"battery_lt": "BatteryWatcher", "scan_skips_last": "ScanGuard", "scan_max_for_min": "ScanGuard",
             "estop_always_success": "EStop", "dock_result_spoilt": "Dock"}
    for name, node in nodes.items():
        patch = ros2 / "defects" / name / f"{name}.patch"
        rel = _patch_file(patch)
        out.append(Defect(ros2, name, node, rel, _patched(ros2, rel, patch), (ros2 / rel).read_text(encoding="utf-8")))
    delivery = EXAMPLES / "delivery"
    for name, node, diff in (("slow_zone", "SpeedGovernor", "05-slow-zone.diff"),
                             ("stale_command", "WheelController", "02-stale-command.diff")):
        rel = _patch_file(delivery / "fixes" / diff)
        out.append(Defect(delivery, name, node, rel, (delivery / rel).read_text(encoding="utf-8"),
                          _patched(delivery, rel, delivery / "fixes" / diff)))
    thermo = EXAMPLES / "contracts_first"
    rel = "gen/temp_sensor/temp_sensor/logic.py"
    text = (thermo / rel).read_text(encoding="utf-8")
    out.append(Defect(thermo, "kelvin_273", "TempSensor", rel, text, text.replace("kelvin - 273}", "kelvin - 273.15}")))
    for robot in sorted(p for p in ROBOTS.iterdir() if (p / "slips.yaml").is_file()):
        for s in yaml.safe_load((robot / "slips.yaml").read_text(encoding="utf-8")):
            fixed = (robot / s["file"]).read_text(encoding="utf-8")
            assert fixed.count(s["fixed"] + "\n") == 1, (robot.name, s["name"])
            slipped = fixed.replace(s["fixed"] + "\n", s["slipped"] + "\n" if s["slipped"] else "")  # "": removed
            out.append(Defect(robot, s["name"], s["node"], s["file"], slipped, fixed))
    return out


def _workspace(d: Defect, where: Path, text: str) -> Path:
    """A copy of ``d``'s workspace under ``where`` with its implementation file holding ``text``."""
    shutil.copytree(d.robot, where, ignore=IGNORE)
    (where / d.file).write_text(text, encoding="utf-8")
    return where


def _property_entries(ws: Any) -> list[tuple[str, int]]:
    """``(node, evidence index)`` of every property-tests entry of the plan."""
    return [(node, k) for node, entries in ws.plan.evidence.items() for k, e in enumerate(entries)
            if e.backend == "property_tests"]


def statuses(root: Path, only: str | None = None) -> dict[str, tuple[str, str]]:
    """Each property-test obligation of the workspace ``root`` (of node ``only``, else of every node):
    ``id -> (status, cause)``, run by the harness with the entry's seed and budget."""
    from rclverify.app.pipeline import Workspace
    from rclverify.backends.property_tests.harness import read_config, run_guarantee
    ws = Workspace(root)
    out: dict[str, tuple[str, str]] = {}
    for node, k in _property_entries(ws):
        if only is not None and node != only:
            continue
        target = ws.target(node, k)
        cfg = read_config(target.config, target.node, target.root)
        for g in range(1, len(target.node.node.guarantees) + 1):
            try:
                got = run_guarantee(target.checked, target.node, g, cfg, target.root, target.facts, None,
                                    target.mapping)
                status, cause = got.status, (got.counterexample or {}).get("cause", "") if got.status == "failed" else ""
            except Exception as e:  # noqa: BLE001 - code that does not load or run: the obligation fails
                status, cause = "error", type(e).__name__
            out[f"{node}.g{g}.property_tests.e{k}"] = (status, cause)
    return out


@dataclass
class Outcome:
    """What the tool did on one defect (module docstring): the failing obligation and the line the
    diagnosis names first (``cause``: the property test's culprit line, or the line the first checked
    repair edits when it was found around that line; ``""``: no property test failed), whether it is
    ``exact`` (the seeded line), the repairs offered (their
    texts), the first repair's ``verdict`` (``equal``, ``equivalent``, ``miss``, ``none``), the
    obligations it ``breaks`` and the seconds taken."""

    failing: str
    cause: str
    exact: bool
    offered: list[str]
    verdict: str
    breaks: list[str]
    seconds: float


def run_defect(d: Defect, where: Path) -> Outcome:
    """Seed ``d`` in a copy of its workspace under ``where`` and run the tool on it (module docstring)."""
    from rclverify.app.pipeline import Workspace
    from rclverify.diagnosis.code_repair_check import checked_repairs, repaired_line
    from rclverify.diagnosis.edits import Edit
    t0 = time.perf_counter()
    slipped = _workspace(d, where / "slipped", d.slipped)
    before = statuses(slipped, d.node)
    failing = next((oid for oid, (s, c) in before.items() if s == "failed" and c), "")
    if not failing:
        return Outcome("", "", False, [], "none", [], time.perf_counter() - t0)
    cause = before[failing][1]
    reps = checked_repairs(Workspace(slipped), d.node, failing, cause, {k: v[0] for k, v in before.items()})
    offered = [Edit(r["file"], r["edit"]["line"], r["edit"]["col"], r["edit"]["end_line"], r["edit"]["end_col"],
                    r["edit"]["inserted"]).apply(d.slipped) for r in reps]
    named = repaired_line(cause, reps) or cause  # the line the diagnosis names first
    exact = named == f"{d.file}:{d.line}"
    if not offered:
        return Outcome(failing, named, exact, [], "none", [], time.perf_counter() - t0)
    fixed = statuses(_workspace(d, where / "fixed", d.fixed))
    repaired = fixed if offered[0] == d.fixed else statuses(_workspace(d, where / "repaired", offered[0]))
    breaks = sorted(k for k, (s, _) in fixed.items() if s == "discharged" and repaired.get(k, ("absent",))[0] != s)
    same = {k: s for k, (s, _) in repaired.items()} == {k: s for k, (s, _) in fixed.items()}
    verdict = "equal" if offered[0] == d.fixed else "equivalent" if same else "miss"
    return Outcome(failing, named, exact, offered, verdict, breaks, time.perf_counter() - t0)


def _change(old: str, new: str) -> str:
    """The changed line of ``old`` -> ``new``, as ``a -> b`` (stripped), for the table."""
    a, b = old.splitlines(), new.splitlines()
    for op, i1, i2, j1, j2 in difflib.SequenceMatcher(a=a, b=b, autojunk=False).get_opcodes():
        if op != "equal":
            return f"{' / '.join(x.strip() for x in a[i1:i2]) or '-'} -> {' / '.join(x.strip() for x in b[j1:j2]) or '-'}"
    return "-"


def run(only: set[str] | None = None) -> list[tuple[Defect, Outcome]]:
    """Every defect (or those named in ``only``) with the tool's outcome (copies in a temporary folder)."""
    tmp = Path(tempfile.mkdtemp(prefix="rclverify-repair-examples-"))
    try:
        return [(d, run_defect(d, tmp / f"{k}-{d.name}")) for k, d in enumerate(defects())
                if only is None or d.name in only]
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


#: Rounds of a manipulator run: every input value of robot.py's drivers at least once.
ROUNDS = 6
MANIPULATOR = EXAMPLES / "manipulator"
#: The manipulator's defects and the contract node each one breaks, whether by its calls (a service, an action).
MANIPULATOR_DEFECTS = {"guard_last_beam": ("ObstacleGuard", False), "charge_lt": ("ChargeMonitor", False),
                       "limiter_first_five": ("JointLimiter", False), "governor_cap": ("SpeedGovernor", False),
                       "docking_threshold": ("Docking", False), "estop_always": ("EStop", True),
                       "arm_spoilt": ("Arm", True)}


def _ros2_python() -> Path | None:
    import os
    named = os.environ.get("RCLVERIFY_ROS2_PYTHON")
    exe = Path(named) if named else ROOT / ".venv-ros2" / "bin" / "python"
    return exe if exe.is_file() else None


def _watch_module(folder: Path) -> Any:
    """``watch.py`` of the manipulator copy in ``folder`` (its robot the copy's ``robot.py``)."""
    import importlib.util
    import sys
    spec = importlib.util.spec_from_file_location(f"manipulator_watch_{abs(hash(str(folder)))}",
                                                  folder / "watch.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    return mod


def _live(where: Path, robot_text: str | None, defects: str, python: Path) -> tuple[Path, dict[str, str]]:
    """A live run of the manipulator (a copy under ``where`` with ``robot_text`` as its ``robot.py`` when
    given): ``(its log, each contract node's status)``."""
    ws = where / "examples" / "manipulator"
    shutil.copytree(MANIPULATOR, ws, ignore=IGNORE)
    shutil.copyfile(EXAMPLES / "ros2_recording.py", where / "examples" / "ros2_recording.py")
    if robot_text is not None:
        (ws / "robot.py").write_text(robot_text, encoding="utf-8")
    w = _watch_module(ws)
    run = where / "run"
    run.mkdir()
    got = w.watch(run, python, w.loopback_env(run), source="rclpy", defects=defects, burners=0, rounds=ROUNDS)
    return run / "live.jsonl", w.node_status(got["record"])


@dataclass
class LiveOutcome:
    """What the tool did on one manipulator defect: ``named`` the line it names, ``exact``, the
    ``offered`` repairs' texts of ``robot.py``, the first's ``verdict``, the nodes whose live status it
    ``breaks``, ``why`` none was offered and the seconds taken."""

    named: str
    exact: bool
    offered: list[str]
    verdict: str
    breaks: list[str]
    why: str
    seconds: float


def run_manipulator(tmp: Path, python: Path, only: set[str] | None = None) -> list[tuple[str, LiveOutcome]]:
    """The manipulator's defects (module docstring), each ``(name, outcome)``."""
    from rclverify.app.pipeline import Workspace
    from rclverify.backends.monitors.config import load_mapping
    from rclverify.diagnosis.edits import Edit
    from rclverify.diagnosis.run_repair import rejudged, run_repairs
    names = [n for n in MANIPULATOR_DEFECTS if only is None or n in only or "manipulator" in only]
    if not names:
        return []
    checked = Workspace(MANIPULATOR).checked
    cfg = load_mapping(MANIPULATOR, "contracts/mapping.yaml", None)
    text = (MANIPULATOR / "robot.py").read_text(encoding="utf-8")
    _, correct = _live(tmp / "correct", None, "", python)
    out = []
    for name in names:
        t0 = time.perf_counter()
        node, calls = MANIPULATOR_DEFECTS[name]
        log, _ = _live(tmp / name, None, name, python)
        got = run_repairs(MANIPULATOR, checked, cfg, log, node, calls, "robot.py", "build", [[name]], python)
        seeded = next(k for k, x in enumerate(text.splitlines(), 1) if f'bad("{name}")' in x)
        exact = got.line == f"robot.py:{seeded}"
        offered = [Edit(r["file"], r["edit"]["line"], r["edit"]["col"], r["edit"]["end_line"], r["edit"]["end_col"],
                        r["edit"]["inserted"]).apply(text) for r in got.repairs]
        if not offered:
            out.append((name, LiveOutcome(got.line, exact, [], "none", [], got.why, time.perf_counter() - t0)))
            continue
        fixed = rejudged(MANIPULATOR, checked, cfg, log, node, calls, "robot.py", text, "build", [[]], python)
        first = rejudged(MANIPULATOR, checked, cfg, log, node, calls, "robot.py", offered[0], "build", [[name]],
                         python)
        verdict = "equivalent" if first == fixed else "miss"
        _, live = _live(tmp / f"{name}-repaired", offered[0], name, python)
        breaks = sorted(n for n in correct if live.get(n) != correct[n])
        out.append((name, LiveOutcome(got.line, exact, offered, verdict, breaks, "", time.perf_counter() - t0)))
    return out


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--only", default="", help="comma-separated defect names")
    p.add_argument("--smoke", action="store_true", help="CI: one defect of one new robot (rover's odometer_minus)")
    a = p.parse_args()
    only = {"odometer_minus"} if a.smoke else ({x for x in a.only.split(",") if x} or None)
    results = run(only)
    live: list[tuple[str, LiveOutcome]] = []
    python = _ros2_python()
    if not a.smoke and (only is None or "manipulator" in only or only & set(MANIPULATOR_DEFECTS)):
        if python is None:
            print("manipulator: skipped, no ROS 2 Python (.venv-ros2, or RCLVERIFY_ROS2_PYTHON)")
        else:
            tmp = Path(tempfile.mkdtemp(prefix="rclverify-repair-manipulator-"))
            try:
                live = run_manipulator(tmp, python, only)
            finally:
                shutil.rmtree(tmp, ignore_errors=True)
    print(f"{'robot':<16} {'defect':<22} {'node':<15} {'line':<6} {'first repair':<10} breaks  s")
    for d, o in results:
        line = "exact" if o.exact else (o.cause.rpartition(":")[2] or "-") + f"/{d.line}"
        print(f"{d.robot.name:<16} {d.name:<22} {d.node:<15} {line:<6} {o.verdict:<10} {len(o.breaks):>6}  "
              f"{o.seconds:.1f}")
        print(f"{'':<16} seeded fix:   {_change(d.slipped, d.fixed)}")
        if o.offered:
            print(f"{'':<16} first repair: {_change(d.slipped, o.offered[0])}")
    text = (MANIPULATOR / "robot.py").read_text(encoding="utf-8")
    for name, lo in live:
        seeded = next(k for k, x in enumerate(text.splitlines(), 1) if f'bad("{name}")' in x)
        line = "exact" if lo.exact else (lo.named.rpartition(":")[2] or "-") + f"/{seeded}"
        print(f"{'manipulator':<16} {name:<22} {MANIPULATOR_DEFECTS[name][0]:<15} {line:<6} {lo.verdict:<10} "
              f"{len(lo.breaks):>6}  {lo.seconds:.1f}")
        if lo.offered:
            print(f"{'':<16} first repair: {_change(text, lo.offered[0])}")
        else:
            print(f"{'':<16} none: {lo.why}")
        if lo.breaks:
            print(f"{'':<16} breaks (live): {', '.join(lo.breaks)}")
    if live:
        g = sum(1 for _, lo in live if lo.verdict == "equivalent")
        print(f"manipulator: first repair equivalent to the seeded fix {g}/{len(live)}; repairs that break another "
              f"obligation (live) {sum(1 for _, lo in live if lo.breaks)}; failing line exact "
              f"{sum(1 for _, lo in live if lo.exact)}/{len(live)}")
    n = len(results) + len(live)
    good = sum(1 for _, o in results if o.verdict in ("equal", "equivalent")) + \
        sum(1 for _, lo in live if lo.verdict == "equivalent")
    exact = sum(1 for _, o in results if o.exact) + sum(1 for _, lo in live if lo.exact)
    breaks = sum(1 for _, o in results if o.breaks) + sum(1 for _, lo in live if lo.breaks)
    if not n:
        print("no defect named")
        return
    print(f"defects: {n}; first repair equal or equivalent to the seeded fix: {good}/{n} "
          f"({7 * good / n:.1f} of every 7, aim >= 5); repairs that break another obligation: {breaks} (aim 0); "
          f"failing line exact: {exact}/{n} ({7 * exact / n:.1f} of every 7, aim >= 6); "
          f"seconds: {sum(o.seconds for _, o in results) + sum(lo.seconds for _, lo in live):.0f}")


if __name__ == "__main__":
    main()
