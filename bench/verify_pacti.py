"""`rclverify verify` of a chain beside Pacti composing the same chain (issue 51).

The chain (tests/_chain.py) with every assumption widened to ``0 <= x_i <=
1000``: node ``N<i>`` guarantees ``x_{i+1} <= x_i + 1`` and ``0 <=
x_{i+1}``, the environment gives ``0 <= x0 <= 50``, so every assumption
holds in context (``x_i <= 50 + i``) and none locally; the requirement
``SYS: N<n-1>.out.x<n> <= 50 + n`` holds.  For each N (default 100, 200,
400):

* **rclverify verify** in a fresh workspace, in a child process: CPU
  seconds (user + system of it and its children) and wall-clock seconds
  (``wall s``; on two CPUs the second solver's stage uses both, issue 67),
  of which ``cvc5 s`` the
  second solver's own (the seconds cvc5 took per item, issue 50), the side conditions
  discharged locally / in context / otherwise, those in context proved from
  the producers' cone summaries (calculus/summary.py), and SYS's verdict;
* **calculus only**: every node's composition in this process, with the
  summaries and (``--full``) reading the whole cone, CPU seconds;
* **Pacti** (the optional ``bench`` extra): the environment's contract
  composed with ``N0``, ``N1``, ... (bench/compose_pacti.py), CPU seconds,
  and whether it composes the whole chain (the same verdict).

Both source trees are byte-compiled first (``compileall``), as an installed
package is.  ``ratio`` is verify's CPU over Pacti's, ``wall/p`` its wall clock over
Pacti's CPU seconds (Pacti runs on one core).  ``--jobs J`` also runs
``rclverify verify -n J`` (J doit processes: the node tasks and the two
report parts side by side) and prints its CPU and wall clock, and
``-n/p`` its wall clock over Pacti's CPU seconds.  Then the growth per
doubling of each column.  ``--src OLD_SRC`` runs
``rclverify verify`` from another source tree as well (a ``git worktree``
of the old code), ``--repeat K`` takes the median of K runs.

``--floor`` adds two what-if runs of ``rclverify verify`` (not
configurations a user has: the bench patches the child process), to show
where the rest of the distance to Pacti lies: ``no ctx`` without the
fresh Z3 context of every node stage and cone summary (semantics/world.py,
calculus/summary.py: the integrity decision, docs/integrity.md), ``no ctx,
no cvc5`` without cvc5 as well, as on a machine where it is not installed
(the second solver of issue 50, added after issue 51's baseline: every
discharging query decided again by cvc5 with a checked proof; each item
then reads ``one solver``).  Their verdicts are not compared.

    python bench/verify_pacti.py                         # N = 100, 200, 400
    python bench/verify_pacti.py --sizes 100,200 --full  # and the calculus reading whole cones
    python bench/verify_pacti.py --sizes 200 --floor     # and the two what-if runs
    python bench/verify_pacti.py --smoke                 # N = 5, with --floor: seconds (CI)

Figures are printed, not asserted; the exit status is 1 only when a
verdict differs from the expected one (a side condition not discharged,
SYS not proved, Pacti not composing the chain).
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import compileall
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Iterator

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "bench"))

from _chain import write_chain  # noqa: E402
from _scratch import describe, scratch  # noqa: E402
from compose_pacti import pacti_chain  # noqa: E402

BOUND = 1000
#: The child process: runs its arguments and prints their CPU seconds (with their children).
PROBE = ("import json, resource, subprocess, sys\n"
         "r = subprocess.run(sys.argv[1:], capture_output=True, text=True)\n"
         "u = resource.getrusage(resource.RUSAGE_CHILDREN)\n"
         "print(json.dumps({'rc': r.returncode, 'out': r.stderr[-2000:], 'cpu': u.ru_utime + u.ru_stime}))\n")


#: The what-if child of ``--floor``: ``rclverify verify`` with the fresh Z3 contexts (``ctx``) and the
#: second solver's stage (``cvc5``) switched off by patching, then its CPU seconds like :data:`PROBE`.
WHATIF = ("import sys, types\n"
          "off = sys.argv[1].split(',')\n"
          "sys.argv = ['rclverify'] + sys.argv[2:]\n"
          "import z3\n"
          "if 'ctx' in off:\n"
          "    import rclverify.semantics.world as W, rclverify.app.pipeline as P, rclverify.calculus.summary as S\n"
          "    assert P.fresh_z3 is W.fresh and S.z3 is z3, 'what-if: the names patched here moved'\n"
          "    W.fresh = P.fresh_z3 = lambda: None\n"
          "    S.z3 = types.SimpleNamespace(**{k: getattr(z3, k) for k in dir(z3) if not k.startswith('__')})\n"
          "    S.z3.Context = z3.main_ctx\n"
          "if 'cvc5' in off:\n"
          "    sys.modules['cvc5'] = None  # as on a machine without cvc5: each item reads 'one solver'\n"
          "    from rclverify.stages.crosscheck.cvc5_decide import version\n"
          "    assert version() == '', 'what-if: cvc5 still found'\n"
          "from rclverify.cli.commands import main\n"
          "sys.exit(main())\n")


def workspace(root: Path, n: int) -> Path:
    return write_chain(root, n, bound=BOUND, requirements=[("SYS", f"N{n - 1}.out.x{n} <= {50 + n}")])


def whatif(root: Path, off: str) -> float:
    """CPU seconds of ``rclverify verify`` of ``root`` with ``off`` (``ctx``,
    ``ctx,cvc5``) switched off (:data:`WHATIF`); raises ``RuntimeError`` when it fails."""
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    p = subprocess.run([sys.executable, "-c", PROBE, sys.executable, "-c", WHATIF, off, "verify", "-n", "1", "-w",
                        str(root)],
                       capture_output=True, text=True, env=env)
    probe = json.loads(p.stdout)
    if probe["rc"] != 0:
        raise RuntimeError(f"what-if {off}: exit {probe['rc']}: {probe['out'][-500:]}")
    return float(probe["cpu"])


def verify(root: Path, src: Path, jobs: int = 1) -> dict[str, Any]:
    """``rclverify verify`` of ``root`` with the source tree ``src`` (``jobs`` doit processes, ``-n``): CPU,
    wall clock and the verdicts."""
    env = dict(os.environ, PYTHONPATH=str(src))
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, "-c", PROBE, sys.executable, "-m", "rclverify.cli.commands", "verify",
                        "-n", str(jobs), "-w", str(root)],
                       capture_output=True, text=True, env=env)
    wall = time.perf_counter() - t0
    probe = json.loads(p.stdout)
    rep = json.loads((root / "reports" / "assurance.json").read_text(encoding="utf-8"))
    scs = rep["side_conditions"]
    local = sum(1 for s in scs if s["status"] == "discharged" and s.get("verdict") != "discharged in context")
    context = sum(1 for s in scs if s.get("verdict") == "discharged in context")
    summaries = sum(1 for s in scs if (s.get("context") or {}).get("summaries"))
    sys_req = next((r for r in rep["requirements"] if r["id"] == "SYS"), {})
    try:  # the second solver's share: cvc5's own seconds per item (issue 50's stage)
        cross = json.loads((root / "artifacts" / "crosscheck" / "index.json").read_text(encoding="utf-8"))
        cvc5 = sum(float((r.get("cvc5") or {}).get("duration_s") or 0) for r in cross.get("items", []))
    except (OSError, ValueError):
        cvc5 = 0.0
    return {"cpu": probe["cpu"], "wall": wall, "rc": probe["rc"], "local": local, "context": context, "other": len(scs) - local - context,
            "summaries": summaries, "SYS": str(sys_req.get("verdict") or sys_req.get("status")), "cvc5": cvc5}


def calculus(root: Path, summaries: bool) -> float:
    """CPU seconds of every node's composition of the workspace at ``root`` in this process."""
    from rclverify.calculus.compose import compose_node
    from rclverify.semantics import world
    from rclverify.stages.workspace import Workspace
    ws = Workspace(root)
    checked, model = ws.checked, ws.model
    facts = {m: [f.expr for f in fs] for m, fs in ws.plan.facts.items()}
    t0 = time.process_time()
    for node in checked.nodes:
        world.fresh()
        compose_node(checked, model, node, facts=facts, summaries=summaries)
    return time.process_time() - t0


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--sizes", default="100,200,400", help="chain lengths (default 100,200,400)")
    p.add_argument("--src", help="also run `rclverify verify` from this source tree (the old code)")
    p.add_argument("--full", action="store_true", help="also time the calculus reading whole cones")
    p.add_argument("--repeat", type=int, default=1, help="median of this many runs of each figure")
    p.add_argument("--floor", action="store_true",
                   help="also run verify without fresh Z3 contexts, and without them and the second solver (what-if)")
    p.add_argument("--smoke", action="store_true", help="N = 5, with --floor: seconds (CI)")
    p.add_argument("--jobs", type=int, default=1, metavar="J",
                   help="also run `rclverify verify -n J` (J doit processes) and print its CPU and wall clock")
    args = p.parse_args(argv)
    args.floor = args.floor or args.smoke  # the what-if patches name internals: CI keeps them working
    from compose_pacti import _pacti
    pc = _pacti()
    for tree in [ROOT / "src"] + ([Path(args.src)] if args.src else []):
        # byte-compiled first: where PYTHONDONTWRITEBYTECODE is set, a tree without its .pyc files compiles every
        # module in every run (0.55 CPU s of rclverify verify), which would be charged to one tree only
        compileall.compile_dir(str(tree), quiet=1)
    sizes = [5] if args.smoke else [int(x) for x in args.sizes.split(",")]
    print(f"CPU seconds, medians of {args.repeat}; {os.cpu_count()} CPU(s); chain with every x_i <= {BOUND}")
    print(describe(Path(tempfile.gettempdir())))
    head = f"{'N':>5} {'verify s':>9} {'wall s':>7} {'cvc5 s':>7} {'local':>5} {'ctx':>5} {'summ':>5} {'SYS':>8}"
    head += f" {'old s':>8}" if args.src else ""
    head += f" {'calc s':>7}" + (f" {'calc full':>9}" if args.full else "")
    head += f" {'no ctx':>7} {'no ctx,cvc5':>11}" if args.floor else ""
    head += f" {'-n' + str(args.jobs) + ' s':>7} {'-n' + str(args.jobs) + ' wall':>8}" if args.jobs > 1 else ""
    head += f" {'pacti s':>8} {'ratio':>6} {'wall/p':>6}" + (f" {'-n/p':>6}" if args.jobs > 1 else "")
    print(head)
    ok, rows = True, []
    with scratch() as folders:
        for n in sizes:
            ok = _size(args, pc, n, folders, rows) and ok
    for a, b in zip(rows, rows[1:]):
        growth = {k: b[k] / a[k] for k in ("verify", "old", "calc", "full", "noctx", "bare", "pacti")
                  if a.get(k) and b.get(k)}
        print(f"growth {a['n']} -> {b['n']}: " + ", ".join(f"{k} {v:.2f}x" for k, v in growth.items()))
    return 0 if ok else 1


