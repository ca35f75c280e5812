"""Margin targets (docs/statistics.md, "Margin targets"): ``margin of guarantee
K >= M in Q % of answers at L %`` decided from the margins of the runs'
answers, each counted once, by the Clopper-Pearson bound as violation targets
are; the control, the same runs against a larger margin, misses it; the
counts of one run (kept margins, a run with more answers than kept); a margin
target where none belongs is a located plan error."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from msgspec.structs import replace

from rclverify.backends.monitors.margin_target import of_margin
from rclverify.backends.monitors.payload import SpaceMargin
from rclverify.backends.monitors.verdicts import KEPT_MARGINS
from rclverify.cli.commands import main
from rclverify.model.plan.target_text import parse_target

BRAKE = """node Brake{x} {{
  inputs( dist : REAL )
  outputs( speed : REAL )
  topics( std_msgs/Float64 {y}_dist matches(in.dist), std_msgs/Float64 {y}_speed matches(out.speed) )
  assume( TRUE )
  guarantee( out.speed <= in.dist )
}}
"""
PLAN = """name: brakes
contracts: [contracts/brake.rcl]
nodes:
  BrakeA:
    evidence:
      - backend: monitors
        mapping: contracts/mapping.yaml
        traces: [runs/r0.jsonl, runs/r1.jsonl, runs/r2.jsonl]
        target: margin of guarantee 1 >= 0.2 in 90 % of answers at 95 %
  BrakeB:
    evidence:
      - backend: monitors
        mapping: contracts/mapping.yaml
        traces: [runs/r0.jsonl, runs/r1.jsonl, runs/r2.jsonl]
        target: margin of guarantee 1 >= 0.3 in 90 % of answers at 95 %
