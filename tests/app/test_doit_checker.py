"""app/doit_checker.py: doit's md5 checker, each file hashed once per file state (issue 67)."""
from __future__ import annotations

import io
import os
import random
from pathlib import Path

import pytest
from doit.dependency import MD5Checker as DoitMD5Checker
from doit.exceptions import TaskFailed
from doit.task import Task

from rclverify.app import doit_checker
from rclverify.app.doit_checker import MD5Checker
from rclverify.app.progress import ProgressReporter
from rclverify.app.tasks import doit_config


def test_the_same_states_and_answers_as_doits_checker_on_random_edits(tmp_path: Path) -> None:
    """Oracle: doit's own checker on the same files, through rewrites (new inode), rewrites of the same
    size, touched files and unchanged ones; ours hashes each file state once."""
    rng = random.Random(67)
    ours, doits = MD5Checker(), DoitMD5Checker()
    files = [tmp_path / f"f{k}" for k in range(5)]
    for f in files:
        f.write_bytes(os.urandom(rng.randint(0, 300)))
    saved = {str(f): doits.get_state(str(f), None) for f in files}
    for step in range(200):
        f = rng.choice(files)
        what = rng.choice(["rewrite", "same-size", "touch", "nothing"])
        if what == "rewrite":
            tmp = f.with_suffix(".tmp")
            tmp.write_bytes(os.urandom(rng.randint(0, 300)))
            os.replace(tmp, f)
        elif what == "same-size":
            data = bytearray(f.read_bytes())
            if data:
                data[rng.randrange(len(data))] ^= rng.choice([0, 1])  # sometimes the same bytes
            tmp = f.with_suffix(".tmp")
            tmp.write_bytes(bytes(data))
            os.replace(tmp, f)
        elif what == "touch":
            st = f.stat()
            os.utime(f, ns=(st.st_atime_ns, st.st_mtime_ns + rng.choice([1, 10 ** 9])))
        for g in files:
            p, st = str(g), g.stat()
            assert ours.check_modified(p, st, saved[p]) == doits.check_modified(p, st, saved[p]), (step, what)
            for current in (None, saved[p]):
                assert ours.get_state(p, current) == doits.get_state(p, current), (step, what)
        if rng.random() < 0.3:
            saved[str(f)] = doits.get_state(str(f), None)


def test_a_file_named_by_many_tasks_is_hashed_once(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    model = tmp_path / "model.json"
    model.write_text("{}" * 1000)
    calls: list[str] = []
    real = doit_checker.get_file_md5
    monkeypatch.setattr(doit_checker, "get_file_md5", lambda p: calls.append(p) or real(p))
    checker = MD5Checker()
    states = {checker.get_state(str(model), None) for _ in range(500)}
    assert len(states) == 1 and calls == [str(model)]
    tmp = tmp_path / "model.tmp"
    tmp.write_text("[]" * 1000)  # the same size, written by rename: a new inode
    os.replace(tmp, model)
    assert checker.get_state(str(model), None) != next(iter(states)) and len(calls) == 2


def test_doit_saves_our_states_under_its_checkers_name() -> None:
    """doit runs a task again when the saved checker name differs: a workspace verified before keeps its state."""
    assert MD5Checker.__name__ == DoitMD5Checker.__name__
    assert doit_config()["check_file_uptodate"] is MD5Checker


def test_stats_are_kept_only_between_two_task_events_of_our_reporter(tmp_path: Path) -> None:
    """A file dependency's ``stat`` is taken once between two task events while rclverify's reporter
    runs the run; a task that starts, succeeds or fails forgets them, and without that reporter (or
    after its run) every call stats the file again, as doit does."""
    f = tmp_path / "dep"
    f.write_text("a")

    def rewrite(text: str) -> None:
        tmp = tmp_path / "dep.tmp"
        tmp.write_text(text)
        os.replace(tmp, f)  # a new inode, as every write of rclverify's

    checker = MD5Checker()
    first = checker.info(str(f))
    rewrite("bb")
    assert checker.info(str(f)).st_ino != first.st_ino  # no reporter: nothing kept
    reporter = ProgressReporter(io.StringIO(), {})
    kept = checker.info(str(f))
    rewrite("ccc")
    assert checker.info(str(f)) is kept  # no task event since: the same stat
    task = Task("evidence:x", [(lambda: True, [], {})])
    for event in (reporter.execute_task, reporter.add_success):
        event(task)
        now = checker.info(str(f))
        assert now.st_size == f.stat().st_size and now.st_ino == f.stat().st_ino
        rewrite(now.st_size * "d" + "d")
    reporter.add_failure(task, TaskFailed("failed"))
    assert checker.info(str(f)).st_ino == f.stat().st_ino
    with pytest.raises(OSError):
        checker.info(str(tmp_path / "missing"))  # a missing file is never kept
    reporter.complete_run()
    before = checker.info(str(f))
    rewrite("e")
    assert checker.info(str(f)).st_ino != before.st_ino  # the run is over: nothing kept
    ProgressReporter(io.StringIO(), {})  # a reporter whose run never ended (its process raised) ...
    fresh = MD5Checker()  # ... and a new run's checker: it starts with nothing kept
    before = fresh.info(str(f))
    rewrite("ff")
    assert fresh.info(str(f)).st_ino != before.st_ino
