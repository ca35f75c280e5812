"""Backend jobs on a Dask cluster give the evidence of a local run (timing fields aside)."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from importlib.util import find_spec
from pathlib import Path
from typing import Any

import pytest

# the module needs Dask's distributed scheduler; looked up, not imported, while the suite is collected
pytestmark = pytest.mark.skipif(find_spec("distributed") is None, reason="dask.distributed is not installed")

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


@pytest.fixture(scope="module")
def distributed() -> Any:
    """``dask.distributed``, imported when a test of this module first needs it (not when every worker
    collects the suite: about 0.2 CPU s); skips without it."""
    return pytest.importorskip("dask.distributed")


@pytest.fixture(autouse=True)
def _environment_given_back() -> Any:
    """Each test's process environment restored after it: Dask's nanny writes its workers' environment
    (``OMP_NUM_THREADS=1``, ``OPENBLAS_NUM_THREADS=1``, ``MALLOC_TRIM_THRESHOLD_``, ``PYTHONHASHSEED``)
    into the process that starts a ``LocalCluster``, and the tests the same pytest worker runs later,
    and the processes they start, would inherit it."""
    given = dict(os.environ)
    yield
    os.environ.clear()
    os.environ.update(given)


@pytest.fixture(scope="module")
def local(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The workspace verified without a cluster, once for the module: the two cluster tests compare their
    copies' artifacts with its, and only read it."""
    ws = _workspace(tmp_path_factory.mktemp("cluster") / "local")
    r = _verify(ws)
    assert r.returncode == 0, r.stdout + r.stderr
    return ws


def test_evidence_from_a_local_cluster_equals_the_local_run(tmp_path: Path, local: Path, distributed: Any) -> None:
    remote = tmp_path / "remote"
    shutil.copytree(local, remote, ignore=shutil.ignore_patterns("artifacts", "reports", ".doit.db*", ".doit.sqlite*"))
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


def _artifact_files(ws: Path) -> dict[str, list[str]]:
    """Every artifact but the evidence records, caches and locks: path -> its lines, timing lines aside."""
    art = ws / "artifacts"
    skip = ("evidence/", "cache/")
    return {p.relative_to(art).as_posix(): _without_timing_lines(p.read_text(errors="replace"))
            for p in sorted(art.rglob("*"))
            if p.is_file() and not p.relative_to(art).as_posix().startswith(skip) and not p.name.endswith(".lock")}


def test_workers_that_cannot_see_the_workspace_run_in_their_own_copy(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                                    local: Path, distributed: Any) -> None:
    """Workers in their own processes and working folders, told not to read the submitting machine's
    paths (as on other machines): the workspace's sources go to them, the jobs run in their copy, and
    the evidence and every artifact the jobs wrote equal a local run's."""
    remote = tmp_path / "remote"
    shutil.copytree(local, remote, ignore=shutil.ignore_patterns("artifacts", "reports", ".doit.db*", ".doit.sqlite*"))
    folder = tmp_path / "worker-folder"
    monkeypatch.setenv("RCLVERIFY_CLUSTER_ISOLATED", "1")  # the worker processes inherit it
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None,
                                  protocol="tcp://", host="127.0.0.1", local_directory=str(folder)) as cluster:
        r = _verify(remote, "--cluster", cluster.scheduler_address)
        assert r.returncode == 0, r.stdout + r.stderr
        # (Dask removes a worker's folder when the worker closes)
        copies = list(folder.rglob("rclverify-workspaces/*/contracts/plan.yaml"))
        assert len(copies) == 1  # the sources went once, and the jobs ran there
        copy = copies[0].parents[1]
        assert (copy / "artifacts" / "obligations" / "N1.json").is_file()
        assert not list(copy.glob("artifacts/evidence/*.json"))  # the records came back as JSON only
    assert _evidence(remote) == _evidence(local)
    assert _artifact_files(remote) == _artifact_files(local)


def test_a_worker_runs_in_place_only_where_the_sources_are_the_same(tmp_path: Path,
                                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    """A folder at the workspace's path whose backend input differs (a stale copy on a worker's
    machine) is not used: its evidence would be of other files."""
    from rclverify.app import cluster, cluster_files
    ws = _workspace(tmp_path / "ws")
    key = cluster_files.digest(ws)
    assert cluster._in_place(str(ws), "contracts/plan.yaml", key)
    (ws / "backends" / "hoare" / "clamp.imp").write_text(CLAMP.replace("y := 0", "y := 1"))
    assert not cluster._in_place(str(ws), "contracts/plan.yaml", key)
    (ws / "backends" / "hoare" / "clamp.imp").write_text(CLAMP)
    assert cluster._in_place(str(ws), "contracts/plan.yaml", key)
    monkeypatch.setenv("RCLVERIFY_CLUSTER_ISOLATED", "1")
    assert not cluster._in_place(str(ws), "contracts/plan.yaml", key)
    # artifacts and reports are not sources: a run's outputs leave the digest alone
    (ws / "artifacts").mkdir()
    (ws / "artifacts" / "x.json").write_text("{}")
    assert cluster_files.digest(ws) == key


def test_shipped_files_are_checked_and_stay_in_the_worker_folder(tmp_path: Path) -> None:
    from rclverify.app import cluster_files
    ws = _workspace(tmp_path / "ws")
    name, blob = cluster_files.digest(ws), cluster_files.archive(ws)
    with pytest.raises(cluster_files.ShippingError, match="damaged"):
        cluster_files.materialise(tmp_path / "w1", name, blob.replace(b"y := x", b"y := 7"))
    assert not list((tmp_path / "w1" / "rclverify-workspaces").iterdir())  # nothing half-made left
    copy = cluster_files.materialise(tmp_path / "w1", name, blob)
    assert (copy / "backends" / "hoare" / "clamp.imp").read_text() == CLAMP
    with pytest.raises(cluster_files.ShippingError, match="leave"):
        cluster_files.place(copy, {"../escape.txt": b"x"})
    assert not (tmp_path / "w1" / "rclverify-workspaces" / "escape.txt").exists()
