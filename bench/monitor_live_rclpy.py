"""How much the live monitor hears, and how fast it answers, from a real
rclpy publisher on Fast DDS (ROS 2's default middleware; issue 62).

The publisher is an rclpy node in the ROS 2 Python (``.venv-ros2``, ROS 2's
PyPI wheels, or the one ``RCLVERIFY_ROS2_PYTHON`` names) on
``rmw_fastrtps_cpp``; ``rclverify monitor --live --ros2`` watches three of
its topics, each of another kind of type: ``/a`` ``std_msgs/Float64``,
``/b`` ``sensor_msgs/JointState`` (sequences of strings and numbers, read
at ``position[0]``), ``/c`` ``geometry_msgs/PoseWithCovarianceStamped`` (a
nested fixed array, read at ``pose.pose.position.x``), reliable, keep-last
1000, round-robin.  Everything on 127.0.0.1 (Cyclone's loopback
configuration, ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``), a random
``ROS_DOMAIN_ID``.  Two runs, each with processes of its own:

* **loss** at ``--total-rate`` messages/s over the three topics (default
  5000) for ``--seconds`` s: messages published, heard (per topic) and
  checked, and the difference;
* **latency** at ``--latency-rate`` (default 1000/s): publication (the
  rclpy ``publish`` call's wall-clock time) to the verdict received by a
  listener on ``/rclverify/verdict`` (bench/monitor_live_dds.py's), p50 and
  p99 in ms, over the verdicts decided on arrival.  Messages are judged at
  their publishers' source timestamps and released when the watermark (the
  clock less ``--lateness``, the monitor's ``--reorder-window``) passes
  them (docs/semantics.md, "Event time"), so a verdict's latency is at
  least the bound; the line says whether p99 is within the bound + 5 ms.

``--source dds|rclpy|both`` (default both): the monitor hears the
publisher through its own Cyclone DDS participant, through rclpy (its agent
in the ROS 2 Python, docs/ros2.md "Two sources"), or each in turn;
``--listener dds|rclpy``: the latency run's verdicts heard by a Cyclone DDS
reader (default) or by an rclpy subscriber, as a ROS 2 user hears them.

``--burn N``: N processes spinning ``while True: pass`` beside each run
(started before its processes, every one stopped after it), the load of
other work on a shared machine.  ``--nice N``: the monitor (and the
rclpy agent it starts) at niceness N, as a robot's integrator may run it
(``nice -n -5``, systemd's ``Nice=``; raising a priority needs the
privilege); the publisher, the listener and the burners stay at 0.

Prints the figures, the load average as each run ends and the core count;
asserts nothing.  The monitor's CPU a message is given twice: over its
whole process (start-up included: at 1000 msg/s for 5 s its imports and
type making are most of it) and over the traffic alone (from just before
the publisher starts to the run's end), the rclpy agent's likewise; the
engine thread's is its own thread's (``engine_cpu_us_per_message``), and
the traffic's is split by thread name (``/proc/<pid>/task``: the engine,
the bus, Cyclone's own threads), the threads of 5 us a message or more.
``--stages``: the latency run's monitor goes through ``bench/_stages.py``,
which times each message's stages (the source, the engine's queue, the
watermark, judging, the verdict's way to the listener) and the timer runs,
and the line per stage says where the slowest 1 % of the verdicts spent
their time, and whether the engine thread, before a late release, ran,
waited for a core or slept.
``--smoke`` (the test suite's): 1 s at 300 and 200 messages/s through the
rclpy source only, unless ``--source`` names others (the suite's live
tests hear rclpy nodes through both sources); without a ROS 2 Python it
says why and exits 0.
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
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench"))
from monitor_live_dds import CONFIG, _latency  # noqa: E402  (the loopback config; verdicts decided on arrival)

#: seconds the monitor has, after SIGINT, to judge the messages still queued and write its evidence (on a
#: loaded machine a backlog of 20,000 messages takes tens of seconds); SIGKILL after it
STOP_GRACE_S = 180.0
TOPICS = {"a": ("std_msgs/Float64", "data", "A"), "b": ("sensor_msgs/JointState", "position[0]", "B"),
          "c": ("geometry_msgs/PoseWithCovarianceStamped", "pose.pose.position.x", "C")}
#: the verdicts as a ROS 2 user hears them: an rclpy subscriber of /rclverify/verdict (in the ROS 2 Python)
RCLPY_LISTENER = """\
import json, signal, sys, time
import rclpy
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from std_msgs.msg import String
rclpy.init()
n = Node("verdict_listener")
got = []
n.create_subscription(String, "/rclverify/verdict", lambda m: got.append((time.time(), m.data)),
                      QoSProfile(depth=100000, reliability=ReliabilityPolicy.RELIABLE))
