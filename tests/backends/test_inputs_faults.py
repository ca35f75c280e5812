"""Faults end in one plain or located line and exit 1, never a traceback, with
the previous reports and evidence untouched (issue 20): a read-only
``reports/``, a full disk, a missing workspace or plan; reports readable by
others; one run at a time per workspace (two real processes)."""
from __future__ import annotations

import contextlib
import hashlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Iterator

import pytest

from _restore import restored
from rclverify.cli.commands import main
from rclverify.records.published import published_mode, write_published

SRC = Path(__file__).resolve().parents[2] / "src"
ENV = {**os.environ, "PYTHONPATH": str(SRC), "RCLVERIFY_NO_WAIT": ""}
RCL = "contracts/sensor.rcl"


def run(ws: Path, *argv: str, env: dict[str, str] | None = None, timeout: float = 120) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", *argv], cwd=ws, env=env or ENV, capture_output=True, text=True,
                          timeout=timeout)


@pytest.fixture()
def fresh(tmp_path: Path) -> Path:
    """A new `rclverify init` workspace, not verified yet."""
    root = tmp_path / "ws"
    assert main(["init", str(root)]) == 0
    return root


@pytest.fixture(scope="module")
def verified(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A verified `rclverify init` workspace, made once for the module."""
    root = tmp_path_factory.mktemp("verified") / "ws"
    assert main(["init", str(root)]) == 0
    r = run(root, "rclverify.cli.commands", "verify")
    assert r.returncode == 0, r.stdout + r.stderr
    return root


@pytest.fixture()
def ws(verified: Path, tmp_path: Path) -> Iterator[Path]:
    """The module's verified workspace, put back as verified after the test (tests/_restore.py: in place,
    since doit's state names its files by absolute path and a copy would run every task again)."""
    with restored(verified, tmp_path / "before") as root:
        yield root


def edit_contract(ws: Path, k: int) -> None:
    """Change Sensor's second guarantee (the report must be written again)."""
    p = ws / RCL
    text = p.read_text(encoding="utf-8")
    p.write_text(text.replace("out.sensor_value <= in.reading )", f"out.sensor_value <= in.reading + {k} - {k} )"),
                 encoding="utf-8")


def digests(root: Path, *dirs: str) -> dict[str, str]:
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
            for d in dirs for p in sorted((root / d).rglob("*")) if p.is_file()}


def _mount(*argv: str) -> None:
    subprocess.run(["mount", *argv], check=True, capture_output=True, timeout=30)


@contextlib.contextmanager
def read_only(directory: Path) -> Iterator[None]:
    """``directory`` read-only: mode 0555 for an ordinary user; for root (whom
    modes do not stop) a read-only bind mount of the directory on itself."""
    if os.geteuid() != 0:
        directory.chmod(0o555)
        try:
            yield
        finally:
            directory.chmod(0o755)
        return
    try:
        _mount("--bind", str(directory), str(directory))
    except (OSError, subprocess.CalledProcessError) as exc:
        pytest.skip(f"root without permission to mount (needed to make a directory read-only for root): {exc}")
    try:
        _mount("-o", "remount,ro,bind", str(directory))
        yield
    finally:
        subprocess.run(["umount", str(directory)], check=True, timeout=30)


@contextlib.contextmanager
def full_disk(directory: Path) -> Iterator[None]:
    """``directory`` on a small tmpfs holding its current files and then filled up."""
    if os.geteuid() != 0:
        pytest.skip("a full file system is simulated with a tmpfs mount, which needs root")
    saved = {p.name: p.read_bytes() for p in directory.iterdir() if p.is_file()}
    try:
        _mount("-t", "tmpfs", "-o", "size=2m", "tmpfs", str(directory))
    except (OSError, subprocess.CalledProcessError) as exc:
        pytest.skip(f"cannot mount a tmpfs here: {exc}")
    try:
        for name, data in saved.items():
            (directory / name).write_bytes(data)
        with open(directory / ".filler", "wb", buffering=0) as fh:  # unbuffered: nothing left to flush at close
            with contextlib.suppress(OSError):
                while True:
                    fh.write(b"\0" * 4096)
        yield
    finally:
        subprocess.run(["umount", str(directory)], check=True, timeout=30)


