"""Generated robots on a ``/clock`` that changes its rate and pauses (``--clock-change``, both cores busy),
each kept as its bag and judged offline (the bag holds the raw stamps; the log holds what the live run
placed before the fix).

Seed 1069 (7 nodes, DDS source, x0.5 from 5000 s changing to x0.75, paused for 0.94 s, then x0.75 and
x1): Sensor0 (``sensor_msgs/Range``, on the wall clock: it leads a fuse) published twice while the clock
was paused, both readings stamped 5004.139 s; Relay1 copies each reading's stamp onto its answer, 0.3 s
later.  Both readings' stamps run in another clock (set aside); the answer's copied stamp named the
first message so stamped, so the answer to the second reading was placed at the first (traces/
event_time.py, ``CopiedStamps``): the second reading had no answer of its own within its deadline,
``false`` live, on the log and on the bag of a correct relay.  Which reading the answer answers is not
the run's to say (both carry its stamp): its deadline is now ``undecided``, with why
(backends/monitors/deadline_skew.py, ``published_after``), the answer ``inconclusive``, never red.

Seed 1074 (10 nodes, DDS source, x1.5 from 100 s, x0.5, paused for 0.61 s, x0.5): three relays stamp
their answers to one unstamped reading with their own clock; while it was paused all three stamped
108.302 s.  Placing the k-th copy at the k-th message so stamped (a first attempt at seed 1069) put
Relay4's and Relay8's answers at Relay1's later answer, after the reading they answer and before the
next: ``violated`` on two correct relays.  A relay copies only the stamps of what its node reads (the
contracts: ``CopiedStamps``' ``reads``), and an unstamped reading gives none: the relays' answers are
their own, at their source times: every answer satisfied.

Seed 1072 (8 nodes, rclpy source, x1.5 from 5000 s, x0.75, paused for 0.76 s, x0.75, x1): Sensor0
(``sensor_msgs/Range`` on the wall clock, leading a fuse) stamped three readings with the paused
clock's time, which another sensor had stamped first; all three were placed at that sensor's message,
so Alarm1's answers were read as late: a false deadline, and six verdicts live != log.  Its readings
after the first are now its own, at their source times.
The rules and their controls: tests/traces/test_clock_paused_copies.py.

Seed 1075 (8 nodes, rclpy source, x1.5 from 100 s, x1, paused for 0.67 s, x1, x2): three relays stamp
their answers to one unstamped reading with their own clock.  The clock paused just after Relay6's
answer, so Relay1's and Relay7's answers to the next reading carried Relay6's stamp exactly and were
placed as copies of it, before the reading they answer: its deadline ``false`` at both (live, log and
bag).  By the contracts a relay copies only the stamps of what its node reads, here an unstamped
reading: each answer is its own, every deadline met, live as on the bag.  The rule for an output placed
before its trigger as a copy but published after it (``undecided``, never ``false``:
backends/monitors/deadline_skew.py, ``published_after``) and its control, an answer in the run's clock
stamped beyond the skew before its trigger, which stays ``false``:
tests/backends/test_deadline_heard_late.py."""
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

SEED_1069 = Path(__file__).resolve().parents[1] / "data" / "robot_seed1069"
SEED_1072 = Path(__file__).resolve().parents[1] / "data" / "robot_seed1072"
SEED_1074 = Path(__file__).resolve().parents[1] / "data" / "robot_seed1074"
SEED_1075 = Path(__file__).resolve().parents[1] / "data" / "robot_seed1075"


def _bag_rows(seed: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
              capsys: pytest.CaptureFixture[str]) -> list[Any]:
    """``rclverify monitor --json`` on a copy of the kept workspace ``seed``'s bag: its rows."""
    ws = tmp_path / "ws"
    shutil.copytree(seed, ws)
    monkeypatch.chdir(ws)
    main(["monitor", "-w", str(ws), "--mapping", "mapping.yaml", "--horizon", "1.0", "--json", "runs/bag"])
    rows: list[Any] = json.loads(capsys.readouterr().out)
    return rows


