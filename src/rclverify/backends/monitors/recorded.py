"""One recorded run checked against the selected nodes' contracts: the
message monitors, the deadline, period and declaration monitors, and a
live ROS 2 log's calls, all fed by one pass over the run (a log may be a
stream, read once), and the items the run did not judge (:mod:`.judged`:
silence is never green).

``rclverify monitor TRACE...`` (:mod:`rclverify.cli.monitor`) prints what
:func:`check_recorded` returns; nothing here prints.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Iterable, Iterator, Mapping, Sequence

from rclverify.lang.types import Checked, CheckedNode
from rclverify.traces import read_trace
from rclverify.traces.events import header_stamp_ns
from rclverify.backends.monitors.check import check_trace
from rclverify.backends.monitors.deadline_topics import has_deadlines
from rclverify.backends.monitors.declarations import (DeclarationMonitor, DeclarationResult, add_periods,
                                                      has_declarations)
from rclverify.backends.monitors.judged import Counted, Heard, not_judged
from rclverify.backends.monitors.log_calls import LogCalls
from rclverify.backends.monitors.periods import PeriodMonitor, PeriodResult, has_periods
from rclverify.backends.monitors.node_topics import copy_sources
from rclverify.backends.monitors.stamp_order import StampWatch, in_stamp_order, second_read, unless_stale
from rclverify.backends.monitors.summary import verdict_status
from rclverify.backends.monitors.widths import judged_at_widths, refuse_out_of_range
from rclverify.backends.monitors.verdicts import NodeResult
from rclverify.backends.monitors.run_origin import unseen_links

if TYPE_CHECKING:
    from rclverify.backends.monitors.bag_calls import BagCalls
    from rclverify.backends.monitors.deadline_records import DeadlineResult
    from rclverify.backends.monitors.deadlines import DeadlineMonitor


@dataclass
class RecordedRun:
    """What one recorded run says.  ``events``: events read; ``results``
    one :class:`.NodeResult` per node; ``deadlines``, ``periods``,
    ``declarations``: the results of those monitors (nodes that declare
    them); ``calls``: a live ROS 2 log's call summary (``None``: no call
    lines), with its per-node call ``call_entries`` and
    ``deadline_entries`` and ``missed`` ``(missed, judged)`` call
    deadlines; ``not_judged``: the items the run did not judge;
    ``stamp_order``: how a run recorded out of stamp order was judged
    (``""``: in the order read); ``stale``: why a run that could not be read
    again in stamp order gives no green (:mod:`.stamp_order`)."""

    events: int
    results: list[NodeResult]
    deadlines: list[DeadlineResult]
    periods: list[PeriodResult]
    declarations: list[DeclarationResult]
    calls: dict[str, Any] | None
    call_entries: list[dict[str, Any]]
    deadline_entries: list[dict[str, Any]]
    missed: tuple[int, int]
    not_judged: list[dict[str, str]]
    stamp_order: str = ""
    stale: str = ""

    def verdict(self, res: NodeResult, trace: str) -> tuple[str, str]:
        """``(status, explanation)`` of node result ``res`` on this run: its
        verdict (:func:`.summary.verdict_status`), inconclusive when the run
        is :attr:`stale`, with how the run was ordered said."""
        status, text = unless_stale(verdict_status(res, trace), self.stale)
        return status, text + (f"; {self.stamp_order}" if self.stamp_order else "")


def check_recorded(checked: Checked, nodes: Sequence[CheckedNode], cfg: Any, root: Path, trace: str,
                   on_warning: Callable[[str], None], margins: bool = False,
                   on_verdict: Callable[[str, Any, float | None], None] | None = None) -> RecordedRun:
    """Check the run at path ``trace`` against ``nodes`` under the monitor
    configuration ``cfg`` (:func:`.config.load_mapping`; its message
    directories relative to the workspace ``root``); ``on_warning`` gets
    the reader's warnings; ``margins``: the untimed check also computes the
    space margins (:func:`.check.check_trace`; the run is then streamed);
    ``on_verdict(kind, verdict, stamp)``, when given, receives every verdict
    of the pass the result is of, once the run is read, in the order decided:
    ``("guarantee", Verdict)`` for a topic's message, ``("call", Verdict)``
    for a call's or a goal's message and ``("deadline", DeadlineVerdict)``
    for a trigger's deadline (a topic's or a call's); ``stamp`` the judged
    message's header stamp (s; ``None``: it has none, or a deadline's).
    Raises :class:`rclverify.traces.TraceError` for
    a run that cannot be read, and whatever a malformed run makes the
    readers raise (the caller reports either, located)."""
    keep = on_verdict is not None
    one = _pass(checked, nodes, cfg, root, trace, on_warning, None, margins, keep)
    lag, note, stale = second_read(one.watch, trace, _readable_again(Path(trace)))  # one clock (stamp_order.py)
    if lag is not None:  # the first pass's verdicts are dropped with it
        one = _pass(checked, nodes, cfg, root, trace, on_warning, lag, margins, keep)
    one.note = note  # also without a second read: a writer in another clock a live log set aside, named
    dmons, pmons, decl, calls, heard, events, results = (one.dmons, one.pmons, one.decl, one.calls, one.heard,
                                                         one.events, one.results)
    dres = [m.finish() for m in dmons]
    pres = [p.finish() for p in pmons]
    decl_res = [add_periods(dm.finish(), dm.node, next((p for p in pres if p.node == dm.node.name), None))
                for dm in decl]
    summary = calls.finish()
    statuses = {res.node: [unless_stale(verdict_status(res, trace), stale)] for res in results}
    centries, dentries = calls.entries(), calls.deadline_entries()
    for c in centries:
        statuses.setdefault(c["node"], []).append((c["status"], c["explanation"]))
    dcounts = {d.node: {**d.counts, "undecided": d.unaccepted.get("undecided", 0)} for d in dres}
    why = {d.node: d.first_unaccepted["reason"] for d in dres
           if d.first_unaccepted is not None and d.first_unaccepted["why"] == "undecided"}
    for r in calls.deadlines():  # the topic and the call deadlines summed, as the live run does
        total = dcounts.setdefault(r.node, {})
        for v, k in r.counts.items():
            total[v] = total.get(v, 0) + k
    items = not_judged(nodes, Heard({**heard, **calls.messages}, dict(calls.orphans),
                                    unseen=unseen_links(calls.origin.origin)), statuses, dcounts,
                       f"in {trace}", decided_of(results, centries), why)
    if one.bag is not None:  # a bag without a link's call topics: say what it lacks (bag_calls.py)
        one.bag.explain(items)
    if on_verdict is not None:
        for kind, v in one.verdicts:
            on_verdict(kind, v, None if kind == "deadline" else one.stamps.get((v.topic.strip("/"), v.time)))
    return RecordedRun(events, results, dres, pres, decl_res, summary, centries, dentries,
                       calls.missed() if summary is not None else (0, 0), items, one.note, stale)


@dataclass
class _Pass:
    """The monitors of one read of a run and what the untimed check returned."""

    dmons: list[DeadlineMonitor]
    pmons: list[PeriodMonitor]
    decl: list[DeclarationMonitor]
    calls: LogCalls
    heard: dict[str, int]
    watch: StampWatch
    events: int
    results: list[NodeResult]
    note: str = ""
    bag: BagCalls | None = None
    #: every verdict decided, ``(kind, verdict)`` (:func:`check_recorded`'s ``on_verdict``); empty unless kept
    verdicts: list[tuple[str, Any]] = field(default_factory=list)
    #: (topic, time) -> header stamp (s) of each message read that has one; empty unless verdicts are kept
    stamps: dict[tuple[str, float], float] = field(default_factory=dict)


def _pass(checked: Checked, nodes: Sequence[CheckedNode], cfg: Any, root: Path, trace: str,
          on_warning: Callable[[str], None], lag: float | None, margins: bool = False, keep: bool = False) -> _Pass:
    """One read of the run feeding every monitor; in stamp order when ``lag`` is given
    (:func:`.stamp_order.in_stamp_order`); each node's constants compared as its fields carry them (widths.py);
    ``keep``: every verdict kept in :attr:`_Pass.verdicts`."""
    kept: list[tuple[str, Any]] = []
    answer = (lambda v: kept.append(("guarantee", v))) if keep else None
    deadline = (lambda v: kept.append(("deadline", v))) if keep else None
    dirs = [root / d for d in cfg.msg_dirs]
    judged = [judged_at_widths(checked, n, cfg.rules, dirs) for n in nodes]  # the live monitor's route too
    sources = [(k, s) for _, f in judged for k, s in f.items()]
    nodes = [n for n, _ in judged]
    dmons: list[DeadlineMonitor] = []
    if any(has_deadlines(n) for n in nodes):
        from rclverify.backends.monitors.batch_deadlines import deadline_monitor  # deferred: start-up (loaded only by a run with a deadline)
        dmons = [deadline_monitor(checked, n, cfg.rules, deadline, horizon=cfg.horizon, tolerance=cfg.tolerance)
                 for n in nodes if has_deadlines(n)]  # in batch where eligible (batch_deadlines.py)
    pmons = [PeriodMonitor(n, cfg.rules) for n in nodes if has_periods(n)]
    decl = [DeclarationMonitor(checked, n, cfg.rules, tolerance=cfg.tolerance) for n in nodes if has_declarations(n)]
    calls = LogCalls(checked, nodes, cfg.rules, cfg.horizon, trace)  # a live log's calls (log_calls.py)
    if calls.book is not None and keep:
        calls.book.on_verdict, calls.book.on_deadline = (lambda v: kept.append(("call", v))), deadline
    heard: dict[str, int] = {}
    run: Iterable[Any] = read_trace(Path(trace), [root / d for d in cfg.msg_dirs], streams=True, on_warning=on_warning)
    bag: BagCalls | None = None
    if calls.active:
        from rclverify.backends.monitors.bag_calls import BagCalls, bag_connections, is_ros2_bag  # deferred: start-up (loaded only by a run with calls)
        if is_ros2_bag(Path(trace)):
            bag = BagCalls(nodes, calls, trace, bag_connections(Path(trace), dirs))  # a bag's recorded calls (bag_calls.py)
    run = refuse_out_of_range(run, Path(trace), sources)  # a hand-made log's value no field carries (widths.py)
    reads = copy_sources(checked)  # whose stamps a writer may copy: the reorder and the watch read it alike
    if lag is not None:
        run = in_stamp_order(run, lag, reads)
    tapped: list[Any] = [*dmons, *pmons, *decl]
    source = _Tapped(run, tapped) if tapped else run  # a log keeps its columnar reading where it can (_Tapped)
    if bag is not None:
        source = bag.tap(source)
    elif calls.active:
        source = calls.tap(source)  # only nodes with links: never the batch path
    watch = StampWatch(getattr(cfg.rules, "skew", None) or 0.0, reads)  # the engine's transport skew (engine.py)
    stamps: dict[tuple[str, float], float] = {}
    if keep:  # each message's header stamp, what every path shares (the run is then streamed)
        source = _stamped(source, stamps)
    events, results = check_trace(checked, nodes, Counted(source, heard, watch), cfg.rules, cfg.horizon,
                                  answer, tolerance=cfg.tolerance, margins=margins)
    return _Pass(dmons, pmons, decl, calls, heard, watch, events, results, bag=bag, verdicts=kept, stamps=stamps)


def _stamped(events: Iterable[Any], stamps: dict[tuple[str, float], float]) -> Iterator[Any]:
    """``events`` unchanged, each one's header stamp (s) put in ``stamps`` under its (topic, time)."""
    for ev in events:
        ns = header_stamp_ns(ev.fields)
        if ns is not None:
            stamps[(ev.topic.strip("/"), ev.time)] = ns / 1e9
        yield ev