"""
MARGINS = (0.25, 0.5, 0.75)  # a third of the answers keep 0.25: above A's 0.2, below B's 0.3


def _run(r: int) -> str:
    """Run ``r``: twelve answers per brake, margins 0.25, 0.5, 0.75 in turn (exact in binary)."""
    rows: list[dict[str, Any]] = []
    for i in range(12):
        t, dist = 1.0 + i + r / 10, float(1 + (i + r) % 4)
        for y in "ab":
            rows += [{"topic": f"{y}_dist", "time": t, "data": dist},
                     {"topic": f"{y}_speed", "time": t + 0.01, "data": dist - MARGINS[i % 3]}]
    return "".join(json.dumps(x) + "\n" for x in sorted(rows, key=lambda x: float(x["time"])))


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    ws = tmp_path_factory.mktemp("mt") / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "runs").mkdir()
    (ws / "contracts" / "brake.rcl").write_text(BRAKE.format(x="A", y="a") + BRAKE.format(x="B", y="b"))
    (ws / "contracts" / "plan.yaml").write_text(PLAN)
    (ws / "contracts" / "mapping.yaml").write_text("horizon: 1.0\n")
    for r in range(3):
        (ws / "runs" / f"r{r}.jsonl").write_text(_run(r))
    main(["verify", "-w", str(ws)])
    out: dict[str, Any] = json.loads((ws / "reports" / "assurance.json").read_text(encoding="utf-8"))
    return out


def _runset(report: dict[str, Any], node: str) -> dict[str, Any]:
    [ev] = [e for e in report["evidence"] if e["obligation"] == f"{node}.g1.monitors.runs_unstated_e0"]
    return ev


def test_a_margin_target_met_from_the_answers_margins_with_its_bound(report) -> None:
    ev = _runset(report, "BrakeA")
    assert ev["status"] == "discharged", ev["explanation"]
    # 36 answers (12 in each of 3 distinct runs), none below 0.2: the 95 % bound 1 - 0.05^(1/36)
    assert "0 violating answer(s) in 36" in ev["explanation"] and "0.0798" in ev["explanation"]
    assert "margin of guarantee 1 >= 0.2 in 90 % of answers at 95 %" in ev["explanation"]
    # each run's own record is discharged: a margin target judges a separate claim
    assert all(e["status"] == "discharged" for e in report["evidence"] if "runs_" not in e["obligation"])


def test_the_control_with_a_larger_margin_misses_it(report) -> None:
    ev = _runset(report, "BrakeB")
    assert ev["status"] == "failed", ev["explanation"]
    assert "12 violating answer(s) in 36" in ev["explanation"] and "the target is missed" in ev["explanation"]


def test_one_run_s_counts() -> None:
    row = {"status": "discharged", "answers": 5, "violations": 0, "inconclusive": 1}
    m = [SpaceMargin(guarantee=1, answers=5, undefined=2, lowest=[None, 0.05, 0.2, 0.3, 0.4])]
    got = of_margin(row, m, 1, 0.25, "answer")
    assert (got["answers"], got["violations"], got["inconclusive"]) == (5, 3, 3)  # -inf, 0.05, 0.2 below
    assert (of_margin(row, m, 1, 0.25, "run")["violations"], of_margin(row, m, 1, 0.01, "run")["violations"]) == (1, 1)
    clean = of_margin(row, [replace(m[0], lowest=[0.3, 0.4], undefined=0)], 1, 0.25, "run")
    assert (clean["violations"], clean["inconclusive"]) == (0, 1)
    # more answers than kept, every kept one below: the others are undecided, never clean
    full = [SpaceMargin(guarantee=1, answers=1000, undefined=0, lowest=[0.1] * KEPT_MARGINS)]
    got = of_margin({**row, "inconclusive": 0}, full, 1, 0.5, "answer")
    assert (got["answers"], got["violations"], got["inconclusive"]) == (KEPT_MARGINS, KEPT_MARGINS, 1000 - KEPT_MARGINS)
    # a record that kept only its smallest margin: clean when it is, else one below and the others undecided
    only = [SpaceMargin(guarantee=1, answers=10, undefined=0, margin=0.3, holds=None)]
    assert of_margin({**row, "inconclusive": 0}, only, 1, 0.25, "answer")["violations"] == 0
    got = of_margin({**row, "inconclusive": 0}, only, 1, 0.5, "answer")
    assert (got["answers"], got["violations"], got["inconclusive"]) == (1, 1, 9)


def test_the_text_reads_and_a_bad_one_says_why() -> None:
    t = parse_target("margin of guarantee 2 >= 0.1 in 99 % of answers at 95 %")
    assert (t.margin, t.bound, t.level, t.per, t.guarantee) == (0.1, 0.01, 0.95, "answer", 2)
    assert parse_target("margin of guarantee 1 >= 0.05 in 0.9 of runs at 0.99").per == "run"
    for bad, says in (("margin of guarantee 1 >= 0.1 in 100 % of answers at 95 %", "between 0 and 100 %"),
                      ("margin of guarantee 0 >= 0.1 in 99 % of answers at 95 %", "1-based"),
                      ("margin >= 0.1 in 99 % of answers at 95 %", "a target reads")):
        with pytest.raises(ValueError, match=says):
            parse_target(bad)


def test_a_requirement_may_not_state_one(tmp_path: Path, capsys) -> None:
    ws = tmp_path / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts" / "brake.rcl").write_text(BRAKE.format(x="A", y="a"))
    (ws / "contracts" / "plan.yaml").write_text(
        "name: b\ncontracts: [contracts/brake.rcl]\nrequirements:\n  - id: R\n    text: slow\n"
        "    formal: \"always BrakeA.out.speed <= BrakeA.in.dist\"\n"
        "    target: margin of guarantee 1 >= 0.1 in 99 % of runs at 95 %\n")
    assert main(["verify", "-w", str(ws)]) != 0
    text = "".join(capsys.readouterr())
    assert "contracts/plan.yaml:7:" in text and "a margin target belongs on a node's monitors entry" in text