def test_seed_1069_a_relay_copying_stamps_of_a_paused_clock_is_never_red(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    rows = _bag_rows(SEED_1069, tmp_path, monkeypatch, capsys)
    deadlines = {r["node"]: r["deadlines"]["counts"] for r in rows if "deadlines" in r}
    counts = {r["node"]: r["counts"] for r in rows if "counts" in r}
    relay = next(r["deadlines"] for r in rows if r["node"] == "Relay1" and "deadlines" in r)
    assert deadlines["Relay1"]["false"] == 0 and deadlines["Relay1"]["true"] == 24, deadlines["Relay1"]
    assert relay["unaccepted"]["undecided"] == 1 and "a clock standing still" in relay["first_unaccepted"]["reason"]
    assert all(c["false"] == 0 for c in deadlines.values()), deadlines
    assert counts["Relay1"]["satisfied"] == 24 and counts["Relay1"]["inconclusive"] == 1, counts["Relay1"]
    assert all(c["violated"] == 0 for c in counts.values()), counts
    other = [(r["node"], d["declaration"], d["verdict"]) for r in rows for d in r.get("declarations", [])
             if d["verdict"] != "true"]
    assert other == [], other


def test_seed_1075_a_relay_copies_only_its_own_readings_stamp_every_deadline_met(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    """Relay1's and Relay7's answers carry the stamp Relay6's carries on the paused clock: by the stamps
    alone a copy of Relay6's (placed before the reading they answer: a deadline false, then undecided); by
    the contracts each relay reads its own sensor only, so each answer is its own reading's copy: every
    deadline of the three relays met, every answer satisfied."""
    rows = _bag_rows(SEED_1075, tmp_path, monkeypatch, capsys)
    deadlines = {r["node"]: r["deadlines"] for r in rows if "deadlines" in r}
    assert all(d["counts"]["false"] == 0 for d in deadlines.values()), {n: d["counts"] for n, d in deadlines.items()}
    for relay in ("Relay1", "Relay6", "Relay7"):
        assert deadlines[relay]["unaccepted"]["undecided"] == 0 and deadlines[relay]["counts"]["true"] == 25
    assert all(r["counts"]["violated"] == 0 and r["counts"]["inconclusive"] == 0 for r in rows if "counts" in r)
    assert {r["node"]: r["counts"]["satisfied"] for r in rows if "counts" in r and r["node"].startswith("Relay")} \
        == {"Relay1": 25, "Relay6": 25, "Relay7": 25}


def test_seed_1075_live_is_the_bag() -> None:
    """The bag replayed through the online engine (as the live run judged it) gives the bag's verdicts on
    the sensor and its three relays, every deadline met on both."""
    names = ("Sensor0", "Relay1", "Relay6", "Relay7")
    online, bag = finals(_online(SEED_1075, names)), finals(_offline(SEED_1075, "runs/bag", names))
    assert compare(online, bag) == [], [d.text(("live", "bag")) for d in compare(online, bag)]
    undecided = sorted(b[0] for b, rs in online.items() for r in rs if b[1] == "deadline" and r["verdict"] == "undecided")
    assert undecided == [], undecided
    assert not [r for b, rs in online.items() for r in rs if b[1] == "deadline" and r["verdict"] == "false"]


def test_seed_1074_answers_stamped_alike_on_a_paused_clock_are_never_violated(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    rows = _bag_rows(SEED_1074, tmp_path, monkeypatch, capsys)
    counts = {r["node"]: r["counts"] for r in rows if "counts" in r}
    assert all(c["violated"] == 0 for c in counts.values()), counts
    assert all(counts[r]["inconclusive"] == 0 and counts[r]["satisfied"] == 49 for r in ("Relay4", "Relay8")), counts
    assert all(r["deadlines"]["counts"]["false"] == 0 for r in rows if "deadlines" in r)


def test_seed_1072_a_sensor_stamping_a_paused_clocks_time_keeps_its_readings_apart(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    rows = _bag_rows(SEED_1072, tmp_path, monkeypatch, capsys)
    counts = {r["node"]: r["counts"] for r in rows if "counts" in r}
    assert all(c["violated"] == 0 and c["superseded"] == 0 and c["inconclusive"] == 0 for c in counts.values()), counts
    assert all(r["deadlines"]["counts"]["false"] == 0 for r in rows if "deadlines" in r)


def test_seed_1072_live_is_the_bag() -> None:
    names = ("Sensor0", "Sensor3", "Sensor6", "Alarm1", "Alarm2")  # every stamped writer: the copies' first
    online, bag = finals(_online(SEED_1072, names)), finals(_offline(SEED_1072, "runs/bag", names))
    assert compare(online, bag) == [], [d.text(("live", "bag")) for d in compare(online, bag)]
