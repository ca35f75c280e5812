"""A damaged recorded run of a million lines, checked without a traceback and in flat memory.

Writes, lazily from a thread into a named pipe (nothing on disk), a
ROSMonitoring log of ``--lines`` lines: the bundled nominal run repeated
with time shifted, every line damaged with probability ``--damage`` in a
way a log can survive (a missing field, a field of the wrong type, NaN, a
time out of order, an unknown topic), and a malformed last line.  The
reader and all four nodes' monitors check it; prints events/s (CPU time),
the located error for the last line and the peak RSS (MiB) after 10 % and
at the end.

Usage::

    python3 bench/monitor_fuzz.py [--lines 1000000] [--damage 0.05]
    python3 bench/monitor_fuzz.py --smoke      # 2,000 lines: a few seconds
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import json
import os
import random
import resource
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any, Iterator

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))


def _damaged(n: int, damage: float, seed: int = 1) -> Iterator[str]:
    lines = [json.loads(x) for x in (ROOT / "backends/monitors/traces/nominal.jsonl").read_text().splitlines()]
    span = lines[-1]["time"] + 1.0
    rng = random.Random(seed)

    def gen() -> Iterator[str]:
        for k in range(n - 1):
            e = dict(lines[k % len(lines)])
            e["time"] = e["time"] + span * (k // len(lines))
            if rng.random() < damage:
                kind = rng.randrange(5)
                key = rng.choice([f for f in e if f not in ("topic", "time")])
                if kind == 0:
                    e.pop(key)
                elif kind == 1:
                    e[key] = rng.choice([None, "x", [1, 2], {"a": 1}, True])
                elif kind == 2:
                    e[key] = float("nan")
                elif kind == 3:
                    e["time"] -= rng.uniform(0, 50)
                else:
                    e["topic"] = "unknown_topic"
            yield json.dumps(e) + "\n"
        yield '{"topic": "r", "time": \n'
    return gen()


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--lines", type=int, default=1_000_000)
    p.add_argument("--damage", type=float, default=0.05)
    p.add_argument("--smoke", action="store_true", help="2,000 lines only: a few seconds (CI)")
    a = p.parse_args()
    if a.smoke:
        a.lines = 2_000
    from rclverify.backends.monitors.check import check_trace
    from rclverify.backends.monitors.config import load_mapping
    from rclverify.lang.typecheck import load
    from rclverify.traces import TraceError
    from rclverify.traces.jsonl import read_jsonl
    checked = load([ROOT / "contracts" / "remote_inspection.rcl"])
    cfg = load_mapping(ROOT, "backends/monitors/mapping.yaml", 2.0)
    with tempfile.TemporaryDirectory() as d:
        fifo = Path(d) / "run.jsonl"
        os.mkfifo(fifo)

        def write() -> None:
            with fifo.open("w", encoding="utf-8") as fh:
                for line in _damaged(a.lines, a.damage):
                    fh.write(line)
        th = threading.Thread(target=write, daemon=True)
        th.start()
        rss: dict[str, float] = {}
        counted = [0]

        def events() -> Iterator[Any]:
            for ev in read_jsonl(fifo):
                counted[0] += 1
                if counted[0] == a.lines // 10:
                    rss["10%"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
                yield ev
        t0 = time.process_time()
        error = ""
        try:
            check_trace(checked, list(checked.nodes.values()), events(), cfg.rules, cfg.horizon)
        except TraceError as exc:
            error = str(exc).replace(str(fifo), "run.jsonl")
        cpu = time.process_time() - t0
        th.join(10)
    rss["end"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"fuzz: {a.lines:,} line(s), damage {a.damage:.0%}: {counted[0]:,} event(s) checked in {cpu:.1f} s CPU "
          f"({counted[0] / cpu:,.0f} events/s, all four nodes)")
    print(f"fuzz: the malformed last line: {error or 'NOT REPORTED'}")
    print(f"fuzz: peak RSS {rss.get('10%', 0):.0f} MiB at 10 %, {rss['end']:.0f} MiB at the end")
    return 0


if __name__ == "__main__":
    sys.exit(main())
