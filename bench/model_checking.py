"""The Agent's model checking by SPIN: the case study's 39 derived instances and the authors' properties.

In a temporary copy of the case study's Agent (its contract, the plan's
``ajpf`` entry, ``backends/ajpf/jackal.gwen`` and ``backends/ajpf/authors.psl``)
the ``ajpf`` backend exports the 39 guarantee instances plus the 39
instances of the paper's properties (lines 1405-1472) and runs each with
``model_checker: spin``.  Printed: the explored graph's states and
transitions, the seconds to explore it (once), to build the verifier
(once, in an empty cache of its own unless ``--warm``), and per obligation
the verdict and pan's seconds; then the totals.
Figures are printed, not asserted; expect +-25% on a shared machine.

Usage::

    PYTHONPATH=src python3 bench/model_checking.py [--authors-only | --derived-only] [--warm]
    PYTHONPATH=src python3 bench/model_checking.py --smoke    # 2 obligations: a few seconds

Without SPIN (or without the Gwendolen explorer) it says so and skips the
run (exit 0).
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import os
import shutil
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

import yaml

REPO = Path(__file__).resolve().parents[1]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--derived-only", action="store_true", help="only the 39 instances of the guarantees")
    ap.add_argument("--authors-only", action="store_true", help="only backends/ajpf/authors.psl")
    ap.add_argument("--warm", action="store_true", help="use the user's verifier cache (default: build anew)")
    ap.add_argument("--smoke", action="store_true", help="the first derived and the first authors' obligation (CI)")
    args = ap.parse_args()
    import rclverify.backends.model_checking.explore  # noqa: F401  (stage one; an import error fails the bench)
    if shutil.which("spin") is None or shutil.which("gcc") is None:
        print("model checking: skipped: spin or gcc is not installed (apt-get install spin gcc)")
        return 0
    from rclverify.backends.model_checking.ajpf.backend import AjpfBackend
    from rclverify.backends.model_checking import backend as mc
    from rclverify.stages.workspace import Workspace
    os.environ.pop("MCAPL_HOME", None)
    os.environ.pop("AJPF_HOME", None)
    plan = yaml.safe_load((REPO / "contracts/plan.yaml").read_text(encoding="utf-8"))
    entry = next(e for e in plan["nodes"]["Agent"]["evidence"] if e["backend"] == "ajpf")
    entry = {**entry, "model_checker": "spin", "properties": ["backends/ajpf/authors.psl"]}
    with tempfile.TemporaryDirectory(prefix="rclverify-mc-") as tmp:
        root = Path(tmp) / "ws"
        root.mkdir()
        if not args.warm:  # a cold build: the verifier is made in an empty cache of its own
            os.environ["XDG_CACHE_HOME"] = str(Path(tmp) / "cache")
        (root / "contracts").mkdir()
        (root / "backends/ajpf").mkdir(parents=True)
        shutil.copy(REPO / "contracts/remote_inspection.rcl", root / "contracts")
        for f in ("jackal.gwen", "authors.psl"):
            shutil.copy(REPO / "backends/ajpf" / f, root / "backends/ajpf")
        (root / "contracts/plan.yaml").write_text(yaml.safe_dump(
            {"contracts": ["contracts/remote_inspection.rcl"], "nodes": {"Agent": {"evidence": [entry]}}}),
            encoding="utf-8")
        t0 = time.perf_counter()
        target = Workspace(root).target("Agent", 0)
        obligations = AjpfBackend().export(target)
        if args.derived_only:
            obligations = [o for o in obligations if o.guarantee > 0]
        if args.authors_only:
            obligations = [o for o in obligations if o.guarantee == 0]
        if args.smoke:
            obligations = [o for o in obligations if o.guarantee > 0][:1] + [o for o in obligations
                                                                            if o.guarantee == 0][:1]
        export_s = time.perf_counter() - t0
        mc.clear_caches()
        t1 = time.perf_counter()
        verdicts: Counter[str] = Counter()
        first = None
        for o in obligations:
            ev = AjpfBackend().run(o, target)
            d = ev.details
            if first is None:
                first = d
                print(f"graph: {d.get('states')} states, {d.get('transitions')} transitions, "
                      f"complete={d.get('complete')}, depth {d.get('depth')}; explored in {d.get('explore_s')} s; "
                      f"verifier built in {d.get('build_s')} s")
            verdicts[ev.status] += 1
            print(f"{o.id:40s} {ev.status:12s} pan {d.get('pan_s', 0):6.3f} s  "
                  f"stored {d.get('spin_states_stored')}")
        total = time.perf_counter() - t1
    print(f"{len(obligations)} obligations: " + ", ".join(f"{n} {s}" for s, n in sorted(verdicts.items())))
    print(f"export {export_s:.2f} s, run {total:.2f} s (wall clock; graph explored once, verifier built once)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
