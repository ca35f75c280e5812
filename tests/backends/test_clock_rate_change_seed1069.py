"""Generated robot 1069 (7 nodes, DDS source, ``/clock`` x0.5 from 5000 s changing to x0.75, paused for
0.94 s, then x0.75 and x1: ``--clock-change``, both cores busy), kept as its bag and judged offline.

Sensor0 (``sensor_msgs/Range``, on the wall clock: it leads a fuse) published twice while the clock was
paused, both readings stamped 5004.139 s; Relay1 copies each reading's stamp onto its answer, 0.3 s
later.  Both readings' stamps run in another clock (set aside); the answer's copied stamp named the
first message so stamped, so the answer to the second reading was placed at the first (traces/
event_time.py, ``CopiedStamps``): the second reading had no answer of its own within its deadline,
``false`` live, on the log and on the bag of a correct relay, and the answer ``inconclusive``.  A copy
of a stamp shared by several messages of its writer (a clock standing still) now names them in order,
the k-th copy the k-th message: every deadline of the relay met, every answer satisfied.  The bag holds
the raw stamps (its log holds what the live run placed before the fix).  The rule and its control:
tests/traces/test_clock_paused_copies.py."""
from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest

from rclverify.cli.commands import main

SEED_1069 = Path(__file__).resolve().parents[1] / "data" / "robot_seed1069"


def test_seed_1069_a_relay_copying_stamps_of_a_paused_clock_meets_every_deadline(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    ws = tmp_path / "ws"
    shutil.copytree(SEED_1069, ws)
    monkeypatch.chdir(ws)
    main(["monitor", "-w", str(ws), "--mapping", "mapping.yaml", "--horizon", "1.0", "--json", "runs/bag"])
    rows: list[Any] = json.loads(capsys.readouterr().out)
    deadlines = {r["node"]: r["deadlines"]["counts"] for r in rows if "deadlines" in r}
    counts = {r["node"]: r["counts"] for r in rows if "counts" in r}
    assert deadlines["Relay1"]["false"] == 0 and deadlines["Relay1"]["true"] == 25, deadlines["Relay1"]
    assert all(c["false"] == 0 for c in deadlines.values()), deadlines
    assert counts["Relay1"]["satisfied"] == 25 and counts["Relay1"]["inconclusive"] == 0, counts["Relay1"]
    assert all(c["violated"] == 0 for c in counts.values()), counts
    other = [(r["node"], d["declaration"], d["verdict"]) for r in rows for d in r.get("declarations", [])
             if d["verdict"] != "true"]
    assert other == [], other
