"""A plan path is resolved again on every run: a symbolic link the plan names,
retargeted outside the workspace after a verified run, is refused by the
incremental run with the clean run's located error and exit code
(docs/integrity.md, "Every plan path is resolved again on every run")."""
from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from _restore import restored

RCL = """node Echo {
  inputs( r : REAL )
  outputs( y : REAL )
  topics( std_msgs/Float64 r matches(in.r), std_msgs/Float64 out matches(out.y) )
  assume( in.r >= 0 )
  guarantee( out.y == in.r )
}
"""
PLAN = """contracts: [contracts/echo.rcl]
nodes:
  Echo:
    evidence:
      - backend: monitors
        traces: [traces/run.jsonl]
"""


def _log(values: list[float]) -> str:
    rows = []
    for k, v in enumerate(values):
        rows += [{"topic": "r", "time": float(k), "data": v}, {"topic": "out", "time": k + 0.01, "data": v}]
    return "".join(json.dumps(r) + "\n" for r in rows)


def _verify(ws: Path) -> tuple[int, list[str]]:
    """``rclverify verify --strict`` in a process of its own (as a user runs it):
    its exit code and the lines that say ``error:``."""
    p = subprocess.run([sys.executable, "-m", "rclverify.cli.commands", "verify", "-w", str(ws), "--strict"],
                       capture_output=True, text=True, timeout=300)
    said = (p.stdout + p.stderr).splitlines()
    assert "Traceback" not in p.stdout + p.stderr
    return p.returncode, [line for line in said if "error:" in line]


def _workspace(tmp_path: Path) -> tuple[Path, Path]:
    ws, outside = tmp_path / "ws", tmp_path / "outside"
    (ws / "contracts").mkdir(parents=True)
    (ws / "traces").mkdir()
    outside.mkdir()
    (ws / "contracts" / "echo.rcl").write_text(RCL, encoding="utf-8")
    (ws / "contracts" / "plan.yaml").write_text(PLAN, encoding="utf-8")
    (ws / "traces" / "good.jsonl").write_text(_log([1.0, 2.0]), encoding="utf-8")
    (ws / "traces" / "other.jsonl").write_text(_log([3.0]), encoding="utf-8")
    (outside / "secret.jsonl").write_text(_log([1.0, 2.0, 4.0]), encoding="utf-8")
    (ws / "traces" / "run.jsonl").symlink_to("good.jsonl")
    return ws, outside


def _retarget(link: Path, target: Path | str) -> None:
    link.unlink()
    link.symlink_to(target)


@pytest.fixture(scope="module")
def verified(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, tuple[int, list[str]]]:
    """The workspace verified once for the module, its link inside: ``(workspace, the folder outside it, the
    run's exit code and error lines)``.  Each test retargets the link in place and puts the workspace back
    (tests/_restore.py), so that its next run is the incremental one a user's edit gets."""
    ws, outside = _workspace(tmp_path_factory.mktemp("paths"))
    return ws, outside, _verify(ws)


def test_a_trace_link_retargeted_outside_is_refused_as_by_a_clean_run(
        tmp_path: Path, verified: tuple[Path, Path, tuple[int, list[str]]]) -> None:
    with restored(verified[0], tmp_path / "before") as ws:
        _retargeted_outside(ws, verified[1], verified[2], tmp_path)


def _retargeted_outside(ws: Path, outside: Path, first: tuple[int, list[str]], tmp_path: Path) -> None:
    assert first == (0, [])  # control: inside the workspace, the run is discharged
    records = {p.name: p.read_bytes() for p in (ws / "artifacts" / "evidence").glob("*.json")}
    _retarget(ws / "traces" / "run.jsonl", outside / "secret.jsonl")
    clean = tmp_path / "clean"
    shutil.copytree(ws, clean, symlinks=True, ignore=shutil.ignore_patterns("artifacts", "reports", ".doit*"))
    rc, errors = _verify(clean)
    assert rc == 1 and errors == [f"contracts/plan.yaml:6:18: error: path 'traces/run.jsonl' resolves to "
                                  f"{(outside / 'secret.jsonl').resolve()}, outside the workspace (through a symbolic "
                                  "link); every file the plan names must lie inside the workspace (so the assessor's "
                                  "bundle contains it)"]
    assert _verify(ws) == (rc, errors)  # the incremental run: the same refusal, nothing read from outside
    assert records and records == {p.name: p.read_bytes() for p in (ws / "artifacts" / "evidence").glob("*.json")}


def test_a_link_retargeted_inside_the_workspace_is_verified_again(
        tmp_path: Path, verified: tuple[Path, Path, tuple[int, list[str]]]) -> None:
    with restored(verified[0], tmp_path / "before") as ws:
        _retargeted_inside(ws, verified[2])


def _retargeted_inside(ws: Path, first: tuple[int, list[str]]) -> None:
    assert first == (0, [])
    _retarget(ws / "traces" / "run.jsonl", "other.jsonl")  # control: still inside, so no error
    assert _verify(ws) == (0, [])
    report = json.loads((ws / "reports" / "assurance.json").read_text(encoding="utf-8"))
    assert {e["status"] for e in report["evidence"]} == {"discharged"}