def assert_one_plain_error(r: subprocess.CompletedProcess[str], cause: str) -> None:
    out = r.stdout + r.stderr
    assert r.returncode == 1, out
    assert "Traceback" not in out and out.count("error: ") == 1, out
    assert f"error: cannot write reports/: {cause}" in out, out
    assert "the reports and evidence of the last run are unchanged" in out


COMMANDS = [("rclverify.cli.commands", "verify"), ("doit", "verify")]


def test_read_only_reports_is_one_plain_error_and_the_reports_stay(ws: Path) -> None:
    # Before: a Python traceback and exit 2.
    before = digests(ws, "reports", "artifacts/evidence")
    edit_contract(ws, 1)
    with read_only(ws / "reports"):
        for command in COMMANDS:
            r = run(ws, *command)
            assert_one_plain_error(r, "Read-only file system" if os.geteuid() == 0 else "Permission denied")
    assert digests(ws, "reports", "artifacts/evidence") == before


def test_a_full_disk_is_one_plain_error_and_the_reports_stay(ws: Path) -> None:
    before = digests(ws, "reports")
    edit_contract(ws, 2)
    with full_disk(ws / "reports"):
        for command in COMMANDS:
            r = run(ws, *command)
            assert_one_plain_error(r, "No space left on device")
        after = digests(ws, "reports")
    after.pop("reports/.filler")
    assert after == before
    r = run(ws, *COMMANDS[1])  # space again: the run completes and writes the new report
    assert r.returncode == 0 and digests(ws, "reports") != before
    # written readable by others: the mode a plain open() gives (0644 under umask 022)
    for p in (ws / "reports").iterdir():
        assert p.stat().st_mode & 0o777 == published_mode(), p


def test_a_full_disk_under_the_whole_workspace_is_one_plain_error(tmp_path: Path) -> None:
    # doit's own state file fills up too: its sqlite3 traceback (exit 3) becomes one line and exit 1.
    disk = tmp_path / "disk"
    disk.mkdir()
    if os.geteuid() != 0:
        pytest.skip("a full file system is simulated with a tmpfs mount, which needs root")
    try:
        _mount("-t", "tmpfs", "-o", "size=8m", "tmpfs", str(disk))
    except (OSError, subprocess.CalledProcessError) as exc:
        pytest.skip(f"cannot mount a tmpfs here: {exc}")
    try:
        ws = disk / "ws"
        assert main(["init", str(ws)]) == 0
        assert run(ws, "rclverify.cli.commands", "verify").returncode == 0
        before = digests(ws, "reports", "artifacts/evidence")
        edit_contract(ws, 4)
        with open(disk / "filler", "wb", buffering=0) as fh:
            with contextlib.suppress(OSError):
                while True:
                    fh.write(b"\0" * 4096)
        for command in COMMANDS:
            r = run(ws, *command)
            out = r.stdout + r.stderr
            assert r.returncode == 1 and "Traceback" not in out and out.count("error: ") == 1, out
            assert "No space left on device" in out or "disk is full" in out, out
        assert digests(ws, "reports", "artifacts/evidence") == before
        (disk / "filler").unlink()
        r = run(ws, *COMMANDS[1])
        assert r.returncode == 0, r.stdout + r.stderr
    finally:
        subprocess.run(["umount", str(disk)], check=True, timeout=30)


def test_missing_workspace_and_missing_plan_are_one_error_each(tmp_path: Path, fresh: Path) -> None:
    ws = fresh
    r = run(tmp_path, "rclverify.cli.commands", "verify", "-w", str(tmp_path / "nope"))
    assert r.returncode == 1 and r.stderr == f"{tmp_path / 'nope'}: error: no such workspace directory\n"
    assert not (tmp_path / "nope").exists()
    r = run(ws, "rclverify.cli.commands", "verify", "--plan", "contracts/nope.yaml")
    out = r.stdout + r.stderr
    assert r.returncode == 1 and "Traceback" not in out and "DependencyError" not in out
    assert out.count("error:") == 1
    assert "contracts/nope.yaml:1:1: error: cannot read the verification plan: No such file or directory" in out


def test_published_files_take_the_umask_mode(tmp_path: Path) -> None:
    mask = os.umask(0o022)
    os.umask(mask)
    mode = published_mode()
    assert mode == 0o666 & ~mask
    new = tmp_path / "new.txt"
    assert write_published(new, "y") is True and new.stat().st_mode & 0o777 == mode
    old = tmp_path / "old.txt"
    old.write_text("x", encoding="utf-8")
    old.chmod(0o600)  # a report written by an earlier version: same text, only the mode is corrected
    assert write_published(old, "x") is False and old.stat().st_mode & 0o777 == mode


