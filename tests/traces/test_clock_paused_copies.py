"""A copied stamp of a clock standing still (traces/event_time.py, ``CopiedStamps``): while a simulated
clock is paused, one writer stamps several messages alike; a node copying each one's stamp onto its
answer names them in order, the k-th copy the k-th message published before it, never the first for all
(generated seed 1069: tests/backends/test_clock_rate_change_seeds.py)."""
from __future__ import annotations

from rclverify.traces.event_time import CopiedStamps

PAUSED = 5004.139


def test_each_copy_of_a_stamp_shared_by_a_paused_writer_names_its_own_message() -> None:
    c = CopiedStamps()
    assert c.place("s0", PAUSED, 10.0) == (10.0, False)
    assert c.place("r1", PAUSED, 10.3) == (10.0, True)
    assert c.place("s0", PAUSED, 10.4) == (10.4, False)  # the clock still paused: the same stamp again
    assert c.place("r1", PAUSED, 10.7) == (10.4, True)  # the second copy names the second reading
    assert c.copied == 2


def test_a_copy_names_only_messages_published_before_it_and_a_single_stamp_as_before() -> None:
    """The control: a stamp of one message is named by every copy of it (a node answering one reading
    twice); a copy heard before the writer's next message so stamped names the last one before it; the
    writer's own messages are never copies of itself."""
    c = CopiedStamps()
    c.place("s0", 7.0, 1.0)
    assert c.place("r1", 7.0, 1.2) == (1.0, True)
    assert c.place("r1", 7.0, 1.25) == (1.0, True)
    c.place("s0", 8.0, 2.0)
    c.place("s0", 8.0, 2.4)
    assert c.place("a2", 8.0, 2.1) == (2.0, True)
    assert c.place("a2", 8.0, 2.2) == (2.0, True)  # the second copy, before the second message: the last before it
    assert c.place("s0", 8.0, 2.8) == (2.8, False)
    assert c.copy_of("r9", 8.0, 2.9) == 2.0


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
