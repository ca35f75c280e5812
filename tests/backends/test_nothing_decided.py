"""Nothing decided is never green, and undecided is never failed:

* a run where every answer is undecided (a NaN on every input) fails
  `rclverify monitor --strict` with the item named, while the control, a run
  with decided answers, passes it;
* a statistical target missed only through undecided answers is
  inconclusive, never failed; decided violations still fail it;
* a run's identity for statistics is what it carries: a log written again
  with another key order, spacing or blank lines is the same run, a bag
  written again in another storage too; another message is another run.
"""
from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.runset import run_digest
from rclverify.cli.commands import main
from rclverify.model.plan.target_text import parse_target
from rclverify.records.statistics import decide

FILTER = """
node Filter {
  inputs( x : REAL )
  outputs( y : REAL )
  topics( std_msgs/Float64 x matches(in.x), std_msgs/Float64 y matches(out.y) )
  assume( TRUE )
  guarantee( out.y >= in.x )
}
"""


def _bag(path: Path, rows: list[tuple[str, float, float]], storage: str = "sqlite3") -> Path:
    from rosbags.rosbag2 import StoragePlugin, Writer

    from rclverify.traces.bag import typestore
    store = typestore([])
    f64 = store.types["std_msgs/msg/Float64"]
    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    with Writer(path, version=9, storage_plugin=plugin) as w:
        conns: dict[str, Any] = {}
        for topic, t, v in rows:
            conn = conns.get(topic) or conns.setdefault(
                topic, w.add_connection("/" + topic, "std_msgs/msg/Float64", typestore=store))
            w.write(conn, round(t * 1e9), store.serialize_cdr(f64(data=v), "std_msgs/msg/Float64"))
    return path


def _ws(tmp: Path) -> Path:
    (tmp / "contracts").mkdir()
    (tmp / "contracts" / "c.rcl").write_text(FILTER)
    (tmp / "contracts" / "plan.yaml").write_text("contracts: [contracts/c.rcl]\n")
    return tmp


def test_a_run_where_nothing_was_decided_fails_strict(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ws = _ws(tmp_path)
    nan = _bag(tmp_path / "nan", [("x", 1.0, math.nan), ("y", 1.1, 2.0), ("x", 2.0, math.nan), ("y", 2.1, 3.0)])
    assert main(["monitor", "-w", str(ws), str(nan)]) == 0  # no violation: without --strict, exit 0 as before
    capsys.readouterr()
    assert main(["monitor", "-w", str(ws), "--strict", str(nan)]) == 1
    out = capsys.readouterr()
    assert "not judged: node Filter (Filter): nothing decided" in out.out
    # the control: decided answers pass --strict
    fine = _bag(tmp_path / "fine", [("x", 1.0, 1.0), ("y", 1.1, 2.0), ("x", 2.0, 2.5), ("y", 2.1, 3.0)])
    assert main(["monitor", "-w", str(ws), "--strict", str(fine)]) == 0


def test_a_target_missed_only_through_undecided_answers_is_inconclusive() -> None:
    t = parse_target("violation probability <= 0.1 at 95 % per answer")
    assert decide({"answers": 0, "violations": 0, "inconclusive": 95}, t)["status"] == "inconclusive"
    d = decide({"answers": 20, "violations": 1, "inconclusive": 75}, t)
    assert d["status"] == "inconclusive" and "only if the 75 undecided" in d["explanation"]
    assert decide({"answers": 95, "violations": 30, "inconclusive": 0}, t)["status"] == "failed"
    assert decide({"answers": 95, "violations": 30, "inconclusive": 40}, t)["status"] == "failed"
    runs = parse_target("violation probability <= 0.1 at 95 % per run")
    assert decide({"runs": 60, "violating_runs": 0, "undecided_runs": 60}, runs)["status"] == "inconclusive"


def test_a_reformatted_log_is_the_same_run(tmp_path: Path) -> None:
    lines = [{"topic": "x", "time": 1.0, "data": 1.5}, {"topic": "y", "time": 1.1, "data": 2.0}]
    (tmp_path / "a.jsonl").write_text("".join(json.dumps(x) + "\n" for x in lines))
    (tmp_path / "b.jsonl").write_text("\n".join(json.dumps(dict(reversed(list(x.items()))), indent=None,
                                                           separators=(" , ", " : ")) + "\n" for x in lines) + "\n\n")
    (tmp_path / "c.jsonl").write_text("".join(json.dumps({**x, "data": x["data"] + 1}) + "\n" for x in lines))
    assert run_digest(tmp_path, "a.jsonl") == run_digest(tmp_path, "b.jsonl")
    assert run_digest(tmp_path, "a.jsonl") != run_digest(tmp_path, "c.jsonl")


def test_a_bag_written_again_in_another_storage_is_the_same_run(tmp_path: Path) -> None:
    rows = [("x", 1.0, 1.0), ("y", 1.1, 2.0)]
    _bag(tmp_path / "sq", rows)
    _bag(tmp_path / "mc", rows, "mcap")
    _bag(tmp_path / "other", [("x", 1.0, 1.0), ("y", 1.1, 2.5)])
    assert run_digest(tmp_path, "sq") == run_digest(tmp_path, "mc")
    assert run_digest(tmp_path, "sq") != run_digest(tmp_path, "other")