# ---------------------------------------------------------------------------
# One run at a time per workspace
# ---------------------------------------------------------------------------

HOLD = """
import sys
from pathlib import Path
from rclverify.core import runlock
runlock.acquire(Path(sys.argv[1]))
print("held", flush=True)
sys.stdin.read()
"""


@contextlib.contextmanager
def holder(ws: Path) -> Iterator[subprocess.Popen[str]]:
    """A real process holding the workspace's run lock until its stdin closes."""
    p = subprocess.Popen([sys.executable, "-c", HOLD, str(ws)], env=ENV, stdin=subprocess.PIPE,
                         stdout=subprocess.PIPE, text=True)
    try:
        assert p.stdout is not None and p.stdout.readline() == "held\n"
        yield p
    finally:
        if p.poll() is None:
            p.kill()
        p.wait(timeout=30)


def test_a_second_run_exits_with_no_wait(fresh: Path) -> None:
    ws = fresh
    with holder(ws) as h:
        r = run(ws, "rclverify.cli.commands", "verify", "--no-wait")
        assert r.returncode == 1 and "Traceback" not in r.stderr
        assert f"error: not waiting for the run in progress (pid {h.pid})" in r.stderr
        r = run(ws, "doit", "verify", env={**ENV, "RCLVERIFY_NO_WAIT": "1"})
        assert r.returncode == 1 and "Traceback" not in r.stdout + r.stderr
        assert f"not waiting for the run in progress (pid {h.pid})" in r.stderr


