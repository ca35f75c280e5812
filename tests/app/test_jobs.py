"""How many doit processes a run uses without ``-n`` (app/jobs.py; docs/decisions.md, "Processes"):
one per CPU of this process, at most four, or ``RCLVERIFY_JOBS``; the number reaches doit
(tasks run in that many processes), and a bad ``RCLVERIFY_JOBS`` is one plain error."""
from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from rclverify.app.jobs import ENV, MAX_DEFAULT, JobsError, default_jobs
from rclverify.app.tasks import doit_config
from rclverify.core.cpus import allowed_cpus

ROOT = Path(__file__).resolve().parents[2]

#: A dodo.py with the workspace's DOIT_CONFIG and two independent tasks that each write the id of
#: the process that ran them (and wait a little, so that two processes both take one).
PIDS_DODO = """\
import os, time
from pathlib import Path
from rclverify.app.tasks import doit_config

DOIT_CONFIG = dict(doit_config(), reporter="console", check_file_uptodate="md5")
Path("main.pid").write_text(str(os.getpid()))  # doit's own process (the dodo is loaded there)


def _write(name):
    time.sleep(0.5)
    Path(name).write_text(str(os.getpid()))


def task_a():
    return {"actions": [(_write, ["a.pid"])], "targets": ["a.pid"], "uptodate": [False]}


def task_b():
    return {"actions": [(_write, ["b.pid"])], "targets": ["b.pid"], "uptodate": [False]}


def task_verify():
    return {"actions": None, "task_dep": ["a", "b"]}
"""


#: A dodo.py with the workspace's DOIT_CONFIG (its reporter too): one task prints 3,000 lines from a
#: worker while 40 others print 100 lines each from the other worker and the main process announces
#: each task, as a run's node and evidence tasks do.
LINES_DODO = """\
import time
from rclverify.app.tasks import doit_config

DOIT_CONFIG = dict(doit_config(), check_file_uptodate="md5")


def _talk():
    for k in range(3000):
        print(f"line {k:04d} " + "x" * 40)
        if k % 100 == 0:
            time.sleep(0.01)


def _nap(k):
    for j in range(100):
        print(f"quiet {k:02d} {j:03d} " + "y" * 30)
    time.sleep(0.02)


def task_talk():
    return {"actions": [_talk], "uptodate": [False], "verbosity": 2}


def task_quiet():
    for k in range(40):
        yield {"name": str(k), "actions": [(_nap, [k])], "uptodate": [False], "verbosity": 2}


def task_verify():
    return {"actions": None, "task_dep": ["talk", "quiet"]}
"""


def test_without_the_variable_a_run_uses_every_cpu_up_to_the_most() -> None:
    assert default_jobs({}) == max(1, min(MAX_DEFAULT, len(allowed_cpus())))


@pytest.mark.parametrize("value, expected", [("1", 1), ("3", 3), (" 2 ", 2), ("16", 16)])
def test_the_variable_sets_the_number(value: str, expected: int) -> None:
    assert default_jobs({ENV: value}) == expected


@pytest.mark.parametrize("value", ["0", "-1", "two", "1.5"])
def test_a_bad_variable_is_refused_with_its_name_and_value(value: str) -> None:
    with pytest.raises(JobsError, match=rf"RCLVERIFY_JOBS='{value}': not a whole number"):
        default_jobs({ENV: value})


def test_the_number_is_doits_num_process(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(ENV, "3")
    assert doit_config()["num_process"] == 3


def _pids(tmp_path: Path, jobs: str) -> tuple[set[str], str]:
    (tmp_path / "dodo.py").write_text(PIDS_DODO)
    env = {**os.environ, ENV: jobs, "PYTHONPATH": str(ROOT / "src")}
    r = subprocess.run([sys.executable, "-m", "doit"], cwd=tmp_path, env=env, capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0, r.stdout + r.stderr
    return {(tmp_path / f).read_text() for f in ("a.pid", "b.pid")}, (tmp_path / "main.pid").read_text()


def test_the_default_reaches_doit_two_processes_run_two_tasks(tmp_path: Path) -> None:
    pids, main = _pids(tmp_path, "2")
    assert len(pids) == 2 and main not in pids


def test_one_process_is_doits_serial_runner_the_tasks_in_doits_own_process(tmp_path: Path) -> None:
    """One process is doit's serial runner (``-n 0``), not ``-n 1``'s worker beside the main process: an
    in-process caller (``rclverify verify`` called from Python) keeps the actions' output."""
    pids, main = _pids(tmp_path, "1")
    assert pids == {main}


def test_verify_with_a_bad_variable_is_one_line_and_frees_the_workspace(tmp_path: Path) -> None:
    ws = tmp_path / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts" / "plan.yaml").write_text("contracts: []\n")
    env = {**os.environ, ENV: "many", "PYTHONPATH": str(ROOT / "src")}
    cmd = [sys.executable, "-m", "rclverify.cli.commands", "verify", "-w", str(ws)]
    r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=120)
    assert r.returncode == 1 and "Traceback" not in r.stderr, r.stderr
    assert r.stderr.strip() == "error: RCLVERIFY_JOBS='many': not a whole number of processes of at least 1"
    # the run lock was given back: a run with a good value is not told to wait
    r = subprocess.run(cmd + ["--no-wait"], env={**env, ENV: "1"}, capture_output=True, text=True, timeout=300)
    assert "run in progress" not in r.stderr and "waiting" not in r.stderr, r.stderr


def test_in_two_processes_every_line_comes_out_whole(tmp_path: Path) -> None:
    """Without a terminal, the main process's task lines and a worker's prints share the pipe: each
    line is written whole (app/progress.py's ``whole_lines``), never cut at a buffer's end and
    joined to another process's line."""
    (tmp_path / "dodo.py").write_text(LINES_DODO)
    # unbuffered, as in many CI images: without whole_lines, print's text and newline were two writes
    env = {**os.environ, ENV: "2", "PYTHONPATH": str(ROOT / "src"), "PYTHONUNBUFFERED": "1"}
    r = subprocess.run([sys.executable, "-m", "doit"], cwd=tmp_path, env=env, capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0, r.stdout + r.stderr
    lines = r.stdout.splitlines()
    bad = [x for x in lines if not re.fullmatch(r"line \d{4} x{40}|quiet \d\d \d{3} y{30}|\.  (talk|quiet:\d+|verify)", x)]
    assert not bad, bad[:5]
    assert sorted(x for x in lines if x.startswith("line ")) == [f"line {k:04d} " + "x" * 40 for k in range(3000)]
    assert len([x for x in lines if x.startswith("quiet ")]) == 4000