stop = []
signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
print("listening", flush=True)
while not stop:
    rclpy.spin_once(n, timeout_sec=0.05)
open(sys.argv[1], "w").write(json.dumps(got))
"""
PUBLISHER = """\
import json, sys, time
sys.path.insert(0, sys.argv[4])
import rclpy
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from std_msgs.msg import Float64
from sensor_msgs.msg import JointState
from geometry_msgs.msg import PoseWithCovarianceStamped
from _pace import paced
rate, seconds, out = float(sys.argv[1]), float(sys.argv[2]), sys.argv[3]
rclpy.init()
node = Node("bench_talker")
qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
pubs = {"a": node.create_publisher(Float64, "a", qos), "b": node.create_publisher(JointState, "b", qos),
        "c": node.create_publisher(PoseWithCovarianceStamped, "c", qos)}
until = time.monotonic() + 30
while min(p.get_subscription_count() for p in pubs.values()) < 1:
    if time.monotonic() > until:
        sys.exit("the monitor's readers did not match")
    time.sleep(0.05)
time.sleep(0.5)
j = JointState(name=["shoulder", "elbow", "wrist"], position=[0.5, 1.0, 1.5], velocity=[0.0] * 3, effort=[2.0] * 3)
p = PoseWithCovarianceStamped()
p.pose.pose.position.x = 1.0
p.pose.covariance[0] = 0.1
msgs = [("a", Float64(data=1.0)), ("b", j), ("c", p)]
sent, elapsed = paced(msgs, rate, seconds, lambda topic, msg: pubs[topic].publish(msg))
with open(out, "w") as fh:
    json.dump({"sent": sent, "elapsed": elapsed}, fh)
