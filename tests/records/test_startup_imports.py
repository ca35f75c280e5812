"""What a process of rclverify imports before it does any work (issue 67: the suite's time).

Every ``doit verify``, ``rclverify report``, ``bundle``, ``status`` and ``explain`` process imports the
command line, the doit tasks and the report's builder.  The heavy optional libraries are imported
where they are used, so a process that does not need them does not pay for them: ``scipy.stats``
(about 0.75 CPU s; only a statistical target's bound needs it, records/statistics.py), Hypothesis
(property tests), networkx (the worst-path search), cvc5 (the second solver), Dask (the cluster),
numpy (monitoring).  Measured with ``python3 -X importtime``: the import of ``scipy.stats`` at the
top of records/statistics.py made every report-building process about 0.6 CPU s slower.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

SRC = Path(__file__).resolve().parents[2] / "src"

#: The modules every command and every doit run of a workspace imports.
ENTRY = ("rclverify.cli.commands", "rclverify.app.tasks", "rclverify.app.pipeline", "rclverify.report.build")
#: Libraries imported only where they are used.
DEFERRED = ("scipy", "hypothesis", "networkx", "cvc5", "dask", "distributed", "numpy", "pandas")

PROBE = """
import importlib, json, sys
for name in sys.argv[1].split(","):
    importlib.import_module(name)
print(json.dumps(sorted({m.split(".")[0] for m in sys.modules})))
"""


def test_the_entry_modules_import_no_heavy_library_they_do_not_need() -> None:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(SRC)] + (
        [os.environ["PYTHONPATH"]] if os.environ.get("PYTHONPATH") else []))}
    r = subprocess.run([sys.executable, "-c", PROBE, ",".join(ENTRY)], env=env, capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0, r.stderr
    loaded = set(json.loads(r.stdout))
    assert {"rclverify", "z3"} <= loaded, loaded  # the probe did import the entry modules
    assert not loaded & set(DEFERRED), sorted(loaded & set(DEFERRED))


def test_a_bound_still_imports_scipy_when_it_needs_it() -> None:
    """The deferred import is there when a bound is computed: a Clopper-Pearson upper bound with
    violations (the closed form covers only k = 0) is scipy's Beta quantile."""
    from rclverify.records.statistics import upper_bound
    # 1 violation in 10 runs at 95 %: the 0.95 quantile of Beta(2, 9), about 0.3942
    assert abs(upper_bound(1, 10, 0.95) - 0.39416) < 1e-4


def test_a_pipeline_run_without_recorded_runs_loads_no_numpy(tmp_path: Path) -> None:
    """The temporal requirements' stage digests the plan's recorded runs (traces/files.py) without
    loading the monitors, and with them numpy (about 70 ms of every small pipeline process): a run
    of a fresh ``rclverify init`` workspace, which records none, does not load numpy, nor Dask or
    scipy; it does load z3 and cvc5 (the second solver) and decides its requirement."""
    ws = tmp_path / "ws"
    env = {**os.environ, "RCLVERIFY_JOBS": "1", "PYTHONPATH": os.pathsep.join([str(SRC)] + (
        [os.environ["PYTHONPATH"]] if os.environ.get("PYTHONPATH") else []))}
    init = subprocess.run([sys.executable, "-m", "rclverify.cli.commands", "init", str(ws)], env=env,
                          capture_output=True, text=True, timeout=120)
    assert init.returncode == 0, init.stderr
    probe = ("import json, runpy, sys\n"
             "try:\n    sys.argv = ['doit', 'verify']; runpy.run_module('doit', run_name='__main__')\n"
             "except SystemExit as e:\n    code = e.code\n"
             "print(json.dumps([code, sorted({m.split('.')[0] for m in sys.modules})]))\n")
    r = subprocess.run([sys.executable, "-c", probe], cwd=ws, env=env, capture_output=True, text=True, timeout=300)
    code, loaded = json.loads(r.stdout.strip().splitlines()[-1])
    assert code in (0, None), r.stdout + r.stderr
    assert {"z3", "cvc5", "doit"} <= set(loaded), loaded
    assert not set(loaded) & {"numpy", "scipy", "dask", "distributed", "pandas"}, loaded
    report = json.loads((ws / "reports" / "assurance.json").read_text(encoding="utf-8"))
    assert report["requirements"] and all(r["status"] for r in report["requirements"])
