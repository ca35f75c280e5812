"""Every bench script runs (issue 44, "benches run"): each ``bench/*.py``
in its ``--smoke`` mode (small sizes, a few seconds), as its own process,
as CI runs it.  A bench that no longer imports, or raises, fails here;
a part whose peer tool or live service is missing says so and is skipped
by the bench itself (bench/README.md).  The figures are printed, never
asserted: speed is the benches' business, not the tests'.

Each bench runs with a temporary directory of its own and a user cache
(``XDG_CACHE_HOME``) that the benches of one test worker share, never the
user's own: what rclverify keeps there (lark's parser tables, jinja2's
compiled templates, SPIN's built verifiers) is a pure speed-up checked by
its own tests (tests/core/test_startup_cache.py, tests/lang/test_rcl_parser.py),
and a cold one cost every bench process its parser tables again (about
0.3 CPU s each; docs/ci.md, "Round seventeen")."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
#: bench/compose_pacti.py --smoke is run, and its figures checked, by tests/bench/test_bench_compose_pacti.py.
BENCHES = sorted(p.name for p in (REPO / "bench").glob("*.py") if not p.name.startswith("_")
                 and p.name != "compose_pacti.py")
#: The benches that start live services (a ROS 1 master, DDS participants, a WebSocket oracle) or run
#: the whole pipeline several times: run from tests/bench/test_bench_smoke_live.py, so that pytest-xdist's
#: one-file-per-worker distribution (--dist loadfile) gives the two halves to the two workers.
HEAVY = ("monitor_live_dds.py", "monitor_live_rclpy.py", "monitor_live.py", "incremental_equivalence.py",
         "verify_pacti.py", "diagnosis_scale.py", "pipeline_scale.py", "second_solver.py", "manipulator_live.py",
         "verify_under_load.py")


def test_there_are_benches() -> None:
    assert "diagnosis_scale.py" in BENCHES and "pipeline_scale.py" in BENCHES


@pytest.fixture(scope="session")
def bench_cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The user cache (``XDG_CACHE_HOME``) of every bench this worker runs: one directory for the worker's
    session, under its pytest base directory."""
    return tmp_path_factory.mktemp("bench-cache")


@pytest.mark.parametrize("bench", [b for b in BENCHES if b not in HEAVY])
def test_bench_runs_in_smoke_mode(bench: str, tmp_path: Path, bench_cache: Path) -> None:
    run_smoke(bench, tmp_path, bench_cache)


def run_smoke(bench: str, tmp_path: Path, cache: Path) -> str:
    """Run ``bench/<bench> --smoke`` as its own process, ``tmp_path`` its temporary directory and ``cache`` its
    user cache, and check it printed figures and exited 0; returns what it printed."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO / "src")] + (
        [os.environ["PYTHONPATH"]] if os.environ.get("PYTHONPATH") else [])),
           "TMPDIR": str(tmp_path), "XDG_CACHE_HOME": str(cache)}
    p = subprocess.run([sys.executable, str(REPO / "bench" / bench), "--smoke"], cwd=tmp_path, env=env,
                       capture_output=True, text=True, timeout=300)
    out = p.stdout + p.stderr
    assert p.returncode == 0, f"{bench} --smoke exited {p.returncode}:\n{out[-4000:]}"
    assert "Traceback" not in out, out[-4000:]
    assert p.stdout.strip(), f"{bench} --smoke printed no figures"
    return p.stdout
