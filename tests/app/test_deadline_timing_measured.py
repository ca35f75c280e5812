"""A proved end-to-end deadline is no pass while a hop's deadline is measured
by no run (issue 64): a timed guarantee discharged by a property test (which
checks its formula only) leaves the deadline's chain evidence outstanding and
fails --strict, saying so; a recorded run that times it (monitors) passes."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from rclverify.cli.commands import main

RELAY = """node Relay {
  inputs( x : BOOL )
  outputs( y : BOOL )
  topics( std_msgs/Bool x matches(in.x), std_msgs/Bool y matches(out.y) )
  assume( TRUE )
  guarantee( out.y == in.x ) triggered by in.x within 50 ms
}
"""
PLAN = """name: relay
contracts: [contracts/relay.rcl]
requirements:
  - id: ECHO
    text: The relay echoes its input within 100 ms.
    deadline: {path: [Relay], within: 100 ms}
    supported_by: [{node: Relay, guarantees: [1]}]
nodes:
  Relay:
    evidence:
      - {backend: property_tests, implementation: impl/relay.py:relay, max_examples: 10}
"""
RUN = [{"topic": "x", "time": 1.0, "data": True}, {"topic": "y", "time": 1.02, "data": True},
       {"topic": "x", "time": 2.0, "data": False}, {"topic": "y", "time": 2.01, "data": False}]


@pytest.fixture(scope="module")
def relay(tmp_path_factory: pytest.TempPathFactory) -> Path:
    ws = tmp_path_factory.mktemp("timing") / "relay"
    for d in ("contracts", "impl", "runs"):
        (ws / d).mkdir(parents=True)
    (ws / "contracts" / "relay.rcl").write_text(RELAY, encoding="utf-8")
    (ws / "impl" / "relay.py").write_text("def relay(x: bool) -> dict[str, bool]:\n    return {'y': x}\n")
    (ws / "runs" / "run.jsonl").write_text("".join(json.dumps(x) + "\n" for x in RUN), encoding="utf-8")
    return ws


def _verify(ws: Path, plan: str) -> tuple[int, dict[str, Any]]:
    (ws / "contracts" / "plan.yaml").write_text(plan, encoding="utf-8")
    rc = main(["verify", "-w", str(ws), "--strict"])
    return rc, json.loads((ws / "reports" / "assurance.json").read_text(encoding="utf-8"))


def test_a_hop_timed_by_no_run_leaves_the_deadline_open(relay):
    rc, report = _verify(relay, PLAN)
    [d] = report["deadlines"]
    [hop] = d["chain"]
    assert d["verdict"] == "proved" and hop["status"] == "pending" and "measured by no run" in hop["timing"]
    assert rc == 1 and not report["meta"]["strict_ok"]
    summary = json.loads((relay / "artifacts" / "report" / "summary.json").read_text(encoding="utf-8"))
    assert any("proved from a chain whose evidence is outstanding" in r for r in summary["strict"])


def test_a_recorded_run_that_times_it_closes_it(relay):
    rc, report = _verify(relay, PLAN + "      - {backend: monitors, traces: [runs/run.jsonl]}\n")
    [d] = report["deadlines"]
    assert d["chain"][0]["status"] == "discharged" and "timing" not in d["chain"][0]
    assert rc == 0 and report["meta"]["strict_ok"]
