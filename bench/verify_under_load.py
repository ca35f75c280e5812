"""``rclverify verify`` of the bundled case study run several times, each
cold (a fresh copy: no artifacts, no cache), with both cores kept busy by
CPU-burning processes (docs/decisions.md, "Results never depend on the
wall clock"): are all the verdicts the same every time?

A run's verdicts are every health finding's status (realizability
included) with its model, every side condition's, obligation's and
evidence's status, every requirement's verdict, every derived property's
status, the summary's status and whether ``--strict`` would pass
(``reports/assurance.json``).  Prints one line per run (wall and CPU
seconds, the number of verdicts, the realizability findings, how many
findings say the machine cut them short) and whether every run's verdicts
equal the first's; the verdicts that differ are named.  Asserts nothing;
exits 0.

``--runs N`` (default 5), ``--burners B`` (default 2, the machine's two
cores), ``--src SRC`` (the rclverify source tree to run); ``--smoke`` (the test suite's): a one-node workspace written on the
spot, two runs beside one burner.
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator, Sequence

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench"))
from pipeline_scale import copy_case_study  # noqa: E402

#: The smoke run's workspace: one node whose realizability is decided (its guarantees conflict when
#: ``in.on``), a quantifier over an input sequence in its assumption.
SMOKE_RCL = """
node Clamp {
  inputs( xs : seq(INTEGER), on : BOOL )
  outputs( y : INTEGER )
  assume( forall(x in in.xs | 0 <= x) )
  guarantee( in.on -> exists(x in in.xs | out.y == x) )
  guarantee( out.y <= 10 )
}
"""
SMOKE_PLAN = "name: under load\ncontracts:\n  - contracts/clamp.rcl\nconnections: []\nenvironment: {}\n"
SMOKE_DODO = ("from pathlib import Path\nfrom rclverify.app.tasks import build_tasks, doit_config\n"
              "DOIT_CONFIG = doit_config()\nglobals().update(build_tasks(Path(__file__).parent))\n")


@contextmanager
def burning(n: int) -> Iterator[None]:
    """``n`` processes each spinning one core for the duration of the block (killed at its end)."""
    procs = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(n)]
    try:
        yield
    finally:
        for p in procs:
            p.kill()
        for p in procs:
            p.wait()


def write_smoke(dest: Path) -> None:
    (dest / "contracts").mkdir(parents=True)
    (dest / "contracts" / "clamp.rcl").write_text(SMOKE_RCL)
    (dest / "contracts" / "plan.yaml").write_text(SMOKE_PLAN)
    (dest / "dodo.py").write_text(SMOKE_DODO)


def verdicts(ws: Path) -> dict[str, str]:
    """Every verdict of the report ``ws/reports/assurance.json``: a key naming it -> its verdict text."""
    rep = json.loads((ws / "reports" / "assurance.json").read_text())
    out: dict[str, str] = {}
    for f in rep.get("findings", []):
        out[f"finding {f['id']}"] = f"{f.get('status')} {json.dumps(f.get('model'), sort_keys=True)}"
    for s in rep.get("side_conditions", []):
        out[f"side condition {s['id']}"] = f"{s.get('status')} {json.dumps(s.get('model'), sort_keys=True)}"
    for o in rep.get("obligations", []):
        out[f"obligation {o['id']}"] = str(o.get("status"))
    for e in rep.get("evidence", []):
        out[f"evidence {e['obligation']} {e.get('backend')}"] = str(e.get("status"))
    for r in rep.get("requirements", []):
        out[f"requirement {r['id']}"] = f"{r.get('status')} {r.get('verdict')}"
    for d in rep.get("derived_properties", []):
        out[f"derived {d.get('node')} {d.get('property')}"] = str(d.get("status"))
    out["summary"] = str(rep.get("summary", {}).get("status"))
    out["strict_ok"] = str(rep.get("meta", {}).get("strict_ok"))
    return out


def one_run(make: Any, base: Path, k: int, src: Path) -> tuple[dict[str, str], float, float, int]:
    """One cold ``rclverify verify`` of a fresh workspace ``make`` writes, with the rclverify source tree
    ``src``: (verdicts, wall s, CPU s, exit status)."""
    ws = base / f"run{k}"
    make(ws)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(src)] + (
        [os.environ["PYTHONPATH"]] if os.environ.get("PYTHONPATH") else []))}
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "rclverify.cli.commands", "verify", "-w", str(ws)], env=env,
                       capture_output=True, text=True, timeout=3600)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if not (ws / "reports" / "assurance.json").exists():
        print(f"run {k}: no report (exit {p.returncode}): {(p.stdout + p.stderr).strip()[-600:]}", flush=True)
        return {}, wall, cpu, p.returncode
    return verdicts(ws), wall, cpu, p.returncode


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=5, help="cold runs (default 5)")
    ap.add_argument("--burners", type=int, default=2, help="CPU-burning processes beside the runs (default 2)")
    ap.add_argument("--smoke", action="store_true", help="CI: a one-node workspace, two runs, one burner")
    ap.add_argument("--src", metavar="SRC", default=str(ROOT / "src"),
                    help="the rclverify source tree to run (default: this checkout's src/)")
    args = ap.parse_args(argv)
    runs, burners = (2, 1) if args.smoke else (args.runs, args.burners)
    make = write_smoke if args.smoke else copy_case_study
    what = "a one-node workspace" if args.smoke else "the case study"
    print(f"`rclverify verify` of {what}, {runs} cold runs beside {burners} CPU burner(s), "
          f"{os.cpu_count()} CPU(s)", flush=True)
    first: dict[str, str] | None = None
    differ: set[str] = set()
    same = 0
    with tempfile.TemporaryDirectory(prefix="rclverify-underload-") as d, burning(burners):
        for k in range(1, runs + 1):
            got, wall, cpu, rc = one_run(make, Path(d), k, Path(args.src).resolve())
            real = {key: v.split(" ")[0] for key, v in got.items() if key.startswith("finding ") and key.endswith(".realizable")}
            cut = sum(1 for v in got.values() if "inconclusive" in v)
            print(f"run {k}: exit {rc}, {wall:.1f} s wall, {cpu:.1f} s CPU, {len(got)} verdicts, "
                  f"realizability {json.dumps(real, sort_keys=True)}, {cut} inconclusive", flush=True)
            if first is None:
                first = got
            if got and got == first:
                same += 1
            differ |= {key for key in set(first) | set(got) if first.get(key) != got.get(key)}
    print(f"identical verdicts: {same} of {runs} runs" + ("" if not differ else
          "; differing: " + ", ".join(sorted(differ)[:20])), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
