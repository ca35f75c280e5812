"""Every bench starts: ``python3 bench/X.py --help`` exits 0 with its usage, run by a Python without
rclverify's dependencies (Debian's own ``python3`` where there is one), as a user reading bench/README.md
would first run it.  A bench needing a package the interpreter lacks runs again under the project's
``.venv`` (bench/_venv.py) before it imports one; a helper run as a program of another bench answers
``--help`` with its command line instead of failing on its missing arguments."""
from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[2] / "bench"
#: the benches a user can start: every script with a command line of its own
SCRIPTS = sorted(p for p in BENCH.glob("*.py") if '__name__ == "__main__"' in p.read_text())
#: a Python without the project's dependencies where the machine has one
BARE = shutil.which("python3", path="/usr/bin") or sys.executable


def test_the_benches_are_found() -> None:
    assert len(SCRIPTS) > 40 and BENCH / "_stages.py" in SCRIPTS and BENCH / "monitor_peers.py" in SCRIPTS


@pytest.mark.parametrize("script", SCRIPTS, ids=[p.name for p in SCRIPTS])
def test_a_bench_answers_help(script: Path) -> None:
    p = subprocess.run([BARE, str(script), "--help"], capture_output=True, text=True, timeout=120, cwd=BENCH.parent)
    assert p.returncode == 0, (script.name, p.stdout[-2000:], p.stderr[-2000:])
    assert "usage" in (p.stdout + p.stderr).lower(), (script.name, p.stdout[-2000:])