print("published", len(sent), flush=True)
time.sleep(1.0)
"""


def ros2_python() -> tuple[Path | None, str]:
    """The ROS 2 Python and ``""``, or ``None`` and why there is none."""
    named = os.environ.get("RCLVERIFY_ROS2_PYTHON")
    exe = Path(named) if named else ROOT / ".venv-ros2" / "bin" / "python"
    if not exe.exists():
        return None, f"no ROS 2 Python at {exe} (scripts/setup.sh --tests installs ROS 2's wheels into .venv-ros2)"
    probe = subprocess.run([str(exe), "-c", "import rclpy, rmw_fastrtps_cpp"], capture_output=True, text=True,
                           timeout=60)
    if probe.returncode != 0:
        return None, f"the ROS 2 Python cannot import rclpy: {(probe.stderr.strip().splitlines() or [''])[-1]}"
    return exe, ""


def _workspace(ws: Path) -> None:
    rcl = "\n".join(f"node {node} {{\n  inputs( )\n  outputs( v : REAL )\n  topics( {typ} {t} matches(out.v) )\n"
                    f"  assume( TRUE )\n  guarantee( out.v >= 0 )\n}}\n" for t, (typ, _f, node) in TOPICS.items())
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/bench.rcl").write_text(rcl)
    (ws / "contracts/plan.yaml").write_text("contracts: [contracts/bench.rcl]\n")
    (ws / "mapping.yaml").write_text("topics:\n" + "".join(f"  {t}: {{fields: ['{f}']}}\n"
                                                           for t, (_typ, f, _n) in TOPICS.items()))


def _run(tmp: Path, env: dict[str, str], ros2: Path, rate: float, seconds: float, latency: bool,
         source: str = "dds", listener: str = "dds", lateness: float = 0.05, burn: int = 0,
         nice: int = 0, stages: bool = False) -> dict[str, Any]:
    from _live import burners, cpu_seconds, stop, wait_text
    tag = f"{'lat' if latency else 'loss'}{int(rate)}{source}"
    procs: list[subprocess.Popen[bytes]] = []

    def start(args: list[str], name: str) -> subprocess.Popen[bytes]:
        p = subprocess.Popen(args, env=env, cwd=tmp, stdout=(tmp / name).open("wb"), stderr=subprocess.STDOUT,
                             start_new_session=True)
        procs.append(p)
        return p
    with burners(burn):
        try:
            return _started(tmp, env, ros2, rate, seconds, latency, source, listener, lateness, tag, start, procs,
                            nice, stages)
        finally:
            for p in procs:
                stop(p)


def _started(tmp: Path, env: dict[str, str], ros2: Path, rate: float, seconds: float, latency: bool, source: str,
             listener: str, lateness: float, tag: str, start: Any, procs: list[subprocess.Popen[bytes]],
             nice: int = 0, stages: bool = False) -> dict[str, Any]:
    """One run's processes started by ``start`` (listener, monitor, publisher), waited for and stopped;
    ``stages``: the monitor run through bench/_stages.py, each message's stages timed (``res["stages"]``)."""
    from _live import children_cpu_seconds, children_thread_cpu_seconds, cpu_seconds, stop, thread_cpu_seconds, \
        wait_text
    lis = None
    if latency and listener == "rclpy":
        (tmp / "listener.py").write_text(RCLPY_LISTENER)
        lis = start([str(ros2), str(tmp / "listener.py"), str(tmp / f"verdicts{tag}.json")], f"listener{tag}.out")
        wait_text(tmp / f"listener{tag}.out", "listening", 30)
    elif latency:
        lis = start([sys.executable, str(ROOT / "bench" / "monitor_live_dds.py"), "--listener",
                     str(tmp / f"verdicts{tag}.json")], f"listener{tag}.out")
        wait_text(tmp / f"listener{tag}.out", "listening", 30)
    command = ([str(ROOT / "bench" / "_stages.py"), str(tmp / f"stages{tag}.json")] if stages
               else ["-m", "rclverify.cli.commands"])  # the same monitor, its stages timed or not
    mon = start((["nice", "-n", str(nice)] if nice else []) + [sys.executable, *command, "monitor", "--live", "--ros2", "-w", str(tmp / "ws"),
                 "--mapping", "mapping.yaml", "--horizon", "1.0", "--reorder-window", str(lateness), "--status", "0",
                 "--log", str(tmp / f"live{tag}.jsonl"), "--evidence", str(tmp / f"evidence{tag}.json"),
                 "--source", source, "--ros2-python", str(ros2)],
                f"monitor{tag}.out")
    wait_text(tmp / f"monitor{tag}.out", "monitoring", 30)
    time.sleep(0.5)  # the monitor's start-up ends (its agent's taps matched): its CPU from here on is the run's
    cpu0, agent_cpu0, threads0 = cpu_seconds(mon.pid), children_cpu_seconds(mon.pid), thread_cpu_seconds(mon.pid)
    agent_threads0 = children_thread_cpu_seconds(mon.pid)
    (tmp / "publisher.py").write_text(PUBLISHER)
    pub = start([str(ros2), str(tmp / "publisher.py"), str(rate), str(seconds), str(tmp / f"sent{tag}.json"),
                 str(ROOT / "bench")], f"publisher{tag}.out")
    pub.wait(seconds * 3 + 60)
    time.sleep(1.5)  # the last messages arrive and are judged
    cpu, agent_cpu = cpu_seconds(mon.pid), children_cpu_seconds(mon.pid)
    run_cpu = None if cpu is None or cpu0 is None else cpu - cpu0
    threads = {k: v - threads0.get(k, 0.0) for k, v in thread_cpu_seconds(mon.pid).items()}
    agent_threads = {k: v - agent_threads0.get(k, 0.0) for k, v in children_thread_cpu_seconds(mon.pid).items()}
    t_stop = time.monotonic()
    stop(mon, signal.SIGINT, grace=STOP_GRACE_S)  # it judges what it heard and not yet judged, then exits
    ended = time.monotonic() - t_stop
    if lis is not None:
        stop(lis)
    load = os.getloadavg()[0]  # the 1-minute load average as the run ends (burners and all)
    if not (tmp / f"sent{tag}.json").exists():
        raise SystemExit(f"the rclpy publisher failed:\n{(tmp / f'publisher{tag}.out').read_text()[-2000:]}")
    res: dict[str, Any] = {"sent": json.loads((tmp / f"sent{tag}.json").read_text()), "cpu": cpu, "agent_cpu": agent_cpu, "ended": ended,
                           "run_cpu": run_cpu, "agent_run_cpu": agent_cpu - agent_cpu0, "threads": threads,
                           "agent_threads": agent_threads,
                           "load": load,
                           "record": json.loads((tmp / f"evidence{tag}.json").read_text()),
                           "log_topics": [json.loads(x)["topic"] for x in
                                          (tmp / f"live{tag}.jsonl").read_text().splitlines()]}
    if latency:
        res["verdicts"] = json.loads((tmp / f"verdicts{tag}.json").read_text())
    if stages and (tmp / f"stages{tag}.json").exists():
        res["stages"] = json.loads((tmp / f"stages{tag}.json").read_text())
    return res


