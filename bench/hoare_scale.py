"""CPU of the ``hoare`` backend's export and run over a synthetic system, in one process.

Calls the pipeline's stage functions directly, as one doit process does:
:func:`rclverify.app.pipeline.stage_export` for every node, then
:func:`rclverify.app.pipeline.stage_run` for every exported ``hoare`` obligation
(the other backends' obligations are exported but not run).  The workspace is
the one of ``bench/pipeline_scale.py`` (N nodes, each with a ``hoare`` entry
over one shared clamp program, two guarantees, so 2N triples), written to a
temporary directory unless ``--workspace`` names an existing one (its
artifacts are overwritten).

Prints, per stage, the CPU seconds of this process (``time.process_time``,
less disturbed by other work on a shared machine than wall-clock time) and the
wall-clock seconds, and the process's peak resident memory.  The contracts are loaded and type-checked before the
clock starts (doit does that once per process too).  ``--profile FILE`` writes
a cProfile of both stages (profiling inflates the times).  The figures are
printed, not asserted.

Usage::

    python bench/hoare_scale.py --nodes 1000
    python bench/hoare_scale.py --workspace DIR --profile hoare.prof
    python bench/hoare_scale.py --smoke                 # 3 nodes: a few seconds
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import cProfile
import resource
import shutil
import sys
import tempfile
import time
from pathlib import Path
from typing import Callable, Sequence

sys.path.insert(0, str(Path(__file__).resolve().parent))

from pipeline_scale import generate  # noqa: E402  (a sibling bench script)

from rclverify.app.pipeline import Workspace, stage_export, stage_run  # noqa: E402


def timed(fn: Callable[[], int]) -> tuple[int, float, float]:
    """``(fn(), CPU seconds, wall seconds)``."""
    c0, w0 = time.process_time(), time.perf_counter()
    n = fn()
    return n, time.process_time() - c0, time.perf_counter() - w0


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nodes", type=int, default=1000, help="nodes of the generated system (default 1000)")
    ap.add_argument("--workspace", help="an existing workspace to use instead of generating one")
    ap.add_argument("--profile", help="write a cProfile of the export and run stages to this file")
    ap.add_argument("--smoke", action="store_true", help="3 nodes only: a few seconds (CI)")
    args = ap.parse_args(argv)
    if args.smoke:
        args.nodes = 3
    tmp = None
    if args.workspace:
        root = Path(args.workspace)
    else:
        tmp = Path(tempfile.mkdtemp(prefix="rclverify-hoare-"))
        root = tmp / "ws"
        generate(root, args.nodes, property_tests=False)
    try:
        ws = Workspace(root)
        nodes = ws.node_names()  # loads and checks the contracts and the plan
        hoare: list[tuple[str, str]] = []
        prof = cProfile.Profile() if args.profile else None

        def export() -> int:
            for node in nodes:
                hoare.extend((node, o.id) for o in stage_export(ws, node) if o.backend == "hoare")
            return len(nodes)

        def run() -> int:
            for node, oid in hoare:
                stage_run(ws, node, oid)
            return len(hoare)

        if prof is not None:
            prof.enable()
        n_nodes, cpu_e, wall_e = timed(export)
        n_runs, cpu_r, wall_r = timed(run)
        if prof is not None:
            prof.disable()
            prof.dump_stats(args.profile)
        print(f"hoare scale: {n_nodes} nodes, {n_runs} hoare obligations")
        print(f"{'stage':<8} {'calls':>6} {'cpu s':>7} {'wall s':>7}")
        print(f"{'export':<8} {n_nodes:>6} {cpu_e:>7.2f} {wall_e:>7.2f}")
        print(f"{'run':<8} {n_runs:>6} {cpu_r:>7.2f} {wall_r:>7.2f}")
        print(f"{'total':<8} {'':>6} {cpu_e + cpu_r:>7.2f} {wall_e + wall_r:>7.2f}")
        print(f"peak resident memory of this process: {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB")
    finally:
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
