"""Generated seed 1147 (6 nodes, rclpy source, ``--clock-change``: x0.75 from 5000 s, x0.5, paused for
0.67 s, x0.5, x2; one CPU burner beside), kept as its bag and judged offline.

Sensor0 publishes an unstamped ``std_msgs/Float32`` every 200 ms on the wall clock; Relay1, Relay2,
Relay4 and Relay5 answer each reading 25-54 ms later with a ``sensor_msgs/Range`` stamped with their
own (simulated) clock.  While the clock was paused every answer carried one stamp, 5005.194 s, first
written by Relay1's answer to the reading before the pause; the answers of Relay2, Relay4 and Relay5
to the next three readings carry it too.  Taken for copies of Relay1's answer, they were placed one
reading early when the k-th copy named the k-th message so stamped (``violated`` x2 at each of the
three correct relays, live, on the log and on the bag), and all at Relay1's first answer when every
copy named the first (three readings in a row with no answer placed among them: each relay's
``progress( within 2 steps )`` ``false``).  A stamp standing still is copied only by a writer that
copied two fresh stamps of its first writer before (traces/event_time.py, ``CopiedStamps``): no answer
violated, no deadline false, every relay's progress ``true``.  An output placed before its
publication keeps a row it may answer from ``false`` (backends/monitors/declarations.py; the rule and
its controls: tests/backends/test_declarations_copied_stamps.py).  The bag replayed through the online
engine gives the bag's verdicts, one by one.
"""
from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path
from typing import Any

import pytest

from rclverify.cli.commands import main

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
from _robot_verdicts import compare, finals  # noqa: E402
from test_generated_seed_faults import _offline, _online  # noqa: E402

SEED_1147 = Path(__file__).resolve().parents[1] / "data" / "robot_seed1147"
RELAYS = ("Relay2", "Relay4", "Relay5")


def _rows(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> list[Any]:
    """The bag's rows, as ``rclverify monitor --json`` prints them."""
    ws = tmp_path / "ws"
    shutil.copytree(SEED_1147, ws)
    monkeypatch.chdir(ws)
    main(["monitor", "-w", str(ws), "--mapping", "mapping.yaml", "--horizon", "1.0", "--json", "runs/bag"])
    rows: list[Any] = json.loads(capsys.readouterr().out)
    return rows


def test_no_answer_of_a_correct_relay_is_violated_on_the_paused_clock(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    rows = _rows(tmp_path, monkeypatch, capsys)
    counts = {r["node"]: r["counts"] for r in rows if "counts" in r}
    assert all(c["violated"] == 0 for c in counts.values()), counts
    assert counts["Relay1"]["satisfied"] == 48 and counts["Sensor0"]["satisfied"] == 48, counts
    deadlines = {r["node"]: r["deadlines"] for r in rows if "deadlines" in r}
    assert all(d["counts"]["false"] == 0 for d in deadlines.values()), {n: d["counts"] for n, d in deadlines.items()}
    assert deadlines["Relay1"]["counts"]["true"] == 48, deadlines["Relay1"]


def test_every_relays_progress_is_true(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    rows = _rows(tmp_path, monkeypatch, capsys)
    decl = {(r["node"], d["declaration"]): d for r in rows for d in r.get("declarations", [])}
    assert [k for k, d in decl.items() if d["verdict"] == "false"] == [], decl
    for relay in RELAYS:  # their answers during the pause are their own now (a stamp standing still is
        # copied only by a writer that copied two fresh stamps of its first writer: CopiedStamps), placed
        # among the readings they answer
        d = decl[(relay, "progress")]
        assert d["verdict"] == "true", d
    assert decl[("Relay1", "periodic out.r")]["verdict"] == "true", decl
    assert decl[("Sensor0", "periodic out.x")]["verdict"] == "true", decl


def test_the_online_engine_gives_the_bags_verdicts() -> None:
    names = ("Sensor0", "Relay1", *RELAYS)
    online, bag = finals(_online(SEED_1147, names)), finals(_offline(SEED_1147, "runs/bag", names))
    assert compare(online, bag) == [], [d.text(("live", "bag")) for d in compare(online, bag)]
