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
