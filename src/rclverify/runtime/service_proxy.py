"""The live ROS 1 monitor of services and actions.

``python3 -m rclverify.runtime.service_proxy --contracts FILE ...
--forward /estop=/estop_real --log run.jsonl`` starts a rospy node that

* serves each service a monitored contract links with ``serves(...)``
  under its own name (``/estop``) and forwards every call to the real
  server (``--forward /estop=/estop_real``): the proxy sees the request and
  the response, stamps them with its ROS clock when it receives the request
  and when the server's answer comes back (ROSMonitoring 2.0's scheme), and
  feeds them to the deadline monitors as ``estop/request`` and
  ``estop/response`` events;
* subscribes to each linked action's actionlib topics ``<a>/goal``,
  ``<a>/feedback`` and ``<a>/result``, whose header stamps are the clock;
* advances the monitors' clock every ``--tick`` seconds
  (``rospy.Time.now()``: wall time, or ``/clock`` under ``use_sim_time``),
  so an unanswered call is ``false`` as soon as its deadline expires.

**Inside** ``rclverify monitor --live`` (:func:`proxy_factory`) the proxy
serves, forwards and stamps the same way but judges nothing: each observed
message goes to the live engine at its receipt on the run's clock, written
to the run's log as a message line, and the run's own deadline checks
(:mod:`.logchecks`, the record's ``topic_deadlines``, the ``kind:
"deadline"`` lines and verdicts on the verdict topic) are the one judge of
every call's and goal's deadline, the verdicts ``rclverify monitor LOG``
gives on that log.  The proxy's lines there are its ``event`` lines only.

**Simulated time.**  The proxy's stamps and clock are its ROS clock, which
reads ``/clock`` exactly when the ROS 1 system's ``/use_sim_time`` parameter
is true when it starts: a global parameter every rospy and roscpp node reads,
so the servers' clock too.  The command's deadlines are judged in that clock.
The command reads no mapping, so it judges every node in that clock; inside
``rclverify monitor --live`` the run's checks judge each node in the clock its
mapping says (:mod:`.live_ros1`).  Under
``/use_sim_time`` rospy's clock reads 0 (ROS's "not set") until its first
``/clock``: the proxy serves once it is set (waiting at most
:data:`CLOCK_WAIT_S`), and a call whose request it stamps 0 all the same has
its deadline verdict ``undecided``, saying so (:data:`UNSET_CLOCK`), never
judged against a later stamp.

**The log** is a trace the offline check reads (``rclverify monitor LOG``):
each observed message is a message line (``{"topic": "estop/request",
"time": ..., <its fields>}``: written by the proxy to ``--log``, by the live
engine inside ``rclverify monitor --live``), and every line of the proxy's
own is on the topic :data:`PROXY_LOG_TOPIC`, which no contract names, with a
``time`` and a ``kind``: ``event`` (``index``, the message's topic as
``call``, the proxy's ``stamp``, its ``fields``), and from the command
``verdict`` (a deadline verdict's fields) and ``summary``; their ``time`` is
the live run's clock inside ``rclverify monitor --live``, else the proxy's
(an event's stamp, a verdict's answer or else its deadline, the summary's
last tick).  On SIGINT/SIGTERM or after ``--duration`` seconds the command's
obligations still within their deadline are ``currently_false``, a
``summary`` line closes the log and the exit code is 1 when a verdict was
``false``, else 0 (2 for a usage error, with one line on standard error).
Classes come from the workspace's ``.srv``/``.action`` files
(:mod:`.ros1_interfaces`).
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

from rclverify.lang.errors import RclError
from rclverify.lang.typecheck import load
from rclverify.traces.events import Event
from rclverify.backends.monitors.deadline_records import DeadlineResult, DeadlineVerdict
from rclverify.backends.monitors.deadlines import DeadlineMonitor
from rclverify.runtime.ros1 import RosUnavailable, flatten, import_rospy
from rclverify.runtime.ros1_interfaces import action_classes, service_class
from rclverify.runtime.shapes import DeadlineSummary
from rclverify.runtime.stopping import StopFlag, on_signals
from rclverify.runtime.ros1 import (REGISTER_TIMEOUT_S, SHUTDOWN_TIMEOUT_S, bound_master_calls, check_master, finish_within,
                                    run_bounded, shutdown_limit)

#: the topic of the proxy's own log lines (events, deadline verdicts, the summary): one no contract names, so
#: the offline check of the log passes over them (as over the live run's ``rclverify/verdict`` lines)
PROXY_LOG_TOPIC = "rclverify/proxy"
#: the longest the proxy waits for its ROS clock to be set (the first ``/clock`` under ``/use_sim_time``) before
#: it serves (s)
CLOCK_WAIT_S = 5.0
#: why a call whose request was stamped before the proxy's ROS clock was set has no deadline verdict
UNSET_CLOCK = ("the request came before the service proxy's ROS clock was set (under /use_sim_time, before its "
               "first /clock): its stamp 0 is no time, the deadline cannot be judged")


class ProxyRun:
    """The monitors and the log of one live run (thread-safe).

    ``monitors``: the deadline monitors it judges with; ``judge=False`` (inside
    ``rclverify monitor --live``, whose own checks judge the deadlines) takes
    none, and :meth:`close` then writes no ``summary`` line.  ``log``: the
    JSON-lines file to write (this module's own command: each
    message a message line and each of the proxy's own lines, module
    docstring); or ``write(obj)``, a sink for each of the proxy's own lines
    (``rclverify monitor --live``: the live monitor's log, whose engine
    writes the message lines) and ``publish(text)`` for each
    deadline verdict as JSON text; ``forward(topic,
    fields, stamp)`` receives every observed message too (``rclverify
    monitor --live``: the live engine, whose node monitors then check each
    call's response against the server's guarantees and the client's
    assumption, and whose deadline checks judge its deadline);
    ``clock()`` (s), when given, is the ``time`` of the
    proxy's own lines (the live run's clock), else the time they are about
    in the proxy's clock.  Raises ``ValueError`` for monitors given with
    ``judge=False``."""

    def __init__(self, monitors: list[DeadlineMonitor], log: Path | None = None, *,
                 write: Callable[[Mapping[str, object]], None] | None = None,
                 publish: Callable[[str], None] | None = None,
                 forward: Callable[[str, Mapping[str, object], float], None] | None = None,
                 clock: Callable[[], float] | None = None,
                 judge: bool = True) -> None:
        if monitors and not judge:
            raise ValueError("a proxy that does not judge takes no deadline monitors")
        self.monitors, self.lock, self.index, self.false = monitors, threading.Lock(), 0, 0
        self.judge = judge
        self.now = 0.0  # the latest time (s, the proxy's clock) heard or ticked: the summary line's
        self._first: dict[str, DeadlineVerdict] = {}  # a node's first verdict on a request stamped 0, as given
        self._unset: dict[str, list[DeadlineVerdict]] = {}  # a node's verdicts on requests stamped 0, as judged
        self._first_false: dict[str, DeadlineVerdict] = {}  # a node's first false on a request stamped in time
        for m in monitors:
            m.on_verdict = self._verdict
        self.fh = log.open("w", encoding="utf-8") if log is not None else None
        self.sink, self.publish, self.forward, self.clock = write, publish, forward, clock

    def _write(self, t: float, obj: Mapping[str, object]) -> None:
        """One of the proxy's own lines: ``obj`` on :data:`PROXY_LOG_TOPIC` at ``clock()`` when given (the
        live run's clock, the other lines' ``time``), else at ``t`` (s, the proxy's clock)."""
        obj = {"topic": PROXY_LOG_TOPIC, "time": self.clock() if self.clock is not None else t, **obj}
        if self.sink is not None:
            self.sink(obj)
        if self.fh is not None:
            self.fh.write(json.dumps(obj) + "\n")  # its topic first, as the live log's own lines
            self.fh.flush()

    def _verdict(self, v: DeadlineVerdict) -> None:
        why = None
        if v.trigger_stamp == 0:  # a request stamped before the clock was set: counted undecided
            why = UNSET_CLOCK
            if not v.update:
                self._unset.setdefault(v.node, []).append(v)
        if why is None and v.verdict == "false" and not v.update:
            self._first_false.setdefault(v.node, v)
        if why is not None:  # judged in no clock: undecided, never true or false
            v = dataclasses.replace(v, verdict="undecided", reason=why, time_margin=None)
            if not v.update:
                self._first.setdefault(v.node, v)
        self.false += v.verdict == "false" and not v.update
        t = v.answer if v.answer is not None else v.due  # decided by the answer, else by the deadline passing
        self._write(t, {"kind": "verdict", **v.to_json()})
        if self.publish is not None:
            self.publish(json.dumps({"kind": "deadline", **v.to_json()}, sort_keys=True))

    def event(self, topic: str, fields: Mapping[str, object], stamp: float) -> None:
        """One observed message; ``stamp`` (s) is set as its header stamp when it has none (``forward``
        receives its fields as observed)."""
        given = fields
        if "header" not in fields:
            secs = int(stamp)
            fields = {**fields, "header": {"stamp": {"secs": secs, "nsecs": int(round((stamp - secs) * 1e9))}}}
        with self.lock:
            ev = Event(self.index, stamp, topic, fields, f"live:{self.index + 1}")
            self.index += 1
            self.now = max(self.now, stamp)
            if self.fh is not None:  # the message line (live, the engine writes it: ``forward``)
                self.fh.write(json.dumps({"topic": topic, "time": stamp, **fields}) + "\n")
            self._write(stamp, {"kind": "event", "index": ev.index, "call": topic, "stamp": stamp, "fields": fields})
            for m in self.monitors:
                m.feed(ev)
            if self.forward is not None:
                self.forward(topic, given, stamp)

    def tick(self, now: float) -> None:
        with self.lock:
            self.now = max(self.now, now)
            for m in self.monitors:
                m.advance(now)

    def close(self) -> DeadlineSummary:
        """The run's end: each obligation within its deadline ``currently_false`` (its verdict line
        written); returns the summary (``results`` one per monitor, ``false`` the count of first ``false``
        verdicts), written as the ``summary`` line, closing the log, where the proxy judges."""
        with self.lock:
            results = [self._result(m.finish()).to_json() for m in self.monitors]
            summary: DeadlineSummary = {"kind": "summary", "results": results, "false": self.false}
            if self.judge:
                self._write(self.now, summary)
            if self.fh is not None:
                self.fh.close()
        return summary


    def _result(self, res: DeadlineResult) -> DeadlineResult:
        """``res`` as the summary gives it: a call whose request was stamped before the clock was set is
        counted ``undecided`` with the triggers not accepted (its margin and its ``false`` not the first's)."""
        unset = self._unset.get(res.node, [])
        if not unset:
            return res
        wheres = {v.trigger_where for v in unset}
        counts = dict(res.counts)
        for v in unset:
            counts[v.verdict] = max(counts.get(v.verdict, 0) - 1, 0)
        unaccepted = {**res.unaccepted, "undecided": res.unaccepted.get("undecided", 0) + len(unset)}
        first = self._first.get(res.node)
        return dataclasses.replace(
            res, counts=counts, unaccepted=unaccepted,
            first_false=self._first_false.get(res.node) if res.first_false is not None
            and res.first_false.trigger_where in wheres else res.first_false,
            time_margins={k: m for k, m in res.time_margins.items() if m.trigger_where not in wheres},
            first_unaccepted=res.first_unaccepted if first is None else
            {"guarantee": first.guarantee, "where": first.trigger_where, "stamp": first.trigger_stamp,
             "why": "undecided", "reason": UNSET_CLOCK})


def wait_clock(now: Callable[[], float], limit: float = CLOCK_WAIT_S) -> bool:
    """Wait until ``now()`` (s, the proxy's ROS clock) is set (not 0), at most ``limit`` seconds; whether it is."""
    end = time.monotonic() + limit
    while now() == 0:
        if time.monotonic() >= end:
            return False
        time.sleep(0.01)
    return True


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python3 -m rclverify.runtime.service_proxy",
                                description="monitor ROS 1 services (through a proxy) and actions live")
    p.add_argument("--contracts", nargs="+", required=True, help="RCL files of the system")
    p.add_argument("--interfaces", action="append", default=[], help="directory of <pkg>/srv and <pkg>/action files")
    p.add_argument("--forward", action="append", default=[], metavar="SVC=REAL",
                   help="serve SVC and forward each call to REAL (one per monitored service)")
    p.add_argument("--log", default="services_live.jsonl", help="JSON-lines log of events and verdicts")
    p.add_argument("--duration", type=float, default=0.0, help="stop after this many seconds (0: until SIGTERM)")
    p.add_argument("--tick", type=float, default=0.05, help="seconds between clock advances")
    return p


