"""A copied stamp of a clock standing still (traces/event_time.py, ``CopiedStamps``): while a simulated
clock is paused, several messages carry one stamp (one writer's readings, the copies of them, the
answers of writers stamping with the clock's time); which question such a message answers is not the
run's to say, so each message of another writer so stamped is placed at the first message so stamped
and judged against every question asked from there until it was published (generated seeds 1069 and
1074: tests/backends/test_clock_rate_change_seeds.py); and two writers stamping alike within the
transport skew are no copies of each other (generated seed 1091)."""
from __future__ import annotations

from rclverify.traces.event_time import CopiedStamps

PAUSED = 5004.139


def test_every_copy_of_a_stamp_a_paused_clock_shares_is_placed_at_its_first_message() -> None:
    c = CopiedStamps()
    assert c.place("s0", PAUSED, 10.0) == (10.0, False)
    assert c.place("r1", PAUSED, 10.3) == (10.0, True)
    assert c.place("s0", PAUSED, 10.4) == (10.4, False)  # the clock still paused: the same stamp again
    assert c.place("r1", PAUSED, 10.7) == (10.0, True)  # it may answer the first reading or the second
    assert c.place("r4", PAUSED, 10.75) == (10.0, True)  # a writer stamping with the clock's time alike
    assert c.copied == 3


def test_a_copy_names_a_message_of_another_writer_published_before_it() -> None:
    """The control: a stamp of one message is named by every copy of it; the writer's own messages are
    never copies of itself; a stamp nobody stamped before is no copy."""
    c = CopiedStamps()
    c.place("s0", 7.0, 1.0)
    assert c.place("r1", 7.0, 1.2) == (1.0, True)
    assert c.place("r1", 7.0, 1.25) == (1.0, True)
    assert c.place("s0", 7.0, 1.4) == (1.4, False)
    assert c.place("r1", 8.0, 1.5) == (1.5, False)
    assert c.copy_of("r9", 7.0, 1.9) == 1.0


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