def bench(total_rate: float, latency_rate: float, seconds: float, sources: tuple[str, ...] = ("dds", "rclpy"),
          listener: str = "dds", lateness: float = 0.05, burn: int = 0, nice: int = 0, stages: bool = False) -> None:
    """The benchmark (module docstring), once per source, beside ``burn`` CPU burners, the monitor (and
    its agent) at niceness ``nice``; ``stages``: the latency run's stages timed (bench/_stages.py)."""
    ros2, why = ros2_python()
    if ros2 is None:
        print(f"rclpy: skipped: {why}")
        return
    for source in sources:
        _bench(ros2, total_rate, latency_rate, seconds, source, listener, lateness, burn, nice, stages)


def _bench(ros2: Path, total_rate: float, latency_rate: float, seconds: float, source: str,
           listener: str = "dds", lateness: float = 0.05, burn: int = 0, nice: int = 0, stages: bool = False) -> None:
    from _live import p99
    beside = (f"{burn} CPU burner(s), " if burn else "") + (f"monitor at nice {nice}, " if nice else "")
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        _workspace(tmp / "ws")
        (tmp / "cyclonedds.xml").write_text(CONFIG)
        env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONSTARTUP")}
        env.update(PYTHONPATH=str(ROOT / "src"), CYCLONEDDS_URI=(tmp / "cyclonedds.xml").as_uri(),
                   ROS_DOMAIN_ID=str(random.SystemRandom().randint(1, 230)), ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST",
                   RMW_IMPLEMENTATION="rmw_fastrtps_cpp", ROS_LOG_DIR=str(tmp / "ros_log"), PYTHONUNBUFFERED="1")
        if total_rate > 0:
            res = _run(tmp, {**env, "PYTHONPATH": str(ROOT / "src")}, ros2, total_rate, seconds, latency=False,
                       source=source, lateness=lateness, burn=burn, nice=nice)
            load = f"{beside}load average {res['load']:.1f} on {os.cpu_count()} core(s)"
            sent, rec = res["sent"]["sent"], res["record"]
            per = {t: sum(1 for topic, _t in sent if topic == t) for t in TOPICS}
            heard = {t: rec["qos"][t]["samples"] for t in TOPICS}
            lost = len(sent) - rec["events"]
            print(f"rclpy publisher, {source} source: loss: {total_rate:.0f} msg/s asked over {len(TOPICS)} topics: published {len(sent)} in "
                  f"{res['sent']['elapsed']:.2f} s ({len(sent) / res['sent']['elapsed']:.0f} msg/s); heard "
                  f"{sum(heard.values())} ({', '.join(f'/{t} {heard[t]}/{per[t]}' for t in TOPICS)}); checked "
                  f"{rec['events']}; lost {lost}{f' ({lost / len(sent):.1%})' if lost else ''}; engine queue dropped "
                  f"{rec.get('dropped_messages', 0)}, longest {rec.get('backlog_max', 0)}; decode errors {sum(rec['decode_errors'].values())}; {load}")
            if res["cpu"] is not None:
                print(f"rclpy publisher, {source} source: loss: monitor CPU {res['cpu'] / max(1, len(sent)) * 1e6:.0f} us per message "
                      f"(start-up included; {_traffic(res)}), engine thread {rec.get('engine_cpu_us_per_message', 0):.0f} us"
                      f"; the monitor exited {res['ended']:.1f} s after SIGINT"
                      + (f", the rclpy agent {res['agent_cpu'] / max(1, len(sent)) * 1e6:.0f} us" if source == "rclpy" else ""))
        if latency_rate > 0:
            res = _run(tmp, env, ros2, latency_rate, seconds, latency=True, source=source, listener=listener,
                       lateness=lateness, burn=burn, nice=nice, stages=stages)
            lat = _latency(res)
            if lat:
                print(f"rclpy publisher, {source} source, {listener} listener: latency: {latency_rate:.0f} msg/s: publication -> verdict received over {len(lat)} "
                      f"verdict(s) decided on arrival: p50 {statistics.median(lat):.2f} ms, p99 {p99(lat):.2f} ms, "
                      f"max {lat[-1]:.2f} ms; checked {res['record']['events']} of {len(res['sent']['sent'])}; "
                      f"late {res['record'].get('late_events', 0)}; {_cpu(res, source)}; lateness bound {lateness * 1e3:g} ms (p99 "
                      f"{'within' if p99(lat) <= lateness * 1e3 + 5 else 'beyond'} the bound + 5 ms); "
                      f"{beside}load average {res['load']:.1f}")
                if "stages" in res:
                    from _stages import stage_table
                    for line in stage_table(res["stages"], res["sent"]["sent"], res["log_topics"], res["verdicts"],
                                            lateness):
                        print(f"rclpy publisher, {source} source: stage {line}")
            else:
                print(f"rclpy publisher, {source} source, {listener} listener: latency: {latency_rate:.0f} msg/s: no verdict decided on arrival was received "
                      f"(checked {res['record']['events']} of {len(res['sent']['sent'])})")