class ProxyUsage(ValueError):
    """A live run that cannot start as asked (a served service without ``--forward``)."""


def deadline_nodes(checked: Any) -> list[Any]:
    """The checked nodes with a guarantee that has a deadline: what the proxy monitors."""
    return [n for n in checked.nodes.values() if any(c.deadline is not None for c in n.node.guarantees)]


def start_proxy(rospy: Any, checked: Any, forwards: Mapping[str, str], dirs: Sequence[Path], run: ProxyRun,
                now: Callable[[], float]) -> list[Any]:
    """Serve each monitored service (``forwards``: ``/svc`` -> the real
    server's name) and subscribe to each linked action's actionlib topics,
    feeding ``run``; ``rospy.init_node`` must have run.  Returns the rospy
    handles (keep them for the run).  Raises :class:`ProxyUsage` for a
    served service without a forward and :class:`~.ros1.RosUnavailable` when
    a class cannot be made from the interface files."""
    nodes = deadline_nodes(checked)
    services = {lk.name: lk for n in nodes for lk in n.node.links if lk.kind == "service" and lk.role == "serves"}
    actions = {lk.name: lk for n in nodes for lk in n.node.links if lk.kind == "action"}
    missing = [s for s in services if "/" + s.lstrip("/") not in forwards]
    if missing:
        raise ProxyUsage(f"say where {', '.join(missing)} is served: --forward /{missing[0].lstrip('/')}=/REAL")
    svc_classes = {s: service_class(lk.ros_type, list(dirs)) for s, lk in services.items()}
    wait_clock(now)  # a call stamped before the clock is set is undecided (module docstring): few are
    with tempfile.TemporaryDirectory(prefix="rclverify-actions-") as gen:  # the classes live on without their files
        act_classes = {a: action_classes(lk.ros_type, list(dirs), Path(gen)) for a, lk in actions.items()}
    keep: list[Any] = []
    for name, cls in svc_classes.items():
        real = forwards["/" + name.lstrip("/")]

        rospy.wait_for_service(real, timeout=30)
        # one persistent connection to the real server: a call's stamps do not include connecting anew
        conn = {"proxy": rospy.ServiceProxy(real, cls, persistent=True)}

        def handle(req: Any, name: str = name, cls: Any = cls, real: str = real, conn: dict[str, Any] = conn) -> Any:
            run.event(f"{name}/request", flatten(req), now())
            try:
                resp = conn["proxy"](req)
            except rospy.ServiceException:  # the server restarted: connect again once; a second failure reaches the caller
                conn["proxy"] = rospy.ServiceProxy(real, cls, persistent=True)
                resp = conn["proxy"](req)
            run.event(f"{name}/response", flatten(resp), now())
            return resp
        keep.append(rospy.Service("/" + name.lstrip("/"), cls, handle))
    for name, classes in act_classes.items():
        for part, cls in classes.items():
            topic = f"{name.lstrip('/')}/{part}"
            keep.append(rospy.Subscriber("/" + topic, cls,
                                         lambda msg, topic=topic: run.event(topic, flatten(msg), now())))
    return keep


