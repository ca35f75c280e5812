"""Throughput of the property_tests backend on the bundled workspace.

For the Radiation Sensor and the Agent (their implementations under
``backends/property_tests/``), it runs Hypothesis on every guarantee in two
ways and prints wall-clock figures:

* ``backend``: the run exactly as ``doit verify`` does it (stops at the
  first violation and shrinks it); checked examples per second counts every
  example whose outputs were checked, shrinking included;
* ``all-N``: N examples (``--examples``, default 200) drawn with the same
  seed and checked against the guarantee without stopping at a violation
  (no shrinking), so the time for the full N examples is measured even when
  the contract cannot be met (the Agent's).

Inputs are drawn under the plan's environment facts, as the backend draws
them; the one-time Z3 model of the facts is in the first guarantee's time.

Aims (issue 7): at least 100 checked examples per second for the Radiation
Sensor; the Agent's 200 examples in under 30 s on 2 cores.  Issue 25: the
Agent at 500 checked examples per second.  The figures are printed, not
asserted: wall-clock seconds and this process's CPU seconds (the machine
may be shared; CPU seconds do not count other processes' load).

Usage::

    python bench/property_tests.py [--examples 200] [--root .]
    python bench/property_tests.py --smoke     # 5 examples: a few seconds
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import time
from typing import Any
from pathlib import Path

from rclverify.backends.property_tests.harness import GuaranteeRun, load_implementation, read_config
from rclverify.app.pipeline import Workspace

NODES = ("RadiationSensor", "Agent")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--examples", type=int, default=200)
    ap.add_argument("--root", type=Path, default=Path(__file__).resolve().parents[1])
    ap.add_argument("--smoke", action="store_true", help="5 examples per guarantee: a few seconds (CI)")
    args = ap.parse_args()
    if args.smoke:
        args.examples = 5
    ws = Workspace(args.root)
    print(f"{'node':<16} {'guarantee':>9} {'mode':>8} {'status':>12} {'checked':>8} {'failing':>8} "
          f"{'seconds':>8} {'ex/s':>8} {'cpu_s':>8} {'ex/cpu_s':>8}")
    cpu_total = time.process_time()
    for name in NODES:
        entries = [e for e in ws.plan.evidence.get(name, ()) if e.backend == "property_tests"]
        if not entries:
            print(f"{name}: no property_tests entry in the plan")
            continue
        target = ws.target(name, entries[0].index)
        for mode in ("backend", f"all-{args.examples}"):
            cfg = read_config({**target.config, "max_examples": args.examples}, target.node, target.root)
            impl = load_implementation(target.root, cfg)
            total_n, total_t, total_c = 0, 0.0, 0.0
            for k in range(1, len(target.node.node.guarantees) + 1):
                run = GuaranteeRun(target.checked, target.node, k, cfg, impl, target.facts,
                                   stop_at_failure=mode == "backend")
                t0, c0 = time.perf_counter(), time.process_time()
                out = run.run()
                dt, dc = time.perf_counter() - t0, time.process_time() - c0
                n = out.counts.steps
                total_n, total_t, total_c = total_n + n, total_t + dt, total_c + dc
                print(f"{name:<16} {k:>9} {mode:>8} {out.status:>12} {n:>8} {out.counts.failures:>8} "
                      f"{dt:>8.2f} {n / dt:>8.1f} {dc:>8.2f} {_rate(n, dc):>8}")
            print(f"{name:<16} {'all':>9} {mode:>8} {'':>12} {total_n:>8} {'':>8} {total_t:>8.2f} "
                  f"{total_n / total_t:>8.1f} {total_c:>8.2f} {_rate(total_n, total_c):>8}")
    print(f"CPU seconds of the whole run (imports and one-time Z3 models included): "
          f"{time.process_time() - cpu_total:.2f}")


def _rate(n: int, seconds: float) -> Any:
    return f"{n / seconds:.1f}" if seconds > 0 else "-"


if __name__ == "__main__":
    main()
