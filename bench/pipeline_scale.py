"""How the whole pipeline (``doit verify``) scales with the number of nodes.

Writes a synthetic workspace of N nodes for each N and measures, each in a
fresh ``python -m doit`` process:

* **cold**: ``doit verify`` on the fresh workspace (no artifacts, no doit state),
* **no-op**: a second ``doit verify`` with nothing changed (must execute no task),
* **edit**: ``doit verify`` after editing one contract (the middle node's
  second guarantee), with the tasks that ran,

plus the peak resident memory of each run (the largest ``ru_maxrss`` of the
doit process and its children, from ``resource.getrusage(RUSAGE_CHILDREN)``
in an intermediate process), the CPU seconds (user + system) of the run
and the numbers of nodes, obligations and side
conditions.  Wall-clock seconds; on a shared machine expect +-25%.

The synthetic system (see :func:`topology`): node ``N<k>`` produces ``v<k>``
and reads ``v<k-1>`` (a chain); every third node also reads ``v<k-3>`` (a
join, rule R3; node ``k-3`` then feeds two consumers, a branch, R2); every
tenth node closes a loop by reading the output of the node four places
downstream (R4).  Node ``N0`` reads the environment input ``e0``.  Every node
has two guarantees and a ``hoare`` evidence entry over one shared clamp
program (``backends/hoare/clamp.imp``), so each node gives Hoare obligations
checked by Z3, and the calculus and health checks run as usual
(``--hoare EVERY``: only every EVERY-th node; 0 for none, which leaves the
calculus and health checks alone, the workload the issue's speed aims were
first measured on).
Every tenth node (``--property-tests EVERY``; 0 for none) also has a
``property_tests`` entry, 25 Hypothesis examples against the same clamp
written in Python (``backends/property_tests/clamp.py``).

Usage::

    python bench/pipeline_scale.py                     # N = 10 100 500 1000
    python bench/pipeline_scale.py --sizes 10,100 -n 2 # quick run, doit -n 2
    python bench/pipeline_scale.py --keep DIR          # keep the workspaces under DIR
    python bench/pipeline_scale.py --hoare 0 --property-tests 0   # calculus and health only
    python bench/pipeline_scale.py --smoke             # N = 2, no property tests: a few seconds
    python bench/pipeline_scale.py --case-study [--compare OLD_SRC] [--repeat K] [--no-compile]

``--case-study`` measures instead a cold ``doit verify`` of the bundled case
study (its contracts, plan, backends' inputs and ``dodo.py`` copied to a
temporary directory), CPU seconds of doit and its children (SPIN, gcc,
Dafny, ...), and, in the same process just before each run, a fixed
pure-Python reference loop (``bench/_reference.py``): the CPU as a multiple
of the loop is the figure comparable across machines and loads (issue 44).
With ``--compare OLD_SRC`` each code runs on its own copy, alternating, and
the ratio new/old of the multiples is printed.  Each tree's bytecode is
written first (``compileall``, as ``scripts/setup.sh`` does for the
installed package), so that no run spends its CPU compiling modules, which
it would in a tree never imported or with ``PYTHONDONTWRITEBYTECODE`` set
(``--no-compile``: as the trees are).

The figures are printed, not asserted.
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _reference import reference_cpu  # noqa: E402

REPO = Path(__file__).resolve().parents[1]

CLAMP = """\
// A clamp: y is x when x is not negative, else 0.  The synthetic nodes of
// bench/pipeline_scale.py are bound to it (in.<first input> -> x).
var x, z : REAL;
var y : REAL;

IF (x < 0) THEN
   y := 0
ELSE
   y := x
"""

DODO = """\
from pathlib import Path

from rclverify.app.tasks import build_tasks, doit_config

DOIT_CONFIG = doit_config()

