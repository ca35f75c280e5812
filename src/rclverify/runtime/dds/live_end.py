"""The end of a live run on DDS (:mod:`.live`): the wait for its stop, the
stop of its threads and its evidence record.

:class:`DdsRunEnd` is the part of the run (``live._DdsRun``) that runs
once the bus and the engine thread are started: :meth:`~DdsRunEnd.wait`
until the stop, the duration or a thread's death, with a status line
(:func:`status_line`) every ``status_s`` s; :meth:`~DdsRunEnd.finish` stops
the bus and the engine thread and makes the evidence record: the ROS 1 one
(``live.stop_and_record``) with the run's ``source``, ``rmw`` and
``middleware`` (:meth:`~DdsRunEnd.origin`), ``calls`` (per node the
call-by-call verdicts' status), ``deadlines``, ``qos`` (per contract topic the
reader's QoS and what it heard), ``clock`` (the same of ``/clock``, the run's
simulated clock, when a publisher of it was heard), ``warnings``, ``enforce``,
``bypass`` and ``bag`` (docs/ros2.md), the recorded bag ending at the time the live
run's clock reached (:func:`run_clock`, :mod:`rclverify.traces.bag_end`), whatever
its contracts are.
"""
from __future__ import annotations

import json
import math
import time as _time
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Any, Callable, Mapping

from rclverify.records.store import atomic_write_text
from rclverify.lang.types import CheckedNode
from rclverify.backends.monitors.run_origin import unseen_line
from rclverify.ros.live.dds import domain_id
from rclverify.backends.monitors.summary import verdict_status
from rclverify.runtime.dds.bag import BagRecorder
from rclverify.runtime.dds.bag_calls import CallRecorder
from rclverify.backends.monitors.dds_calls import CallBook
from rclverify.runtime.dds.services import CallTaps
from rclverify.runtime.live import LiveRun, stop_and_record
from rclverify.runtime.worker import EngineWorker
from rclverify.runtime.dds.trust import downgrade
from rclverify.runtime.dds.nobody import nobody_line
from rclverify.runtime.shapes import TapJson


def status_line(live: LiveRun, calls: Mapping[tuple[str, str], int]) -> str:
    """The topic engine's status line, then the calls' verdicts per node."""
    line = live.status_line(wait=False)  # never waits for the bound's library: a stop is heard (live_status.py)
    per: dict[str, list[str]] = {}
    for (node, verdict), n in sorted(dict(calls).items()):  # copied at once: the engine thread adds to it
        per.setdefault(node, []).append(f"{n} {verdict}")
    return line + ("" if not per else " | calls: " + "; ".join(f"{n} {', '.join(v)}" for n, v in per.items()))


def _version() -> str:
    try:
        return f"cyclonedds {version('cyclonedds')}"
    except PackageNotFoundError:
        return "cyclonedds (version unknown)"