def proxy_factory(checked: Any, forward: Sequence[str],
                  dirs: Sequence[Path]) -> Callable[[Any, Any], ProxyRun] | None:
    """The ``proxy`` argument of :func:`.live_ros1.run_ros1` for ``rclverify
    monitor --live --forward SVC=REAL --interfaces DIR``: ``None`` when
    neither option is given; else a function ``start(rospy, live)`` that
    starts the proxy, judging nothing (module docstring, "Inside"): it
    writes its ``event`` lines to the live run's log (``LiveRun.note``) and
    hands each observed message to the live engine at its receipt on the
    wall clock, the run's clock (:mod:`.live_ros1`, "The run's clock"),
    whose deadline checks judge it.  Raises :class:`ProxyUsage` for a
    malformed ``--forward``."""
    if not forward and not dirs:
        return None
    forwards = parse_forwards(forward)

    def start(rospy: Any, live: Any) -> ProxyRun:
        run = ProxyRun([], write=live.note, judge=False, clock=time.time,  # the engine: the run's clock
                       forward=lambda topic, fields, _stamp: live.push(topic, fields, time.time()))
        run.handles = start_proxy(rospy, checked, forwards, dirs, run,  # type: ignore[attr-defined]
                                  lambda: rospy.Time.now().to_sec())
        return run
    return start