globals().update(build_tasks(Path(__file__).parent))
"""


def topology(n: int) -> dict[int, list[int]]:
    """Producers of each node ``0..n-1``: chain, joins every third node, a
    loop back from every tenth node (see the module docstring)."""
    prod: dict[int, list[int]] = {k: ([k - 1] if k else []) for k in range(n)}
    for k in range(3, n, 3):
        prod[k].append(k - 3)
    for k in range(10, n, 10):
        if k + 4 < n:
            prod[k].append(k + 4)
    return prod


def contract(k: int, producers: list[int]) -> str:
    """RCL text of node ``N<k>``."""
    ins = [f"v{p}" for p in producers] or ["e0"]
    first = ins[0]
    assume = " and ".join(f"0 <= in.{i}" for i in ins)
    return (
        f"// Synthetic node {k}.\n"
        f"node N{k} {{\n"
        f"  inputs( {', '.join(f'{i} : REAL' for i in ins)} )\n"
        f"  outputs( v{k} : REAL )\n"
        f"  assume( {assume} )\n"
        f"  guarantee( 0 <= out.v{k} )\n"
        f"  guarantee( in.{first} <= 100 -> out.v{k} <= in.{first} + 1 )\n"
        f"}}\n"
    )


def has_property_tests() -> bool:
    """Whether this tree implements the ``property_tests`` backend."""
    from rclverify import backends
    return "property_tests" in getattr(backends, "IMPLEMENTED", {})


def implementation(k: int, producers: list[int]) -> str:
    """Python text of node ``N<k>``'s clamp, the callable ``n<k>`` that the
    ``property_tests`` backend calls with one keyword argument per input."""
    ins = [f"v{p}" for p in producers] or ["e0"]
    return (f"def n{k}({', '.join(ins)}):\n"
            f"    return {{'v{k}': {ins[0]} if {ins[0]} >= 0 else 0}}\n\n\n")


def evidence(nodes: dict[str, object], impls: list[str], k: int, producers: list[int], hoare: bool,
             property_tests: bool) -> None:
    """Node ``N<k>``'s plan entries, added to ``nodes``: a ``hoare`` entry over
    the clamp program (``hoare``), a ``property_tests`` entry of 25 examples
    over its clamp in Python, whose text is appended to ``impls``
    (``property_tests``)."""
    ins = [f"v{p}" for p in producers] or ["e0"]
    binding = {f"in.{ins[0]}": "x", f"out.v{k}": "y", **{f"in.{i}": "z" for i in ins[1:]}}
    entries: list[dict[str, object]] = []
    if hoare:
        entries.append({"backend": "hoare", "program": "backends/hoare/clamp.imp", "binding": binding})
    if property_tests:
        impls.append(implementation(k, producers))
        entries.append({"backend": "property_tests", "implementation": f"backends/property_tests/clamp.py:n{k}",
                        "max_examples": 25})
    if entries:
        nodes[f"N{k}"] = {"evidence": entries}


def generate(root: Path, n: int, property_tests: bool, pt_every: int = 10, hoare_every: int = 1) -> None:
    """Write an ``n``-node workspace under ``root`` (which must not exist);
    every ``hoare_every``-th node (0: none) gets a ``hoare`` entry over the
    clamp program; with ``property_tests``, every ``pt_every``-th node also
    gets a ``property_tests`` entry (25 examples) over its clamp in Python."""
    (root / "contracts").mkdir(parents=True)
    (root / "backends" / "hoare").mkdir(parents=True)
    (root / "backends" / "hoare" / "clamp.imp").write_text(CLAMP)
    (root / "dodo.py").write_text(DODO)
    prod = topology(n)
    nodes: dict[str, object] = {}
    impls: list[str] = []
    for k in range(n):
        (root / "contracts" / f"n{k}.rcl").write_text(contract(k, prod[k]))
        evidence(nodes, impls, k, prod[k], bool(hoare_every) and k % hoare_every == 0,
                 property_tests and k % pt_every == 0)
    if impls:
        (root / "backends" / "property_tests").mkdir(parents=True)
        (root / "backends" / "property_tests" / "clamp.py").write_text("".join(impls))
    plan = {"name": f"synthetic system of {n} nodes", "contracts": [f"contracts/n{k}.rcl" for k in range(n)],
            "nodes": nodes}
    (root / "contracts" / "plan.yaml").write_text(yaml.safe_dump(plan, sort_keys=False))


@dataclass
class Run:
    seconds: float
    cpu: float
    peak_mb: float
    ran: list[str]
    rc: int
    output: str


PROBE = ("import resource, subprocess, sys, json\n"
         "r = subprocess.run(sys.argv[1:], capture_output=True, text=True)\n"
         "u = resource.getrusage(resource.RUSAGE_CHILDREN)\n"
         "print(json.dumps({'rc': r.returncode, 'out': r.stdout + r.stderr,"
         " 'maxrss_kb': u.ru_maxrss, 'cpu': u.ru_utime + u.ru_stime}))\n")


def doit_verify(root: Path, jobs: int, src: str | None = None) -> Run:
    """Run ``python -m doit -n jobs verify`` in ``root`` (``-n 0``, doit's serial runner, for one job); time, peak memory,
    executed tasks.  ``src``: the rclverify source tree to run (put first on
    ``PYTHONPATH``; default: the installed one)."""
    cmd = [sys.executable, "-m", "doit", "-n", str(jobs if jobs > 1 else 0), "verify"]  # doit's -n 0: serial
    env = dict(os.environ)
    if src:
        env["PYTHONPATH"] = os.pathsep.join([str(Path(src).resolve())] + ([env["PYTHONPATH"]] if env.get("PYTHONPATH") else []))
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, "-c", PROBE, *cmd], cwd=root, capture_output=True, text=True, env=env)
    seconds = time.perf_counter() - t0
    res = json.loads(p.stdout)
    ran = [line[3:] for line in res["out"].splitlines() if line.startswith(".  ")]
    return Run(seconds, res["cpu"], res["maxrss_kb"] / 1024, ran, res["rc"], res["out"])


def summarise(ran: list[str]) -> str:
    """Tasks that ran, grouped by stage: ``check, compose x3 (N4, N5, N7), ...``."""
    groups: dict[str, list[str]] = {}
    for t in ran:
        stage, _, name = t.partition(":")
        groups.setdefault(stage, []).append(name)
    parts = []
    for stage, names in groups.items():
        names = [x for x in names if x]
        if not names:
            parts.append(stage)
        elif stage == "evidence":
            parts.append(f"evidence x{len(names)}")
        else:
            parts.append(f"{stage} {'/'.join(names)}")
    return ", ".join(parts)


def edit_one(root: Path, n: int) -> str:
    """Change the middle node's second guarantee (100 -> 99, still provable;
    called again: back to 100); its name."""
    k = n // 2
    p = root / "contracts" / f"n{k}.rcl"
    text = p.read_text()
    p.write_text(text.replace("<= 100 ->", "<= 99 ->") if "<= 100 ->" in text else text.replace("<= 99 ->", "<= 100 ->"))
    return f"N{k}"


def counts(root: Path) -> tuple[int, int]:
    """(obligations, side conditions) in the written report."""
    rep = json.loads((root / "reports" / "assurance.json").read_text())
    return len(rep["obligations"]), len(rep["side_conditions"])


def _sizes(values: Sequence[str]) -> list[int]:
    out = []
    for v in values:
        out += [int(p) for p in v.split(",") if p.strip()]
    if not out or min(out) < 1:
        raise SystemExit("sizes must be positive integers")
    return out


def figures(cold: Run, noop: Run, edit: Run) -> str:
    """One row's columns: cold s, (cpu), MB, no-op s, (cpu), ran, edit s, (cpu), MB."""
    return (f"{cold.seconds:>7.1f} {cold.cpu:>7.1f} {cold.peak_mb:>5.0f} {noop.seconds:>7.2f} {noop.cpu:>6.2f} "
            f"{len(noop.ran):>3} {edit.seconds:>6.2f} {edit.cpu:>6.2f} {edit.peak_mb:>5.0f}")


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", nargs="+", default=["10", "100", "500", "1000"],
                    help="numbers of nodes (space or comma separated)")
    ap.add_argument("-n", "--jobs", type=int, default=1, help="doit parallel processes (doit -n)")
    ap.add_argument("--keep", help="write the workspaces under this directory and keep them")
    ap.add_argument("--property-tests", type=int, default=10, metavar="EVERY",
                    help="give every EVERY-th node a property_tests entry (default 10; 0: none)")
    ap.add_argument("--hoare", type=int, default=1, metavar="EVERY",
                    help="give every EVERY-th node a hoare entry (default 1: every node; 0: none, the calculus "
                         "and health checks alone, the workload the issue's aims were measured on)")
    ap.add_argument("--compare", metavar="OLD_SRC",
                    help="also run the rclverify source tree OLD_SRC (e.g. a git worktree's src/ of the code "
                         "before a change) on its own copy of each workspace, alternating with this tree's runs, "
                         "and print both rows and the ratio new/old")
    ap.add_argument("--src", metavar="NEW_SRC", help="the source tree to measure (default: the installed rclverify)")
    ap.add_argument("--repeat", type=int, default=1, metavar="K",
                    help="with --compare: K no-op runs and K edits (the constant toggled) per code, alternating; "
                         "the medians are printed (default 1); with --case-study: K cold runs per code")
    ap.add_argument("--smoke", action="store_true", help="N = 2 without property tests: a few seconds (CI)")
    ap.add_argument("--case-study", action="store_true",
                    help="a cold `doit verify` of the bundled case study, as a multiple of the reference loop")
    ap.add_argument("--no-compile", action="store_true",
                    help="with --case-study: do not write each tree's bytecode first (then a tree without it, "
                         "or PYTHONDONTWRITEBYTECODE, makes every run compile the modules it imports)")
    args = ap.parse_args(argv)
    if args.case_study:
        return case_study(args)
    if args.smoke:
        args.sizes, args.property_tests = ["2"], 0
    sizes = _sizes(args.sizes)
    if args.compare:
        return compare(sizes, args)
    pt = has_property_tests() and args.property_tests > 0
    base = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="rclverify-bench-"))
    print(f"pipeline scale: doit{' -n ' + str(args.jobs) if args.jobs > 1 else ''} verify, "
          f"{os.cpu_count()} CPU(s); obligations: "
          + ("hoare" + (f" on every {args.hoare}th node" if args.hoare > 1 else "") if args.hoare > 0 else "none")
          + (f", property_tests on every {args.property_tests}th node" if pt else " (no property_tests)"))
    header = (f"{'nodes':>6} {'oblig.':>7} {'side c.':>7} {'cold s':>7} {'(cpu)':>7} {'MB':>5} {'no-op s':>7} "
              f"{'(cpu)':>6} {'ran':>3} {'edit s':>6} {'(cpu)':>6} {'MB':>5}  tasks run after the edit")
    print(header)
    print("-" * len(header))
    try:
        for n in sizes:
            root = base / f"n{n}"
            if root.exists():
                shutil.rmtree(root)
            generate(root, n, pt, args.property_tests, args.hoare)
            cold = doit_verify(root, args.jobs)
            if cold.rc != 0:
                print(f"{n:>6}  cold run failed (exit {cold.rc}):\n{cold.output[-3000:]}")
                return 1
            nob, nsc = counts(root)
            noop = doit_verify(root, args.jobs)
            edited = edit_one(root, n)
            edit = doit_verify(root, args.jobs)
            ran = summarise([t for t in edit.ran if t != "verify"])
            print(f"{n:>6} {nob:>7} {nsc:>7} {figures(cold, noop, edit)}  ({edited}) {ran}", flush=True)
    finally:
        if not args.keep:
            shutil.rmtree(base, ignore_errors=True)
    print("cold/no-op/edit: wall-clock seconds of one `doit verify`; (cpu): CPU seconds (user+sys) of doit and its "
          "children; MB: peak RSS of the largest process; ran: tasks the no-op run executed (0 expected).")
    return 0