class DdsRunEnd:
    """The end of one live run on DDS (module docstring).  The run sets the
    attributes below while it joins and listens; the ``out`` and ``warn``
    lines go to the user, ``warn``'s to the record's ``warnings`` too."""

    nodes: list[CheckedNode]
    enforce: dict[str, str]
    out: Callable[[str], None]
    live: LiveRun
    #: the DDS bus, or the rclpy source's with its face
    bus: Any
    book: CallBook | None
    calls: CallTaps | None
    call_counts: dict[tuple[str, str], int]
    recorder: BagRecorder | None
    #: the tap of ``/clock`` heard beside the contract topics (``None``: a contract names it, or none)
    clock_tap: Any
    call_recorder: CallRecorder | None
    warnings: list[str]
    decode_errors: dict[str, int]
    receipt_timed: int
    by_receipt: bool
    t0: float

    def warn(self, text: str) -> None:
        self.warnings.append(text)
        self.out(text)

    def origin(self) -> tuple[str, str, str]:
        """``(source, rmw, middleware)`` of this run: ``rclpy`` with the agent's
        middleware, or ``dds`` with the monitor's own participant."""
        hello = getattr(self.bus, "hello", None)
        if hello is not None:
            return ("rclpy", str(hello.get("rmw", "")), f"rclpy {hello.get('rclpy', '')} on {hello.get('rmw', '')} "
                    f"(ROS 2 Python {hello.get('python', '')}, domain {domain_id()})")
        return "dds", "DDS participant (Cyclone DDS)", f"DDS domain {domain_id()} ({_version()})"

    def source_rmw(self) -> str:
        """The middleware the rclpy agent runs on (its hello), or ``DDS``."""
        hello = getattr(self.bus, "hello", {})
        return str(hello.get("rmw", "DDS"))

    def wait(self, worker: EngineWorker, stop: Any, duration: float | None, tick_s: float, status_s: float) -> None:
        """Until ``stop`` is set, ``duration`` s passed or a thread died,
        with a status line every ``status_s`` s."""
        t0 = self.t0 = _time.monotonic()
        next_status = t0 + status_s
        while not stop.is_set():
            if duration is not None and _time.monotonic() - t0 >= duration:
                break
            stop.wait(min(0.1, tick_s * 5))
            if worker.error is not None or self.bus.error is not None:
                break  # a dead thread: stop and say so, never monitor on silently
            if status_s > 0 and _time.monotonic() >= next_status:
                self.out(status_line(self.live, self.call_counts))
                next_status += status_s

    def finish(self, worker: EngineWorker, evidence: Path | None) -> dict[str, Any]:
        """Stop the threads and make the evidence record (module docstring),
        written to ``evidence`` when given."""
        bus, live, calls, book = self.bus, self.live, self.calls, self.book
        bus_error = ""
        try:
            bus.stop()
        except Exception as exc:  # noqa: BLE001 - said in the record
            bus_error = f"{type(exc).__name__}: {exc}"
        try:
            worker.stop()
        except Exception:  # noqa: BLE001 - stop_and_record stops it again and records the error
            pass
        unheard = calls.unheard() if calls is not None else {}  # the rclpy source: links it heard nothing of
        for name, why in unheard.items():
            self.warn(f"{calls.where[name] if calls is not None else name}: warning: {name}: the rclpy source hears "
                      f"calls through introspection events only, and {why}: enable introspection on its server "
                      "(docs/ros2.md), or monitor with --source dds")
        if unheard:
            live.note(unseen_line(_time.time(), [f"{name}: {why}" for name, why in unheard.items()]))
        summary = calls.finish() if calls is not None else None  # while the log is open
        record_ = stop_and_record(worker, live, None, self.out)
        if bus_error:
            record_["bus_error"] = bus_error
            for n in record_["nodes"]:
                n["status"], n["explanation"] = "error", f"the DDS reader thread stopped: {bus_error}"
        source, rmw, middleware = self.origin()
        record_.update(source=source, rmw=rmw, middleware=middleware,
                       unseen=[f"{name}: {why}" for name, why in unheard.items()])
        clock_tap = self.clock_tap
        qos: dict[str, TapJson] = {t.key: t.to_json() for t in bus.taps if t is not clock_tap}
        clock: TapJson | None = clock_tap.to_json() if clock_tap is not None else None
        for key, n in getattr(bus, "before", {}).items():
            into = clock if clock_tap is not None and key == clock_tap.key else qos.get(key)
            if into is not None:
                into["published_before_heard"] = n
        writers = getattr(getattr(bus, "discovery", None), "writers", None)  # the DDS source's discovery only
        nobody = nobody_line(qos, _time.monotonic() - self.t0, middleware,
                             None if writers is None else len({w.participant for w in writers.values()}))
        if nobody is not None:  # said, and in the record's warnings (nobody.py)
            self.warn(nobody)
        if clock is not None and (clock["publishers_heard"] or clock["samples"]):
            record_["clock"] = clock  # the run's simulated clock, heard beside the contract topics
        record_.update(warnings=self.warnings, decode_errors=self.decode_errors, qos=qos,
                       event_time={"clock": "receipt (--reorder-window 0)" if self.by_receipt else
                                   "source timestamp", "receipt_timed": self.receipt_timed})
        if summary is not None and book is not None:
            record_["calls"] = _calls_record(summary, book, calls)
            record_["deadlines"] = {"results": summary["deadlines"], "false": summary["false"]}
            # a node whose timed guarantees are triggered through its services or actions is judged by the call
            # book: the log checks' topic deadline monitor of it, which sees no call, is not a second verdict
            by_calls = {r["node"] for r in summary["deadlines"]}
            record_["topic_deadlines"] = [d for d in record_.get("topic_deadlines", [])
                                          if not (d["status"] == "pending" and d["node"] in by_calls)]
        if self.enforce:
            record_["enforce"] = live.gate_counts  # type: ignore[attr-defined]
        bypass = {k: sorted(v) for k, v in bus.bypass.items() if v}
        if bypass:
            record_["bypass"] = bypass
        downgrade(record_["nodes"], {n.name: [t.field.strip("/") for t in n.node.topics] for n in self.nodes},
                  bypass, {t.key: t.reader_changes for t in bus.taps})
        if self.recorder is not None:
            end = run_clock(live)
            if end is not None:  # the bag ends where the live clock did (traces/bag_end.py)
                self.recorder.end(end)
            record_["bag"] = self.recorder.close()
            if self.call_recorder is not None and self.call_recorder.failed:
                record_["bag"]["calls_failed"] = self.call_recorder.failed
        record_["not_judged"] = live.not_judged(record_)  # silence is never green (judged.py; record's unseen too)
        if evidence is not None:
            atomic_write_text(evidence, json.dumps(record_, indent=2, sort_keys=True) + "\n")
        self.out(status_line(live, self.call_counts))
        return record_


def run_clock(live: LiveRun) -> float | None:
    """The time (s since the epoch, the log's time line) the live run's monitors' clock reached when it
    stopped: the latest of every node monitor's (moved by each message released and by the timer to the
    engine's watermark, :meth:`~rclverify.backends.monitors.online.OnlineEngine.tick`) and of the deadline
    checks' (:mod:`rclverify.runtime.logchecks`: the same watermark, and every line the log carries); a
    question whose horizon that clock passed was closed live, and a deadline it passed is ``false``.
    ``None`` when no clock moved (nothing heard, no timer run)."""
    clocks = [m.now for m in live.engine.monitors if math.isfinite(m.now)]
    clocks += [d.now for d in live.checks.deadlines if d.now_ns is not None]
    return max(clocks) if clocks else None


def _calls_record(summary: Mapping[str, object], book: CallBook, calls: CallTaps | None) -> dict[str, Any]:
    """The record's ``calls``: the counts of the call-by-call verdicts, each
    node's status over its calls, and the samples heard per call topic."""
    out: dict[str, Any] = {"counts": summary["counts"], "nodes": [], "samples": calls.counts if calls is not None else {},
                           "undecided": summary.get("undecided", {}), "unjudged": summary.get("unjudged", {})}
    for name, res in book.results.items():
        status, explanation = verdict_status(res, "the live calls")
        explanation = book.with_notes(name, explanation)  # undecided answers and endpoints not heard, whatever the status
        out["nodes"].append({"node": name, "status": status, "explanation": explanation, **res.to_json()})
    return out


__all__ = ["DdsRunEnd", "run_clock", "status_line"]
