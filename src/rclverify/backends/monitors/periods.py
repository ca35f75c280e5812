"""Periodic outputs checked against message stamps, in the clock of the node that stamps them.

A node's ``periodic( out.y, 100 ms )`` (docs/rcl-language.md, "Progress,
initial values and periodic outputs") says the node refreshes ``out.y`` at
least once per period of its own clock: a rate, a watchdog's heartbeat.  On
a recorded run the messages that carry ``out.y`` (the topic ``topics(...)``
binds to it, :func:`.deadline_topics.topic_bindings`) are read at their
stamps as the deadline monitor reads them (:func:`.stamp_order.run_clock`:
the header's stamp, else the trace's time), and:

* every gap between two consecutive messages of ``out.y`` is at most the
  period: ``true``; a longer gap is ``false``, with both stamps (gaps are
  compared to the microsecond, :data:`TOLERANCE_S`: stamps read as floats
  since the epoch are only that exact, and ``1.3 - 1.2`` is not ``0.1``);
* after the last message, the run goes on (its last event of any topic) for
  more than a period: ``false`` (the output stopped being refreshed);
* no message of ``out.y`` at all: nothing was checked (``pending``); the
  time before the first message is not judged (a recorded run may start
  before the node does).

**The node's clock.**  A message whose header stamp runs in another clock
than the run's (simulated time on ``/clock``, a driver stamping seconds off:
:func:`~rclverify.traces.event_time.other_clock`) is placed at its source
time, its stamp set aside (:func:`~rclverify.traces.event_time.without_stamp`
keeps it, :func:`~rclverify.traces.event_time.aside_stamp`).  Its gaps are
then measured on those set-aside stamps, the clock the node publishes by
(at a real-time factor of 2, a 100 ms period is 50 ms of the wall clock);
the run's end, in the run's clock, is carried into the node's clock from
the output's last message at the output's own rate, its stamps' span over
its placed times' span (1 for a driver's offset; the factor measured for
simulated time), so the tail is the node's time too.  With a single message
of such an output the rate is unknown and the tail is not judged
(:attr:`PeriodResult.unrated`).  A message without a stamp carries no clock
but the run's, in which it is judged.

A period in steps (``periodic( out.y, 3 steps )``), ``progress( ... )``
and ``initially( ... )`` are judged on the same run by :mod:`.declarations`
(a step of the node there is one of its input events), which also turns
this module's result into the verdict row of each period in time; a bound
in time is a guarantee's deadline (``triggered by in.x within 200 ms``,
:mod:`.deadlines`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Iterable

from rclverify.lang.liveness import period_seconds
from rclverify.lang.types import CheckedNode
from rclverify.traces.event_time import aside_stamp
from rclverify.traces.events import Event
from rclverify.backends.monitors.deadline_topics import topic_bindings
from rclverify.backends.monitors.stamp_order import run_clock
from rclverify.backends.monitors.shapes import PeriodGapJson, PeriodResultJson, PeriodsPart


#: The slack of a gap against its period (s): the resolution of an epoch stamp read as a float.
TOLERANCE_S = 1e-6


@dataclass
class PeriodResult:
    """One node's periodic outputs on one run: per output ``out.y``, the
    messages seen and the first gap longer than its period (``None``:
    none), as ``{"from": stamp, "to": stamp or None (the run's end),
    "gap": s, "period": s, "where": the later message's place}``, stamps and
    gaps in the node's clock (module docstring); ``clocks``: per output whose
    stamps were set aside in another clock, its rate against the run's clock
    (node s per run s); ``unrated``: such outputs with one message, whose
    tail was not judged."""

    node: str
    periods: dict[str, float] = field(default_factory=dict)
    messages: dict[str, int] = field(default_factory=dict)
    late: dict[str, PeriodGapJson] = field(default_factory=dict)
    end: float | None = None
    clocks: dict[str, float] = field(default_factory=dict)
    unrated: list[str] = field(default_factory=list)

    def to_json(self) -> PeriodResultJson:
        out: PeriodResultJson = {"node": self.node, "periods": dict(self.periods), "messages": dict(self.messages),
                                 "late": dict(self.late), "end": self.end}
        if self.clocks:
            out["clocks"] = {k: round(v, 6) for k, v in self.clocks.items()}
        if self.unrated:
            out["unrated"] = list(self.unrated)
        return out


def has_periods(node: CheckedNode) -> bool:
    """Whether ``node`` declares a period in time (one a recorded run can check)."""
    return any(period_seconds(p) is not None for p in node.node.periodic)


class PeriodMonitor:
    """The periodic outputs of ``node`` (periods in time) checked one event
    at a time (module docstring): :meth:`feed` every event of the run in
    order, then :meth:`finish` for the :class:`PeriodResult`; so the untimed,
    deadline and period checks of a run share one read of it."""

    def __init__(self, node: CheckedNode) -> None:
        self.result = res = PeriodResult(node.name)
        for p in node.node.periodic:
            s = period_seconds(p)
            if s is not None:
                res.periods[f"out.{p.output.name}"] = float(s)
        self.topics: dict[str, list[str]] = {}
        for topic, keys in topic_bindings(node).items():
            outs = [k for k, _ in keys if k in res.periods]
            if outs:
                self.topics[topic] = outs
        #: per output, its last message: (stamp in the node's clock, where, time on the run's clock)
        self.last: dict[str, tuple[float, str, float]] = {}
        #: per output whose stamps were set aside, its first message's (node's stamp, run's time)
        self.first_aside: dict[str, tuple[float, float]] = {}

    def feed(self, ev: Event) -> None:
        res = self.result
        at = run_clock(ev)
        res.end = at if res.end is None else max(res.end, at)
        outs = self.topics.get(ev.topic.lstrip("/"))
        if not outs:
            return
        own = aside_stamp(ev.fields) if ev.fields else None
        stamp = at if own is None else own
        for key in outs:
            res.messages[key] = res.messages.get(key, 0) + 1
            if own is not None:
                self.first_aside.setdefault(key, (own, at))
            before = self.last.get(key)
            if before is not None and key not in res.late and stamp - before[0] > res.periods[key] + TOLERANCE_S:
                res.late[key] = {"from": before[0], "to": stamp, "gap": stamp - before[0],
                                 "period": res.periods[key], "where": ev.where}
            self.last[key] = (stamp, ev.where, at)

    def finish(self) -> PeriodResult:
        res = self.result
        for key, (stamp, where, at) in self.last.items():
            if key in res.late or res.end is None:
                continue
            tail = res.end - stamp
            if key in self.first_aside:  # the run's end carried into the node's clock at the output's rate
                s0, t0 = self.first_aside[key]
                if at - t0 <= 0 or stamp - s0 <= 0:
                    res.unrated.append(key)
                    continue
                res.clocks[key] = rate = (stamp - s0) / (at - t0)
                tail = (res.end - at) * rate
            if tail > res.periods[key] + TOLERANCE_S:
                res.late[key] = {"from": stamp, "to": None, "gap": tail, "period": res.periods[key],
                                 "where": where}
        return res


def check_periods(node: CheckedNode, events: Iterable[Event]) -> PeriodResult:
    """The periodic outputs of ``node`` (periods in time) over a recorded
    run's ``events``, in order (module docstring; :class:`PeriodMonitor`)."""
    m = PeriodMonitor(node)
    for ev in events:
        m.feed(ev)
    return m.finish()


def period_status(res: PeriodResult, trace: str) -> tuple[str, str]:
    """Evidence status and explanation of one node's periods on a run: a gap
    longer than a period -> ``failed`` (named with its stamps); no message
    of some periodic output -> ``pending``; else ``discharged``."""
    for key, g in res.late.items():
        after = (f"the next at {g['to']:.3f} s ({g['where']})" if g["to"] is not None
                 else f"none after it although {trace} goes on to {res.end:.3f} s")
        return "failed", (f"{res.node}.{key} is declared periodic every {_ms(g['period'])} but a message at "
                          f"{g['from']:.3f} s has {after}: a gap of {_ms(g['gap'])}")
    silent = [k for k in res.periods if not res.messages.get(k)]
    if silent:
        return "pending", f"{trace} has no message of {', '.join(f'{res.node}.{k}' for k in silent)}: its period was not checked"
    return "discharged", ", ".join(f"{res.node}.{k}: {res.messages[k]} messages, no gap over {_ms(res.periods[k])}"
                                   for k in res.periods)


def with_periods(res: PeriodResult, trace: str, status: str, explanation: str) -> tuple[str, str, PeriodsPart]:
    """The monitor's verdict combined with the node's periods on the same run
    (``res``, :class:`PeriodMonitor`): a failed period fails the evidence,
    otherwise the verdict stands (a period that saw no message adds a note).
    Returns ``(status, explanation, {"periods": ...})``."""
    pstatus, pexpl = period_status(res, trace)
    if pstatus == "failed":
        return "failed", f"periods: {pexpl}; {explanation}", {"periods": res.to_json()}
    return status, f"{explanation}; periods: {pexpl}", {"periods": res.to_json()}


def _ms(x: float) -> str:
    return f"{x * 1000:.0f} ms" if abs(x) < 10 else f"{x:.3f} s"
