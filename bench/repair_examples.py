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

Usage::

    python bench/repair_examples.py              # every defect, a table and the totals
    python bench/repair_examples.py --only battery_lt,odometer_minus

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
    from rclverify.diagnosis.code_repair import checked_repairs, repaired_line
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


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--only", default="", help="comma-separated defect names")
    p.add_argument("--smoke", action="store_true", help="CI: one defect of one new robot (rover's odometer_minus)")
    a = p.parse_args()
    results = run({"odometer_minus"} if a.smoke else ({x for x in a.only.split(",") if x} or None))
    print(f"{'robot':<16} {'defect':<22} {'node':<15} {'line':<6} {'first repair':<10} breaks  s")
    for d, o in results:
        line = "exact" if o.exact else (o.cause.rpartition(":")[2] or "-") + f"/{d.line}"
        print(f"{d.robot.name:<16} {d.name:<22} {d.node:<15} {line:<6} {o.verdict:<10} {len(o.breaks):>6}  "
              f"{o.seconds:.1f}")
        print(f"{'':<16} seeded fix:   {_change(d.slipped, d.fixed)}")
        if o.offered:
            print(f"{'':<16} first repair: {_change(d.slipped, o.offered[0])}")
    n = len(results)
    good = sum(1 for _, o in results if o.verdict in ("equal", "equivalent"))
    exact = sum(1 for _, o in results if o.exact)
    breaks = sum(1 for _, o in results if o.breaks)
    print(f"defects: {n}; first repair equal or equivalent to the seeded fix: {good}/{n} "
          f"({7 * good / n:.1f} of every 7, aim >= 5); repairs that break another obligation: {breaks} (aim 0); "
          f"failing line exact: {exact}/{n} ({7 * exact / n:.1f} of every 7, aim >= 6); "
          f"seconds: {sum(o.seconds for _, o in results):.0f}")


if __name__ == "__main__":
    main()
