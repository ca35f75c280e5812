"""Copied stamps of a clock standing still (traces/event_time.py, ``CopiedStamps``): while a simulated
clock is paused, several messages carry one stamp (one writer's readings, the copies of them, the
messages of writers stamping with the clock's time).  A fresh stamp (heard once) carried by another
writer is a copy, and teaches that its writer copies the first's stamps; a stamp that stands still is a
copy only for a writer that copied two fresh stamps of the first before, placed at the first message so
stamped (generated seed 1069); any other message carrying it is its own writer's, at its source time
(generated seeds 1072 and 1074: tests/backends/test_clock_rate_change_seeds.py); two writers stamping
alike within the transport skew are no copies of each other (generated seed 1091)."""
from __future__ import annotations

from rclverify.traces.event_time import CopiedStamps

PAUSED = 5004.139


def test_a_relay_copying_a_paused_sensors_stamp_is_placed_at_its_first_message() -> None:
    c = CopiedStamps()
    for k, t in enumerate((1.0, 2.0)):  # two fresh stamps copied: r1 copies s0's stamps
        c.place("s0", 100.0 + k, t)
        assert c.place("r1", 100.0 + k, t + 0.3) == (t, True)
    assert c.place("s0", PAUSED, 10.0) == (10.0, False)
    assert c.place("r1", PAUSED, 10.3) == (10.0, True)
    assert c.place("s0", PAUSED, 10.4) == (10.4, False)  # the clock still paused: the same stamp again
    assert c.place("r1", PAUSED, 10.7) == (10.0, True)  # it may answer the first reading or the second
    assert c.copied == 4


def test_a_writer_stamping_a_paused_clocks_time_is_placed_at_its_own_time() -> None:
    """Sensor s0 stamps the paused clock's time again and again; s3 stamped it first.  s0's first
    message carries a fresh stamp (a copy, as far as the run can tell); every later one its own (seed
    1072: all three were placed at s3's message).  The control: a relay that copied two fresh stamps of
    s3 before is placed at s3's message."""
    c = CopiedStamps()
    assert c.place("s3", PAUSED, 7.1388) == (7.1388, False)
    assert c.place("s0", PAUSED, 7.2631) == (7.1388, True)
    assert c.place("s0", PAUSED, 7.5146) == (7.5146, False)
    assert c.place("s0", PAUSED, 7.7635) == (7.7635, False)
    c = CopiedStamps()
    for k, t in enumerate((1.0, 2.0)):
        c.place("s3", 100.0 + k, t)
        c.place("r1", 100.0 + k, t + 0.1)
    c.place("s3", PAUSED, 7.1388)
    c.place("s0", PAUSED, 7.2631)
    assert c.place("r1", PAUSED, 7.5) == (7.1388, True)


def test_two_writers_stamping_alike_within_the_skew_are_no_copies() -> None:
    """Two relays stamping a simulated clock's time with their own clock within one of its ticks, 7.5 ms
    apart (generated seed 1091), are heard in either order: neither names the other, whichever comes
    first, so the live run and its bag place both at their own source times.  The control: a copy
    published 30 ms after the message it copies names it."""
    for first, second in (("r3", "r2"), ("r2", "r3")):
        c = CopiedStamps()
        t = {"r3": 100.8031, "r2": 100.8106}
        assert c.place(first, 102.7101, t[first]) == (t[first], False)
        assert c.place(second, 102.7101, t[second]) == (t[second], False)
        assert c.copied == 0
    c = CopiedStamps()
    c.place("s0", 102.7101, 100.8031)
    assert c.place("r1", 102.7101, 100.8331) == (100.8031, True)
    assert c.copy_of("r9", 102.7101, 100.9) is None  # the stamp stands still now, r9 copied nothing before


def test_by_the_contracts_a_writer_copies_only_what_its_node_reads() -> None:
    """With ``reads`` (the topics each writer's node reads: backends/monitors/node_topics.py
    ``copy_sources``), a relay copies its input's stamp however many other relays copied it first (seeds
    1178, 1187: by the stamps alone the second relay's copies stood still and were its own, ``violated``)
    and never another writer's that stamped alike (seed 1149: a second sensor stamping the same tick);
    a sensor, reading nothing, copies nothing, paused or not (seed 1072); a paused sensor's readings
    copied by its relay are placed at its first message so stamped.  The control: a topic no contract
    writes keeps the rule by the stamps alone."""
    reads = {"r3": frozenset({"s0"}), "r4": frozenset({"s0"}), "r1": frozenset({"s0"}),
             "s0": frozenset(), "s5": frozenset()}
    c = CopiedStamps(reads)
    assert c.place("s0", 100.0, 1.0) == (1.0, False)
    assert c.place("r4", 100.0, 1.127) == (1.0, True)
    assert c.place("r3", 100.0, 1.211) == (1.0, True)  # the stamp heard twice already: still s0's copy
    assert c.place("s5", 101.0, 2.0) == (2.0, False)
    assert c.place("s0", 101.0, 2.01) == (2.01, False)  # within the skew of s5's: its own
    assert c.place("r1", 101.0, 2.5) == (2.01, True)  # s0's, not s5's (s5's came first)
    assert c.place("s5", PAUSED, 10.0) == (10.0, False)
    assert c.place("s0", PAUSED, 10.2) == (10.2, False)  # a sensor never copies: its own reading
    assert c.place("s0", PAUSED, 10.4) == (10.4, False)
    assert c.place("r1", PAUSED, 10.6) == (10.2, True)  # placed at its input's first, judged until 10.6
    assert c.copied == 4
    control = CopiedStamps({"r1": frozenset({"s0"})})
    control.place("s0", 100.0, 1.0)
    control.place("r4", 100.0, 1.127)  # no contract writes r4: the stamps alone say it copies s0's
    assert control.copied == 1
    assert control.place("x", 100.0, 1.3) == (1.3, False)  # heard twice: stands still, x no copier of s0
