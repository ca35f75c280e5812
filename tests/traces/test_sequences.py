"""Sequences on the wire: `sensor_msgs/LaserScan.ranges` (an unbounded float32
sequence) into a `seq(REAL)` input, judged offline from a ROS 2 bag and from
a log (traces/mapping.py, the sequence rule).  Before, every message read
"no mapping rule for a variable of type seq(REAL)": every check of a scan
node inconclusive.  A right and a wrong minimum over the ranges; an infinity
among them (a beam with no return) is no RCL number: undecided, with the
reason."""
from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from _scan import scan_bag
from rclverify.cli.commands import main

SCAN = """
node Scan {
  inputs( ranges : seq(REAL) )
  outputs( closest : REAL )
  topics( sensor_msgs/LaserScan scan matches(in.ranges), std_msgs/Float64 closest matches(out.closest) )
  assume( TRUE )
  guarantee( out.closest in in.ranges and forall(r in in.ranges | out.closest <= r) )
}
"""


def _ws(tmp: Path) -> Path:
    (tmp / "contracts").mkdir()
    (tmp / "contracts" / "c.rcl").write_text(SCAN)
    (tmp / "contracts" / "plan.yaml").write_text("contracts: [contracts/c.rcl]\n")
    (tmp / "mapping.yaml").write_text("topics:\n  scan: {fields: [ranges]}\n  closest: {fields: [data]}\n")
    return tmp


def _bag(path: Path, ranges: list[float], closest: float) -> Path:
    return scan_bag(path, ranges, "closest", "Float64", closest)


def _monitor(ws: Path, run: Path, capsys: pytest.CaptureFixture[str]) -> tuple[int, str]:
    code = main(["monitor", "-w", str(ws), "--mapping", "mapping.yaml", "--horizon", "1", str(run)])
    return code, capsys.readouterr().out


def test_a_right_and_a_wrong_minimum_over_laserscan_ranges(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ws = _ws(tmp_path)
    code, out = _monitor(ws, _bag(tmp_path / "right", [3.0, 2.5, 4.0], 2.5), capsys)
    assert code == 0 and "1 satisfied" in out
    code, out = _monitor(ws, _bag(tmp_path / "wrong", [3.0, 2.5, 4.0], 3.0), capsys)
    assert code == 1 and "1 violated" in out


def test_a_log_with_an_array_field(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ws = _ws(tmp_path)
    run = tmp_path / "run.jsonl"
    run.write_text(json.dumps({"topic": "scan", "time": 1.0, "ranges": [1.5, 0.75]}) + "\n"
                   + json.dumps({"topic": "closest", "time": 1.01, "data": 0.75}) + "\n")
    assert _monitor(ws, run, capsys)[0] == 0


def test_an_infinite_range_is_undecided_with_the_reason(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ws = _ws(tmp_path)
    code, out = _monitor(ws, _bag(tmp_path / "inf", [3.0, math.inf, 4.0], 3.0), capsys)
    assert code == 0 and "inconclusive" in out and "item 1 of field 'ranges' is inf" in out


def test_a_plan_statement_quantifies_over_a_sequence_and_its_counterexample_reads_as_rcl(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """`forall(r in Scan.in.ranges | ...)` in a requirement: before, "unknown type or set '__q0____'"
    (the binder's domain was read as a type); the counterexample printed Z3's `seq.unit(2)`."""
    ws = _ws(tmp_path)
    (ws / "contracts" / "plan.yaml").write_text(
        "contracts: [contracts/c.rcl]\nrequirements:\n  - id: R1\n    text: the closest range is positive\n"
        "    formal: \"forall(r in Scan.in.ranges | r > 0) -> Scan.out.closest > 1\"\n")
    main(["requirements", "-w", str(ws)])  # the statement checks, and Z3 decides it
    out = capsys.readouterr().out
    assert "R1: refuted" in out and "in.ranges = <" in out and "seq." not in out, out


def test_a_sequence_model_value_is_written_as_a_sequence_literal() -> None:
    import z3

    from rclverify.semantics.modeltext import value_to_rcl
    s = z3.Solver()
    x = z3.Const("x", z3.SeqSort(z3.RealSort()))
    s.add(z3.Length(x) == 3, x[0] == 1.5, x[1] == 2, x[2] == 0.25)
    assert s.check() == z3.sat
    assert value_to_rcl(s.model()[x]) == "<1.5, 2, 0.25>"
    assert value_to_rcl(z3.Empty(z3.SeqSort(z3.IntSort()))) == "<>"
