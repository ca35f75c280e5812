"""Realizability verdicts are a function of the inputs alone (docs/decisions.md,
"Results never depend on the wall clock"): the checks of the case study and
of the ros2_robot example, run with both cores kept busy (by the parallel
suite's own workers, or by two CPU-burning processes when run alone), give the same findings every time, equal to an idle run's; with
the wall-clock net made as small as a loaded machine made the old one, the
same comparison sees the difference (the control)."""
from __future__ import annotations

import os
import subprocess
import sys
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

import pytest

from rclverify.calculus.health.realizable import realizability_findings
from rclverify.lang.typecheck import load
from rclverify.model.plan.load import load_plan
from rclverify.semantics import wallclock, world

ROOT = Path(__file__).resolve().parents[2]
#: (workspace, contract files): the case study (the Agent is not realizable: a table witness, its model
#: sensitive to the search's path) and the ros2_robot example (ScanGuard's query has a quantifier over a
#: sequence's items, on which quantifier elimination spends its steps slowly).
WORKSPACES = ((ROOT, ["contracts/remote_inspection.rcl"]), (ROOT / "examples" / "ros2_robot", ["contracts/robot.rcl"]))
RUNS = 3
#: CPU-burning processes beside the checks: none in the parallel suite (its own workers keep both cores
#: busy, and a burner's CPU is the suite's time), two when the module runs alone; RCLVERIFY_BURNERS says
BURNERS = int(os.environ.get("RCLVERIFY_BURNERS", "0" if os.environ.get("PYTEST_XDIST_WORKER") else "2"))


@contextmanager
def burning(n: int = BURNERS) -> Iterator[None]:
    """``n`` processes spinning a core each for the duration of the block."""
    procs = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(n)]
    try:
        yield
    finally:
        for p in procs:
            p.kill()
        for p in procs:
            p.wait()


def verdicts() -> dict[str, tuple[object, ...]]:
    """Every node's realizability finding of :data:`WORKSPACES`: id -> (status, model, conflict, query text)."""
    out: dict[str, tuple[object, ...]] = {}
    for root, files in WORKSPACES:
        checked = load([root / f for f in files])
        plan = load_plan(root, "contracts/plan.yaml")
        for node in checked.nodes:
            world.fresh()  # as the health stage does: each node from a fresh Z3 state
            for f in realizability_findings(checked, node, [(x.expr, x.loc) for x in plan.facts.get(node, ())],
                                            plan.instances.get(node)):
                out[f.id] = (f.status, f.model, f.core, f.smt2)
    return out


@pytest.fixture(scope="module")
def idle() -> dict[str, tuple[object, ...]]:
    return verdicts()


def test_the_verdicts_under_load_are_the_idle_ones(idle: dict[str, tuple[object, ...]]) -> None:
    assert idle["Agent.realizable"][0] == "problem" and idle["ScanGuard.realizable"][0] == "ok"
    assert not any(v[0] == "inconclusive" for v in idle.values())
    with burning():
        for _ in range(RUNS):
            assert verdicts() == idle


def test_control_a_net_the_load_outruns_changes_the_verdicts(idle: dict[str, tuple[object, ...]],
                                                            monkeypatch: pytest.MonkeyPatch) -> None:
    """Nets of 0.02 times the budget (the old net of ten times it on a machine fifty times slower): the
    table witness of the Agent is cut, its finding inconclusive, and the comparison above sees it."""
    monkeypatch.setattr(wallclock, "MIN_WALL_MS", 0)
    monkeypatch.setattr(wallclock, "SAFETY_FACTOR", 0.02)
    loaded = verdicts()  # no burners needed: nets of 12 ms are outrun by the Agent's 100 ms queries on any core
    assert loaded != idle
    assert loaded["Agent.realizable"][0] == "inconclusive"
