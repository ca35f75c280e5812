"""How the diagnosis scales with the system (issue 44): a chain whose side conditions all fail.

Writes a synthetic workspace of N nodes in one contract file, node ``N<k>``
reading ``v<k-1>`` and producing ``v<k>`` (``N0`` reads the environment
input ``v_e``), every node with the contract

    assume( 0 <= in.v<k-1> and in.v<k-1> <= 10 )
    guarantee( 0 <= out.v<k> and out.v<k> <= 100 )

so every link's side condition ``in.v <= 10`` fails (the producer promises
only ``<= 100``), and the diagnosis looks for each one's culprits and
repairs (strengthen the producer, weaken the consumer: docs/diagnosis.md).
Each candidate repair is the contract with one edit, checked again.

For each N it runs ``rclverify verify`` on a fresh copy (no artifacts, no
cache) in a child process and prints its CPU seconds (user + system of the
process and its children), the number of failed side conditions and of
repairs found, the CPU seconds of a fixed pure-Python reference loop run in
the same process just before (the machine's speed at the time), and the
ratio of the largest N's CPU to the smallest N's: linear growth is
``N_max / N_min`` (8 for 200 against 25); the issue's aim is at most 12.

Usage::

    python bench/diagnosis_scale.py                  # N = 25 50 200
    python bench/diagnosis_scale.py --sizes 10,25    # other sizes
    python bench/diagnosis_scale.py --smoke          # N = 3 and 6, a few seconds
    python bench/diagnosis_scale.py --keep DIR       # keep the workspaces under DIR

The figures are printed, not asserted.
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Sequence

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _reference import ITERATIONS, reference_cpu  # noqa: E402

SRC = Path(__file__).resolve().parents[1] / "src"

#: The child process: runs ``rclverify verify`` and prints its CPU (with its own children).
PROBE = ("import json, resource, subprocess, sys\n"
         "r = subprocess.run(sys.argv[1:], capture_output=True, text=True)\n"
         "u = resource.getrusage(resource.RUSAGE_CHILDREN)\n"
         "print(json.dumps({'rc': r.returncode, 'out': r.stdout[-4000:] + r.stderr[-4000:],"
         " 'cpu': u.ru_utime + u.ru_stime}))\n")


def node_text(k: int) -> str:
    """The contract of node ``N<k>`` (module docstring)."""
    x = f"v{k - 1}" if k else "v_e"
    return (f"node N{k} {{\n  inputs( {x} : REAL )\n  outputs( v{k} : REAL )\n"
            f"  assume( 0 <= in.{x} and in.{x} <= 10 )\n"
            f"  guarantee( 0 <= out.v{k} and out.v{k} <= 100 )\n}}\n")


def write_workspace(root: Path, n: int) -> None:
    """A workspace of the failing chain of ``n`` nodes under ``root`` (new)."""
    (root / "contracts").mkdir(parents=True)
    (root / "contracts" / "chain.rcl").write_text("".join(node_text(k) for k in range(n)), encoding="utf-8")
    (root / "contracts" / "plan.yaml").write_text(
        f"name: failing-chain-{n}\ncontracts:\n  - contracts/chain.rcl\n", encoding="utf-8")


def verify(root: Path, src: Path = SRC) -> dict[str, object]:
    """``rclverify verify`` in ``root`` in a child process: ``{"rc", "out", "cpu"}``."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(src)] + ([env["PYTHONPATH"]] if env.get("PYTHONPATH") else []))
    cmd = [sys.executable, "-m", "rclverify.cli.commands", "verify", "-n", "1", "-w", str(root)]  # serial, as measured
    p = subprocess.run([sys.executable, "-c", PROBE, *cmd], capture_output=True, text=True, env=env)
    if p.returncode != 0 or not p.stdout.strip():
        raise RuntimeError(f"the probe failed (exit {p.returncode}): {p.stderr[-2000:]}")
    return dict(json.loads(p.stdout))


def counts(root: Path) -> tuple[int, int]:
    """(failed side conditions, repairs of the side-condition diagnoses) in the written report."""
    rep = json.loads((root / "reports" / "assurance.json").read_text(encoding="utf-8"))
    failed = sum(1 for sc in rep["side_conditions"] if sc["status"] == "failed")
    repairs = sum(len(d["repairs"]) for d in rep["diagnoses"] if d["kind"] == "side-condition")
    return failed, repairs


def _sizes(values: Sequence[str]) -> list[int]:
    out = [int(p) for v in values for p in v.split(",") if p.strip()]
    if not out or min(out) < 2:
        raise SystemExit("sizes must be integers of at least 2")
    return out


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", nargs="+", default=["25", "50", "200"], help="numbers of nodes (default 25 50 200)")
    ap.add_argument("--keep", help="write the workspaces under this directory and keep them")
    ap.add_argument("--smoke", action="store_true", help="N = 3 and 6 only: a few seconds (CI)")
    ap.add_argument("--src", help="the rclverify source tree to run (default: this repository's src/)")
    a = ap.parse_args(argv)
    sizes = [3, 6] if a.smoke else _sizes(a.sizes)
    base = Path(a.keep) if a.keep else Path(tempfile.mkdtemp(prefix="rclverify-diagscale-"))
    print(f"diagnosis scale: `rclverify verify` on a chain whose side conditions all fail, {os.cpu_count()} CPU(s)")
    header = f"{'nodes':>6} {'failed sc':>9} {'repairs':>7} {'cpu s':>8} {'ref s':>6} {'cpu/ref':>8} {'cpu/node':>9}"
    print(header)
    print("-" * len(header))
    cpu: dict[int, float] = {}
    try:
        for n in sizes:
            root = base / f"n{n}"
            if root.exists():
                shutil.rmtree(root)
            write_workspace(root, n)
            # smoke: a hundredth of the loop, scaled (an estimate; the figures of a smoke run are not compared)
            ref = reference_cpu(ITERATIONS // 100) * 100 if a.smoke else reference_cpu()
            r = verify(root, Path(a.src) if a.src else SRC)
            if not (root / "reports" / "assurance.json").is_file():
                print(f"{n:>6}  verify wrote no report (exit {r['rc']}):\n{r['out']}")
                return 1
            failed, repairs = counts(root)
            cpu[n] = float(r["cpu"])  # type: ignore[arg-type]
            print(f"{n:>6} {failed:>9} {repairs:>7} {cpu[n]:>8.2f} {ref:>6.2f} {cpu[n] / ref:>8.1f} "
                  f"{cpu[n] / n:>9.3f}", flush=True)
    finally:
        if not a.keep:
            shutil.rmtree(base, ignore_errors=True)
    lo, hi = min(cpu), max(cpu)
    if hi > lo:
        print(f"CPU ratio N={hi} / N={lo}: {cpu[hi] / cpu[lo]:.1f} (linear: {hi / lo:.1f}; aim: at most "
              f"{1.5 * hi / lo:.0f})")
    print("cpu s: CPU seconds (user+sys) of `rclverify verify` and its children; ref s: the reference loop "
          "(bench/_reference.py) just before; the exit status of verify is 1 (the side conditions fail).")
    return 0


if __name__ == "__main__":
    sys.exit(main())
