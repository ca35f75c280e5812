"""The cost of the second solver (issue 50; docs/second-solver.md).

Copies the bundled case study (the repository's contracts and plan) into a
temporary workspace, runs `rclverify verify` cold, then decides every
discharging query again with cvc5 from a cold second-solver record, and
prints:

* the CPU seconds of the cold run (Z3 and everything else);
* the CPU seconds of the second-solver stage alone, and cvc5's own
  seconds summed over the items, with the items' agreement counts, in
  all and per kind of item;
* the CPU seconds of `bundle --recheck` (both solvers, from the bundle alone).

`--smoke` uses the generated three-node workspace of `rclverify init`
instead (a few seconds).
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def _cpu() -> float:
    import os
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--smoke", action="store_true", help="a three-node workspace, a few seconds")
    args = ap.parse_args()
    from rclverify.cli.commands import main as cli
    from rclverify.stages.crosscheck.stage import INDEX, stage_crosscheck
    with tempfile.TemporaryDirectory() as tmp:
        ws = Path(tmp) / "ws"
        if args.smoke:
            cli(["init", str(ws)])
        else:
            files = subprocess.run(["git", "ls-files", "contracts", "backends", "dodo.py"], cwd=REPO,
                                   capture_output=True, text=True, check=True).stdout.split()
            for f in files:
                (ws / f).parent.mkdir(parents=True, exist_ok=True)
                shutil.copy2(REPO / f, ws / f)
        c0 = _cpu()
        cli(["verify", "-n", "1", "-w", str(ws)])  # serial: the figures are one process's
        cold = _cpu() - c0
        nodes = sorted(p.stem for p in (ws / "artifacts/calculus").glob("*.json"))
        (ws / INDEX).unlink()
        shutil.rmtree(ws / "artifacts/crosscheck/proofs", ignore_errors=True)
        c0 = _cpu()
        index = stage_crosscheck(ws, nodes)
        stage = _cpu() - c0
        cvc5_s = sum((r.get("cvc5") or {}).get("duration_s", 0.0) for r in index["items"])
        archive = Path(tmp) / "b.tar.gz"
        cli(["bundle", "-w", str(ws), "-o", str(archive)])
        c0 = _cpu()
        rc = cli(["bundle", "--recheck", str(archive)])
        recheck = _cpu() - c0
    print(f"workspace: {'rclverify init (3 nodes)' if args.smoke else 'the bundled case study'}")
    print(f"cold `rclverify verify` (Z3 and the rest):    {cold:7.2f} CPU s")
    print(f"second-solver stage (cvc5, {len(index['items'])} items):   {stage:7.2f} CPU s "
          f"({cvc5_s:.2f} s in cvc5; {stage / cold:.1%} of the cold run)")
    print(f"agreement: {index['counts']}")
    kinds: dict[str, dict[str, int]] = {}
    for r in index["items"]:
        by = kinds.setdefault(r["kind"], {})
        by[r["agreement"]] = by.get(r["agreement"], 0) + 1
    for kind, by in sorted(kinds.items()):
        print(f"  {kind}: {by}")
    print(f"`bundle --recheck` (Z3 and cvc5 from text): {recheck:7.2f} CPU s (rc {rc})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
