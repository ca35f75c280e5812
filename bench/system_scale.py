"""Issue 51's large system: joins, branches, loops, services and deadlines, on one machine or split over Dask.

Writes the synthetic system of ``bench/pipeline_scale.py`` (node ``N<k>``
reads ``v<k-1>``; every third node also reads ``v<k-3>``: a join, rule R3,
and a branch, R2; every tenth node reads ``v<k+4>``: a loop, R4) and adds:

* **services**: every ``--services``-th node ``N<k>`` calls a service
  ``q<k>`` that its producer ``N<k-1>`` serves (``services( ... calls(out.q<k>,
  in.r<k>) )`` and ``serves(in.q<k>, out.r<k>)``): the client assumes the
  answer is at least 0 and the server guarantees it, within 5 ms of the
  request; each pair is one more loop;
* **deadlines**: every node's second guarantee is timed (``triggered by
  in.<first input> within 10 ms``) and every ``--deadlines``-th node ``N<k>``
  carries a requirement ``D<k>`` with the formal statement ``N<k>.out.v<k>
  >= 0`` and a 100 ms deadline along ``N<k-4> -> ... -> N<k>`` (five hops of
  10 ms: proved, with the worst path searched);
* the evidence of ``pipeline_scale.py``'s default workload: a Hoare triple
  per node over the shared clamp program (``--hoare EVERY``), property tests
  on every tenth node (``--property-tests EVERY``).

For each N it measures a cold ``doit -n JOBS verify``, a no-op re-run and
the peak memory, once with the backend jobs run locally and once per
``--workers`` count on a local Dask cluster (``LocalCluster`` on 127.0.0.1,
one thread per worker process; ``RCLVERIFY_CLUSTER``, docs/scale.md): wall
seconds, CPU seconds of doit and its children, the workers' own CPU
seconds, peak RSS of the largest doit process, and the verdicts (side
conditions discharged, deadlines proved, overall status), which must be
the same in every mode.

Usage::

    python3 bench/system_scale.py                          # N = 1000, local, then 1 and 2 workers
    python3 bench/system_scale.py --sizes 200 --workers 2 -n 2
    python3 bench/system_scale.py --smoke                  # N = 12, local: a few seconds (CI)
    python3 bench/system_scale.py --sizes 200 --workers 0,2 --isolated   # workers as on other machines

``--isolated`` starts the workers with ``RCLVERIFY_CLUSTER_ISOLATED=1``,
each in its own working folder: they do not read the workspace's folder, so
the sources travel to them once and each job's artifacts with it, as on
machines that share no file system (docs/scale.md, "Workers that do not
share the file system"); the ``copy MB`` column is the size of their
copies when the run ends.

The figures are printed, not asserted (the issue's aims: cold within 3
minutes and 2 GiB on 2 cores, a no-op re-run within 2 s).
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import json
import os
import shutil
import sys
import tempfile
from pathlib import Path
from typing import Any, Sequence

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _scratch import describe  # noqa: E402
from pipeline_scale import CLAMP, DODO, doit_verify, evidence, has_property_tests, topology  # noqa: E402

#: Service calls and deadline requirements: every how many nodes (defaults).
SERVICES_EVERY = 25
DEADLINES_EVERY = 100
#: Hops of a deadline's path, each guarantee's time limit and the deadline.
HOPS, HOP_MS, WITHIN_MS = 5, 10, 100


def contract(k: int, producers: list[int], serves: int | None, calls: bool) -> str:
    """RCL text of node ``N<k>``: ``serves`` the client index it answers, ``calls``
    whether it calls its producer's service ``q<k>``."""
    ins = [f"v{p}" for p in producers] or ["e0"]
    first = ins[0]
    inputs = [f"{i} : REAL" for i in ins]
    outputs = [f"v{k} : REAL"]
    assume = [f"0 <= in.{i}" for i in ins]
    guarantees = [f"guarantee( 0 <= out.v{k} )",
                  f"guarantee( in.{first} <= 100 -> out.v{k} <= in.{first} + 1 ) triggered by in.{first} within {HOP_MS} ms"]
    services = []
    if serves is not None:
        inputs.append(f"q{serves} : BOOL")
        outputs.append(f"r{serves} : REAL")
        guarantees.append(f"guarantee( 0 <= out.r{serves} and out.r{serves} <= 10 ) triggered by in.q{serves} within 5 ms")
        services.append(f"bench_msgs/Query q{serves} serves(in.q{serves}, out.r{serves})")
    if calls:
        inputs.append(f"r{k} : REAL")
        outputs.append(f"q{k} : BOOL")
        assume.append(f"0 <= in.r{k}")
        guarantees.append(f"guarantee( out.q{k} )")
        services.append(f"bench_msgs/Query q{k} calls(out.q{k}, in.r{k})")
    lines = [f"// Synthetic node {k} (bench/system_scale.py).", f"node N{k} {{",
             f"  inputs( {', '.join(inputs)} )", f"  outputs( {', '.join(outputs)} )"]
    if services:
        lines.append(f"  services( {', '.join(services)} )")
    lines.append(f"  assume( {' and '.join(assume)} )")
    lines += [f"  {g}" for g in guarantees]
    return "\n".join(lines + ["}", ""])


