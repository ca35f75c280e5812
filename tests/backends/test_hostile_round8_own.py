"""Hostile round eight, the cases of our own pass on this round's surfaces
(one clock per run, a run's identity, the lean install): each was a wrong
green or an unlocated failure before its fix, each with its control."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from _blocked import cli_without
from rclverify.backends.monitors import recorded
from rclverify.backends.monitors.config import load_mapping
from rclverify.backends.monitors.runset import run_digest
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "safety_stop"
WALL = 1_700_000_000.0

def _stamp(t: float) -> dict[str, Any]:
    return {"header": {"stamp": {"secs": int(t), "nsecs": round((t % 1) * 1e9)}}}


def _statuses(trace: Path) -> list[str]:
    checked = check([parse_text((EXAMPLE / "contracts" / "safety_stop.rcl").read_text(), "s.rcl")])
    run = recorded.check_recorded(checked, [checked.nodes["Base"]], load_mapping(EXAMPLE, None), EXAMPLE,
                                  str(trace), lambda w: None)
    return [run.verdict(r, str(trace))[0] for r in run.results]


def test_stamps_in_simulated_time_beside_the_wall_clock_are_not_ordered_as_one_clock(tmp_path: Path) -> None:
    """The requests carry header stamps in simulated time (100 s), the responses none (the wall clock):
    ordered by one key, every response would come after every request, and the reorder buffer would
    hold the whole run.  The requests' writer is named as another clock (its measured offset) and its
    messages are placed at their recorded times (issue 106: before, the verdicts were withheld, and the
    reds stood); the seeded defect (a request refused) is still found on the placed run."""
    rows = [{"topic": "estop/request", "time": WALL + 0.0, **_stamp(100.0), "data": True},
            {"topic": "estop/response", "time": WALL + 0.1, "success": True},
            {"topic": "estop/request", "time": WALL + 1.0, **_stamp(101.0), "data": True},
            {"topic": "estop/response", "time": WALL + 1.1, "success": True}]
    trace = tmp_path / "two_clocks.jsonl"
    trace.write_text("".join(json.dumps(r) + "\n" for r in rows))
    checked = check([parse_text((EXAMPLE / "contracts" / "safety_stop.rcl").read_text(), "s.rcl")])
    run = recorded.check_recorded(checked, [checked.nodes["Base"]], load_mapping(EXAMPLE, None), EXAMPLE,
                                  str(trace), lambda w: None)
    status, text = run.verdict(run.results[0], str(trace))
    assert status == "discharged" and "/estop/request: header stamps -1699999900.000 s" in text, text
    assert "another clock (2 of 2 stamped message(s)" in text and "placed at their source times" in text, text
    # the seeded defect on the same two clocks: a refused stop is red, on the placed run
    bad = [*rows[:3], {**rows[3], "success": False}]
    trace.write_text("".join(json.dumps(r) + "\n" for r in bad))
    assert _statuses(trace) == ["failed"]
    # the control: the same run on one clock (every message stamped) is judged, and green
    one = [{**r, **_stamp(r["time"] - WALL + 100.0)} for r in rows]
    trace.write_text("".join(json.dumps(r) + "\n" for r in one))
    assert _statuses(trace) == ["discharged"]


def test_a_number_written_another_way_is_the_same_run(tmp_path: Path) -> None:
    (tmp_path / "a.jsonl").write_text('{"topic": "x", "time": 1, "data": 2}\n')
    (tmp_path / "b.jsonl").write_text('{"topic": "x", "time": 1.0, "data": 2e0}\n')
    (tmp_path / "c.jsonl").write_text('{"topic": "x", "time": 1.0, "data": 2.5}\n')
    assert run_digest(tmp_path, "a.jsonl") == run_digest(tmp_path, "b.jsonl") != run_digest(tmp_path, "c.jsonl")


@pytest.mark.parametrize("blocked,args,words", [
    ("rosbags", ["monitor", "-w", str(EXAMPLE), "BAG"], "reading a bag needs rclverify's [ros] extra"),
    ("cryptography", ["bundle", "--keygen", "KEY"], "needs rclverify's [sign] extra"),
])
def test_a_missing_extra_on_the_command_line_is_one_line(tmp_path: Path, blocked: str, args: list[str],
                                                         words: str) -> None:
    bag = tmp_path / "run.mcap"
    bag.write_bytes(b"\x89MCAP0\r\n")
    args = [str(bag) if a == "BAG" else str(tmp_path / "key") if a == "KEY" else a for a in args]
    r = cli_without(blocked, *args, cwd=tmp_path)
    assert r.returncode in (1, 2) and "Traceback" not in r.stderr, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and words in lines[0], r.stderr
