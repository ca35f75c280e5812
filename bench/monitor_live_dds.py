"""How fast the live monitor answers over DDS (``bench/monitor_live.py --ros2``).

On 127.0.0.1 only (a Cyclone configuration with the loopback interface,
multicast off, unicast peer 127.0.0.1) and a random ``ROS_DOMAIN_ID``:
``rclverify monitor --live --ros2`` on the case study's contracts (all four
nodes, or the ``--node`` ones; ``--reorder-window 0``: the case study's
messages carry no header stamp), a listener on ``rt/rclverify/verdict`` and
a publisher sending the bundled nominal run's messages round-robin over its
eight topics (``gazebo_radiation_plugin/Snapshot`` made from the workspace's
``.msg``, reliable) at each rate of ``--rates`` for ``--seconds`` s, each
its own process.  Prints per rate:

* messages published, events the monitor checked, whether it kept up;
* the monitor process's CPU per message and its engine thread's;
* the verdict latency, publication to verdict received, median and 99th
  percentile (ms), over the events decided on arrival (as
  ``bench/monitor_live.py`` measures ROS 1's).

Then memory: one run of ``--memory-seconds`` s (default 600, the 10 minutes
the issue asks; ``--smoke``: 1 s at 1000 messages/s, no memory run) at the first rate, the monitor's
resident set size sampled every second: at the start of the traffic, its
peak, at the end, and the growth over the last half of the run.  Figures
are printed, not asserted.
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import json
import os
import random
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
from _pace import paced  # noqa: E402

MSG = ROOT / "backends" / "monitors" / "msg"
CONFIG = """<?xml version="1.0" encoding="UTF-8"?>
<CycloneDDS xmlns="https://cdds.io/config"><Domain Id="any">
  <General><Interfaces><NetworkInterface name="lo" multicast="false"/></Interfaces>
    <AllowMulticast>false</AllowMulticast></General>
  <Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>20</MaxAutoParticipantIndex>
    <Peers><Peer address="127.0.0.1"/></Peers></Discovery>
</Domain></CycloneDDS>
"""


def _rss_kib(pid: int) -> int | None:
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    except OSError:
        pass
    return None


def publisher(rate: float, seconds: float, out: Path, nodes: list[str]) -> int:
    """Publish the nominal run's messages on the monitored topics at ``rate``/s; write (topic, t_pub)."""
    from _live import messages as _lines
    from rclverify.runtime.dds.types import TypeBook
    from rclverify.runtime.ros1 import contract_topics
    from rclverify.lang.typecheck import load
    from rclverify.ros.live.dds import make_participant, topic_name
    from rclverify.ros.live.dds_qos import QosProfile, to_dds
    from cyclonedds.pub import DataWriter
    from cyclonedds.topic import Topic
    checked = load([ROOT / "contracts" / "remote_inspection.rcl"])
    topics = {t.lstrip("/") for t in contract_topics(checked, [checked.nodes[n] for n in nodes] if nodes
                                                     else checked.nodes.values())}
    lines = [e for e in _lines() if e["topic"] in topics]
    book = TypeBook([MSG])
    Snapshot = book.message("gazebo_radiation_plugin/Snapshot")
    dp = make_participant()
    qos = to_dds(QosProfile(reliable=True, depth=1000))
    pubs = {t: DataWriter(dp, Topic(dp, topic_name(t), Snapshot), qos=qos) for t in sorted({e["topic"] for e in lines})}
    deadline = time.monotonic() + 30
    while any(w.get_publication_matched_status().current_count < 1 for w in pubs.values()):
        if time.monotonic() > deadline:
            print("publisher: the monitor's readers did not match", file=sys.stderr)
            return 2
        time.sleep(0.05)
    time.sleep(0.5)
    msgs = [(e["topic"], book.build(Snapshot, e)) for e in lines]
    sent, elapsed = paced(msgs, rate, seconds, lambda topic, msg: pubs[topic].write(msg))
    out.write_text(json.dumps({"sent": sent, "elapsed": elapsed}))
    time.sleep(1.0)
    return 0


