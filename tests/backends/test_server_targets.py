"""A ``target:`` on a service or action server counts its judged calls and goals (issue 106;
docs/statistics.md, "What a run counts"): a run's answers are those judged on its topics and those judged
on its calls and goals, each once.  Before, a server's target counted only its undecided calls and read
``pending: no judged answer yet`` whatever the run showed, so ``--strict`` could never pass."""
from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.backend import MonitorsBackend
from rclverify.stages.workspace import Workspace

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "ros2_robot"
#: A target the bundled run's few answers meet at 90 % when each is counted (0 in n needs n >= 2).
TARGET = "violation probability <= 80 % at 90 % per answer"


def _workspace(tmp: Path, traces: list[str]) -> Workspace:
    """The ros2_robot example's contracts, mapping, interfaces and recorded run (its live log and its bag),
    with one monitors entry per server and a target on it."""
    for rel in ("contracts/robot.rcl", "contracts/mapping.yaml", "runs/robot.jsonl"):
        (tmp / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(EXAMPLE / rel, tmp / rel)
    shutil.copytree(EXAMPLE / "interfaces", tmp / "interfaces")
    shutil.copytree(EXAMPLE / "runs" / "robot", tmp / "runs" / "robot")
    entry = {"backend": "monitors", "mapping": "contracts/mapping.yaml", "traces": traces, "target": TARGET}
    (tmp / "contracts/plan.yaml").write_text(json.dumps({"contracts": ["contracts/robot.rcl"], "nodes": {
        "EStop": {"evidence": [entry]}, "Dock": {"evidence": [entry]}}}), encoding="utf-8")
    return Workspace(tmp)


def _runset(ws: Workspace, node: str) -> tuple[Any, list[Any]]:
    """The run-set evidence of ``node``'s entry and the evidence of each of its runs."""
    target, backend = ws.target(node, 0), MonitorsBackend()
    obligations = backend.export(target)
    (ob,) = [o for o in obligations if o.data.get("run_set") is not None]
    return backend.run(ob, target), [backend.run(o, target) for o in obligations if o is not ob]


@pytest.mark.parametrize("node", ["EStop", "Dock"])
def test_a_servers_target_counts_its_judged_calls_and_goals_once(tmp_path: Path, node: str) -> None:
    ev, runs = _runset(_workspace(tmp_path, ["runs/robot.jsonl", "runs/robot"]), node)
    judged = [r.details["calls"]["counts"] for r in runs]
    answers = [c["satisfied"] + c["violated"] for c in judged]
    assert all(r.status == "discharged" for r in runs) and answers[0] == answers[1] > 0  # the log and its bag
    s = ev.details["statistics"]
    assert [r["answers"] for r in s["runs"]] == answers  # each run counts its calls' (or goals') answers
    # one run in two forms: counted once, its answers once
    assert (s["counts"]["runs"], s["counts"]["duplicates"], s["counts"]["answers"]) == (1, 1, answers[0])
    assert ev.status == "discharged" and "0 violating answer(s) in" in ev.explanation, ev.explanation


def test_the_control_a_server_with_no_call_in_its_run_stays_pending(tmp_path: Path) -> None:
    """The other side: a run where the server answered nothing gives its target nothing to count."""
    ws = _workspace(tmp_path, ["runs/quiet.jsonl"])
    lines = [json.loads(x) for x in (tmp_path / "runs/robot.jsonl").read_text(encoding="utf-8").splitlines()]
    quiet = [x for x in lines if "estop" not in json.dumps(x)]
    (tmp_path / "runs/quiet.jsonl").write_text("".join(json.dumps(x) + "\n" for x in quiet), encoding="utf-8")
    ev, _ = _runset(ws, "EStop")
    assert ev.details["statistics"]["counts"]["answers"] == 0
    assert ev.status == "pending" and "no judged answer yet" in ev.explanation, ev.explanation
