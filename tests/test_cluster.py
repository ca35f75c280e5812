"""Backend jobs on a Dask cluster give the evidence of a local run (timing fields aside)."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

distributed = pytest.importorskip("dask.distributed")

CLAMP = """\
var x, z : REAL;
var y : REAL;

IF (x < 0) THEN
   y := 0
ELSE
   y := x
"""

# N1's second guarantee does not hold for the clamp (y == x, not x + 1): a
# failed obligation with a counterexample, so that more than "discharged" is compared.
RCL = """\
node N0 {
  inputs( e0 : REAL )
  outputs( v0 : REAL )
  assume( 0 <= in.e0 )
  guarantee( 0 <= out.v0 )
}
node N1 {
  inputs( v0 : REAL )
  outputs( v1 : REAL )
  assume( 0 <= in.v0 )
  guarantee( 0 <= out.v1 )
  guarantee( out.v1 >= in.v0 + 1 )
}
"""

PLAN = """\
name: cluster test
contracts: [contracts/system.rcl]
nodes:
  N0:
    evidence:
      - {backend: hoare, program: backends/hoare/clamp.imp, binding: {in.e0: x, out.v0: y}}
  N1:
    evidence:
      - {backend: hoare, program: backends/hoare/clamp.imp, binding: {in.v0: x, out.v1: y}}
      - {backend: review, record: backends/review/n1.yaml}
"""

TIMING = ("started", "duration_s", "record_sha256")  # the seal covers the timing fields too


def _workspace(path: Path) -> Path:
    (path / "contracts").mkdir(parents=True)
    (path / "backends" / "hoare").mkdir(parents=True)
    (path / "contracts" / "system.rcl").write_text(RCL)
    (path / "contracts" / "plan.yaml").write_text(PLAN)
    (path / "backends" / "hoare" / "clamp.imp").write_text(CLAMP)
    # a review record not filled in yet: its two obligations are pending
    from rclverify.backends.review.blank import blank_record
    from rclverify.lang.typecheck import load
    (path / "backends" / "review").mkdir(parents=True)
    node = load([path / "contracts" / "system.rcl"]).nodes["N1"]
    (path / "backends" / "review" / "n1.yaml").write_text(blank_record(node, path))
    return path


def _verify(ws: Path, *extra: str) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k != "RCLVERIFY_CLUSTER"}
    return subprocess.run([sys.executable, "-m", "rclverify.cli.commands", "verify", "-w", str(ws), *extra],
                          capture_output=True, text=True, timeout=300, env=env)


def _evidence(ws: Path) -> dict[str, dict]:
    out = {}
    for p in sorted((ws / "artifacts" / "evidence").glob("*.json")):
        record = json.loads(p.read_text())
        out[p.name] = {k: v for k, v in record.items() if k not in TIMING}
    return out


def _without_timing_lines(text: str) -> list[str]:
    return [line for line in text.splitlines() if not any(f'"{k}"' in line for k in TIMING)]


def test_evidence_from_a_local_cluster_equals_the_local_run(tmp_path: Path) -> None:
    local = _workspace(tmp_path / "local")
    r = _verify(local)
    assert r.returncode == 0, r.stdout + r.stderr
    remote = tmp_path / "remote"
    shutil.copytree(tmp_path / "local", remote, ignore=shutil.ignore_patterns("artifacts", "reports", ".doit.db*", ".doit.sqlite*"))
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None, protocol="tcp://",
                                  host="127.0.0.1") as cluster:
        r = _verify(remote, "--cluster", cluster.scheduler_address)
        assert r.returncode == 0, r.stdout + r.stderr
    # the jobs ran on the cluster's worker (a thread of this process): it loaded the copy
    from rclverify.app import cluster as rc
    assert any(key[0] == str(remote.resolve()) for key in rc._WORKER_WORKSPACES)
    got, want = _evidence(remote), _evidence(local)
    assert set(got) == set(want) and len(want) == 5
    assert got == want
    statuses = sorted(e["status"] for e in want.values())
    assert statuses == ["discharged", "discharged", "failed", "pending", "pending"]
    # byte for byte, apart from the two timing lines
    for name in want:
        a = (local / "artifacts" / "evidence" / name).read_text()
        b = (remote / "artifacts" / "evidence" / name).read_text()
        assert _without_timing_lines(a) == _without_timing_lines(b), name


def test_unreachable_cluster_fails_the_job_with_one_message(tmp_path: Path) -> None:
    ws = _workspace(tmp_path / "ws")
    env = {**os.environ, "RCLVERIFY_CLUSTER": "tcp://127.0.0.1:9"}
    code = ("import rclverify.app.cluster as c; c.CONNECT_TIMEOUT_S = 2; "
            "from rclverify.cli.commands import main; raise SystemExit(main(['verify', '-w', %r]))" % str(ws))
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, env=env)
    assert r.returncode != 0
    assert "cannot reach the Dask scheduler at tcp://127.0.0.1:9" in r.stdout + r.stderr
    assert "Traceback" not in r.stdout + r.stderr
    assert not list((ws / "artifacts" / "evidence").glob("*.json"))
