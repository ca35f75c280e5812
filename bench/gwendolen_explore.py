"""How long the Gwendolen explorer takes on the case study's agent.

Explores ``backends/ajpf/jackal.gwen`` under the case study's verification
environment (after each ``move``: a move_base result, success or failure, a
red or orange radiation alarm, or nothing; docs/model-checking.md) and
prints the number of states and transitions, whether the graph is complete,
its depth and the wall-clock seconds of parsing plus exploration (best of
``--repeat`` runs).  With ``--after action`` the environment reacts after
every action instead (a much larger graph; use ``--max-states`` to bound
it).  Figures are printed, not asserted; expect +-25% on a shared machine.

Usage::

    PYTHONPATH=src python3 bench/gwendolen_explore.py [--repeat 3] [--after move|action] [--max-states N]
    PYTHONPATH=src python3 bench/gwendolen_explore.py --smoke    # one run: a few seconds
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import time
from pathlib import Path

from rclverify.backends.model_checking.environment import environment_from_plan
from rclverify.backends.model_checking.explore import explore

ROOT = Path(__file__).resolve().parents[1]
PROGRAM = "backends/ajpf/jackal.gwen"
PERCEPTS = ["movebase_result(_, 3)", "movebase_result(_, 2)", "danger_red", "danger_orange"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--after", default="move", help="'move' (the case study) or 'action' (every action)")
    ap.add_argument("--max-states", type=int, default=100_000)
    ap.add_argument("--smoke", action="store_true", help="one run of the case study's graph (CI)")
    args = ap.parse_args()
    if args.smoke:
        args.repeat, args.after = 1, "move"
    after = "action" if args.after == "action" else [args.after]
    env = environment_from_plan({"percepts": PERCEPTS, "after": after, "at_most": 1})
    best = float("inf")
    graph = None
    for _ in range(max(args.repeat, 1)):
        t0 = time.perf_counter()
        graph = explore(ROOT / PROGRAM, PROGRAM, env, max_states=args.max_states)
        best = min(best, time.perf_counter() - t0)
    assert graph is not None
    print(f"program      {PROGRAM}")
    print(f"environment  {env.describe()}")
    print(f"states       {len(graph.states)}")
    print(f"transitions  {len(graph.transitions)}")
    print(f"complete     {graph.complete}{'' if graph.complete else ' (' + graph.cut + ')'}")
    print(f"depth        {graph.depth}")
    print(f"seconds      {best:.3f} (best of {max(args.repeat, 1)})")


if __name__ == "__main__":
    main()
