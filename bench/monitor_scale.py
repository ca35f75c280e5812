"""How fast offline trace checking runs, and whether its memory stays flat.

Streams a synthetic run of the case study (the events of
``scripts/make_traces.py``'s nominal run, repeated with time shifted, so
every node sees realistic inputs and outputs) through the monitors of the
contracts in ``contracts/remote_inspection.rcl`` with the bundled mapping
(``backends/monitors/mapping.yaml``, horizon 2 s), and prints:

* events per second (CPU time) for each node alone and for all nodes
  together, on ``--events`` events generated in memory (no file);
* with ``--bag``: the time to write a ROS 2 bag (sqlite3) of
  ``--bag-events`` messages with rosbags' writer, and to read and check it
  (all nodes, or ``--bag-nodes``);
* the resident set size (peak RSS, MiB) after 10 % and after 100 % of each
  run, so "memory flat in the trace length" can be seen (the monitor keeps
  only the state and the pending obligations).

The verdict counts printed after the bag run are not a finding: each
repetition of the run starts with the previous repetition's last reading and
command still in the state (the state reading of docs/monitors.md), so the
first inspection of every repetition is checked against a stale reading.

``--no-cache`` turns off the monitor's evaluation cache, for the rate of a
run whose states never repeat.

Targets the issue names: >= 20,000 events/s on the case study's contracts,
a one-million-event bag in under 60 s.  The figures are printed, not
asserted.  Usage::

    python3 bench/monitor_scale.py [--events 50000] [--bag --bag-events 1000000 --bag-nodes RadiationSensor]
    python3 bench/monitor_scale.py --smoke     # 1,000 events and a bag of 1,000: a few seconds
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import importlib.util
import resource
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Iterator

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from rclverify.backends.monitors.check import check_trace  # noqa: E402
from rclverify.backends.monitors.config import load_mapping  # noqa: E402
from rclverify.lang.typecheck import load  # noqa: E402
from rclverify.traces import read_trace  # noqa: E402
from rclverify.traces.events import Event  # noqa: E402


def _make_traces() -> Any:
    spec = importlib.util.spec_from_file_location("make_traces", ROOT / "scripts" / "make_traces.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def synthetic(n: int, mt: Any) -> Iterator[tuple[float, str, dict[str, Any]]]:
    """``n`` (time, topic, fields) of the nominal run, repeated."""
    base = list(mt.events("nominal"))
    span = base[-1][0] + 1.0
    k = 0
    rep = 0
    while k < n:
        for t, topic, fields in base:
            if k >= n:
                return
            yield t + rep * span, topic, fields
            k += 1
        rep += 1


def rss_mib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def run(checked: Any, cfg: Any, nodes: list[str], events: Any, n: int) -> tuple[float, float, float, Any]:
    marks: dict[str, float] = {}

    def tap(it: Any) -> Iterator[Any]:
        for k, ev in enumerate(it):
            if k == n // 10:
                marks["rss10"] = rss_mib()
            yield ev
    t0 = time.process_time()
    count, results = check_trace(checked, [checked.nodes[x] for x in nodes], tap(events), cfg.rules, cfg.horizon)
    dt = time.process_time() - t0
    return count / dt if dt else float("inf"), marks.get("rss10", rss_mib()), rss_mib(), results


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--events", type=int, default=50_000)
    ap.add_argument("--bag", action="store_true")
    ap.add_argument("--bag-events", type=int, default=1_000_000)
    ap.add_argument("--bag-nodes", nargs="*", default=None)
    ap.add_argument("--no-cache", action="store_true",
                    help="evaluate every formula afresh (the synthetic run repeats states, which the cache exploits)")
    ap.add_argument("--smoke", action="store_true", help="1,000 events, a bag of 1,000 messages (CI)")
    args = ap.parse_args()
    if args.smoke:
        args.events, args.bag, args.bag_events = 1_000, True, 1_000
    if args.no_cache:
        from rclverify.backends.monitors.check import NodeMonitor
        NodeMonitor.cache_size = 0
    checked = load([ROOT / "contracts/remote_inspection.rcl"])
    cfg = load_mapping(ROOT, "backends/monitors/mapping.yaml", 2.0)
    mt = _make_traces()
    print(f"{'nodes':<32} {'events':>9} {'events/s':>10} {'RSS@10% MiB':>12} {'RSS@100% MiB':>13}")
    groups = [[n] for n in checked.nodes] + [list(checked.nodes)]
    for nodes in groups:
        evs = (Event(k, t, topic, f, "synthetic") for k, (t, topic, f) in enumerate(synthetic(args.events, mt)))
        rate, r10, r100, _ = run(checked, cfg, nodes, evs, args.events)
        print(f"{'+'.join(nodes) if len(nodes) < 4 else 'all nodes':<32} {args.events:>9} {rate:>10.0f} "
              f"{r10:>12.1f} {r100:>13.1f}")
    if args.bag:
        from rosbags.rosbag2 import Writer
        from rclverify.traces.bag import typestore
        store = typestore([ROOT / "backends/monitors/msg"])
        snap = store.types["gazebo_radiation_plugin/msg/Snapshot"]
        with tempfile.TemporaryDirectory() as tmp:
            bag = Path(tmp) / "big_bag"
            t0 = time.perf_counter()
            with Writer(bag, version=9) as w:
                conns: dict[str, Any] = {}
                for t, topic, fields in synthetic(args.bag_events, mt):
                    if topic not in conns:
                        conns[topic] = w.add_connection("/" + topic, "gazebo_radiation_plugin/msg/Snapshot",
                                                        typestore=store)
                    w.write(conns[topic], int(t * 1e9),
                            store.serialize_cdr(snap(**fields), "gazebo_radiation_plugin/msg/Snapshot"))
            wrote = time.perf_counter() - t0
            nodes = args.bag_nodes or list(checked.nodes)
            t0 = time.perf_counter()
            rate, r10, r100, results = run(checked, cfg, nodes, read_trace(bag, [ROOT / "backends/monitors/msg"]),
                                           args.bag_events)
            wall = time.perf_counter() - t0
            print(f"bag of {args.bag_events} messages: written in {wrote:.1f} s; read and checked "
                  f"({'+'.join(nodes)}) in {wall:.1f} s wall, {rate:.0f} events/s CPU; "
                  f"RSS {r10:.1f} MiB at 10 %, {r100:.1f} MiB at 100 %")
            for r in results:
                print(f"  {r.node}: {r.counts}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
