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

**A simulated clock may change its rate or pause.**  Stamps more than
:data:`SIMULATED_S` from their source times are simulated time (a ``/clock``
from 0 s), whose real-time factor changes mid-run and which stops while the
simulator is paused; its factor after the output's last message is not
measured by anything the output carries.  The latest stamp of that clock
heard after the output's last message (a stamp set aside, of any writer, no
further ahead of the output's last stamp than :data:`AHEAD_FACTOR` times its
measured rate since, and 1 s: the same clock, not another writer's far
ahead) is where the clock is known to have got: more than the period past
the output's last stamp is ``false``; else the tail is that stamp's lead and
the rest of the run carried at the measured rate, and a tail so carried over
the period is not judged (:attr:`PeriodResult.unrated`, ``inconclusive``):
the clock may have slowed or paused after the last message (a real-time
factor falling from 2 to 0.5 carries a 0.45 s tail of the node's clock as
1.8 s; a clock paused for 1.5 s after it carries none as 1.5 s at a factor
of 1).  A driver's offset (a
clock within :data:`SIMULATED_S` of the run's) runs at the wall clock's
rate and is judged at its measured rate as before.

A period in steps (``periodic( out.y, 3 steps )``), ``progress( ... )``
and ``initially( ... )`` are judged on the same run by :mod:`.declarations`
(a step of the node there is one of its input events), which also turns
this module's result into the verdict row of each period in time; a bound
in time is a guarantee's deadline (``triggered by in.x within 200 ms``,
:mod:`.deadlines`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Iterable, Mapping

from rclverify.lang.liveness import period_seconds
from rclverify.lang.types import CheckedNode
from rclverify.traces.event_time import aside_stamp
from rclverify.traces.events import Event, to_ns
from rclverify.traces.mapping import TopicRule, sim_time_of
from rclverify.traces.sim_clock import CLOCK_TOPIC, SimClock, clock_value_ns
from rclverify.backends.monitors.period_clock import LATE, UNDECIDED, judge_gap, read_at, sim_gap
from rclverify.backends.monitors.skew import DEFAULT_SKEW_S
from rclverify.backends.monitors.deadline_topics import topic_bindings
from rclverify.backends.monitors.stamp_order import run_clock

if TYPE_CHECKING:
    from rclverify.backends.monitors.shapes import PeriodGapJson, PeriodResultJson, PeriodsPart


#: The slack of a gap against its period (s): the resolution of an epoch stamp read as a float.
TOLERANCE_S = 1e-6
#: a stamp set aside more than this (s) from its source time is simulated time (a clock that may change its
#: rate or pause), one nearer a clock offset from the run's (a driver's), which keeps the wall clock's rate
SIMULATED_S = 86_400.0
#: a later stamp is of an output's simulated clock only if no further past its last stamp than this many times
#: the time since, at the output's measured rate (and 1 s): beyond, it is taken for another clock
AHEAD_FACTOR = 2.0


@dataclass
class PeriodResult:
    """One node's periodic outputs on one run: per output ``out.y``, the
    messages seen and the first gap longer than its period (``None``:
    none), as ``{"from": stamp, "to": stamp or None (the run's end),
    "gap": s, "period": s, "where": the later message's place}``, stamps and
    gaps in the node's clock (module docstring); ``clocks``: per output whose
    stamps were set aside in another clock, its rate against the run's clock
    (node s per run s); ``unrated``: such outputs with one message, whose
    tail was not judged, and outputs in simulated time whose tail is over
    the period at the measured rate but shown by no later stamp of their
    clock (module docstring)."""

    node: str
    periods: dict[str, float] = field(default_factory=dict)
    messages: dict[str, int] = field(default_factory=dict)
    late: dict[str, PeriodGapJson] = field(default_factory=dict)
    end: float | None = None
    clocks: dict[str, float] = field(default_factory=dict)
    unrated: list[str] = field(default_factory=list)
    #: per output judged in simulated time (:mod:`.period_clock`), why its first gap not decided was not
    undecided: dict[str, str] = field(default_factory=dict)

    def to_json(self) -> PeriodResultJson:
        out: PeriodResultJson = {"node": self.node, "periods": dict(self.periods), "messages": dict(self.messages),
                                 "late": dict(self.late), "end": self.end}
        if self.clocks:
            out["clocks"] = {k: round(v, 6) for k, v in self.clocks.items()}
        if self.unrated:
            out["unrated"] = list(self.unrated)
        if self.undecided:
            out["undecided"] = dict(self.undecided)
        return out


