"""A run's simulated clock, as its ``/clock`` topic carried it.

A node under ``use_sim_time`` reads its time from ``/clock``
(``rosgraph_msgs/Clock``: one field ``clock``, a ``builtin_interfaces/Time``
``sec``/``nanosec`` in ROS 2, a ROS 1 ``time`` ``secs``/``nsecs``): its clock
stands at the value of the last ``/clock`` message it received, so it moves in
steps, at the simulator's real-time factor, and stands still while the
simulator is paused (REP 2008, ROS 2 design "Clock and Time").  The monitor
hears the same messages on the run's clock (their source times live, the
recorded or logged time offline) and keeps each as a sample ``(time on the
run's clock, value)``: :class:`SimClock`.  Through it a time of the run's clock
maps to the simulated time a node read then (:meth:`SimClock.at`), and a
simulated time to the time of the run's clock when the simulated clock passed it
(:meth:`SimClock.passed`), which is what judges a deadline kept in simulated
time (docs/semantics.md, "Deadlines in simulated time").

A ``/clock`` whose value goes back (a simulator reset), or a sample heard out of
the run's order, cannot relate the two clocks from there on:
:attr:`SimClock.broken` says why, and a monitor reading it gives no verdict that
rests on it.
"""
from __future__ import annotations

from bisect import bisect_left, bisect_right
from typing import Any, Mapping

#: the topic a simulated clock is published on (without its leading ``/``, as the monitors key topics)
CLOCK_TOPIC = "clock"


def is_clock_topic(topic: str) -> bool:
    """Whether ``topic`` (with or without a leading ``/``) is the run's ``/clock``."""
    return topic.lstrip("/") == CLOCK_TOPIC


def clock_value_ns(fields: Mapping[str, Any]) -> int | None:
    """The simulated time (integer ns) a ``/clock`` message's ``fields`` carry: ``clock`` with ROS 2's
    ``sec``/``nanosec`` or ROS 1's ``secs``/``nsecs`` (nested, or flattened as ``clock.sec`` and
    ``clock.nanosec`` in a ROSMonitoring log line); ``None`` when they carry none that reads as integers."""
    c = fields.get("clock")
    if not isinstance(c, Mapping):
        c = {k[6:]: v for k, v in fields.items() if isinstance(k, str) and k.startswith("clock.")}
    for s, n in (("sec", "nanosec"), ("secs", "nsecs")):
        sec, nsec = c.get(s), c.get(n)
        if isinstance(sec, int) and isinstance(nsec, int) and not isinstance(sec, bool) \
                and not isinstance(nsec, bool) and 0 <= nsec < 1_000_000_000:
            return sec * 1_000_000_000 + nsec
    return None


class SimClock:
    """The ``/clock`` samples heard in a run, in the run's order: ``(t, value)``, both integer ns, ``t`` on
    the run's clock.  Values never go back while :attr:`broken` is empty."""

    __slots__ = ("times", "values", "broken", "kept_ns", "heard_ns")

    def __init__(self, kept_s: float = 600.0) -> None:
        self.times: list[int] = []
        self.values: list[int] = []
        #: why the two clocks cannot be related from the last sample on (``""``: they can)
        self.broken = ""
        #: how far back (ns of the run's clock) samples are kept at least: once the samples span twice
        #: that, the older half is forgotten (:meth:`forget_before`), so memory is bounded by the window
        self.kept_ns = round(kept_s * 1e9)
        #: the time (ns, the run's clock) of the last sample heard, one repeating the value included
        self.heard_ns: int | None = None

    @property
    def heard(self) -> bool:
        """Whether any ``/clock`` sample was heard."""
        return bool(self.times) or bool(self.broken)

    def see(self, t_ns: int, value_ns: int, where: str = "") -> None:
        """One ``/clock`` sample: heard at ``t_ns`` (the run's clock) carrying ``value_ns``.  A value before
        the last one (a reset), or a sample placed before the last one (heard out of order), breaks the
        relation (:attr:`broken`, naming ``where``)."""
        if self.broken:
            return
        times, values = self.times, self.values
        if times and t_ns < times[-1]:
            self.broken = f"a /clock message ({where or 'a sample'}) was placed before the one heard before it"
            return
        if values and value_ns < values[-1]:
            self.broken = (f"/clock went back from {values[-1] / 1e9:.3f} s to {value_ns / 1e9:.3f} s"
                           + (f" at {where}" if where else "") + " (the simulation was reset)")
            return
        self.heard_ns = t_ns
        if values and value_ns == values[-1] and times:
            return  # the clock stands still: the first sample of the value says when it got there
        times.append(t_ns)
        values.append(value_ns)
        if t_ns - times[0] > 2 * self.kept_ns:
            self.forget_before(t_ns - self.kept_ns)

    def forget_before(self, t_ns: int) -> None:
        """Drop the samples before ``t_ns`` but the last of them (it gives the value at ``t_ns``)."""
        i = bisect_right(self.times, t_ns) - 1
        if i > 0:
            del self.times[:i], self.values[:i]

    def heard_after(self, t_ns: int) -> bool:
        """Whether a sample placed after ``t_ns`` (ns, the run's clock) was heard (one repeating the value
        included), so that :meth:`at` of ``t_ns`` no longer changes: ``/clock``'s one writer publishes in
        order, so no sample placed before it comes later (or :attr:`broken`: :meth:`at` is ``None`` from
        here on)."""
        return bool(self.broken) or (self.heard_ns is not None and self.heard_ns > t_ns)

    def at(self, t_ns: int) -> int | None:
        """The simulated time (ns) at ``t_ns`` of the run's clock: the value of the last sample placed at or
        before it; ``None`` before the first sample kept (older ones are forgotten: :attr:`kept_ns`), or once
        :attr:`broken`."""
        if self.broken:
            return None
        i = bisect_right(self.times, t_ns) - 1
        return self.values[i] if i >= 0 else None

    def passed(self, target_ns: int) -> int | None:
        """When (ns, the run's clock) the simulated clock first went past ``target_ns``: the time of the
        first sample whose value exceeds it; ``None`` when none has yet (or :attr:`broken`)."""
        if self.broken:
            return None
        i = bisect_right(self.values, target_ns)
        return self.times[i] if i < len(self.times) else None

    def reached(self, target_ns: int) -> int | None:
        """When (ns, the run's clock) the simulated clock first stood at or past ``target_ns``; ``None`` when
        it has not yet (or :attr:`broken`)."""
        if self.broken:
            return None
        i = bisect_left(self.values, target_ns)
        return self.times[i] if i < len(self.times) else None


__all__ = ["CLOCK_TOPIC", "SimClock", "clock_value_ns", "is_clock_topic"]
