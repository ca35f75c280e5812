"""One read of a recorded run feeding every monitor of a node
(:mod:`.backend`): the untimed check, and beside it the deadline, period
and declaration monitors (:class:`Beside`), a live log's calls, the run's
span in trace time (:class:`TraceSpan`), the topics heard and the stamps'
order; the run is read once (:func:`read_run`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Iterable, Iterator

from rclverify.traces import read_trace
from rclverify.backends.base import NodeTarget
from rclverify.backends.monitors.bag_calls import BagCalls, bag_connections, is_ros2_bag
from rclverify.backends.monitors.check import check_trace
from rclverify.backends.monitors.run_origin import RunOrigin
from rclverify.backends.monitors.shapes import RunSource
from rclverify.backends.monitors.config import MonitorConfig
from rclverify.backends.monitors.deadline_topics import has_deadlines
from rclverify.backends.monitors.batch_deadlines import deadline_monitor
from rclverify.backends.monitors.declarations import DeclarationMonitor, has_declarations
from rclverify.backends.monitors.judged import Counted
from rclverify.backends.monitors.lifecycle import gate_of, gated
from rclverify.backends.monitors.log_calls import LogCalls
from rclverify.backends.monitors.periods import PeriodMonitor, has_periods
from rclverify.backends.monitors.widths import judged_at_widths, refuse_out_of_range
from rclverify.backends.monitors.node_topics import copy_sources
from rclverify.backends.monitors.stamp_order import StampWatch, in_stamp_order


@dataclass
class RunRead:
    """One pass of the monitors over a run (:func:`read_run`)."""

    beside: "Beside"
    calls: LogCalls
    span: "TraceSpan"
    heard: dict[str, int]
    watch: StampWatch
    events: int
    results: list[Any]
    summary: dict[str, Any] | None
    bag: BagCalls | None = None
    origin: RunSource | None = None
    gate: Any = None


def read_run(target: NodeTarget, cfg: MonitorConfig, trace: str, lag: float | None) -> RunRead:
    """One read of the run at ``trace`` feeding the untimed check, the deadlines, the periods, the
    declarations and a live log's calls; in stamp order when ``lag`` (s, :func:`.stamp_order.in_stamp_order`)
    is given.  Raises what the readers and the checkers raise (the caller reports it)."""
    # the contract's constants compared as the fields carry them (widths.py)
    node, fields = judged_at_widths(target.checked, target.node, cfg.rules, [target.root / d for d in cfg.msg_dirs])
    beside = Beside()
    if has_deadlines(node):
        beside.add("deadlines", lambda: deadline_monitor(target.checked, node, cfg.rules,
                                                         horizon=cfg.horizon, tolerance=cfg.tolerance))
    if has_periods(node):  # periodic outputs on the same run (periods.py)
        beside.add("periods", lambda: PeriodMonitor(node, cfg.rules))
    if has_declarations(node):  # initially, progress, periodic judged on the same run (declarations.py)
        beside.add("declarations", lambda: DeclarationMonitor(target.checked, node, cfg.rules,
                                                              tolerance=cfg.tolerance))
    # a live log's service calls and action goals, judged as the live run judged them (log_calls.py)
    calls = LogCalls(target.checked, [node], cfg.rules, cfg.horizon, trace)
    span = TraceSpan()  # the run's duration in trace time (the strength's detail, docs/confidence.md)
    heard: dict[str, int] = {}  # events per topic: what the run did not judge (judged.py)
    reads = copy_sources(target.checked)  # whose stamps a writer may copy: the watch and the reorder read it alike
    watch = StampWatch(getattr(cfg.rules, "skew", None) or 0.0, reads)  # the engine's transport skew (engine.py)
    dirs = [target.root / d for d in cfg.msg_dirs]
    path = target.root / trace
    source: Iterable[Any] = read_trace(path, dirs)
    bag = BagCalls([node], calls, trace, bag_connections(path, dirs)) \
        if calls.active and is_ros2_bag(path) else None  # a bag's recorded calls, as `monitor BAG` reads them
    source = refuse_out_of_range(source, path, fields.items())  # a value no field carries
    if lag is not None:
        source = in_stamp_order(source, lag, reads)
    inner = bag.tap(source) if bag is not None else calls.tap(source) if calls.active else source
    origin = RunOrigin()  # the source and middleware a live log says it was heard through (run_origin.py)
    gate = gate_of([node])  # a managed node's messages judged in its lifecycle scope, as live (lifecycle.py)
    if gate is not None:
        inner = gated(inner, gate)
    events, results = check_trace(target.checked, [node], Counted(span.tap(beside.tap(origin.tap(inner))), heard,
                                                                  watch), cfg.rules, cfg.horizon,
                                  tolerance=cfg.tolerance, margins=True)
    heard = gate.counted(heard) if gate is not None else heard  # the messages the gate kept count as heard
    return RunRead(beside, calls, span, heard, watch, events, results, calls.finish(), bag, origin.origin, gate)


class Beside:
    """The deadline and period monitors of a node fed from the untimed
    check's read of a run (:meth:`tap`), so a run is read once.  An error of
    one of them is kept under its name (its evidence's error, as when it read
    the run itself) and that monitor is fed no more; the read goes on."""

    def __init__(self) -> None:
        self.monitors: dict[str, Any] = {}
        self.errors: dict[str, Exception] = {}

    def add(self, name: str, make: Callable[[], Any]) -> None:
        """The monitor ``make()`` makes, fed under ``name`` (its error kept)."""
        try:
            self.monitors[name] = make()
        except Exception as exc:  # noqa: BLE001 - reported as that check's error
            self.errors[name] = exc

    def tap(self, events: Iterable[Any]) -> Iterator[Any]:
        """``events`` unchanged, each fed to the monitors first."""
        if not self.monitors:
            yield from events
            return
        for ev in events:
            for name, m in list(self.monitors.items()):
                try:
                    m.feed(ev)
                except Exception as exc:  # noqa: BLE001 - reported as that check's error
                    self.errors[name] = exc
                    del self.monitors[name]
            yield ev

    def finish(self) -> dict[str, Any]:
        """Each monitor's result (after the run), by name; a failing finish is an error too."""
        out: dict[str, Any] = {}
        for name, m in self.monitors.items():
            try:
                out[name] = m.finish()
            except Exception as exc:  # noqa: BLE001
                self.errors[name] = exc
        return out


class TraceSpan:
    """The span of a run in trace time: :meth:`tap` passes the events on and
    notes the first and last event's ``time``; :attr:`seconds` is their
    difference (``None`` before any event)."""

    def __init__(self) -> None:
        self.first: float | None = None
        self.last: float | None = None

    def tap(self, events: Any) -> Any:
        for ev in events:
            if self.first is None:
                self.first = ev.time
            self.last = ev.time
            yield ev

    @property
    def seconds(self) -> float | None:
        return None if self.first is None or self.last is None else round(self.last - self.first, 6)