def listener(out: Path) -> int:
    """Collect (received, verdict) from ``rt/rclverify/verdict`` until SIGTERM, then write them."""
    from rclverify.runtime.dds.types import TypeBook
    from rclverify.ros.live.dds import make_participant, take_raw
    from rclverify.ros.live.dds_qos import QosProfile, to_dds
    from cyclonedds.core import InstanceState, ReadCondition, SampleState, ViewState, WaitSet
    from cyclonedds.sub import DataReader
    from cyclonedds.topic import Topic
    String = TypeBook([]).message("std_msgs/String")
    dp = make_participant()
    rd = DataReader(dp, Topic(dp, "rt/rclverify/verdict", String), qos=to_dds(QosProfile(reliable=True, depth=100000)))
    ws = WaitSet(dp)
    cond = ReadCondition(rd, SampleState.Any | ViewState.Any | InstanceState.Any)
    ws.attach(cond)
    got: list[tuple[float, bytes]] = []
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    print("listening", flush=True)
    while not stop.is_set():
        ws.wait(50_000_000)
        now = time.time()
        got += [(now, raw) for raw, _info in take_raw(rd, 1000)]
    out.write_text(json.dumps([(t, String.deserialize(raw).data) for t, raw in got]))
    return 0


def _run(tmp: Path, env: dict[str, str], rate: float, seconds: float, nodes: list[str],
         memory: bool) -> dict[str, Any]:
    from _live import cpu_seconds as _cpu_seconds, stop as _stop, wait_text as _wait_text
    procs: list[subprocess.Popen[bytes]] = []
    tag = f"{int(rate)}{'m' if memory else ''}"

    def start(args: list[str], name: str) -> subprocess.Popen[bytes]:
        p = subprocess.Popen([sys.executable, *args], env=env, cwd=ROOT, stdout=(tmp / name).open("wb"),
                             stderr=subprocess.STDOUT, start_new_session=True)
        procs.append(p)
        return p
    rss: list[tuple[float, int]] = []
    lis = None
    try:
        if not memory:  # the memory run keeps no verdicts (10 minutes of them are hundreds of MB of JSON)
            lis = start([__file__, "--listener", str(tmp / f"verdicts{tag}.json")], f"listener{tag}.out")
        mon = start(["-m", "rclverify.cli.commands", "monitor", "--live", "--ros2", "-w", str(ROOT), "--horizon", "2.0",
                     "--reorder-window", "0", "--status", "0", "--log", str(tmp / f"live{tag}.jsonl"),
                     "--evidence", str(tmp / f"evidence{tag}.json"), *[x for n in nodes for x in ("--node", n)]],
                    f"monitor{tag}.out")
        if lis is not None:
            _wait_text(tmp / f"listener{tag}.out", "listening", 30)
        _wait_text(tmp / f"monitor{tag}.out", "monitoring", 30)
        pub = start([__file__, "--publisher", str(tmp / f"sent{tag}.json"), "--rate", str(rate), "--seconds",
                     str(seconds), *[x for n in nodes for x in ("--node", n)]], f"publisher{tag}.out")
        t0 = time.monotonic()
        while pub.poll() is None and time.monotonic() - t0 < seconds * 3 + 90:
            r = _rss_kib(mon.pid)
            if r is not None:
                rss.append((time.monotonic() - t0, r))
            time.sleep(1.0)
        time.sleep(2.5)  # the horizon passes; the timer resolves what waits
        cpu = _cpu_seconds(mon.pid)
        _stop(mon, signal.SIGINT)
        if lis is not None:
            _stop(lis)
    finally:
        for p in procs:
            _stop(p)
    record = json.loads((tmp / f"evidence{tag}.json").read_text())
    if memory:
        (tmp / f"live{tag}.jsonl").unlink()
        return {"sent": json.loads((tmp / f"sent{tag}.json").read_text()), "record": record, "cpu": cpu, "rss": rss}
    return {"sent": json.loads((tmp / f"sent{tag}.json").read_text()),
            "verdicts": json.loads((tmp / f"verdicts{tag}.json").read_text()), "record": record, "cpu": cpu, "rss": rss,
            "log_topics": [json.loads(x)["topic"] for x in (tmp / f"live{tag}.jsonl").read_text().splitlines()]}


def _latency(res: dict[str, Any]) -> list[float]:
    """Publication -> verdict received (ms) of the verdicts decided on arrival
    (the j-th message published on a topic is the j-th event released on it)."""
    sent = res["sent"]["sent"]
    pub_times: dict[tuple[str, int], float] = {}
    seen: dict[str, int] = {}
    for topic, t in sent:
        pub_times[(topic, seen.get(topic, 0))] = t
        seen[topic] = seen.get(topic, 0) + 1
    per_topic: list[tuple[str, int]] = []
    seen.clear()
    for topic in res["log_topics"]:
        if topic.startswith("rclverify/"):
            continue
        per_topic.append((topic, seen.get(topic, 0)))
        seen[topic] = seen.get(topic, 0) + 1
    lat = []
    for recv, text in res["verdicts"]:
        v = json.loads(text)
        if not v.get("node") or "decided_at" not in v:  # a deadline's or a declaration's verdict: no answer's
            continue
        if abs(v["decided_at"] - v["time"]) > 1e-9 or v["event"] >= len(per_topic):
            continue
        t_pub = pub_times.get(per_topic[v["event"]])
        if t_pub is not None:
            lat.append((recv - t_pub) * 1000)
    return sorted(lat)


