"""The run's simulated clock as its /clock samples (traces/sim_clock.py): the value at a time of the run's
clock, when the clock first passed a simulated time, a clock standing still, a reset, a sample heard out of
order, and memory bounded by the window kept."""
from __future__ import annotations

from rclverify.traces.sim_clock import SimClock, clock_value_ns, is_clock_topic


def test_values_and_passing_times() -> None:
    c = SimClock()
    assert not c.heard and c.at(5) is None and c.passed(0) is None
    for t, v in ((10, 100), (20, 110), (30, 110), (40, 130)):  # 30: standing still
        c.see(t, v)
    assert c.times == [10, 20, 40]  # a value repeated says nothing new
    assert (c.at(9), c.at(10), c.at(35), c.at(99)) == (None, 100, 110, 130)
    assert (c.passed(99), c.passed(100), c.passed(110), c.passed(130)) == (10, 20, 40, None)
    assert (c.reached(110), c.reached(111)) == (20, 40)


def test_a_reset_or_a_sample_out_of_order_breaks_the_relation() -> None:
    c = SimClock()
    c.see(10, 500)
    c.see(20, 0, "bag:7")
    assert "went back" in c.broken and "bag:7" in c.broken and c.at(15) is None and c.passed(0) is None
    d = SimClock()
    d.see(20, 5)
    d.see(10, 6)
    assert "placed before" in d.broken and d.heard


def test_memory_is_bounded_by_the_window_kept() -> None:
    c = SimClock(kept_s=1.0)
    for k in range(100_000):  # 100 s at 1 kHz
        c.see(k * 1_000_000, k * 500_000)
    assert len(c.times) <= 2_001
    assert c.at(99_999_000_000) == 99_999 * 500_000 and c.at(50 * 10**9) is None  # forgotten: not known


def test_clock_fields_of_ros_2_ros_1_and_a_flattened_log() -> None:
    assert clock_value_ns({"clock": {"sec": 3, "nanosec": 5}}) == 3_000_000_005
    assert clock_value_ns({"clock": {"secs": 3, "nsecs": 5}}) == 3_000_000_005
    assert clock_value_ns({"clock.sec": 3, "clock.nanosec": 5}) == 3_000_000_005
    assert clock_value_ns({"clock": {"sec": 3.5, "nanosec": 0}}) is None  # not integers: not a time
    assert clock_value_ns({"clock": {"sec": 3, "nanosec": 10**9}}) is None
    assert is_clock_topic("/clock") and is_clock_topic("clock") and not is_clock_topic("/r1/clock")