def generate(root: Path, n: int, *, services: int = SERVICES_EVERY, deadlines: int = DEADLINES_EVERY,
             hoare: int = 1, property_tests: int = 10) -> dict[str, int]:
    """Write the ``n``-node workspace under ``root`` (which must not exist);
    returns its counts: ``services`` (client/server pairs), ``deadlines``."""
    (root / "contracts").mkdir(parents=True)
    (root / "backends" / "hoare").mkdir(parents=True)
    (root / "backends" / "hoare" / "clamp.imp").write_text(CLAMP)
    (root / "dodo.py").write_text(DODO)
    prod = topology(n)
    clients = {k for k in range(1, n) if services and k % services == 0}
    nodes: dict[str, Any] = {}
    impls: list[str] = []
    pt = property_tests > 0 and has_property_tests()
    for k in range(n):
        (root / "contracts" / f"n{k}.rcl").write_text(
            contract(k, prod[k], k + 1 if k + 1 in clients else None, k in clients))
        evidence(nodes, impls, k, prod[k], bool(hoare) and k % hoare == 0,
                 pt and k % property_tests == 0 and k not in clients and k + 1 not in clients)
    if impls:
        (root / "backends" / "property_tests").mkdir(parents=True)
        (root / "backends" / "property_tests" / "clamp.py").write_text("".join(impls))
    reqs = []
    for k in range(HOPS, n):
        if deadlines and k % deadlines == 0:
            reqs.append({"id": f"D{k}", "text": f"N{k}'s output is not negative, within {WITHIN_MS} ms of N{k - HOPS + 1}'s input",
                         "formal": f"N{k}.out.v{k} >= 0",
                         "deadline": {"path": [f"N{j}" for j in range(k - HOPS + 1, k + 1)], "within": f"{WITHIN_MS} ms"}})
    plan = {"name": f"synthetic system of {n} nodes with services and deadlines",
            "contracts": [f"contracts/n{k}.rcl" for k in range(n)], "requirements": reqs, "nodes": nodes}
    (root / "contracts" / "plan.yaml").write_text(yaml.safe_dump(plan, sort_keys=False))
    return {"services": len(clients), "deadlines": len(reqs)}


def verdicts(root: Path) -> dict[str, Any]:
    """What the run decided, from its report: side conditions discharged / all, deadlines
    proved / all, requirements by verdict, obligations by status, the overall status."""
    rep = json.loads((root / "reports" / "assurance.json").read_text())
    sc = rep["side_conditions"]
    dl = [r for r in rep["requirements"] if r.get("deadline")]
    by: dict[str, int] = {}
    for o in rep["obligations"]:
        by[o["status"]] = by.get(o["status"], 0) + 1
    return {"side conditions": f"{sum(s['status'] == 'discharged' for s in sc)}/{len(sc)}",
            "deadlines proved": f"{sum((r['deadline'] or {}).get('verdict') == 'proved' for r in dl)}/{len(dl)}",
            "requirements met": f"{sum(r['verdict'] == 'met' for r in rep['requirements'])}/{len(rep['requirements'])}",
            "obligations": dict(sorted(by.items())), "overall": rep["summary"]["status"]}


