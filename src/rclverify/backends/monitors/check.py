"""Offline checking of nodes' contracts on a recorded trace, and the engine's public names.

The engine (:class:`~.engine.NodeMonitor`) judges one node's contract on a
stream of messages under the one stream model of docs/semantics.md
(:mod:`rclverify.traces.questions`); its records (:class:`~.verdicts.Verdict`,
:class:`~.verdicts.NodeResult`) are in :mod:`.verdicts`.  This module runs
the engine over a recorded trace (:func:`check_trace`) and keeps every
name the transports and the evidence builder import from it.
"""
from __future__ import annotations

from typing import Callable, Iterable, Mapping

from rclverify.core.extras import installed
from rclverify.semantics.floatsem import Tolerance
from rclverify.lang.types import Checked, CheckedNode
from rclverify.traces.events import Event
from rclverify.traces.mapping import TopicRule
from rclverify.backends.monitors.engine import NodeMonitor
from rclverify.backends.monitors.verdicts import LINK_TOPICS, VERDICTS, NodeResult, Verdict, link_of, producers


def check_trace(checked: Checked, nodes: Iterable[CheckedNode], events: Iterable[Event],
                rules: Mapping[str, TopicRule], horizon: float,
                on_verdict: Callable[[Verdict], None] | None = None,
                tolerance: Tolerance | None = None,
                end: float | None = None, batch: bool = True, margins: bool = False) -> tuple[int, list[NodeResult]]:
    """Stream ``events`` through a monitor per node; returns (events read, results).

    The online engine (:class:`NodeMonitor`) run over a recorded trace: each
    event is fed in order, the clock advanced to the last event's time at the
    end (or to ``end``, seconds, when the run is known to have gone on after
    its last event: a live run's log, whose monitor kept its clock), then
    every monitor finished.  ``on_verdict`` receives every event's verdict
    as it is decided; ``tolerance`` as for :class:`NodeMonitor`.  Raises
    whatever the event source raises (:class:`TraceError`) after the events
    before it were processed.

    One node whose contract the batch path takes (:mod:`.batch`: quantifier-free
    REAL/enumeration contracts, one output topic, no state or link, triggers on one input) is
    judged by it, unless ``batch`` is false: the same verdicts, in the same
    order, the same result (tests/backends/test_monitor_batch.py).  Without numpy (the
    ``fast`` extra) every node is streamed.  A live monitor never comes here:
    it feeds :class:`NodeMonitor` itself.

    ``margins``: every guarantee judged on an answer also has its space
    margin computed (:mod:`rclverify.semantics.robustness`; docs/semantics.md,
    "Margins"): each ``satisfied`` or ``violated`` verdict on an output
    carries its message's margin (:attr:`Verdict.margin`) and each result
    the smallest margin of every guarantee (:attr:`NodeResult.margins`).
    The batch path computes them over its columns as the engine does.
    """
    nodes = list(nodes)
    if len(nodes) == 1 and batch and installed("numpy"):
        from rclverify.backends.monitors.batch import check_batch  # deferred: optional or conditional (numpy, the fast extra)
        done = check_batch(checked, nodes[0], events, rules, horizon, on_verdict, tolerance, end, margins=margins)
        if done is not None:  # eligible: the same verdicts, in batches (batch.py)
            return done[0], [done[1]]
    monitors = [NodeMonitor(checked, n, rules, horizon, on_verdict, tolerance) for n in nodes]
    for m in monitors:
        m.margins = margins
    count = 0
    last_time = 0.0
    if len(monitors) == 1:  # feed() moves the clock first itself
        feed = monitors[0].feed
        for ev in events:
            count += 1
            last_time = ev.time
            feed(ev)
    else:
        for ev in events:
            count += 1
            last_time = ev.time
            for m in monitors:  # every clock first (as a live monitor's timer would), then the message
                m.advance(ev.time)
            for m in monitors:
                m.feed(ev)
    for m in monitors:
        m.advance(max(last_time, end) if end is not None else last_time)
    return count, [m.finish() for m in monitors]


__all__ = ["LINK_TOPICS", "VERDICTS", "NodeMonitor", "NodeResult", "Verdict", "check_trace", "link_of", "producers"]