def has_periods(node: CheckedNode) -> bool:
    """Whether ``node`` declares a period in time (one a recorded run can check)."""
    return any(period_seconds(p) is not None for p in node.node.periodic)


class PeriodMonitor:
    """The periodic outputs of ``node`` (periods in time) checked one event
    at a time (module docstring): :meth:`feed` every event of the run in
    order, then :meth:`finish` for the :class:`PeriodResult`; so the untimed,
    deadline and period checks of a run share one read of it."""

    def __init__(self, node: CheckedNode, rules: Mapping[str, TopicRule] | None = None) -> None:
        self.result = res = PeriodResult(node.name)
        #: the clock the node keeps (the mapping's ``use_sim_time``: :mod:`.period_clock`; no rules: not said)
        self.sim_mode = sim_time_of(rules, node.name) if rules is not None else None
        #: the run's ``/clock`` as heard, and the transport skew (ns) of its delivery to a node
        self.sim = SimClock()
        from rclverify.backends.monitors.deadline_skew import skew_ns  # deferred: start-up (loaded only by a run with a period)
        self.skew_ns = skew_ns(rules) if rules is not None else round(DEFAULT_SKEW_S * 1e9)
        #: per output judged in simulated time: its last message's time (integer ns, the run's clock), where,
        #: and ``/clock`` as the node read it then (:func:`.period_clock.read_at`)
        self.last_sim: dict[str, tuple[int, str, tuple[int | None, int | None]]] = {}
        for p in node.node.periodic:
            s = period_seconds(p)
            if s is not None:
                res.periods[f"out.{p.output.name}"] = float(s)
        # /clock kept back over an output's period, and a minute of lateness
        self.sim.kept_ns = round((max(res.periods.values(), default=0.0) + 60.0) * 1e9)
        self.topics: dict[str, list[str]] = {}
        for topic, keys in topic_bindings(node).items():
            outs = [k for k, _ in keys if k in res.periods]
            if outs:
                self.topics[topic] = outs
        #: per output, its last message: (stamp in the node's clock, where, time on the run's clock)
        self.last: dict[str, tuple[float, str, float]] = {}
        #: per output whose stamps were set aside, its first message's (node's stamp, run's time)
        self.first_aside: dict[str, tuple[float, float]] = {}
        #: per output in simulated time: its last stamp, where it was placed (run's time), its rate measured
        #: until then (None: its first message), the largest stamp of its clock heard after it and where
        #: that was placed (s)
        self.after: dict[str, tuple[float, float, float | None, float, float]] = {}

    def feed(self, ev: Event) -> None:
        res = self.result
        at = run_clock(ev)
        res.end = at if res.end is None else max(res.end, at)
        topic = ev.topic.lstrip("/")
        if topic == CLOCK_TOPIC:  # the run's simulated clock (period_clock.py)
            value = clock_value_ns(ev.fields) if self.sim_mode is not False else None
            if value is not None:  # at its publication, also when the live engine heard it late (Event.stamped)
                self.sim.see(to_ns(ev.stamped), value, ev.where)
            return
        outs = self.topics.get(topic)
        if not outs:
            if self.after and ev.fields:
                self._later(ev, at)
            return
        own = aside_stamp(ev.fields) if ev.fields else None
        stamp = at if own is None else own
        sim_reads = own is None and (self.sim_mode is True or (self.sim_mode is None and self.sim.heard))
        for key in outs:
            res.messages[key] = res.messages.get(key, 0) + 1
            if sim_reads:
                self._sim_message(key, ev, at)
                continue
            if own is not None:
                self.first_aside.setdefault(key, (own, at))
                if abs(own - at) > SIMULATED_S:
                    s0, t0 = self.first_aside[key]
                    self.after[key] = (own, at, (own - s0) / (at - t0) if at > t0 else None, own, at)
            before = self.last.get(key)
            if before is not None and key not in res.late and stamp - before[0] > res.periods[key] + TOLERANCE_S:
                res.late[key] = {"from": before[0], "to": stamp, "gap": stamp - before[0],
                                 "period": res.periods[key], "where": ev.where}
            self.last[key] = (stamp, ev.where, at)

    def _sim_message(self, key: str, ev: Event, at: float) -> None:
        """A message of output ``key`` without a stamp of its own, placed at ``at`` (s), judged in simulated
        time (:mod:`.period_clock`): its gap from the output's last message against the period."""
        res, t2 = self.result, to_ns(at)
        before = self.last_sim.get(key)
        if before is None and key in self.last:  # judged on the run's clock until /clock was heard
            _, where, t = self.last.pop(key)
            before = (to_ns(t), where, read_at(self.sim, to_ns(t), self.skew_ns))
        if before is not None and key not in res.late:
            self._gap(key, before[0], before[2], t2, ev.where)
        self.last_sim[key] = (t2, ev.where, read_at(self.sim, t2, self.skew_ns))

    def _gap(self, key: str, t1: int, first: tuple[int | None, int | None], t2: int, where: str,
             stamped: bool = False, tail: bool = False) -> None:
        """The gap of output ``key`` from ``t1`` (ns, the run's clock; ``first``: ``/clock`` as the node read it
        then, :func:`.period_clock.read_at`, or twice its own stamp in that clock when ``stamped``) to ``t2``
        judged in simulated time (:func:`.period_clock.judge_gap`; a ``stamped`` output in it alone): late in
        :attr:`PeriodResult.late`, undecided in :attr:`PeriodResult.undecided`; ``tail``: ``t2`` is the
        run's end."""
        res = self.result
        period = res.periods[key]
        gap = sim_gap(first, self.sim, t2, self.skew_ns)
        mode = True if stamped else self.sim_mode
        verdict = judge_gap(gap, None if stamped else t2 - t1, round(period * 1e9), mode)
        if verdict == LATE and gap is not None:
            start = first[0]
            res.late[key] = {"from": (start or 0) / 1e9, "to": None if tail else (self.sim.at(t2) or 0) / 1e9,
                             "gap": gap[0] / 1e9, "period": period, "where": where}
        elif verdict == UNDECIDED and key not in res.undecided:
            res.undecided[key] = (
                (self.sim.broken or "no /clock message before it") if gap is None else
                f"{'the run goes on' if tail else 'a gap'} of {gap[0] / 1e6:.0f}-{gap[1] / 1e6:.0f} ms of "
                f"simulated time after the message at {where}" + (
                    ", as /clock reached the node within the transport skew" if mode is True else
                    f" ({(t2 - t1) / 1e6:.0f} ms on the run's clock): over the period in one clock, not in the "
                    "other; the node's clock is not said (the mapping's use_sim_time decides it)"))

    def _later(self, ev: Event, at: float) -> None:
        """Note a stamp set aside in another writer's message placed at ``at``
        (s) for each output in simulated time it may show the clock of: the
        latest heard at or past the largest so far (a clock standing still,
        paused, is heard standing still until then)."""
        s = aside_stamp(ev.fields)
        if s is None:
            return
        for key, (last, was, rate, seen, _) in self.after.items():
            if seen <= s <= last + AHEAD_FACTOR * (rate or 0.0) * max(at - was, 0.0) + 1.0:
                self.after[key] = (last, was, rate, s, at)

    def _tail(self, key: str, end: float, rate: float) -> tuple[float, bool]:
        """``(tail, shown)``: output ``key``'s tail in its simulated clock,
        carried to the run's ``end`` (s) at ``rate`` from the latest stamp of
        that clock heard after its last message (its own last stamp if none),
        and whether that stamp alone passes the period (module docstring)."""
        last, _, _, seen, seen_at = self.after[key]
        return (seen - last) + (end - seen_at) * rate, seen - last > self.result.periods[key] + TOLERANCE_S

    def finish(self) -> PeriodResult:
        res = self.result
        if res.end is not None:
            for key, (t, where, first) in self.last_sim.items():  # the tail in simulated time (period_clock.py)
                if key not in res.late:
                    self._gap(key, t, first, to_ns(res.end), where, tail=True)
        for key, (stamp, where, at) in self.last.items():
            if key in res.late or res.end is None:
                continue
            tail = res.end - stamp
            now = self.sim.at(to_ns(at)) if key in self.first_aside and self.sim_mode is not False else None
            if now is not None and abs(now / 1e9 - stamp) <= 1.0:  # stamped on /clock: its tail read from it
                s0, t0 = self.first_aside[key]
                if at > t0 and stamp > s0:
                    res.clocks[key] = (stamp - s0) / (at - t0)
                self._gap(key, to_ns(at), (to_ns(stamp), to_ns(stamp)), to_ns(res.end), where, stamped=True,
                          tail=True)
                continue
            if key in self.first_aside:  # the run's end carried into the node's clock at the output's rate
                s0, t0 = self.first_aside[key]
                if at - t0 <= 0 or stamp - s0 <= 0:
                    res.unrated.append(key)
                    continue
                res.clocks[key] = rate = (stamp - s0) / (at - t0)
                tail = (res.end - at) * rate
                if key in self.after:
                    tail, shown = self._tail(key, res.end, rate)
                    if tail > res.periods[key] + TOLERANCE_S and not shown:
                        res.unrated.append(key)
                        continue
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
    of some periodic output -> ``pending``; a tail in simulated time not
    judged (:attr:`PeriodResult.unrated`, more than one message) ->
    ``inconclusive``; else ``discharged``."""
    for key, g in res.late.items():
        after = (f"the next at {g['to']:.3f} s ({g['where']})" if g["to"] is not None
                 else f"none after it although {trace} goes on to {res.end:.3f} s")
        return "failed", (f"{res.node}.{key} is declared periodic every {_ms(g['period'])} but a message at "
                          f"{g['from']:.3f} s has {after}: a gap of {_ms(g['gap'])}")
    silent = [k for k in res.periods if not res.messages.get(k)]
    if silent:
        return "pending", f"{trace} has no message of {', '.join(f'{res.node}.{k}' for k in silent)}: its period was not checked"
    if res.undecided:
        return "inconclusive", "; ".join(f"{res.node}.{k}: not decided in simulated time: {why}"
                                         for k, why in res.undecided.items())
    open_ = [k for k in res.unrated if res.messages.get(k, 0) > 1]
    if open_:
        return "inconclusive", (f"{', '.join(f'{res.node}.{k}' for k in open_)}: no gap over its period, but {trace} "
                                "goes on past it after the last message at the measured rate of its simulated clock, "
                                "which no later stamp shows: the clock may have slowed or paused (not judged)")
    return "discharged", ", ".join(f"{res.node}.{k}: {res.messages[k]} messages, no gap over {_ms(res.periods[k])}"
                                   for k in res.periods)


def with_periods(res: PeriodResult, trace: str, status: str, explanation: str) -> tuple[str, str, PeriodsPart]:
    """The monitor's verdict combined with the node's periods on the same run
    (``res``, :class:`PeriodMonitor`): a failed period fails the evidence,
    otherwise the verdict stands (a period that saw no message adds a note), but
    a discharged one is ``inconclusive`` beside a period whose tail could not
    be judged (:func:`period_status`).  Returns ``(status, explanation,
    {"periods": ...})``."""
    pstatus, pexpl = period_status(res, trace)
    if pstatus == "failed":
        return "failed", f"periods: {pexpl}; {explanation}", {"periods": res.to_json()}
    if pstatus == "inconclusive" and status == "discharged":
        return "inconclusive", f"{explanation}; periods: {pexpl}", {"periods": res.to_json()}
    return status, f"{explanation}; periods: {pexpl}", {"periods": res.to_json()}


def _ms(x: float) -> str:
    return f"{x * 1000:.0f} ms" if abs(x) < 10 else f"{x:.3f} s"