class Cluster:
    """A local Dask cluster of ``workers`` single-threaded worker processes on
    127.0.0.1 (none: the jobs run in the doit processes)."""

    def __init__(self, workers: int, isolated: bool = False, folder: Path | None = None) -> None:
        self.workers, self.cluster, self.client = workers, None, None
        self.isolated, self.folder = isolated, folder

    def __enter__(self) -> "Cluster":
        if self.workers:
            import distributed
            if self.isolated:  # the worker processes inherit it: they never run a job in the workspace's folder
                os.environ["RCLVERIFY_CLUSTER_ISOLATED"] = "1"
            extra = {"local_directory": str(self.folder)} if self.folder is not None else {}
            given = dict(os.environ)
            self.cluster = distributed.LocalCluster(n_workers=self.workers, threads_per_worker=1, processes=True,
                                                    dashboard_address=None, host="127.0.0.1", protocol="tcp://",
                                                    **extra)
            # Dask's nanny writes its workers' environment (OMP_NUM_THREADS, MALLOC_TRIM_THRESHOLD_,
            # PYTHONHASHSEED, ...) into this process's: the doit runs timed next must not inherit it
            os.environ.clear()
            os.environ.update(given)
            os.environ.pop("RCLVERIFY_CLUSTER_ISOLATED", None)
            self.client = distributed.Client(self.cluster)
            os.environ["RCLVERIFY_CLUSTER"] = self.cluster.scheduler_address
        return self

    def cpu(self) -> float:
        """The workers' CPU seconds so far (user + system of each worker process)."""
        if self.client is None:
            return 0.0

        def used() -> float:
            import resource
            u = resource.getrusage(resource.RUSAGE_SELF)
            return u.ru_utime + u.ru_stime
        return sum(self.client.run(used).values())

    def working_folders_mb(self) -> float:
        """The size of the workers' working folders (megabytes): the copies of the workspace they run in."""
        if self.folder is None or not self.folder.exists():
            return 0.0
        return sum(p.stat().st_size for p in self.folder.rglob("*") if p.is_file()) / 1e6

    def __exit__(self, *exc: object) -> None:
        os.environ.pop("RCLVERIFY_CLUSTER", None)
        if self.client is not None:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="1000", help="numbers of nodes, comma separated (default 1000)")
    ap.add_argument("--workers", default="0,1,2", help="Dask worker counts to run, 0 = local (default 0,1,2)")
    ap.add_argument("-n", "--jobs", type=int, default=2, help="doit parallel processes (default 2)")
    ap.add_argument("--services", type=int, default=SERVICES_EVERY, metavar="EVERY")
    ap.add_argument("--deadlines", type=int, default=DEADLINES_EVERY, metavar="EVERY")
    ap.add_argument("--hoare", type=int, default=1, metavar="EVERY")
    ap.add_argument("--property-tests", type=int, default=10, metavar="EVERY")
    ap.add_argument("--keep", help="write the workspaces under this directory and keep them")
    ap.add_argument("--isolated", action="store_true", help="workers in their own working folders that never read "
                                                            "the workspace's folder (as on other machines)")
    ap.add_argument("--smoke", action="store_true", help="N = 12, local, no property tests (CI; the cluster "
                                                         "path is tests/app/test_cluster.py's)")
    args = ap.parse_args(argv)
    if args.smoke:
        args.sizes, args.workers, args.property_tests, args.deadlines, args.services = "12", "0", 0, 6, 5
    sizes = [int(x) for x in args.sizes.split(",") if x.strip()]
    workers = [int(x) for x in args.workers.split(",") if x.strip()]
    base = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="rclverify-system-"))
    print(f"system scale: doit -n {args.jobs} verify, {os.cpu_count()} CPU(s); services every {args.services}th "
          f"node, deadlines every {args.deadlines}th, hoare every {args.hoare}th, property tests every "
          f"{args.property_tests}th")
    header = (f"{'nodes':>6} {'svc':>4} {'ddl':>4} {'mode':>9} {'cold s':>7} {'(cpu)':>7} {'wrk cpu':>7} {'MB':>5} "
              f"{'no-op s':>7} {'ran':>3} {'copy MB':>7}  verdicts")
    print(describe(base))
    print(header)
    print("-" * len(header))
    try:
        for n in sizes:
            seen: dict[str, Any] | None = None
            for w in workers:
                root = base / f"n{n}-w{w}"
                if root.exists():
                    shutil.rmtree(root)
                counts = generate(root, n, services=args.services, deadlines=args.deadlines, hoare=args.hoare,
                                  property_tests=args.property_tests)
                folder = base / f"n{n}-w{w}-workers" if w and args.isolated else None
                with Cluster(w, args.isolated, folder) as cl:
                    cold = doit_verify(root, args.jobs)
                    wcpu = cl.cpu()
                    copies_mb = cl.working_folders_mb()
                    if cold.rc != 0:
                        print(f"{n:>6}  cold run failed (exit {cold.rc}):\n{cold.output[-3000:]}")
                        return 1
                    noop = doit_verify(root, args.jobs)
                got = verdicts(root)
                mode = "local" if not w else f"{w} worker" + ("s" if w > 1 else "") + (" (iso)" if args.isolated else "")
                print(f"{n:>6} {counts['services']:>4} {counts['deadlines']:>4} {mode:>9} {cold.seconds:>7.1f} "
                      f"{cold.cpu:>7.1f} {wcpu:>7.1f} {cold.peak_mb:>5.0f} {noop.seconds:>7.2f} {len(noop.ran):>3} "
                      f"{copies_mb:>7.1f}  "
                      f"{json.dumps(got)}", flush=True)
                if seen is not None and got != seen:
                    print(f"{n:>6}  the verdicts differ from the local run's: {seen}")
                    return 1
                seen = got
                # kept until the bench ends: a run timed right after deleting the last one's ~27 files a node
                # would pay for that deletion on some file systems (bench/_scratch.py)
    finally:
        if not args.keep:
            shutil.rmtree(base, ignore_errors=True)
    print("cold/no-op: wall-clock seconds of one `doit verify`; (cpu): CPU seconds of doit and its children; "
          "wrk cpu: the Dask workers' own CPU seconds; MB: peak RSS of the largest doit process; ran: tasks the "
          "no-op run executed (0 expected); copy MB: the workers' copies of the workspace (--isolated).")
    return 0


if __name__ == "__main__":
    sys.exit(main())