def parse_forwards(items: Sequence[str]) -> dict[str, str]:
    """``["/estop=/estop_real"]`` -> ``{"/estop": "/estop_real"}``; raises
    :class:`ProxyUsage` for an item without ``=``."""
    out = {}
    for f in items:
        if "=" not in f:
            raise ProxyUsage(f"--forward {f}: write SVC=REAL, e.g. --forward /estop=/estop_real")
        a, b = f.split("=", 1)
        out["/" + a.strip().lstrip("/")] = b.strip()
    return out


def main(argv: Sequence[str] | None = None) -> int:
    """Run the proxy (module docstring); returns the exit code."""
    args = _parser().parse_args(argv)
    try:
        checked = load(args.contracts)
    except RclError as exc:
        print(str(exc), file=sys.stderr)
        return 2
    dirs = [Path(d) for d in args.interfaces]
    try:
        forwards = parse_forwards(args.forward)
        rospy = import_rospy()
    except (ProxyUsage, RosUnavailable) as exc:
        print(f"service_proxy: error: {exc}", file=sys.stderr)
        return 2
    from rclverify.ros.live.master_rpc import MASTER_TIMEOUT_S  # deferred: start-up (loads rclverify.ros, rclverify.ros.live and more only when called)
    import rosgraph  # deferred: start-up (loads rosgraph only when called)
    uri = rosgraph.get_master_uri()
    stop = StopFlag()  # a handler that takes no lock: a stop is always heard (stopping.py)
    on_signals(stop)
    run = ProxyRun([DeadlineMonitor(checked, n, {}, clock=False) for n in deadline_nodes(checked)], Path(args.log))
    now: Callable[[], float] = lambda: rospy.Time.now().to_sec()  # noqa: E731  (the one clock of the proxy)
    bound_master_calls(rospy, uri, MASTER_TIMEOUT_S)  # a master that hangs holds nothing (ros1.py)

    def register() -> Any:
        check_master(uri, "/rclverify_service_monitor", MASTER_TIMEOUT_S)
        rospy.init_node("rclverify_service_monitor", anonymous=True, disable_signals=True)
        return start_proxy(rospy, checked, forwards, dirs, run, now)

    try:
        keep = run_bounded(stop, REGISTER_TIMEOUT_S, f"registering with the master at {uri}", register)  # noqa: F841
    except (ProxyUsage, RosUnavailable) as exc:
        print(f"service_proxy: error: {exc}", file=sys.stderr)
        run.close()
        finish_within(lambda: rospy.signal_shutdown("usage"),
                      shutdown_limit(exc) if isinstance(exc, RosUnavailable) else SHUTDOWN_TIMEOUT_S)
        return 2
    print("service_proxy: ready", flush=True)
    end = time.monotonic() + args.duration if args.duration > 0 else float("inf")
    while not stop.is_set() and time.monotonic() < end:
        stop.wait(args.tick)
        run.tick(now())
    summary = run.close()
    finish_within(lambda: rospy.signal_shutdown("done"))
    return 1 if summary["false"] else 0


if __name__ == "__main__":
    sys.exit(main())
