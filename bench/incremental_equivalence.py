"""Incremental equals clean, measured over many random edit sequences.

From the verified cut-down case study (``tests/_incremental.py``), each
sequence applies one to ``--length`` random edits (a requirement's text or
tracing, the plan's name, a fact, a connection, a contract's formula or
comment, a Hoare program, experiment data, a review record, a recorded run,
a trace file or a contract file added or deleted, every edit so far
undone), runs ``doit verify``
after each edit, and compares every report file with a from-scratch run on
a copy of the inputs.  Prints the sequences run, the edits applied, the
mismatches (0 expected) and the time taken::

    python3 bench/incremental_equivalence.py                 # 200 sequences, 2 at a time
    python3 bench/incremental_equivalence.py --sequences 20 --jobs 1 --seed 3
    python3 bench/incremental_equivalence.py --smoke     # one sequence of one edit (CI)
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import random
import shutil
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import _incremental as inc  # noqa: E402


def run_sequence(base: str, work: str, seed: int, length: int) -> tuple[int, list[str], list[str]]:
    """Apply one random sequence to a copy of the verified workspace ``base``;
    returns ``(seed, edits applied, mismatches)``."""
    rnd = random.Random(seed)
    root = Path(work) / f"s{seed}"
    ws = root / "inc" / "ws"
    shutil.copytree(base, ws, symlinks=True)
    done: list[str] = []
    bad: list[str] = []
    for _ in range(rnd.randint(1, length)):
        edit = rnd.choice(inc.EDITS)
        done.append(edit(ws, rnd.randrange(1000)))
        diffs = inc.compare(ws, root / "clean" / "ws")
        if diffs:
            bad.append(f"seed {seed}, after {done}:\n" + "\n".join(diffs))
            break
    shutil.rmtree(root, ignore_errors=True)
    return seed, done, bad


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sequences", type=int, default=200)
    ap.add_argument("--length", type=int, default=2, help="most edits in one sequence")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--smoke", action="store_true", help="one sequence of one edit, in this process's pool of one (CI)")
    args = ap.parse_args()
    if args.smoke:
        args.sequences, args.length, args.jobs = 1, 1, 1
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="rclverify-incremental-") as tmp:
        base = inc.make_workspace(Path(tmp) / "base" / "ws")
        proc = inc.verify(base)
        if proc.returncode != 0:
            print(proc.stdout + proc.stderr)
            return 1
        edits, mismatches, runs = 0, [], 0
        with ProcessPoolExecutor(max_workers=args.jobs) as pool:
            futures = [pool.submit(run_sequence, str(base), tmp, args.seed * 100_000 + k, args.length)
                       for k in range(args.sequences)]
            for f in futures:
                seed, done, bad = f.result()
                runs += 1
                edits += len(done)
                mismatches += bad
                for b in bad:
                    print(b, flush=True)
    dt = time.perf_counter() - t0
    print(f"sequences run: {runs}; edits applied: {edits}; mismatches: {len(mismatches)}; "
          f"{dt:.0f} s ({args.jobs} at a time)")
    return 1 if mismatches else 0


if __name__ == "__main__":
    raise SystemExit(main())
