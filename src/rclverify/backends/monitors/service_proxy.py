"""The live ROS 1 monitor of services and actions (issue 33).

``python3 -m rclverify.backends.monitors.service_proxy --contracts FILE ...
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

Every event and verdict is one JSON line of ``--log`` (``{"kind": "event"|
"verdict"|"summary", ...}``); on SIGINT/SIGTERM or after ``--duration``
seconds the obligations still within their deadline are ``currently_false``,
a ``summary`` line closes the log and the exit code is 1 when a verdict was
``false``, else 0 (2 for a usage error, with one line on standard error).
Classes come from the workspace's ``.srv``/``.action`` files
(:mod:`.ros1_interfaces`).
"""
from __future__ import annotations

import argparse
import json
import signal
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any, Sequence

from ...rcl.errors import RclError
from ...rcl.typecheck import load
from ...traces.events import Event
from .deadlines import DeadlineMonitor, DeadlineVerdict
from .ros1 import RosUnavailable, flatten, import_rospy
from .ros1_interfaces import action_classes, service_class


class ProxyRun:
    """The monitors and the log of one live run (thread-safe)."""

    def __init__(self, monitors: list[DeadlineMonitor], log: Path) -> None:
        self.monitors, self.lock, self.index, self.false = monitors, threading.Lock(), 0, 0
        for m in monitors:
            m.on_verdict = self._verdict
        self.fh = log.open("w", encoding="utf-8")

    def _write(self, obj: dict[str, Any]) -> None:
        self.fh.write(json.dumps(obj, sort_keys=True) + "\n")
        self.fh.flush()

    def _verdict(self, v: DeadlineVerdict) -> None:
        self.false += v.verdict == "false" and not v.update
        self._write({"kind": "verdict", **v.to_json()})

    def event(self, topic: str, fields: dict[str, Any], stamp: float) -> None:
        """One observed message; ``stamp`` (s) is set as its header stamp when it has none."""
        if "header" not in fields:
            secs = int(stamp)
            fields = {**fields, "header": {"stamp": {"secs": secs, "nsecs": int(round((stamp - secs) * 1e9))}}}
        with self.lock:
            ev = Event(self.index, stamp, topic, fields, f"live:{self.index + 1}")
            self.index += 1
            self._write({"kind": "event", "index": ev.index, "topic": topic, "time": stamp, "fields": fields})
            for m in self.monitors:
                m.feed(ev)

    def tick(self, now: float) -> None:
        with self.lock:
            for m in self.monitors:
                m.advance(now)

    def close(self) -> dict[str, Any]:
        with self.lock:
            results = [m.finish().to_json() for m in self.monitors]
            summary = {"kind": "summary", "results": results, "false": self.false}
            self._write(summary)
            self.fh.close()
        return summary


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python3 -m rclverify.backends.monitors.service_proxy",
                                description="monitor ROS 1 services (through a proxy) and actions live")
    p.add_argument("--contracts", nargs="+", required=True, help="RCL files of the system")
    p.add_argument("--interfaces", action="append", default=[], help="directory of <pkg>/srv and <pkg>/action files")
    p.add_argument("--forward", action="append", default=[], metavar="SVC=REAL",
                   help="serve SVC and forward each call to REAL (one per monitored service)")
    p.add_argument("--log", default="services_live.jsonl", help="JSON-lines log of events and verdicts")
    p.add_argument("--duration", type=float, default=0.0, help="stop after this many seconds (0: until SIGTERM)")
    p.add_argument("--tick", type=float, default=0.05, help="seconds between clock advances")
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Run the proxy (module docstring); returns the exit code."""
    args = _parser().parse_args(argv)
    try:
        checked = load(args.contracts)
    except RclError as exc:
        print(str(exc), file=sys.stderr)
        return 2
    forwards = dict(f.split("=", 1) for f in args.forward if "=" in f)
    nodes = [n for n in checked.nodes.values() if any(c.deadline is not None for c in n.node.guarantees)]
    dirs = [Path(d) for d in args.interfaces]
    try:
        rospy = import_rospy()
        services = {lk.name: lk for n in nodes for lk in n.node.links if lk.kind == "service" and lk.role == "serves"}
        actions = {lk.name: lk for n in nodes for lk in n.node.links if lk.kind == "action"}
        missing = [s for s in services if "/" + s.lstrip("/") not in forwards]
        if missing:
            print(f"service_proxy: error: say where {', '.join(missing)} is served: --forward /{missing[0]}=/REAL",
                  file=sys.stderr)
            return 2
        svc_classes = {s: service_class(lk.ros_type, dirs) for s, lk in services.items()}
        gen = Path(tempfile.mkdtemp(prefix="rclverify-actions-"))
        act_classes = {a: action_classes(lk.ros_type, dirs, gen) for a, lk in actions.items()}
    except RosUnavailable as exc:
        print(f"service_proxy: error: {exc}", file=sys.stderr)
        return 2
    run = ProxyRun([DeadlineMonitor(checked, n, {}) for n in nodes], Path(args.log))
    rospy.init_node("rclverify_service_monitor", anonymous=True, disable_signals=True)
    now = lambda: rospy.Time.now().to_sec()  # noqa: E731  (the one clock of the proxy)
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
    stop = threading.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: stop.set())
    print("service_proxy: ready", flush=True)
    end = time.monotonic() + args.duration if args.duration > 0 else float("inf")
    while not stop.is_set() and time.monotonic() < end:
        stop.wait(args.tick)
        run.tick(now())
    summary = run.close()
    rospy.signal_shutdown("done")
    return 1 if summary["false"] else 0


if __name__ == "__main__":
    sys.exit(main())