class _Tapped:
    """The run's events, each fed to the deadline, period and declaration monitors ``monitors`` before it is
    passed on.  A log's blocks (``blocks``, the batch path's reading: rows.py) are passed on whole when every
    monitor takes a block (:meth:`.batch_deadlines.BatchDeadlines.feed_block`): each block is fed to them
    first, so the log is read in blocks, not event by event; the monitors' verdicts and results are those of
    their events fed one by one (tests/backends/test_recorded_blocks.py).  A bag is fed event by event
    (its blocks may hold messages with a header stamp, which the batch deadline judge's columns do not read)."""

    def __init__(self, events: Iterable[Any], monitors: Sequence[Any]) -> None:
        self.events, self.monitors = events, monitors

    def __iter__(self) -> Iterator[Any]:
        feeds = [m.feed for m in self.monitors]
        for ev in self.events:
            for feed in feeds:
                feed(ev)
            yield ev

    def blocks(self, fields: Sequence[str], rows: int) -> Iterator[Any] | None:
        """The log's blocks of at most ``rows`` lines (``fields``: the keys the reader asks for, with the
        monitors' own), each fed to the monitors first; ``None`` when the source is no log read in blocks
        (:class:`~rclverify.traces.jsonl_blocks.JsonlLog`) or a monitor takes no block."""
        from rclverify.traces.jsonl_blocks import JsonlLog  # deferred: optional or conditional (numpy, as read_trace)
        from rclverify.backends.monitors.batch_deadlines import BatchDeadlines  # deferred: start-up (loaded only by a run with a deadline, a period or a declaration)
        if not isinstance(self.events, JsonlLog) or not all(isinstance(m, BatchDeadlines) for m in self.monitors):
            return None
        own = [f for m in self.monitors for f in (m.plan.in_field, m.plan.out_field)]
        got = self.events.blocks(list(dict.fromkeys([*fields, *own])), rows)
        return None if got is None else self._fed(got)

    def _fed(self, blocks: Iterator[Any]) -> Iterator[Any]:
        for block in blocks:
            for m in self.monitors:
                if isinstance(block, list):  # the log's exact path: its events
                    for ev in block:
                        m.feed(ev)
                else:
                    m.feed_block(block)
            yield block


def _decided(res: NodeResult) -> int:
    """The answers of ``res`` decided satisfied or violated."""
    return int(res.counts.get("satisfied", 0)) + int(res.counts.get("violated", 0))


def decided_of(results: Iterable[NodeResult], call_entries: Iterable[Mapping[str, Any]]) -> dict[str, int]:
    """Node name -> its answers decided on its topics (``results``) and its calls (``call_entries``:
    :meth:`.log_calls.LogCalls.entries`), for :func:`.judged.not_judged`."""
    out = {r.node: _decided(r) for r in results}
    for e in call_entries:
        c = (e.get("calls") or {}).get("counts") or {}
        out[e["node"]] = out.get(e["node"], 0) + int(c.get("satisfied", 0)) + int(c.get("violated", 0))
    return out


def _readable_again(path: Path) -> bool:
    """Whether the run at ``path`` can be read a second time (a regular file or a bag folder, not a stream)."""
    return path.is_dir() or path.is_file()