#: What a copy of the case study needs to run `doit verify` (workspace-relative).
CASE_STUDY = ("dodo.py", "contracts", "backends", "ros")


def copy_case_study(dest: Path) -> None:
    """The bundled case study's inputs under ``dest`` (new), without artifacts or reports."""
    for rel in CASE_STUDY:
        src = REPO / rel
        if src.is_dir():
            shutil.copytree(src, dest / rel, symlinks=True)
        elif src.exists():
            dest.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dest / rel)
    for rel in ("artifacts", "reports"):
        (dest / rel).mkdir(parents=True, exist_ok=True)


def compile_tree(src: str | None) -> None:
    """Write the bytecode of the rclverify source tree ``src`` (default: the
    installed package), as ``scripts/setup.sh`` does for the installed one:
    with ``PYTHONDONTWRITEBYTECODE`` set (or a tree never imported), every
    ``doit`` process would otherwise compile each module it imports, about
    0.3 CPU s of a cold run that is no work of the code measured.  Python
    reads the files whatever that variable says."""
    env = dict(os.environ)
    if src:
        env["PYTHONPATH"] = os.pathsep.join([str(Path(src).resolve())] + ([env["PYTHONPATH"]] if env.get("PYTHONPATH") else []))
    subprocess.run([sys.executable, "-c", "import compileall, os, rclverify; "
                    "compileall.compile_dir(os.path.dirname(rclverify.__file__), quiet=1)"],
                   env=env, check=True, capture_output=True)


