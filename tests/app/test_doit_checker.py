"""app/doit_checker.py: a file dependency is changed when its content is (issue 107), each file
hashed once per file state (issue 67)."""
from __future__ import annotations

import hashlib
import io
import os
import random
from pathlib import Path

import pytest
from doit.dependency import MD5Checker as DoitMD5Checker
from doit.exceptions import TaskFailed
from doit.task import Task

from rclverify.app import doit_checker
from rclverify.app.doit_checker import ContentChecker
from rclverify.app.progress import ProgressReporter
from rclverify.app.tasks import doit_config
from rclverify.records.records import sha256_file


def _in_place(f: Path, data: bytes, keep_mtime: bool) -> None:
    """Write ``data`` into ``f`` where it is (the same inode), its modification time restored when ``keep_mtime``."""
    st = f.stat()
    with f.open("r+b") as fh:
        fh.write(data)
        fh.truncate()
    if keep_mtime:
        os.utime(f, ns=(st.st_atime_ns, st.st_mtime_ns))


def test_changed_exactly_when_the_content_is_on_random_edits(tmp_path: Path) -> None:
    """Oracle: the content itself (size and sha256 against the state saved), through rewrites (new
    inode), rewrites of the same size, touched files, edits in place with the modification time
    restored, and unchanged files; the state saved holds the digest the evidence records keep."""
    rng = random.Random(107)
    ours = ContentChecker()
    files = [tmp_path / f"f{k}" for k in range(5)]
    for f in files:
        f.write_bytes(os.urandom(rng.randint(0, 300)))
    saved = {str(f): ours.get_state(str(f), None) for f in files}
    kinds = set()
    for step in range(300):
        f = rng.choice(files)
        what = rng.choice(["rewrite", "same-size", "in-place", "touch", "nothing"])
        data = bytearray(f.read_bytes())
        if what == "rewrite":
            tmp = f.with_suffix(".tmp")
            tmp.write_bytes(os.urandom(rng.randint(0, 300)))
            os.replace(tmp, f)
        elif what in ("same-size", "in-place") and data:
            data[rng.randrange(len(data))] ^= rng.choice([0, 1])  # sometimes the same bytes
            if what == "same-size":
                tmp = f.with_suffix(".tmp")
                tmp.write_bytes(bytes(data))
                os.replace(tmp, f)
            else:
                _in_place(f, bytes(data), keep_mtime=True)
        elif what == "touch":
            st = f.stat()
            os.utime(f, ns=(st.st_atime_ns, st.st_mtime_ns + rng.choice([1, 10 ** 9])))
        for g in files:
            p, st = str(g), g.stat()
            content = (st.st_size, sha256_file(g))
            changed = content != tuple(saved[p][1:])
            kinds.add((what, changed))
            assert ours.check_modified(p, st, saved[p]) == changed, (step, what)
            assert ours.get_state(p, saved[p]) == (None if not changed else (st.st_mtime, *content)), (step, what)
            assert ours.get_state(p, None) == (st.st_mtime, *content)
        if rng.random() < 0.3:
            saved[str(f)] = ours.get_state(str(f), None)
    assert ("in-place", True) in kinds and ("touch", False) in kinds  # both sides were met


def test_an_edit_keeping_size_and_mtime_is_a_change_which_doits_checker_misses(tmp_path: Path) -> None:
    """Issue 107: a run rewritten in place, its size and modification time kept.  doit's md5 checker
    believes the time and calls it unchanged (the control: what rclverify had); ours reads the content."""
    f = tmp_path / "run.jsonl"
    f.write_bytes(b'{"topic": "out", "time": 1.0, "data": 2.5}\n')
    ours, doits = ContentChecker(), DoitMD5Checker()
    saved_ours, saved_doits = ours.get_state(str(f), None), doits.get_state(str(f), None)
    assert saved_ours[2] == hashlib.sha256(f.read_bytes()).hexdigest()  # the digest the report compares
    _in_place(f, b'{"topic": "out", "time": 1.0, "data": 2.0}\n', keep_mtime=True)
    st = f.stat()
    assert doits.check_modified(str(f), st, saved_doits) is False
    assert ours.check_modified(str(f), st, saved_ours) is True
    assert ours.get_state(str(f), saved_ours) is not None
    _in_place(f, b'{"topic": "out", "time": 1.0, "data": 2.5}\n', keep_mtime=False)  # undone: unchanged again
    assert ours.check_modified(str(f), f.stat(), saved_ours) is False


def test_a_file_named_by_many_tasks_is_hashed_once(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    model = tmp_path / "model.json"
    model.write_text("{}" * 1000)
    calls: list[str] = []
    real = doit_checker.file_sha256
    monkeypatch.setattr(doit_checker, "file_sha256", lambda p: calls.append(p) or real(p))
    checker = ContentChecker()
    states = {checker.get_state(str(model), None) for _ in range(500)}
    assert len(states) == 1 and calls == [str(model)]
    st = model.stat()
    assert not any(checker.check_modified(str(model), st, next(iter(states))) for _ in range(500))
    assert calls == [str(model)]
    tmp = tmp_path / "model.tmp"
    tmp.write_text("[]" * 1000)  # the same size, written by rename: a new inode
    os.replace(tmp, model)
    assert checker.get_state(str(model), None) != next(iter(states)) and len(calls) == 2


def test_doit_runs_a_task_once_whose_state_another_checker_saved() -> None:
    """doit runs a task again when the saved checker name differs: states saved by doit's md5 checker
    (which believed modification times) are not believed."""
    assert ContentChecker.__name__ != DoitMD5Checker.__name__
    assert doit_config()["check_file_uptodate"] is ContentChecker


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

    checker = ContentChecker()
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
    fresh = ContentChecker()  # ... and a new run's checker: it starts with nothing kept
    before = fresh.info(str(f))
    rewrite("ff")
    assert fresh.info(str(f)).st_ino != before.st_ino
