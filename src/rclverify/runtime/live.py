"""A live monitoring run, independent of the middleware.

:class:`LiveRun` is what ``rclverify monitor --live`` runs around the
:class:`~.online.OnlineEngine`; the ROS 1 runner (:func:`.live_ros1.run_ros1`) and the
ROS 2 layer (:mod:`.ros2`) only move messages in and verdicts out.  It

* writes every released message and every verdict as JSON lines in
  ROSMonitoring's log format (``topic``, ``time``, the fields flattened;
  verdicts on the topic :data:`VERDICT_LOG_TOPIC`, which no contract names,
  so ``rclverify monitor LOG`` re-checks the messages and skips them);
* hands each verdict, as JSON text, to ``publish`` (node, guarantee,
  verdict, time, the first violation's values ...), and each node's latest
  verdict to ``publish_last`` (a latched topic) when it changed, at a
  timer tick at most every :data:`FLUSH_S` (20 ms) and when the run stops;
* keeps a one-line status per node (:meth:`status_line`);
* runs each node's timed guarantees (``triggered by ... within ...``)
  and periodic outputs through the offline check's monitors, fed the very
  lines it writes to the log (:mod:`.logchecks`); each deadline verdict is
  a log line (topic :data:`VERDICT_LOG_TOPIC`, ``kind: "deadline"``,
  ``time`` the clock that decided it) and is published (``{"kind":
  "deadline", ...}``);
* counts what it heard of every item of the contracts (:mod:`.judged`);
* with ``margins``, computes every judged answer's space margin
  (docs/semantics.md, "Margins"): each verdict carries its message's
  (``margin``), the status line each guarantee's smallest so far, the
  record each guarantee's smallest; with ``warn_margin`` (which implies
  ``margins``) ``warn`` gets one line whenever a satisfied answer sets a
  guarantee's new smallest margin below it, before any violation
  (:class:`.live_status.LowMargins`);
* on :meth:`stop` writes a monitoring evidence record shaped like the
  offline one (events, verdict counts, first violation, the log's sha256,
  the deadlines as ``topic_deadlines``, the periods as ``periods``).

docs/monitors.md ("Live monitoring") gives the decisions.
"""
from __future__ import annotations

import hashlib
import json
import math
import threading
from datetime import datetime, timezone
from pathlib import Path
from typing import IO, Any, Callable, Iterable, Mapping

from rclverify.records.store import atomic_write_text
from rclverify.lang.types import Checked, CheckedNode
from rclverify.traces.events import Event
from rclverify.traces.mapping import TopicRule
from rclverify.backends.monitors.summary import monitoring_details, summary_line, tool_versions, verdict_status
from rclverify.backends.monitors.check import NodeResult, Verdict
from rclverify.backends.monitors.deadline_records import DeadlineVerdict
from rclverify.backends.monitors.judged import Heard, count_call_line, explain, not_judged
from rclverify.backends.monitors.run_origin import is_run_start, unseen_links
from rclverify.runtime.lifecycle import LifecycleGate, gate_of
from rclverify.runtime.live_status import LowMargins, least_margins, running_bound
from rclverify.runtime.logchecks import LogChecks
from rclverify.runtime.shapes import LiveCounts, SilenceNote
from rclverify.backends.monitors.online import OnlineEngine
from rclverify.runtime.worker import EngineWorker

VERDICT_LOG_TOPIC = "rclverify/verdict"
#: the least time (s, the run's clock) between two publications of the latched last verdicts and two
#: flushes of the log: the engine worker ticks at each message's release at a high rate (runtime/worker.py)
FLUSH_S = 0.02


