"""Simulated trials of the fleet_trials example: one ROSMonitoring log per run
(``runs/<environment>/<environment>_NNN.jsonl``; the file names differ
across environments, as the obligations named after them must), the planner's speed requests at 10 Hz
and the governor's answer 20 ms after each, computed by the node's own logic
(``nodes/governor.py``).  Each environment has its own request profile and
its own seed, so a run is the same every time the script is run.

    python3 simulate_runs.py [OUT_DIR]     # default: runs/ beside this file

The runs are a simulation: the plan says so (``origin: simulation``), and the
report's bounds hold for the simulator's runs (docs/statistics.md).
"""
from __future__ import annotations

import json
import random
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent / "nodes"))
from governor import governor  # noqa: E402

#: environment -> (runs, seed, least and greatest requested speed in m/s, requests per run)
ENVIRONMENTS = {"warehouse_day": (60, 1, 0.2, 2.0, 30), "loading_dock_night": (25, 2, 0.1, 1.0, 20)}


def run_lines(rng: random.Random, start: float, lo: float, hi: float, count: int) -> list[str]:
    """One run's log lines: each request, then the governor's command 20 ms later."""
    lines = []
    for k in range(count):
        t = start + 0.1 * k
        requested = round(rng.uniform(lo, hi), 3)
        lines.append(json.dumps({"topic": "requested", "time": round(t, 3), "data": requested}))
        lines.append(json.dumps({"topic": "cmd", "time": round(t + 0.02, 3), "data": governor(requested)["cmd"]}))
    return lines


def main(out: Path) -> None:
    for env, (runs, seed, lo, hi, count) in ENVIRONMENTS.items():
        rng = random.Random(seed)
        (out / env).mkdir(parents=True, exist_ok=True)
        for i in range(runs):
            start = 1_800_000_000.0 + 3600.0 * seed + 60.0 * i
            text = "\n".join(run_lines(rng, start, lo, hi, count)) + "\n"
            (out / env / f"{env}_{i:03d}.jsonl").write_text(text, encoding="utf-8")
        print(f"{env}: {runs} run(s) in {out / env}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parent / "runs")