def _traffic(res: dict[str, Any]) -> str:
    """The monitor's CPU per message published from the publisher's start to the run's end (its start-up
    left out), and its rclpy agent's, where measured."""
    n = max(1, len(res["sent"]["sent"]))
    if res.get("run_cpu") is None:
        return "traffic alone unknown"
    def split(threads: dict[str, float]) -> str:
        busy = sorted(((v, k) for k, v in threads.items() if v / n * 1e6 >= 5), reverse=True)
        return " [" + ", ".join(f"{k} {v / n * 1e6:.0f}" for v, k in busy) + "]" if busy else ""
    return (f"traffic alone {res['run_cpu'] / n * 1e6:.0f} us" + split(res.get("threads") or {})
            + (f", agent {res['agent_run_cpu'] / n * 1e6:.0f} us" + split(res.get("agent_threads") or {})
               if res.get("agent_run_cpu") else ""))


def _cpu(res: dict[str, Any], source: str) -> str:
    """The run's CPU per message published: the monitor's process (start-up included, then its traffic
    alone), the rclpy agent's."""
    n = max(1, len(res["sent"]["sent"]))
    mon = (f"monitor {res['cpu'] / n * 1e6:.0f} us (start-up included; {_traffic(res)})" if res["cpu"] is not None
           else "monitor CPU unknown")
    engine = f" (engine thread {res['record'].get('engine_cpu_us_per_message', 0):.0f} us)"
    return mon + engine + (f", agent {res['agent_cpu'] / n * 1e6:.0f} us per message" if source == "rclpy"
                           else " per message")


def main(argv: list[str] | None = None) -> int:
    import argparse
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--total-rate", type=float, default=5000.0, help="messages/s over the three topics (loss run; 0: none)")
    p.add_argument("--latency-rate", type=float, default=1000.0, help="messages/s of the latency run (0: none)")
    p.add_argument("--seconds", type=float, default=5.0)
    p.add_argument("--smoke", action="store_true", help="CI: 1 s at 300 and 200 messages/s")
    p.add_argument("--source", choices=("dds", "rclpy", "both"), default=None,
                   help="how the monitor hears the robot (default: each in turn; with --smoke, rclpy)")
    p.add_argument("--listener", choices=("dds", "rclpy"), default="dds",
                   help="who hears the verdicts in the latency run: a Cyclone DDS reader, or an rclpy subscriber")
    p.add_argument("--lateness", type=float, default=0.05,
                   help="the monitor's lateness bound, --reorder-window (s; default the CLI's 0.05; 0: none)")
    p.add_argument("--burn", type=int, default=0, metavar="N",
                   help="N processes spinning `while True: pass` beside each run (started before it, stopped after)")
    p.add_argument("--nice", type=int, default=0, metavar="N",
                   help="run the monitor (and its rclpy agent) at niceness N (`nice -n N`; below 0 needs the "
                        "privilege to raise a priority); the publisher, the listener and the burners stay at 0")
    p.add_argument("--stages", action="store_true",
                   help="time each message's stages in the latency run (bench/_stages.py): where the tail is")
    a = p.parse_args(argv)
    source = a.source or ("rclpy" if a.smoke else "both")
    sources = ("dds", "rclpy") if source == "both" else (source,)
    if a.smoke:
        bench(300.0, 200.0, 1.0, sources, a.listener, a.lateness, a.burn, a.nice, a.stages)
    else:
        bench(a.total_rate, a.latency_rate, a.seconds, sources, a.listener, a.lateness, a.burn, a.nice, a.stages)
    return 0


if __name__ == "__main__":
    from _live import exit_on_sigterm  # SIGTERM stops what the bench started (bench/_live.py)
    exit_on_sigterm()
    sys.exit(main())
