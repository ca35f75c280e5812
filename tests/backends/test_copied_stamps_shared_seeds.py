"""Generated robots whose stamp-copying relay shares each stamp with another writer, kept as their bags
(``--clock-change``, one CPU burner beside) and judged offline and through the online engine.  All are
correct robots whose relays the rule by stamps alone got wrong (below); by the contracts' rule (the last
paragraph) every relay is never violated, and the online engine gives the bag's verdicts.

Seed 1178 (9 nodes, rclpy source, x0.75 from 100 s, x2, paused for 0.75 s, x2): Relay4 and Relay3
both copy the header stamp of Sensor0's ``sensor_msgs/Range`` onto their answers, 127 and 211 ms after each reading.
Relay4's copy is always heard first, so every stamp Relay3 copies has been heard twice already (the
reading and Relay4's copy) and stands still for ``CopiedStamps`` (traces/event_time.py), which takes a
stamp standing still for a copy only from a writer that copied two fresh stamps of its first writer
before; Relay3 never copies a fresh one, so each of its answers is placed at its source time and judged
against the latest reading: 55 ``violated`` of 67 on a correct relay, live, log and bag (inconclusive 2,
satisfied 65 where every stamp heard again was a copy).

Seed 1187 (10 nodes, DDS source, x1.5 from 100 s, paused for 0.53 s, x1.5, x0.75, x1): three relays
copy Sensor0's stamps, 142, 261 and 478 ms after each reading; Relay5's copy is heard first, and the
two after it are never copies: 19 ``violated`` at Relay3 and 34 at Relay6, all three relays correct
(every answer satisfied or undecided where every stamp heard again was a copy).

Seed 1149 (9 nodes, rclpy source, x1 from 100 s, x1.5, paused for 0.74 s, x1.5): Relay1 copies
Sensor0's stamp about 496 ms after each reading; Sensor5 stamps the same simulated clock and often writes the same
stamp within one tick (not a copy: within the transport skew), so the stamp stands still with Sensor5
its first writer, of whose stamps Relay1 copied none: two answers placed at their source times,
``violated`` on a correct relay, live, log and bag.

The stamps alone do not say which writer a message copies; the contracts do: a node copies only the
stamps of the topics it reads (Relay3 reads Sensor0's topic, not Relay4's; Relay1 reads Sensor0's, not
Sensor5's): ``CopiedStamps``' ``reads``, from backends/monitors/node_topics.py ``copy_sources``.

Seed 1271 (10 nodes, DDS source, x0.75 from 0 s, x1.5, paused for 0.8 s, x1.5): Sensor0 writes three
readings stamped alike while the clock stands still (0.41, 0.41, 1.26, 300 ms apart), and Relay4 copies
each 510 ms later; both copies are placed at the first reading so stamped, and the live log writes each
with that placement as its header stamp (``with_stamp``, its own kept as ``header.stamp_aside``).  The
second copy (1.26) was published 1.11 s after that placement, beyond ``STAMP_BEHIND_S``: read back from
the log as a stamp in another clock, it was set aside again and placed at its source time, where it
answered the reading after the three (1.0068, the two before it superseded): ``violated`` on the log,
no verdict live and on the bag.  A stamp carried so (``event_time.carried``) is the run's clock's."""
from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
from _robot_verdicts import compare, finals  # noqa: E402
from test_generated_seed_faults import _offline, _online  # noqa: E402
from test_clock_rate_change_seeds import _bag_rows  # noqa: E402

DATA = Path(__file__).resolve().parents[1] / "data"




@pytest.mark.parametrize("seed, relay", [(1178, "Relay3"), (1187, "Relay6"), (1149, "Relay1"), (1271, "Relay4")])
def test_a_relay_copying_a_stamp_another_writer_shares_is_never_violated(
        seed: int, relay: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    counts = {r["node"]: r["counts"] for r in _bag_rows(DATA / f"robot_seed{seed}", tmp_path, monkeypatch, capsys) if "counts" in r}
    assert counts[relay]["violated"] == 0, counts[relay]
    assert all(c["violated"] == 0 for c in counts.values()), counts


@pytest.mark.parametrize("seed, relays", [(1178, ("Sensor0", "Relay3", "Relay4")),
                                          (1187, ("Sensor0", "Relay3", "Relay5", "Relay6")),
                                          (1149, ("Sensor0", "Sensor5", "Relay1")),
                                          (1271, ("Sensor0", "Relay4"))])
def test_the_online_engine_gives_the_bags_verdicts(seed: int, relays: tuple[str, ...]) -> None:
    """The bag replayed through the online engine (as the live run judges it) gives the bag's verdicts on the
    sensors and the relays copying their stamps, none of them violated."""
    ws = DATA / f"robot_seed{seed}"
    online, bag = finals(_online(ws, relays)), finals(_offline(ws, "runs/bag", relays))
    assert compare(online, bag) == [], [d.text(("live", "bag")) for d in compare(online, bag)]
    assert not [r for rs in online.values() for r in rs if r["verdict"] in ("violated", "false")]


def test_seed_1271_the_log_gives_the_bags_verdicts() -> None:
    """The run's log (``runs/live.jsonl``, the copies' stamps carried into the run's clock) gives the bag's
    verdicts verdict by verdict, never ``violated`` (Relay4: a correct relay copying its sensor's stamp).
    Fails with a carried stamp read as one in another clock (``violated`` at Relay4, one verdict more)."""
    ws = DATA / "robot_seed1271"
    log, bag = finals(_offline(ws, "runs/live.jsonl")), finals(_offline(ws, "runs/bag"))
    assert not [r for rs in log.values() for r in rs if r["verdict"] in ("violated", "false")]
    assert compare(log, bag) == [], [d.text(("log", "bag")) for d in compare(log, bag)]
