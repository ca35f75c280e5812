"""What judging the declarations costs on a recorded run (issue 64).

A base answers each target with its pose (``initially( out.pose == 0 )``,
``progress( within 1 steps )``, ``periodic( out.pose, 100 ms )``); a run of
``--pairs`` target/pose pairs is made in memory and streamed through
:class:`~rclverify.backends.monitors.declarations.DeclarationMonitor` alone
and through the untimed check, and the CPU microseconds per event are
printed for each (the declarations ride on the untimed check's read of the
run, so their figure is what a run pays in addition), with the verdict rows
so a wrong figure cannot hide a wrong answer.  Printed, never asserted::

    python3 bench/declarations_monitor.py [--pairs 50000]
    python3 bench/declarations_monitor.py --smoke     # 1,000 pairs
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from rclverify.backends.monitors.check import check_trace  # noqa: E402
from rclverify.backends.monitors.declarations import check_declarations  # noqa: E402
from rclverify.backends.monitors.periods import check_periods  # noqa: E402
from rclverify.lang.parser import parse_text  # noqa: E402
from rclverify.lang.typecheck import check  # noqa: E402
from rclverify.traces.events import Event  # noqa: E402
from rclverify.traces.mapping import TopicRule  # noqa: E402

RCL = """node Base {
  inputs( target : INTEGER )
  outputs( pose : INTEGER )
  topics( std_msgs/Int64 target matches(in.target), std_msgs/Int64 pose matches(out.pose) )
  assume( 0 <= in.target and in.target <= 10 )
  guarantee( out.pose == in.target )
  initially( out.pose == 0 )
  progress( within 1 steps )
  periodic( out.pose, 100 ms )
}
"""


def events(pairs: int) -> list[Event]:
    """The initial pose, then ``pairs`` targets (0..10 in turn) each answered 20 ms later."""
    out = [Event(0, 0.0, "pose", {"data": 0}, "run:1")]
    for k in range(pairs):
        t = 0.01 + 0.04 * k
        out.append(Event(len(out), t, "target", {"data": k % 11}, f"run:{len(out) + 1}"))
        out.append(Event(len(out), t + 0.02, "pose", {"data": k % 11}, f"run:{len(out) + 1}"))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=50_000)
    ap.add_argument("--smoke", action="store_true")
    args = ap.parse_args()
    pairs = 1_000 if args.smoke else args.pairs
    checked = check([parse_text(RCL, "base.rcl")])
    node = checked.nodes["Base"]
    evs = events(pairs)
    rules = {"pose": TopicRule(state=True)}
    t0 = time.process_time()
    periods = check_periods(node, evs)
    per = time.process_time() - t0
    t0 = time.process_time()
    res = check_declarations(checked, node, evs, rules, periods)
    decl = time.process_time() - t0
    t0 = time.process_time()
    _, results = check_trace(checked, [node], iter(evs), rules, 2.0)
    untimed = time.process_time() - t0
    n = len(evs)
    print(f"{n} events ({pairs} target/pose pairs)")
    print(f"declarations alone: {decl * 1e6 / n:.1f} us/event CPU ({n / max(decl, 1e-9):,.0f} events/s)")
    print(f"periods in time alone (periods.py, before issue 64): {per * 1e6 / n:.1f} us/event CPU")
    print(f"untimed check alone: {untimed * 1e6 / n:.1f} us/event CPU ({n / max(untimed, 1e-9):,.0f} events/s)")
    print(f"declarations as a share of both: {decl / max(decl + untimed, 1e-9):.0%}")
    for r in res.rows():
        print(f"  {r['declaration']}: {r['verdict']} ({r['reason']})")
    print(f"  untimed: {dict(results[0].counts)}")


if __name__ == "__main__":
    main()
