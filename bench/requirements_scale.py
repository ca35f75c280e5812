"""How the requirement checks scale (issue 21): N nodes, R formal requirements.

Writes a synthetic workspace of ``--chains`` independent chains of
``--depth`` nodes each (node ``C<c>N<k>`` reads ``c<c>_<k-1>`` and produces
``c<c>_<k>``; ``C<c>N0`` reads the environment input ``c<c>_e``), every node
with the contract

    assume( 0 <= in.x and in.x <= 100 )
    guarantee( 0 <= out.y and out.y <= 100 )
    guarantee( in.x <= 50 -> out.y <= in.x )

and one formal requirement per chain over its whole depth:

    C<c>N0.in.c<c>_e <= 50 -> C<c>N<depth-1>.out.c<c>_<depth-1> <= C<c>N0.in.c<c>_e

which Z3 proves from the second guarantee of every node of the chain (the
requirement's cone is the chain).  Then measures, in this process:

* **check**: ``stage_check`` (parse, type-check, plan, snapshots, model);
* **cold**: ``stage_requirements`` with no record (every requirement checked:
  the validity query, the consistency of the used premises, the vacuity of
  the requirement's premise);
* **no-op**: ``stage_requirements`` again (no requirement checked);
* **edit**: the middle node of one chain gets a changed second guarantee
  (still true of the chain), then ``stage_check`` and ``stage_requirements``:
  which requirements were checked again (only that chain's).

Usage::

    python bench/requirements_scale.py                       # 100 chains x 10 = 1000 nodes
    python bench/requirements_scale.py --chains 5 --depth 4  # a quick run
    python bench/requirements_scale.py --smoke               # 2 chains of 3: a few seconds

Wall-clock and CPU seconds are printed, not asserted.
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import resource
import shutil
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from rclverify.app.pipeline import Workspace, stage_check, stage_requirements  # noqa: E402


def node_text(c: int, k: int, temporal: bool = False) -> str:
    x = f"c{c}_{k - 1}" if k else f"c{c}_e"
    y = f"c{c}_{k}"
    # the temporal workload's nodes answer every reading they accept at once (docs/requirements.md, "progress")
    progress = "  progress( within 0 steps )\n" if temporal else ""
    return (f"node C{c}N{k} {{\n  inputs( {x} : REAL )\n  outputs( {y} : REAL )\n"
            f"  assume( 0 <= in.{x} and in.{x} <= 100 )\n"
            f"  guarantee( 0 <= out.{y} and out.{y} <= 100 )\n"
            f"  guarantee( in.{x} <= 50 -> out.{y} <= in.{x} )\n{progress}}}\n")


def write_workspace(root: Path, chains: int, depth: int, temporal: bool = False) -> None:
    (root / "contracts").mkdir(parents=True)
    files, reqs = [], []
    for c in range(chains):
        rel = f"contracts/chain{c}.rcl"
        (root / rel).write_text("".join(node_text(c, k, temporal) for k in range(depth)))
        files.append(rel)
        last = depth - 1
        if temporal:  # a cone of 5..10 nodes: the chain up to node k; proved by 1-induction from node k's guarantee 1
            # (not `always out <= 100`: a first input outside the assumption leaves the first output free)
            k = min(last, 4 + c % 6)
            x = f"c{c}_{k - 1}" if k else f"c{c}_e"
            reqs.append(f"  - id: T{c}\n    text: node {k} of chain {c} always answers a valid reading in range\n"
                        f"    formal: \"always (0 <= C{c}N{k}.in.{x} and C{c}N{k}.in.{x} <= 100 -> "
                        f"C{c}N{k}.out.c{c}_{k} <= 100)\"\n")
            continue
        reqs.append(f"  - id: R{c}\n    text: chain {c} never raises a low reading\n"
                    f"    formal: \"C{c}N0.in.c{c}_e <= 50 -> C{c}N{last}.out.c{c}_{last} <= C{c}N0.in.c{c}_e\"\n")
    (root / "contracts/plan.yaml").write_text("name: requirements-scale\ncontracts:\n"
                                              + "".join(f"  - {f}\n" for f in files)
                                              + "requirements:\n" + "".join(reqs))


def cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def timed(fn):  # type: ignore[no-untyped-def]
    t0, c0 = time.perf_counter(), cpu()
    out = fn()
    return out, time.perf_counter() - t0, cpu() - c0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--chains", type=int, default=100)
    ap.add_argument("--depth", type=int, default=10)
    ap.add_argument("--keep", help="write the workspace here and keep it")
    ap.add_argument("--temporal", action="store_true",
                    help="temporal requirements instead (always ..., a cone of 5-10 nodes each; docs/requirements.md)")
    ap.add_argument("--smoke", action="store_true", help="2 chains of depth 3: a few seconds (CI)")
    a = ap.parse_args()
    if a.smoke:
        a.chains, a.depth = 2, 3
    root = Path(a.keep) if a.keep else Path(tempfile.mkdtemp(prefix="reqscale-")) / "ws"
    if root.exists():
        shutil.rmtree(root)
    write_workspace(root, a.chains, a.depth, a.temporal)
    n = a.chains * a.depth
    print(f"{n} nodes, {a.chains} {'temporal' if a.temporal else 'formal'} requirements over chains of depth {a.depth}")

    ws = Workspace(root)
    _, s, c = timed(lambda: stage_check(ws))
    print(f"check                 {s:7.2f} s  ({c:.2f} CPU s)")
    rows, s, c = timed(lambda: stage_requirements(ws))
    verdicts: dict[str, int] = {}
    for rec, _ in rows:
        key = rec["verdict"] + (f"/{rec.get('consistency')}/{rec.get('vacuity')}" if rec["verdict"] == "proved" else "")
        if rec.get("temporal"):
            key = f"{rec['verdict']}/{rec['temporal']['method']}/k={rec['temporal']['k']}"
        verdicts[key] = verdicts.get(key, 0) + 1
    print(f"cold: {sum(now for _, now in rows):4d} checked   {s:7.2f} s  ({c:.2f} CPU s)  verdicts {verdicts}")
    rows, s, c = timed(lambda: stage_requirements(Workspace(root)))
    print(f"no-op: {sum(now for _, now in rows):3d} checked   {s:7.2f} s  ({c:.2f} CPU s)")

    chain, mid = a.chains // 2, a.depth // 2
    f = root / f"contracts/chain{chain}.rcl"
    x = f"c{chain}_{mid - 1}" if mid else f"c{chain}_e"
    f.write_text(f.read_text().replace(f"guarantee( in.{x} <= 50 -> out.c{chain}_{mid} <= in.{x} )",
                                       f"guarantee( in.{x} <= 50 -> out.c{chain}_{mid} <= in.{x} and 0 <= out.c{chain}_{mid} )"))
    ws = Workspace(root)
    (_, s1, c1) = timed(lambda: stage_check(ws))
    rows, s, c = timed(lambda: stage_requirements(ws))
    again = [rec["id"] for rec, now in rows if now]
    print(f"edit C{chain}N{mid}: check {s1:.2f} s, requirements {s:.2f} s ({c:.2f} CPU s); "
          f"checked again: {', '.join(again) or 'none'}")
    if not a.keep:
        shutil.rmtree(root.parent)
    return 0


if __name__ == "__main__":
    sys.exit(main())
