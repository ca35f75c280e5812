"""How fast the live monitor and the oracle answer.

Live (ROS 1, needs rosmaster and rospy): starts a master on 127.0.0.1 (a
free port), ``rclverify monitor --live`` on the case study's contracts (all
four nodes, or the ``--node`` ones; ``--reorder-window 0``: the case
study's messages carry no header stamp), a listener on the verdict topic, and a publisher sending the
bundled nominal run's messages round-robin over its eight topics at
``--rate`` messages/s for ``--seconds`` s.  Prints

* messages published, events the monitor checked, verdicts received, the
  rate achieved and whether the monitor kept up (every message checked, no
  backlog when the publisher stopped);
* the monitor process's CPU per message and its engine thread's (decode,
  check, log, publish; from the evidence record), and the longest queue of
  messages waiting for the engine thread;
* the verdict latency, publish to verdict received, median / 99th
  percentile / max (ms), over the events decided on arrival (satisfied at
  once, assumption violated, incomplete input), for the whole run and per
  second of it (the first second holds the first states' evaluations).
  An input event whose verdict waits for the node's answer is decided by
  that answer, which is the node's latency, not the monitor's.

Oracle (needs only ``websockets``): ``rclverify oracle`` as its own
process on a free port, serving all four nodes, then only the Radiation
Sensor (the generated config.yaml gives each node's monitor its own
oracle); ``--oracle-events`` events of the nominal run (repeated, time
shifted) sent by one client in the benchmark's process, one at a time
(ROSMonitoring's monitors wait for each verdict) and pipelined; prints
events/s for both and the oracle process's CPU per event (the figure that
does not depend on the machine's load).

Targets the issue names: 2,000 messages/s kept up with, latency median
under 5 ms and 99th percentile under 50 ms; the oracle at 10,000 events/s.
The figures are printed, not asserted.  Usage::

    python3 bench/monitor_live.py [--rate 2000 --seconds 5] [--node NODE ...] [--oracle-events 20000]
                                  [--no-live | --no-oracle]
    python3 bench/monitor_live.py --smoke     # 1 s at 100 messages/s, 200 events to one oracle (CI)

A part whose tools are missing (rospy and a master; websockets) says so and is skipped.

    python3 bench/monitor_live.py --ros2 [--rates 1000,5000] [--seconds 5] [--memory-seconds 600 | --smoke]

``--ros2`` runs the same measurement over DDS instead (ROS 2's wire, Cyclone
DDS; bench/monitor_live_dds.py): latency p50/p99 at each rate and the
monitor's memory over a long run.
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import json
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(ROOT / "bench"))
from _live import (cpu_seconds as _cpu_seconds, exit_on_sigterm as _exit_on_sigterm, messages as _lines,  # noqa: E402
                   p99 as _p99, stop as _stop, wait_text as _wait_text)
from _pace import paced  # noqa: E402


# -- processes the benchmark starts ------------------------------------------------------------

def publisher(rate: float, seconds: float, out: Path, wait_for: int, nodes: list[str]) -> int:
    """Publish the run's messages on the monitored nodes' topics round-robin at
    ``rate``/s; write (topic, t_pub) per message."""
    from rclverify.runtime.ros1 import build_message, contract_topics, import_rospy, message_class
    from rclverify.lang.typecheck import load
    rospy = import_rospy()
    Snapshot = message_class("gazebo_radiation_plugin/Snapshot", [ROOT / "backends/monitors/msg"])
    checked = load([ROOT / "contracts" / "remote_inspection.rcl"])
    topics = {t.lstrip("/") for t in contract_topics(checked, [checked.nodes[n] for n in nodes] if nodes
                                                     else checked.nodes.values())}
    lines = [e for e in _lines() if e["topic"] in topics]
    rospy.init_node("bench_publisher", anonymous=True)
    pubs = {t: rospy.Publisher("/" + t, Snapshot, queue_size=100000) for t in sorted({e["topic"] for e in lines})}
    deadline = time.monotonic() + 20
    while any(p.get_num_connections() < wait_for for p in pubs.values()):
        if time.monotonic() > deadline:
            print("publisher: subscribers did not connect", file=sys.stderr)
            return 2
        time.sleep(0.05)
    time.sleep(0.5)
    msgs = [(e["topic"], build_message(Snapshot, e)) for e in lines]
    sent, elapsed = paced(msgs, rate, seconds, lambda topic, msg: pubs[topic].publish(msg))
    out.write_text(json.dumps({"sent": sent, "elapsed": elapsed}))
    time.sleep(1.0)
    return 0


def listener(topic: str, out: Path) -> int:
    """Collect (received, verdict) until SIGTERM, then write them."""
    from rclverify.runtime.ros1 import import_rospy
    rospy = import_rospy()
    from std_msgs.msg import String
    got: list[tuple[float, str]] = []
    rospy.init_node("bench_listener", anonymous=True, disable_signals=True)
    rospy.Subscriber(topic, String, lambda m: got.append((time.time(), m.data)), queue_size=100000)
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    print("listening", flush=True)
    while not stop.is_set():
        stop.wait(0.1)
    out.write_text(json.dumps([(t, json.loads(d)) for t, d in got]))
    rospy.signal_shutdown("done")
    return 0


# -- live benchmark ------------------------------------------------------------------

def bench_live(rate: float, seconds: float, nodes: list[str]) -> None:
    from rclverify.runtime.ros1 import LocalMaster, RosUnavailable, import_rospy
    try:
        import_rospy()
    except RosUnavailable as exc:
        print(f"live: skipped: {exc}")
        return
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        with LocalMaster(tmp / "ros") as env:
            env = {**env, "PYTHONPATH": str(ROOT / "src")}
            procs = []

            def start(args: list[str], name: str) -> subprocess.Popen[bytes]:
                p = subprocess.Popen([sys.executable, *args], env=env, cwd=ROOT, stdout=(tmp / name).open("wb"),
                                     stderr=subprocess.STDOUT, start_new_session=True)
                procs.append(p)
                return p
            try:
                lis = start([__file__, "--listener", str(tmp / "verdicts.json")], "listener.out")
                mon = start(["-m", "rclverify.cli.commands", "monitor", "--live", "-w", str(ROOT), "--horizon", "2.0",
                             "--reorder-window", "0", "--status", "0", "--log", str(tmp / "live.jsonl"),
                             "--evidence", str(tmp / "evidence.json"),
                             *[x for n in nodes for x in ("--node", n)]], "monitor.out")
                _wait_text(tmp / "listener.out", "listening", 30)
                _wait_text(tmp / "monitor.out", "monitoring", 30)
                pub = start([__file__, "--publisher", str(tmp / "sent.json"), "--rate", str(rate),
                             "--seconds", str(seconds), *[x for n in nodes for x in ("--node", n)]],
                            "publisher.out")
                pub.wait(seconds * 10 + 60)
                time.sleep(2.5)  # the horizon passes; the timer resolves what waits
                cpu = _cpu_seconds(mon.pid)
                _stop(mon, signal.SIGINT)
                _stop(lis)
            finally:
                for p in procs:
                    _stop(p)
            pub_out = json.loads((tmp / "sent.json").read_text())
            verdicts = json.loads((tmp / "verdicts.json").read_text())
            record = json.loads((tmp / "evidence.json").read_text())
            log_topics = [json.loads(line)["topic"] for line in (tmp / "live.jsonl").read_text().splitlines()]
    sent = pub_out["sent"]
    # the j-th message published on a topic is the j-th event the monitor released on it
    pub_times: dict[tuple[str, int], float] = {}
    seen: dict[str, int] = {}
    for topic, t in sent:
        pub_times[(topic, seen.get(topic, 0))] = t
        seen[topic] = seen.get(topic, 0) + 1
    per_topic: list[tuple[str, int]] = []  # released event index -> (topic, j)
    seen.clear()
    for topic in log_topics:
        if topic == "rclverify/verdict":
            continue
        per_topic.append((topic, seen.get(topic, 0)))
        seen[topic] = seen.get(topic, 0) + 1
    print(f"live: nodes monitored: {', '.join(nodes) or 'all four'}")
    print(f"live: published {len(sent)} message(s) in {pub_out['elapsed']:.2f} s "
          f"({len(sent) / pub_out['elapsed']:.0f} msg/s, asked {rate:.0f}); the monitor checked {record['events']} "
          f"event(s) and published {record['verdicts']} verdict(s); {len(verdicts)} verdict message(s) received")
    print(f"live: kept up: {'yes' if record['events'] == len(sent) else 'NO'} "
          f"(lost {len(sent) - record['events']}; {record['late_events']} released after a later-stamped one, "
          f"by at most {record['max_late_s'] * 1000:.2f} ms)")
    if cpu is not None:
        print(f"live: monitor process CPU {cpu:.2f} s (start-up included) = {cpu / len(sent) * 1e6:.0f} us per message: "
              f"about {len(sent) / cpu:,.0f} messages/s on one free core; load average now "
              f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} core(s)")
    print(f"live: engine thread CPU {record.get('engine_cpu_us_per_message', float('nan')):.0f} us per message "
          f"(decode, check, log, publish the verdicts); longest queue {record.get('backlog_max', 0)} message(s)")
    lat = []
    by_second: dict[int, list[float]] = {}
    for recv, v in verdicts:
        if not v.get("node") or abs(v["decided_at"] - v["time"]) > 1e-9:
            continue  # decided by a later answer or by the timer: not the monitor's latency
        if v["event"] >= len(per_topic):
            continue
        t_pub = pub_times.get(per_topic[v["event"]])
        if t_pub is not None:
            lat.append((recv - t_pub) * 1000)
            by_second.setdefault(int(t_pub - sent[0][1]), []).append((recv - t_pub) * 1000)
    if lat:
        lat.sort()
        p99 = lat[min(len(lat) - 1, int(0.99 * len(lat)))]
        print(f"live: verdict latency, publish -> verdict received, over {len(lat)} verdict(s) decided on "
              f"arrival: median {statistics.median(lat):.2f} ms, p99 {p99:.2f} ms, max {lat[-1]:.2f} ms")
        later = sorted(x for sec, xs in by_second.items() if sec >= 1 for x in xs)
        if later:
            print(f"live: after the first second (the first states evaluated): median {statistics.median(later):.2f} ms, "
                  f"p99 {_p99(later):.2f} ms over {len(later)} verdict(s)")
        print("live: per second of the run (published in it), median / p99 / max ms: " + "; ".join(
            f"{s}: {statistics.median(xs):.1f} / {_p99(xs):.1f} / {max(xs):.1f}" for s, xs in sorted(by_second.items())))


# -- oracle benchmark ----------------------------------------------------------------

def bench_oracle(n: int, node: str | None) -> None:
    """``rclverify oracle`` as its own process (as deployed beside ROSMonitoring's
    monitors), one client in this process: events/s one at a time and
    pipelined, and the oracle process's CPU per event."""
    try:
        from websockets.sync.client import connect
    except ImportError as exc:
        print(f"oracle: skipped: websockets is not installed ({exc})")
        return

    from rclverify.runtime.ros1 import free_port
    port = free_port()
    with tempfile.TemporaryDirectory() as d:
        out = Path(d) / "oracle.out"
        proc = subprocess.Popen([sys.executable, "-m", "rclverify.cli.commands", "oracle", "-w", str(ROOT), "--port", str(port),
                                 *(["--node", node] if node else [])], cwd=ROOT, stdout=out.open("wb"),
                                stderr=subprocess.STDOUT, start_new_session=True,
                                env={**os.environ, "PYTHONPATH": str(ROOT / "src")})
        try:
            _wait_text(out, "oracle for", 30)
            lines = _lines()
            span = lines[-1]["time"] + 1.0
            events = [json.dumps({**lines[k % len(lines)],
                                  "time": lines[k % len(lines)]["time"] + span * (k // len(lines))}) for k in range(n)]
            with connect(f"ws://127.0.0.1:{port}") as ws:
                t0 = time.perf_counter()
                for e in events:
                    ws.send(e)
                    ws.recv()
                seq = time.perf_counter() - t0
            cpu0 = _cpu_seconds(proc.pid) or 0.0
            with connect(f"ws://127.0.0.1:{port}", max_size=None) as ws:
                t0 = time.perf_counter()

                def drain() -> None:
                    for _ in range(n):
                        ws.recv()
                rd = threading.Thread(target=drain)
                rd.start()
                for e in events:
                    ws.send(e)
                rd.join()
                pipe = time.perf_counter() - t0
            cpu = (_cpu_seconds(proc.pid) or 0.0) - cpu0
        finally:
            _stop(proc)
    print(f"oracle: {n} event(s), {node or 'all four nodes'}: one at a time {n / seq:,.0f} events/s "
          f"({seq / n * 1e6:.0f} us round trip); pipelined {n / pipe:,.0f} events/s; oracle process CPU "
          f"{cpu / n * 1e6:.0f} us per event pipelined (about {n / cpu if cpu else 0:,.0f} events/s on one free "
          f"core); load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} core(s)")


def main() -> int:
    if "--publisher" not in sys.argv[1:] and "--listener" not in sys.argv[1:]:
        _exit_on_sigterm()  # the parent only: the publisher and the listener have handlers of their own
    if "--ros2" in sys.argv[1:]:  # ROS 2 over DDS: its own script (bench/monitor_live_dds.py)
        sys.path.insert(0, str(ROOT / "bench"))
        from monitor_live_dds import main as dds_main
        return dds_main([a for a in sys.argv[1:] if a != "--ros2"])
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--rate", type=float, default=2000.0)
    p.add_argument("--seconds", type=float, default=5.0)
    p.add_argument("--oracle-events", type=int, default=20000)
    p.add_argument("--node", dest="nodes", action="append", default=[], help="monitor only NODE (repeatable)")
    p.add_argument("--no-live", action="store_true")
    p.add_argument("--no-oracle", action="store_true")
    p.add_argument("--publisher", type=Path, help=argparse.SUPPRESS)
    p.add_argument("--listener", type=Path, help=argparse.SUPPRESS)
    p.add_argument("--smoke", action="store_true", help="1 s at 100 messages/s, 200 events to the oracle of all "
                   "nodes only (CI)")
    a = p.parse_args()
    if a.smoke:
        a.rate, a.seconds, a.oracle_events = 100.0, 1.0, 200
    if a.publisher:
        return publisher(a.rate, a.seconds, a.publisher, wait_for=1, nodes=a.nodes)
    if a.listener:
        return listener("/rclverify/verdict", a.listener)
    if not a.no_live:
        bench_live(a.rate, a.seconds, a.nodes)
    if not a.no_oracle:
        for node in (None,) if a.smoke else (None, "RadiationSensor"):  # one for all; one per monitor (config.yaml)
            bench_oracle(a.oracle_events, node)
    return 0


if __name__ == "__main__":
    sys.exit(main())
