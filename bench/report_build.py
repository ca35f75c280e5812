"""The report built from a verified workspace: CPU seconds of ``build_report`` and of the renderers.

Writes the synthetic system of ``bench/pipeline_scale.py`` (N nodes, a
Hoare triple on every ``--hoare``-th node), verifies it once with
``doit verify``, then times in fresh processes (``--repeat`` each, the
median printed) the report's passes (``rclverify.report.build.build_report``)
and its renderers (JSON, Markdown, SARIF, JUnit; the HTML page waits on
Graphviz and is left out).  With ``--compare OLD_SRC`` the same workspace is
reported by the older source tree too, alternately, and old, new and
new/old are printed; the figures are printed, never asserted.

Usage::

    PYTHONPATH=src python3 bench/report_build.py --sizes 100 500 --compare /path/to/old/src
    PYTHONPATH=src python3 bench/report_build.py --smoke     # N = 4, one repeat
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Sequence

sys.path.insert(0, str(Path(__file__).resolve().parent))
from pipeline_scale import doit_verify, generate  # noqa: E402  (the bench folder is not a package)

#: Run in a fresh process on the workspace in argv[1]: CPU seconds of the build and of the renderers.
PROBE = """
import json, sys, time
from pathlib import Path
from rclverify.stages.workspace import Workspace
from rclverify.report.build import build_report
from rclverify.report.render import render_json, render_markdown
from rclverify.report.sarif import render_sarif
from rclverify.report.junit import render_junit
ws = Workspace(Path(sys.argv[1]))
ws.checked, ws.model, ws.plan  # loaded before the clock starts: the report reads them, it does not make them
t0 = time.process_time()
report = build_report(ws)
t1 = time.process_time()
texts = [render_json(report), render_markdown(report), render_sarif(report), render_junit(report)]
t2 = time.process_time()
print(json.dumps({"build": t1 - t0, "render": t2 - t1, "json_bytes": len(texts[0])}))
"""


def probe(root: Path, src: str) -> dict[str, float]:
    """One fresh process with ``src`` first on ``PYTHONPATH``: its figures (CPU seconds)."""
    env = {**os.environ, "PYTHONPATH": src}
    p = subprocess.run([sys.executable, "-c", PROBE, str(root)], capture_output=True, text=True, env=env, check=False)
    if p.returncode:
        raise SystemExit(f"report probe failed with {src}:\n{p.stderr[-3000:]}")
    return dict(json.loads(p.stdout.strip().splitlines()[-1]))


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[100, 500])
    ap.add_argument("--hoare", type=int, default=10, help="a Hoare triple on every EVERY-th node (default 10)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--compare", metavar="OLD_SRC", help="an older source tree to report the same workspaces with")
    ap.add_argument("--smoke", action="store_true", help="N = 4, one repeat")
    args = ap.parse_args(argv)
    if args.smoke:
        args.sizes, args.repeat = [4], 1
    new = str(Path(__file__).resolve().parents[1] / "src")
    trees = [("new", new)] + ([("old", str(Path(args.compare).resolve()))] if args.compare else [])
    print(f"{'N':>5} {'tree':>4} {'build CPU s':>12} {'render CPU s':>13} {'JSON bytes':>11}")
    with tempfile.TemporaryDirectory() as tmp:
        for n in args.sizes:
            root = Path(tmp) / f"n{n}"
            generate(root, n, property_tests=False, hoare_every=args.hoare)
            run = doit_verify(root, 1, new)
            if not (root / "reports" / "assurance.json").is_file():
                print(f"{n:>5} no report (exit {run.rc}):\n{run.output[-3000:]}")
                return 1
            got: dict[str, list[dict[str, float]]] = {name: [] for name, _ in trees}
            for _ in range(args.repeat):  # alternately, so that the machine's load falls on both alike
                for name, src in trees:
                    got[name].append(probe(root, src))
            med = {name: {k: statistics.median(r[k] for r in rows) for k in rows[0]} for name, rows in got.items()}
            for name, m in med.items():
                print(f"{n:>5} {name:>4} {m['build']:>12.3f} {m['render']:>13.3f} {int(m['json_bytes']):>11}")
            if "old" in med:
                print(f"{n:>5} new/old build {med['new']['build'] / med['old']['build']:.2f}, "
                      f"render {med['new']['render'] / med['old']['render']:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
