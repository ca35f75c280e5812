"""core/numeric.py: numpy and scipy loaded with one OpenBLAS thread, the environment given back."""
from __future__ import annotations

import ast
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[2] / "src" / "rclverify"

#: Prints the process's thread count and whether the variable is in its environment and in a child's.
PROBE = """
import json, os, subprocess, sys
{body}
child = subprocess.run([sys.executable, "-c", "import os; print(os.environ.get('OPENBLAS_NUM_THREADS'))"],
                       capture_output=True, text=True).stdout.strip()
print(json.dumps({{"threads": len(os.listdir("/proc/self/task")), "env": os.environ.get("OPENBLAS_NUM_THREADS"),
                  "child": child}}))
"""


def _probe(body: str, **env: str) -> dict:
    # OpenBLAS also reads GOTO_NUM_THREADS and OMP_NUM_THREADS when its own variable is not set
    full = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS")}
    full.update(env)
    out = subprocess.run([sys.executable, "-c", PROBE.format(body=body)], capture_output=True, text=True,
                         env=full, timeout=120, check=True).stdout
    return json.loads(out.strip().splitlines()[-1])


needs_threads = pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="counts threads in /proc (Linux)")


@needs_threads
def test_numpy_through_rclverify_starts_no_blas_thread_and_leaves_no_variable() -> None:
    plain = _probe("import numpy")
    ours = _probe("import rclverify.traces.table")
    if (os.cpu_count() or 1) > 1:
        assert plain["threads"] > 1, plain  # OpenBLAS's own default: a thread per CPU
    assert ours["threads"] == 1, ours
    assert ours["env"] is None and ours["child"] == "None", ours


@needs_threads
def test_scipy_through_rclverify_starts_no_blas_thread() -> None:
    got = _probe("from rclverify.records.statistics import upper_bound\nassert 0 < upper_bound(2, 50, 0.95) < 1")
    assert got["threads"] == 1 and got["env"] is None and got["child"] == "None", got


@needs_threads
def test_a_value_the_user_set_is_kept() -> None:
    got = _probe("import rclverify.traces.table", OPENBLAS_NUM_THREADS="2")
    assert got["env"] == "2" and got["child"] == "2", got
    if (os.cpu_count() or 1) > 1:
        assert got["threads"] == 2, got


def test_the_scope_restores_the_environment(monkeypatch: pytest.MonkeyPatch) -> None:
    from rclverify.core.numeric import VARIABLE, one_blas_thread
    monkeypatch.delenv(VARIABLE, raising=False)
    with pytest.raises(RuntimeError):
        with one_blas_thread():
            assert os.environ[VARIABLE] == "1"
            raise RuntimeError("a failing import")
    assert VARIABLE not in os.environ
    monkeypatch.setenv(VARIABLE, "4")
    with one_blas_thread():
        assert os.environ[VARIABLE] == "4"
    assert os.environ[VARIABLE] == "4"


def test_no_module_imports_numpy_or_scipy_another_way() -> None:
    """Every import of numpy or scipy (or matplotlib, which loads numpy) goes through core/numeric.py, or
    follows its call in the same function."""
    offenders = []
    for path in sorted(SRC.rglob("*.py")):
        if path.name == "numeric.py" and path.parent.name == "core":
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else (
                [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            for name in names:
                top = name.split(".")[0]
                if top in ("numpy", "scipy"):
                    offenders.append(f"{path.relative_to(SRC)}:{node.lineno}: {name}")
                if top == "matplotlib" and "import_numpy()" not in path.read_text(encoding="utf-8"):
                    offenders.append(f"{path.relative_to(SRC)}:{node.lineno}: {name} without import_numpy()")
    assert not offenders, offenders
