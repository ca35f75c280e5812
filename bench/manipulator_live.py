"""The manipulator (examples/manipulator: sixteen real rclpy nodes on Fast
DDS) watched live many times with both cores kept busy by two CPU-burning
processes (docs/semantics.md, "Event time"; docs/scale.md).

Each round runs the correct robot (through the rclpy source and the
monitor's own DDS participant in turn, recorded as a bag) and the robot with
all seven seeded defects (the other source), and counts:

* the correct robot: violated and undecided answers, false declarations,
  nodes not discharged, and whether its log and its bag, checked offline,
  give the live verdicts answer for answer (satisfied and violated counts
  per node);
* the defective robot: whether exactly the seven defects' nodes are red.

Prints one line per run and a summary (``N of N``); asserts nothing.
``--runs N`` (default 10); ``--smoke`` (the test suite's): one short run of
the correct robot, no burners.  Without a ROS 2 Python it says why and
exits 0.
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "manipulator"
sys.path.insert(0, str(EXAMPLE))
sys.path.insert(0, str(ROOT / "bench"))
from monitor_live_rclpy import ros2_python  # noqa: E402
from watch import loopback_env, node_status, watch  # noqa: E402

NODES = ["ObstacleGuard", "Battery", "ChargeMonitor", "JointLimiter", "SpeedGovernor", "Docking", "Planner",
         "EStop", "Arm"]
RED = {"ObstacleGuard", "ChargeMonitor", "JointLimiter", "SpeedGovernor", "Docking", "EStop", "Arm"}


def offline(tmp: Path, trace: str) -> dict[str, dict[str, int]]:
    """``rclverify monitor --json`` of the run's ``trace`` (the log or the bag): counts per topic node."""
    p = subprocess.run([sys.executable, "-m", "rclverify.cli.commands", "monitor", "-w", str(EXAMPLE), "--mapping",
                        "contracts/mapping.yaml", "--json", *[a for n in NODES[:7] for a in ("--node", n)],
                        str(tmp / trace)], capture_output=True, text=True, timeout=300,
                       env={**os.environ, "PYTHONPATH": str(ROOT / "src")})
    return {e["node"]: e["counts"] for e in json.loads(p.stdout) if "counts" in e}


def correct_run(py: Path, source: str, burners: int, rounds: int, keep: Path | None = None) -> dict[str, Any]:
    """One run of the correct robot: its figures (its files copied to ``keep`` when it is not green)."""
    with tempfile.TemporaryDirectory(prefix="manipulator_") as d:
        tmp = Path(d)
        try:
            return _correct(tmp, py, source, burners, rounds)
        finally:
            if keep is not None and (tmp / "live.json").exists() and json.loads(
                    (tmp / "live.json").read_text()).get("nodes") and _red(tmp):
                shutil.copytree(tmp, keep / tmp.name, ignore=shutil.ignore_patterns("ros_log"))
                print(f"kept {keep / tmp.name}", flush=True)


def _red(tmp: Path) -> bool:
    rec = json.loads((tmp / "live.json").read_text())
    return any(s != "discharged" for s in node_status(rec).values())


def _correct(tmp: Path, py: Path, source: str, burners: int, rounds: int) -> dict[str, Any]:
    r = watch(tmp, py, loopback_env(tmp), source=source, record=True, burners=burners, rounds=rounds)
    rec = r["record"]
    counts = {n["node"]: n["counts"] for n in rec["nodes"]}
    same = True
    for trace in ("live.jsonl", "bag"):
        got = offline(tmp, trace)
        same &= all(got.get(n, {}).get(k, 0) == counts[n].get(k, 0) for n in NODES[:7]
                    for k in ("satisfied", "violated"))
    status = node_status(rec)
    return {"violated": sum(c.get("violated", 0) for c in counts.values()),
            "undecided": sum(c.get("inconclusive", 0) for c in counts.values()),
            "false_declarations": sum(d["status"] != "discharged" for d in rec["declarations"]),
            "not_discharged": sorted(n for n, s in status.items() if s != "discharged"),
            "satisfied": sum(c.get("satisfied", 0) for c in counts.values()), "same_offline": same,
            "late": rec.get("late_events", 0), "exit": r["code"]}


def defective_run(py: Path, source: str, burners: int, rounds: int) -> dict[str, Any]:
    """One run of the robot with every seeded defect: which nodes are red."""
    with tempfile.TemporaryDirectory(prefix="manipulator_") as d:
        tmp = Path(d)
        r = watch(tmp, py, loopback_env(tmp), source=source, defects="all", burners=burners, rounds=rounds)
        red = {n for n, s in node_status(r["record"]).items() if s == "failed"}
        return {"red": sorted(red), "exact": red == RED, "exit": r["code"]}


def main(argv: list[str] | None = None) -> int:
    import argparse
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--runs", type=int, default=10)
    p.add_argument("--smoke", action="store_true", help="CI: one short run of the correct robot, no burners")
    p.add_argument("--keep", type=Path, help="copy each correct run that is not green into this folder")
    a = p.parse_args(argv)
    py, why = ros2_python()
    if py is None:
        print(f"manipulator: skipped: {why}")
        return 0
    if a.smoke:
        c = correct_run(py, "rclpy", 0, 4, a.keep)
        print(f"manipulator smoke: correct robot, rclpy source: {json.dumps(c)}")
        return 0
    green = exact = same = 0
    for k in range(a.runs):
        src, other = ("rclpy", "dds") if k % 2 == 0 else ("dds", "rclpy")
        c = correct_run(py, src, 2, 40, a.keep)
        dfx = defective_run(py, other, 2, 40)
        ok = not (c["violated"] or c["undecided"] or c["false_declarations"] or c["not_discharged"])
        green += ok
        exact += dfx["exact"]
        same += c["same_offline"]
        print(f"run {k + 1}: correct ({src}): {json.dumps(c)}; defects ({other}): {json.dumps(dfx)}", flush=True)
    print(f"manipulator, {a.runs} run(s), both cores busy: correct robot green in {green} of {a.runs}; every defect "
          f"red at its own node only in {exact} of {a.runs}; log and bag = live in {same} of {a.runs}")
    return 0


if __name__ == "__main__":
    from _live import exit_on_sigterm  # SIGTERM stops what the bench started (bench/_live.py)
    exit_on_sigterm()
    sys.exit(main())