def bench_dds(rates: list[float], seconds: float, memory_s: float, nodes: list[str]) -> None:
    """The benchmark (module docstring)."""
    try:
        import cyclonedds  # noqa: F401
    except ImportError as exc:
        print(f"ros2: skipped: {exc}")
        return
    from _live import p99 as _p99
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        (tmp / "cyclonedds.xml").write_text(CONFIG)
        env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "CYCLONEDDS_URI": (tmp / "cyclonedds.xml").as_uri(),
               "ROS_DOMAIN_ID": str(random.SystemRandom().randint(1, 230))}
        for rate in rates if seconds > 0 else ():
            res = _run(tmp, env, rate, seconds, nodes, memory=False)
            sent, rec = res["sent"]["sent"], res["record"]
            lat = _latency(res)
            kept = "kept up" if rec["events"] == len(sent) else f"LOST {len(sent) - rec['events']}"
            print(f"ros2: {rate:.0f} msg/s asked: published {len(sent)} in {res['sent']['elapsed']:.2f} s "
                  f"({len(sent) / res['sent']['elapsed']:.0f} msg/s); checked {rec['events']} "
                  f"({kept}; "
                  f"dropped {rec.get('dropped_messages', 0)}, longest queue {rec.get('backlog_max', 0)})")
            if res["cpu"] is not None:
                print(f"ros2: {rate:.0f} msg/s: monitor CPU {res['cpu'] / len(sent) * 1e6:.0f} us per message "
                      f"(start-up included), engine thread {rec.get('engine_cpu_us_per_message', 0):.0f} us")
            if lat:
                print(f"ros2: {rate:.0f} msg/s: latency publication -> verdict received over {len(lat)} verdict(s) "
                      f"decided on arrival: p50 {statistics.median(lat):.2f} ms, p99 {_p99(lat):.2f} ms, max "
                      f"{lat[-1]:.2f} ms; load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} core(s)")
        if memory_s > 0:
            res = _run(tmp, env, rates[0], memory_s, nodes, memory=True)
            rss = res["rss"]
            if rss:
                half = [r for t, r in rss if t >= rss[-1][0] / 2]
                sent = len(res["sent"]["sent"])
                print(f"ros2: memory over {memory_s:.0f} s at {rates[0]:.0f} msg/s ({sent} published, "
                      f"{res['record']['events']} checked, {res['record'].get('dropped_messages', 0)} dropped): "
                      f"RSS {rss[0][1] / 1024:.1f} MiB at the start, peak "
                      f"{max(r for _, r in rss) / 1024:.1f} MiB, {rss[-1][1] / 1024:.1f} MiB at the end; growth over "
                      f"the second half {(half[-1] - half[0]) / 1024:+.1f} MiB")


def main(argv: list[str] | None = None) -> int:
    import argparse
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--rates", default="1000,5000", help="comma-separated messages/s (default 1000,5000)")
    p.add_argument("--rate", type=float, help=argparse.SUPPRESS)
    p.add_argument("--seconds", type=float, default=5.0)
    p.add_argument("--memory-seconds", type=float, default=600.0)
    p.add_argument("--smoke", action="store_true", help="CI: 1 s at 1000 messages/s, no memory run (the figures are not the issue's)")
    p.add_argument("--memory-only", action="store_true", help="only the memory run")
    p.add_argument("--node", dest="nodes", action="append", default=[])
    p.add_argument("--publisher", type=Path, help=argparse.SUPPRESS)
    p.add_argument("--listener", type=Path, help=argparse.SUPPRESS)
    a = p.parse_args(argv)
    if a.publisher:
        return publisher(a.rate, a.seconds, a.publisher, a.nodes)
    if a.listener:
        return listener(a.listener)
    seconds, memory = (1.0, 0.0) if a.smoke else (a.seconds, a.memory_seconds)
    if a.memory_only:
        seconds = 0.0
    rates = [1000.0] if a.smoke else [float(r) for r in a.rates.split(",")]
    bench_dds(rates, seconds, memory, a.nodes)
    return 0


if __name__ == "__main__":
    if "--publisher" not in sys.argv[1:] and "--listener" not in sys.argv[1:]:
        from _live import exit_on_sigterm  # SIGTERM stops what the bench started (bench/_live.py)
        exit_on_sigterm()
    sys.exit(main())
