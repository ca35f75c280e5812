"""Seeds of the robot generator (bench/robot_generator.py, docs/monitors.md "Generated robots")
whose correct robot the judge gets wrong, kept as their recorded runs and judged offline, as the
runner judges each run's log (`rclverify monitor --json LOG`, live = log on each of them).

Seed 331 (10 nodes, DDS source, ``--clock`` at x1 from 100 s): Relay1 relays an unstamped
``std_msgs/Float32`` reading onto a ``sensor_msgs/Range`` it stamps itself; every fourth answer
carries a stamp 0.2-0.3 ms before the monitor received the reading it answers (both leave one
process at once), within the transport skew of 20 ms.  The guarantee is rightly ``inconclusive``
there (the answer may answer either reading), and so is the reading's deadline: the answer stamped
within the skew before its trigger may be its answer, so the trigger is ``undecided`` with why,
not ``false`` (docs/semantics.md, "Deadlines"; 7 ``false`` deadlines of 32 on a correct node before
the deadline rule read the skew, docs/monitors.md "Faults of rclverify found", fault 6).  The
in-process rule and its controls: tests/backends/test_deadline_skew.py."""
from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest

from rclverify.cli.commands import main

SEED_331 = Path(__file__).resolve().parents[1] / "data" / "robot_seed331"


def _judged(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> list[Any]:
    ws = tmp_path / "ws"
    shutil.copytree(SEED_331, ws)
    monkeypatch.chdir(ws)
    main(["monitor", "-w", str(ws), "--mapping", "mapping.yaml", "--horizon", "1.0", "--json", "runs/live.jsonl"])
    rows: list[Any] = json.loads(capsys.readouterr().out)
    return rows


def _false_deadlines(rows: list[Any]) -> dict[str, int]:
    return {r["node"]: r["deadlines"]["counts"]["false"] for r in rows if "deadlines" in r}


def test_seed_331_every_other_node_meets_its_deadlines_and_no_answer_is_violated(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    rows = _judged(tmp_path, monkeypatch, capsys)
    false = _false_deadlines(rows)
    assert len(false) >= 5 and all(n == 0 for node, n in false.items() if node != "Relay1"), false
    assert all(r["counts"]["violated"] == 0 for r in rows if "counts" in r)


def test_seed_331_a_relay_answer_stamped_just_before_its_trigger_is_no_false_deadline(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    rows = _judged(tmp_path, monkeypatch, capsys)
    assert _false_deadlines(rows)["Relay1"] == 0
    relay = next(r["deadlines"] for r in rows if r["node"] == "Relay1" and "deadlines" in r)
    # the seven readings an answer stamped just before them may answer are undecided, with why; the rest met
    assert relay["unaccepted"]["undecided"] == 7 and relay["counts"]["true"] == 25
    assert "within the transport skew of 20 ms" in relay["first_unaccepted"]["reason"]