def case_study(args: argparse.Namespace) -> int:
    """Cold `doit verify` of the case study: CPU seconds and their multiple of the reference loop,
    for this tree (``--src`` or the installed one) and, with ``--compare``, the old one, alternating."""
    trees = {"new": args.src} if not args.compare else {"old": args.compare, "new": args.src}
    base = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="rclverify-casestudy-"))
    if not args.no_compile:
        for src in trees.values():
            compile_tree(src)
    print(f"case study, cold `doit verify`, {os.cpu_count()} CPU(s); "
          + ", ".join(f"{k}: {v or 'installed'}" for k, v in trees.items())
          + ("; bytecode as the trees have it" if args.no_compile else "; each tree's bytecode written first"))
    print(f"{'code':>5} {'run':>3} {'cpu s':>7} {'ref s':>6} {'cpu/ref':>8} {'wall s':>7}  overall")
    ratios: dict[str, list[float]] = {k: [] for k in trees}
    order = list(trees)
    try:
        for k in range(max(1, args.repeat)):
            for name in order:
                root = base / f"{name}{k}"
                if root.exists():
                    shutil.rmtree(root)
                copy_case_study(root)
                ref = reference_cpu()
                r = doit_verify(root, args.jobs, trees[name])
                overall = next((ln.strip() for ln in r.output.splitlines() if "overall" in ln), f"exit {r.rc}")
                if not (root / "reports" / "assurance.json").is_file():
                    print(f"{name:>5} {k:>3}  no report (exit {r.rc}):\n{r.output[-3000:]}")
                    return 1
                ratios[name].append(r.cpu / ref)
                print(f"{name:>5} {k:>3} {r.cpu:>7.1f} {ref:>6.2f} {r.cpu / ref:>8.1f} {r.seconds:>7.1f}  {overall[:60]}",
                      flush=True)
                if not args.keep:
                    shutil.rmtree(root, ignore_errors=True)
            order.reverse()
    finally:
        if not args.keep:
            shutil.rmtree(base, ignore_errors=True)
    med = {name: sorted(v)[(len(v) - 1) // 2] for name, v in ratios.items()}
    for name, m in med.items():
        print(f"median cpu/ref ({name}): {m:.1f}")
    if "old" in med:
        print(f"new/old: {med['new'] / med['old']:.2f} (the issue's aim: at most 0.50)")
    print("cpu s: CPU seconds (user+sys) of doit and its children; ref s: the reference loop (bench/_reference.py) "
          "in this process just before the run; cpu/ref: the figure comparable across machines and loads.")
    return 0


def median_run(runs: list[Run]) -> Run:
    """The run of median CPU time (the lower middle one of an even count)."""
    return sorted(runs, key=lambda r: r.cpu)[(len(runs) - 1) // 2]


def compare(sizes: list[int], args: argparse.Namespace) -> int:
    """Old and new code side by side: for each N, each code on its own copy
    of the same workspace, each run of one code followed by the same run of
    the other (the order swapped from one run to the next, so neither
    always runs on a warmer machine): cold, no-op, edit."""
    pt = has_property_tests() and args.property_tests > 0
    base = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="rclverify-bench-"))
    trees = {"old": args.compare, "new": args.src}
    print(f"pipeline scale, old ({args.compare}) against new ({args.src or 'installed'}), alternating; "
          f"doit{' -n ' + str(args.jobs) if args.jobs > 1 else ''} verify, {os.cpu_count()} CPU(s)")
    header = f"{'nodes':>6} {'code':>4} {'cold s':>7} {'(cpu)':>7} {'MB':>5} {'no-op s':>7} {'(cpu)':>6} {'ran':>3} {'edit s':>6} {'(cpu)':>6} {'MB':>5}"
    print(header)
    print("-" * len(header))
    try:
        for n in sizes:
            roots = {}
            for name in trees:
                roots[name] = base / f"n{n}-{name}"
                if roots[name].exists():
                    shutil.rmtree(roots[name])
                generate(roots[name], n, pt, args.property_tests, args.hoare)
            samples: dict[str, dict[str, list[Run]]] = {"old": {}, "new": {}}
            order = ["old", "new"]
            phases = ["cold"] + ["no-op"] * max(1, args.repeat) + ["edit"] * max(1, args.repeat)
            for phase in phases:
                for name in order:
                    if phase == "edit":
                        edit_one(roots[name], n)
                    r = doit_verify(roots[name], args.jobs, trees[name])
                    if r.rc != 0:
                        print(f"{n:>6} {name:>4}  {phase} run failed (exit {r.rc}):\n{r.output[-3000:]}")
                        return 1
                    samples[name].setdefault(phase, []).append(r)
                order.reverse()
            runs = {name: {phase: median_run(rs) for phase, rs in by.items()} for name, by in samples.items()}
            for name in ("old", "new"):
                print(f"{n:>6} {name:>4} {figures(runs[name]['cold'], runs[name]['no-op'], runs[name]['edit'])}", flush=True)
            o, w = runs["old"], runs["new"]
            print(f"{n:>6} {'new/old':>9} cold {w['cold'].seconds / o['cold'].seconds:.2f} (cpu {w['cold'].cpu / o['cold'].cpu:.2f}), "
                  f"no-op {w['no-op'].seconds / o['no-op'].seconds:.2f} (cpu {w['no-op'].cpu / o['no-op'].cpu:.2f}), "
                  f"edit {w['edit'].seconds / o['edit'].seconds:.2f} (cpu {w['edit'].cpu / o['edit'].cpu:.2f})", flush=True)
    finally:
        if not args.keep:
            shutil.rmtree(base, ignore_errors=True)
    print("ratios below 1.00 mean the new code is faster; wall-clock figures move with the machine's load, "
          "CPU seconds much less.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