def test_a_second_run_waits_and_proceeds_when_the_first_ends(fresh: Path) -> None:
    ws = fresh
    with holder(ws) as h:
        p = subprocess.Popen([sys.executable, "-m", "doit", "verify"], cwd=ws, env=ENV, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
        assert p.stderr is not None
        assert p.stderr.readline() == f"waiting for the run in progress (pid {h.pid})\n"
        time.sleep(0.5)
        assert p.poll() is None  # still waiting
        h.stdin.close()  # type: ignore[union-attr]  # the first run ends
        out, err = p.communicate(timeout=120)
    assert p.returncode == 0, out + err
    assert "-- verify" in out or ".  verify" in out


def test_report_and_bundle_wait_for_a_run_in_progress(ws: Path) -> None:
    """`rclverify report` rewrites reports/ and `rclverify bundle` packs the
    report with the evidence it is checked against: both take the run lock,
    so neither works on what a `doit verify` in progress is rewriting."""
    before = digests(ws, "reports")
    with holder(ws) as h:
        for argv in (("report", "--no-wait"), ("bundle", "--no-wait", "-o", "b.tar.gz")):
            r = run(ws, "rclverify.cli.commands", *argv)
            assert r.returncode == 1 and "Traceback" not in r.stderr, r.stderr
            assert f"error: not waiting for the run in progress (pid {h.pid})" in r.stderr
        assert digests(ws, "reports") == before and not (ws / "b.tar.gz").exists()
        p = subprocess.Popen([sys.executable, "-m", "rclverify.cli.commands", "report"], cwd=ws, env=ENV,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        assert p.stderr is not None
        assert p.stderr.readline() == f"waiting for the run in progress (pid {h.pid})\n"
        time.sleep(0.5)
        assert p.poll() is None  # still waiting
        h.stdin.close()  # type: ignore[union-attr]  # the run ends
        out, err = p.communicate(timeout=120)
    assert p.returncode == 0, out + err
    assert "reports/assurance.html" in out
    r = run(ws, "rclverify.cli.commands", "bundle", "--no-wait", "-o", "b.tar.gz")
    assert r.returncode == 0 and (ws / "b.tar.gz").is_file(), r.stderr


def test_report_and_bundle_of_a_missing_workspace_make_no_lock_file(tmp_path: Path) -> None:
    """The run lock is taken only where there is a workspace: a mistyped -w
    gives the command's own error and leaves no directory behind."""
    missing = tmp_path / "no-such-ws"
    for argv in (("report",), ("bundle", "-o", str(tmp_path / "b.tar.gz"))):
        r = run(tmp_path, "rclverify.cli.commands", *argv, "-w", str(missing))
        assert r.returncode == 1 and "Traceback" not in r.stderr, r.stderr
        assert not missing.exists()


def test_a_killed_run_leaves_no_stale_lock(fresh: Path) -> None:
    ws = fresh
    with holder(ws) as h:
        p = subprocess.Popen([sys.executable, "-m", "rclverify.cli.commands", "verify"], cwd=ws, env=ENV,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        assert p.stderr is not None and p.stderr.readline().startswith("waiting for the run in progress")
        os.kill(h.pid, signal.SIGKILL)
        out, err = p.communicate(timeout=120)
    assert p.returncode == 0, out + err
    assert (ws / "artifacts/run.lock").exists()  # the file stays; the lock went with the process
    assert run(ws, "rclverify.cli.commands", "verify", "--no-wait").returncode == 0


def test_two_runs_started_together_never_run_a_task_twice(fresh: Path) -> None:
    ws = fresh  # not verified yet: whichever run gets the lock runs every task, the other none
    procs = [subprocess.Popen([sys.executable, "-m", "doit", "verify"], cwd=ws, env=ENV, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True) for _ in range(2)]
    outs = [p.communicate(timeout=120) for p in procs]
    assert [p.returncode for p in procs] == [0, 0], outs
    stdout = "".join(o for o, _ in outs)
    assert stdout.count(".  node:Sensor") == 1 and stdout.count(".  report:html") == 1, outs
    assert sum("waiting for the run in progress" in e for _, e in outs) <= 1


# ---------------------------------------------------------------------------
# A tool that hangs: a per-entry limit
# ---------------------------------------------------------------------------

def test_an_implementation_that_hangs_is_stopped_by_the_entrys_timeout(fresh: Path) -> None:
    ws = fresh
    impl = ws / "backends/property_tests/sensor.py"
    impl.parent.mkdir(parents=True)
    impl.write_text("def sensor(reading):\n    while True:\n        pass\n", encoding="utf-8")
    plan = ws / "contracts/plan.yaml"
    plan.write_text(plan.read_text(encoding="utf-8").replace(
        "  Sensor: {}\n", "  Sensor:\n    evidence:\n      - backend: property_tests\n"
        "        implementation: backends/property_tests/sensor.py:sensor\n        timeout_s: 0.5\n"), encoding="utf-8")
    t0 = time.monotonic()
    r = run(ws, "rclverify.cli.commands", "verify", "--strict")
    assert time.monotonic() - t0 < 60
    out = r.stdout + r.stderr
    assert r.returncode == 1 and "Traceback" not in out, out
    records = sorted((ws / "artifacts/evidence").glob("Sensor.*.json"))
    assert len(records) == 2
    for rec in records:
        data = __import__("json").loads(rec.read_text(encoding="utf-8"))
        assert data["status"] == "inconclusive"
        assert "did not finish within 0.5 s" in data["explanation"] and "loop forever" in data["explanation"]


def test_timeout_s_is_checked_and_the_limit_fires(fresh: Path) -> None:
    from rclverify.backends.property_tests.harness import ConfigError, read_config
    from rclverify.backends.timelimit import TimeLimitExceeded, wall_clock_limit
    with pytest.raises(ConfigError, match="timeout_s must be a number of seconds"):
        read_config({"implementation": "contracts/plan.yaml:x", "timeout_s": "soon"}, None, fresh)  # type: ignore[arg-type]
    with pytest.raises(TimeLimitExceeded):
        with wall_clock_limit(0.05) as enforced:
            assert enforced
            while True:
                pass
    with wall_clock_limit(None) as enforced:
        assert not enforced


def test_fault_messages_name_the_place_and_the_cause() -> None:
    import errno
    from rclverify.core.faults import describe_os_error
    root = Path("/w")
    tmp = PermissionError(errno.EACCES, "Permission denied", "/w/reports/.assurance.html.x1.tmp")
    assert describe_os_error(tmp, root).startswith("error: cannot write reports/: Permission denied (make it writable")
    read = PermissionError(errno.EACCES, "Permission denied", "/w/contracts/a.rcl")
    assert describe_os_error(read, root).startswith("error: cannot access contracts/a.rcl: Permission denied (check")
    full = OSError(errno.ENOSPC, "No space left on device")
    assert describe_os_error(full, root, place="artifacts/evidence/") == (
        "error: cannot write artifacts/evidence/: No space left on device (free some space and run again); "
        "the reports and evidence of the last run are unchanged")
