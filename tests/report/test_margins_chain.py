"""Time margins of an end-to-end deadline's chain, hop by hop, on the recorded
run of the ros2_robot example (docs/semantics.md, "Time margin of a chain"):
the hop's smallest margin is the one the live monitor's own deadline verdicts
recorded in the same log; the chain's measured margin is the bound less the
hop's worst latency; a hop no run timed leaves the chain without one."""
from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest

from _report_schema import check_report
from rclverify.cli.commands import main

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "ros2_robot"
PLAN = """name: ros2_robot margins
contracts: [contracts/robot.rcl]
requirements:
  - id: STOP-NEAR
    text: The base is told to stop within 150 ms of a scan with a near beam.
    deadline: {path: [ScanGuard], within: 150 ms}
    supported_by: [{node: ScanGuard, guarantees: [1]}]
nodes:
  ScanGuard:
    evidence:
      - {backend: monitors, mapping: contracts/mapping.yaml, traces: [runs/robot.jsonl]}
"""


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    ws = tmp_path_factory.mktemp("chain") / "robot"
    shutil.copytree(EXAMPLE / "contracts", ws / "contracts")
    (ws / "runs").mkdir()
    shutil.copy(EXAMPLE / "runs" / "robot.jsonl", ws / "runs" / "robot.jsonl")
    (ws / "contracts" / "plan.yaml").write_text(PLAN, encoding="utf-8")
    assert main(["verify", "-w", str(ws)]) == 0
    out: dict[str, Any] = json.loads((ws / "reports" / "assurance.json").read_text(encoding="utf-8"))
    out["_md"] = (ws / "reports" / "assurance.md").read_text(encoding="utf-8")
    return out


def _live_margins() -> list[int]:
    """The margins (ns) of ScanGuard's deadline verdicts the live monitor wrote into the run's log."""
    out = []
    for line in (EXAMPLE / "runs" / "robot.jsonl").read_text(encoding="utf-8").splitlines():
        rec = json.loads(line)
        v = rec.get("verdict") if rec.get("topic") == "rclverify/verdict" and rec.get("kind") == "deadline" else None
        if v and v["node"] == "ScanGuard" and v["verdict"] == "true":
            out.append(round((v["due"] - v["answer"]) * 1e9))
    return out


def test_each_hop_has_its_smallest_time_margin(report):
    [d] = report["deadlines"]
    [hop] = d["chain"]
    m = hop["time_margin"]
    live = _live_margins()
    assert len(live) == m["answers"] == 6 and m["unanswered"] == 0
    # the recorded run's monitor and the live monitor's verdicts agree on the smallest (within the log's float)
    assert abs(m["margin_ns"] - min(live)) <= 1000 and 0 < m["margin_ns"] < 100_000_000
    assert m["obligation"] == "ScanGuard.g0.monitors.robot_jsonl" and m["trigger_where"] and m["answer_where"]
    # the chain's: 150 ms less the hop's worst latency (100 ms less its margin)
    assert d["time_margin_ns"] == 150_000_000 - (100_000_000 - m["margin_ns"])
    assert d["time_margin"] == f"{d['time_margin_ns'] / 1e6:.3f} ms"
    assert f"measured margin {d['time_margin']}" in report["_md"]
    check_report({k: v for k, v in report.items() if not k.startswith("_")})  # the schema declares the hops' margins


def test_a_hop_no_run_timed_has_none():
    from fractions import Fraction
    from msgspec.structs import replace
    from rclverify.records.deadline_rows import DeadlineHop
    from rclverify.backends.monitors.payload import TimeMarginItem
    from rclverify.report.chain_margins import chain_margin, hop_margin
    assert hop_margin(1, []) is None
    hop = DeadlineHop(node="A", guarantee=1, trigger="in.x", outputs=["y"], within_s="1/10", within="100 ms",
                      loc="a.rcl:1:1", time_margin=None)
    assert chain_margin(Fraction(3, 20), [hop]) is None
    # a trigger never answered: its latency is unbounded, so the chain has no measured margin either
    margin = TimeMarginItem(guarantee=1, margin_ns=5_000_000, answers=2, unanswered=1, trigger_where="t",
                            answer_where="a")
    hop = replace(hop, time_margin=hop_margin(1, [("o", [margin])]))
    assert hop.time_margin and hop.time_margin.margin_ns == 5_000_000 and chain_margin(Fraction(3, 20), [hop]) is None
    # every trigger answered: the bound less the hop's worst latency (100 ms less its 5 ms margin)
    hop = replace(hop, time_margin=hop_margin(1, [("o", [replace(margin, unanswered=0)])]))
    assert chain_margin(Fraction(3, 20), [hop]) == 150_000_000 - (100_000_000 - 5_000_000)