def _json_safe(v: Any) -> Any:
    if isinstance(v, float) and not math.isfinite(v):
        return repr(v)  # JSON has no NaN; the reader would refuse the line
    if isinstance(v, dict):
        return {str(k): _json_safe(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_json_safe(x) for x in v]
    return v


#: the one encoder of the log's and the verdicts' JSON (made once: ``json.dumps`` with options makes one a call)
_ENCODER = json.JSONEncoder(allow_nan=False, separators=(", ", ": "))


def dumps(obj: Any) -> str:
    """Compact JSON; a NaN or an infinity (no JSON number) is written as its
    string (``"nan"``), so every line stays readable by the log reader."""
    try:
        return _ENCODER.encode(obj)
    except ValueError:
        return json.dumps(_json_safe(obj), separators=(", ", ": "))


class LiveRun:
    """One live run: engine, log, verdict sinks, status and evidence.

    ``log`` is the JSON-lines file to write (created, truncated);
    ``publish(text)`` / ``publish_last(node, text)`` the verdict sinks (JSON text);
    ``horizon``, ``reorder_window`` and ``silence_s`` in seconds.  Thread
    safe: :meth:`push` and :meth:`tick` may come from different threads.
    """

    def __init__(self, checked: Checked, nodes: Iterable[CheckedNode], rules: Mapping[str, TopicRule],
                 horizon: float, log: Path, *, reorder_window: float = 0.05, silence_s: float = 0.0,
                 publish: Callable[[str], None] | None = None,
                 publish_last: Callable[[str, str], None] | None = None, margins: bool = False,
                 warn_margin: float | None = None, warn: Callable[[str], None] | None = None) -> None:
        self.log_path = log
        log.parent.mkdir(parents=True, exist_ok=True)
        self._log: IO[str] = log.open("w", encoding="utf-8")
        self.publish, self.publish_last = publish, publish_last
        self.lock = threading.Lock()
        self.started = datetime.now(timezone.utc).isoformat(timespec="seconds")
        self.silences: list[SilenceNote] = []
        self.verdicts = 0
        #: verdicts given as the run stopped, on times the watermark had not passed (OnlineEngine.early)
        self.provisional = 0
        nodes = list(nodes)
        self.nodes = nodes
        self.engine = OnlineEngine(checked, nodes, rules, horizon, reorder_window, silence_s,
                                   on_verdict=self._verdict, on_silence=self._silence, on_event=self._event,
                                   admit=self._admit)
        self._gate: LifecycleGate | None = None
        self.gate = gate_of(nodes)
        #: margins (module docstring): computed when asked for or warned about; warned below ``warn_margin``
        self.low = None if warn_margin is None else LowMargins(self.engine.monitors, warn_margin, warn)
        for m in self.engine.monitors:
            m.margins = margins or warn_margin is not None
        #: the offline check's deadline and period monitors, fed the log's lines (logchecks.py)
        self.checks = LogChecks(checked, nodes, rules, horizon, self._deadline)
        #: link part ("estop/request") -> its call events heard (paired), and answers heard without their call
        self.calls_heard: dict[str, int] = {}
        self.orphans: dict[str, int] = {}
        self.results: list[NodeResult] | None = None
        self._last: dict[str, str] = {}  # node -> latest verdict not yet published as its last verdict
        self._flushed = -math.inf  # the tick time (s) of the last publication of the last verdicts and log flush

    # -- engine callbacks (called under the lock) ----------------------------------
    def _event(self, ev: Event) -> None:
        late = {"late_s": round(ev.late, 6)} if ev.late else {}  # at its source time, with how late it was heard
        # a late message, and one placed at a header stamp older than its publication (a stale copied stamp:
        # ``source`` set, ``stamp`` its time), at its source time: the offline check of the log reads the
        # publication from ``time`` and judges it against every question it could answer, as the engine did
        published = ev.source is not None and (late or ev.stamp == ev.time)
        self._log.write(dumps({"topic": ev.topic, "time": ev.source if published else ev.time,
                               **late, **{k: v for k, v in ev.fields.items() if k not in ("topic", "time")}}) + "\n")

    @property
    def gate(self) -> LifecycleGate | None:
        """What every message passes before the judge: managed nodes' states (lifecycle.py), or
        ``None``; asked in the engine's release order, after the message's log line
        (:attr:`OnlineEngine.admit`), its transition topics ordered with the rest
        (:attr:`OnlineEngine.gate_topics`).  Set before the first message."""
        return self._gate

    @gate.setter
    def gate(self, gate: LifecycleGate | None) -> None:
        self._gate = gate
        self.engine.gate_topics = frozenset(gate.events) if gate is not None else frozenset()

    def _admit(self, ev: Event) -> bool:
        """Whether a released message goes on to the judges: the lifecycle gate's word
        (:meth:`LifecycleGate.admit`), every message without one; an admitted one goes to the deadline
        checks here, after its log line, so they see the questions the guarantees' judge sees."""
        ok = self.gate is None or self.gate.admit(ev.topic, ev.fields, ev.time)
        if ok:
            self.checks.event(ev)
        return ok

    def _deadline(self, v: DeadlineVerdict, t: float) -> None:
        line = {"topic": VERDICT_LOG_TOPIC, "time": t, "kind": "deadline", "verdict": v.to_json()}
        self._log.write(dumps(line) + "\n")
        self.checks.line(line, deadline=True)
        # a `false` given as the run stopped, on a deadline the watermark had not passed: an answer stamped
        # within it may have been in flight (docs/semantics.md, "Provisional verdicts")
        early = v.verdict == "false" and self.engine.early(v.due)
        self.provisional += early
        if self.publish is not None:
            self.publish(dumps({"kind": "deadline", **v.to_json(), **({"provisional": True} if early else {})}))

    def _verdict(self, v: Verdict) -> None:
        self.verdicts += 1
        self.provisional += v.provisional
        text = dumps(v.to_json())  # serialised once: the log line and the published message
        self._log.write(f'{{"topic": "{VERDICT_LOG_TOPIC}", "time": {v.decided_at!r}, "verdict": {text}}}\n')
        if self.checks.active:
            self.checks.line({"topic": VERDICT_LOG_TOPIC, "time": v.decided_at})
        if self.publish is not None:
            self.publish(text)
        self._last[v.node] = text
        if self.low is not None:
            self.low.heard(v)

    def _silence(self, topic: str, seconds: float, silent: bool) -> None:
        note: SilenceNote = {"topic": topic, "silent": silent, "for_s": round(seconds, 3),
                "time": self.engine.monitors[0].now if self.engine.monitors else 0.0}
        if silent:
            self.silences.append(note)
        if self.publish is not None:
            self.publish(dumps({"node": "", "verdict": "silent" if silent else "resumed", "topic": topic,
                                "silent_for_s": round(seconds, 3), "time": note["time"]}))

    # -- input ---------------------------------------------------------------------
    def push(self, topic: str, fields: Mapping[str, object], received: float,
             writer: bytes | str | None = None) -> None:
        """One message from the middleware (its event time in seconds; its
        ``writer``'s id where the source names it: :meth:`OnlineEngine.push`)."""
        with self.lock:
            if self.results is None:
                self.engine.push(topic, fields, received, writer=writer)

    def match(self, sets: Mapping[str, Iterable[bytes | str]]) -> None:
        """The writers the source matches on each topic now (topic -> writer
        ids): :meth:`OnlineEngine.match`, handed over without the lock (a
        mapping replaced whole), from the source's discovery thread."""
        self.engine.match(sets)

    def due(self) -> float:
        """When the next buffered message is released (s; :meth:`OnlineEngine.due`)."""
        with self.lock:
            return self.engine.due() if self.results is None else math.inf

    def tick(self, now: float) -> None:
        """The timer (see :meth:`OnlineEngine.tick`); the latched last verdicts
        published and the log flushed once per :data:`FLUSH_S` of ``now``."""
        with self.lock:
            if self.results is None:
                # the deadline checks' clock: the watermark the engine released up to (never one read again:
                # the source's thread may hand a matched set over in between and move it past the release)
                self.checks.advance(self.engine.tick(now))
                if not now < self._flushed + FLUSH_S:
                    self._flushed = now
                    self._flush_last()
                    self._log.flush()

    def note(self, obj: Mapping[str, object]) -> None:
        """One more line of the log (the service proxy's events,
        :mod:`.service_proxy`; the start-of-run marker, after which
        each node's ``first(in.x)`` is decided as the offline check of the
        log decides it, :mod:`~rclverify.backends.monitors.first_messages`);
        dropped once the run stopped."""
        with self.lock:
            if self.results is None:
                self._log.write(dumps(dict(obj)) + "\n")
                if is_run_start(str(obj.get("topic")), obj):
                    for m in self.engine.monitors:  # first(in.x) decided from here on, as on the log (first_messages.py)
                        m.first.start()
                self.checks.line(obj)
                self._heard_call(obj)

    def _heard_call(self, obj: Mapping[str, object]) -> None:
        """Count a call event of the log (the ROS 1 proxy's ``kind: "event"``
        lines, their message's topic as ``call``; the DDS call book's ``kind:
        "call"`` ones) for :mod:`.judged`."""
        if obj.get("kind") == "event" and isinstance(obj.get("call"), str):
            key = str(obj["call"]).strip("/")
            self.calls_heard[key] = self.calls_heard.get(key, 0) + 1
        else:
            count_call_line(obj, self.calls_heard, self.orphans)

    def _flush_last(self) -> None:
        """Publish each node's latest verdict (latched), at most once per
        :data:`FLUSH_S` rather than at every event: the topic holds the last
        one either way."""
        if self.publish_last is not None:
            for node, text in self._last.items():
                self.publish_last(node, text)
        self._last.clear()

    def status_line(self, wait: bool = True) -> str:
        """``Node: 3 satisfied, 1 violated; 4 answer(s) counted, 95 % bound 0.75 per answer | Node2: ...``
        (a live per-node status: the counts so far, docs/statistics.md); ``wait`` false: at once, the
        bound said to be loading until its library is (:func:`.live_status.running_bound`)."""
        with self.lock:
            parts = [summary_line(m.result) + running_bound(m.result, wait) + least_margins(m.result)
                     for m in self.engine.monitors]
            parts += self.checks.status()
        silent = [t for t, s in self.engine.topics.items() if s.silent]
        return " | ".join(parts) + (f" | silent: {', '.join(sorted(silent))}" if silent else "")

    # -- stop ------------------------------------------------------------------------
    def stop(self, evidence: Path | None = None) -> dict[str, Any]:
        """Finish the run (obligations still within their horizon are ``open``),
        close the log and write the evidence record (atomically) when
        ``evidence`` is given; returns the record."""
        with self.lock:
            if self.results is None:
                self.results = self.engine.finish()
                self.checks.finish()  # currently_false deadlines: logged
                self._flush_last()
                self._log.close()
        sha = hashlib.sha256(self.log_path.read_bytes()).hexdigest()
        versions = tool_versions()
        horizon = self.engine.horizon
        nodes = []
        observed = (datetime.now(timezone.utc) - datetime.fromisoformat(self.started)).total_seconds()
        for res in self.results:
            status, explanation = verdict_status(res, self.log_path.name)
            nodes.append({"node": res.node, "status": status, "explanation": explanation,
                          **monitoring_details(res, self.log_path.name, self.engine.released, sha, versions,
                                               horizon), "statistics": live_counts(res, sha, observed)})
        record = {"kind": "monitoring", "mode": "live", "log": self.log_path.name, "sha256": sha,
                  "started": self.started,
                  "stopped": datetime.now(timezone.utc).isoformat(timespec="seconds"),
                  "events": self.engine.released, "early_released_events": self.engine.released_early,
                  "late_events": self.engine.late,
                  "max_late_s": round(self.engine.max_late_s, 6), "other_clocks": self.engine.clock_lines(),
                  "reorder_window_s": self.engine.reorder_window, "verdicts": self.verdicts,
                  "provisional_verdicts": self.provisional,
                  "silent_topics": self.silences, "nodes": nodes, **self.checks.record(self.log_path.name)}
        if self.gate is not None:
            record["lifecycle"] = self.gate.record(nodes)
        if evidence is not None:
            atomic_write_text(evidence, json.dumps(record, indent=2, sort_keys=True) + "\n")
        return record

    def not_judged(self, record: Mapping[str, Any]) -> list[dict[str, str]]:
        """The items of the monitored contracts this run did not judge
        (:func:`~.judged.not_judged`), from what it heard and the finished
        ``record`` (its ``nodes``, ``calls``, ``deadlines``,
        ``topic_deadlines``, ``decode_errors``, ``warnings``, ``qos``); each
        ``pending`` node of ``record["nodes"]`` gets the reason added to its
        explanation."""
        heard = Heard({**{t: s.received for t, s in self.engine.topics.items()}, **self.calls_heard,
                       **(self.gate.heard if self.gate is not None else {})},
                      dict(self.orphans), dict(record.get("decode_errors") or {}), list(record.get("warnings") or ()),
                      {k: int(v.get("publishers_heard", 0)) for k, v in record["qos"].items()}
                      if isinstance(record.get("qos"), dict) else None, unseen_links(record))
        statuses: dict[str, list[tuple[str, str]]] = {}
        for n in [*record["nodes"], *record.get("calls", {}).get("nodes", [])]:
            statuses.setdefault(n["node"], []).append((n["status"], n["explanation"]))
        counts: dict[str, dict[str, int]] = {}
        undecided_why: dict[str, str] = {}
        results = [e["deadlines"] for e in record.get("topic_deadlines", [])]
        for r in results + list(record.get("deadlines", {}).get("results", [])):
            total = counts.setdefault(r["node"], {})
            for v, k in r["counts"].items():
                total[v] = total.get(v, 0) + k
            total["undecided"] = total.get("undecided", 0) + int((r.get("unaccepted") or {}).get("undecided", 0))
            first = r.get("first_unaccepted")
            if first and first.get("why") == "undecided":
                undecided_why.setdefault(r["node"], str(first.get("reason", "")))
        decided = {n["node"]: int((n.get("statistics") or {}).get("answers", 0)) for n in record["nodes"]}
        for n in record.get("calls", {}).get("nodes", []):  # a node judged by its calls decided them
            c = n.get("counts") or {}
            decided[n["node"]] = decided.get(n["node"], 0) + int(c.get("satisfied", 0)) + int(c.get("violated", 0))
        items = not_judged(self.nodes, heard, statuses, counts, "during the live run", decided, undecided_why)
        for entry in record["nodes"]:  # a pending node says why itself
            explain(entry, items)
        return items


def live_counts(res: NodeResult, sha: str, seconds: float) -> LiveCounts:
    """What a live run counted of one node, as a run's evidence counts it
    (:func:`.runset.run_counts`): the log's content sha256 (its identity: the
    same log named twice in a plan is one run), judged answers, violations,
    undecided answers (inconclusive and still open) and the wall-clock seconds
    observed; ``recorded`` is ``live``."""
    c = res.counts
    return {"recorded": "live", "sha256": sha, "answers": c.get("satisfied", 0) + c.get("violated", 0),
            "violations": c.get("violated", 0), "inconclusive": c.get("inconclusive", 0) + c.get("open", 0),
            "seconds": round(seconds, 3)}


def stop_and_record(worker: EngineWorker, live: LiveRun, evidence: Any, out: Callable[[str], None]) -> dict[str, Any]:
    """Stop ``worker`` (it checks what is still queued), then ``live``, and
    return the monitoring evidence record with the worker's figures: the
    longest queue, the messages dropped and the engine's CPU per message
    (µs).  Verdicts that miss dropped messages prove nothing, so a node that
    would be discharged or pending is ``inconclusive``; an engine that died
    makes every node ``error``.  Shared by the ROS 1 and ROS 2 layers; the
    caller writes the record."""
    engine_error = ""
    try:
        worker.stop()
    except Exception as exc:  # noqa: BLE001 - a bug in the engine: reported in the evidence, the log kept
        engine_error = f"{type(exc).__name__}: {exc}"
        out(f"rclverify monitor --live: error: the verdict engine stopped: {engine_error}")
    record = live.stop(evidence)
    if engine_error:
        record["engine_error"] = engine_error
        for n in record["nodes"]:
            n["status"] = "error"
            n["explanation"] = f"the verdict engine stopped during the run ({engine_error}); verdicts are partial"
    record["backlog_max"] = worker.backlog_max
    record["dropped_messages"] = worker.dropped
    if worker.dropped:
        for n in record["nodes"]:
            if n["status"] in ("discharged", "pending"):
                n["status"] = "inconclusive"
                n["explanation"] = (f"{worker.dropped} message(s) were dropped because the monitor fell "
                                    f"{worker.max_queue} messages behind; the verdicts do not cover them")
    record["engine_cpu_us_per_message"] = round(worker.cpu_s / max(worker.handled, 1) * 1e6, 1)
    return record


__all__ = ["LiveRun", "VERDICT_LOG_TOPIC", "dumps", "live_counts", "stop_and_record"]