def _size(args: argparse.Namespace, pc: Any, n: int, folders: Iterator[Path], rows: list[dict[str, Any]]) -> bool:
    """Time every figure of one chain length ``n`` (each run in a new folder of ``folders``, none deleted
    before the bench ends: bench/_scratch.py), print its row and append it to ``rows``; ``False`` when a
    verdict is wrong."""
    ok = True
    runs, old, calc, full, pac, noctx, bare, par = [], [], [], [], [], [], [], []
    for _ in range(args.repeat):
        d = next(folders)
        runs.append(verify(workspace(d / "ws", n), ROOT / "src"))
        if args.src:
            old.append(verify(workspace(d / "old", n), Path(args.src))["cpu"])
        if args.jobs > 1:
            par.append(verify(workspace(d / "par", n), ROOT / "src", args.jobs))
        calc.append(calculus(d / "ws", True))
        if args.full:
            full.append(calculus(d / "ws", False))
        if args.floor:
            noctx.append(whatif(workspace(d / "noctx", n), "ctx"))
            bare.append(whatif(workspace(d / "bare", n), "ctx,cvc5"))
        if pc is not None:
            r = pacti_chain(pc, n, None, BOUND)
            ok = ok and r["first"] is None
            pac.append(r["seconds"])
    r = runs[0]
    ok = ok and all(x["rc"] == 0 and x["other"] == 0 and x["context"] == n - 1 and x["SYS"].startswith("proved")
                    for x in runs[:1] + par[:1])
    row = {"n": n, "verify": statistics.median(x["cpu"] for x in runs), "calc": statistics.median(calc),
           "wall": statistics.median(x["wall"] for x in runs),
           "old": statistics.median(old) if old else None, "full": statistics.median(full) if full else None,
           "pacti": statistics.median(pac) if pac else None,
           "noctx": statistics.median(noctx) if noctx else None, "bare": statistics.median(bare) if bare else None,
           "par": statistics.median(x["cpu"] for x in par) if par else None,
           "parwall": statistics.median(x["wall"] for x in par) if par else None}
    rows.append(row)
    line = f"{n:5} {row['verify']:9.2f} {row['wall']:7.2f} {r['cvc5']:7.2f} {r['local']:5} {r['context']:5} {r['summaries']:5} {r['SYS'].split(',')[0]:>8}"
    line += f" {row['old']:8.2f}" if args.src else ""
    line += f" {row['calc']:7.2f}" + (f" {row['full']:9.2f}" if args.full else "")
    line += f" {row['noctx']:7.2f} {row['bare']:11.2f}" if args.floor else ""
    line += f" {row['par']:7.2f} {row['parwall']:8.2f}" if par else ""
    line += (f" {row['pacti']:8.2f} {row['verify'] / row['pacti']:6.2f} {row['wall'] / row['pacti']:6.2f}"
             + (f" {row['parwall'] / row['pacti']:6.2f}" if par else "") if row["pacti"] else "  (Pacti not installed)")
    print(line, flush=True)
    return ok


if __name__ == "__main__":
    sys.exit(main())
