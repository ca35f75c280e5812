"""When the collector looks at a run's heap (heap.py): the collector's state
is always given back, and only a doit worker freezes what it inherited."""
from __future__ import annotations

import gc
import multiprocessing
import shutil
from pathlib import Path
from typing import Any

import pytest

from rclverify.core.cache import heap


def test_loading_restores_the_collector_also_after_an_error() -> None:
    assert gc.isenabled()
    with pytest.raises(ValueError):
        with heap.no_collection():
            assert not gc.isenabled()
            raise ValueError("bad input")
    assert gc.isenabled()
    gc.disable()
    try:
        with heap.no_collection():
            pass
        assert not gc.isenabled()  # it was off before: left off
    finally:
        gc.enable()


def _unfrozen_start() -> None:
    """The collector as a fresh process has it: nothing frozen by a build_tasks of an earlier
    test without a doit run to end it, nor by a live monitor an earlier test ran in this worker
    (freeze_for_live: never undone, the monitor's process ends with it)."""
    heap.release_after_run()
    gc.unfreeze()
    assert gc.get_freeze_count() == 0


def test_a_run_heap_is_given_back_after_the_run() -> None:
    _unfrozen_start()
    heap.freeze_for_run()
    assert gc.get_freeze_count() > 0
    heap.release_after_run()
    assert gc.get_freeze_count() == 0
    heap.release_after_run()  # nothing frozen: nothing to do


def _child(queue: "multiprocessing.Queue[int]") -> None:
    heap.freeze_inherited()
    queue.put(gc.get_freeze_count())
    gc.unfreeze()


def test_only_a_forked_worker_freezes_its_inherited_heap() -> None:
    before = gc.get_freeze_count()
    heap.freeze_inherited()  # the test process is no multiprocessing child
    assert gc.get_freeze_count() == before
    ctx = multiprocessing.get_context("fork")
    queue: "multiprocessing.Queue[int]" = ctx.Queue()
    p = ctx.Process(target=_child, args=(queue,))
    p.start()
    frozen = queue.get(timeout=60)
    p.join(60)
    assert p.exitcode == 0 and frozen > 0


def test_a_run_makes_no_full_collection_until_a_task_executes_here() -> None:
    """no_full_collections: full collections off (the third threshold), young ones as before;
    executing() or release_after_run() gives back the thresholds as they were.  Freezing the
    heap alone (build_tasks, which a process may call without running doit) leaves them."""
    heap.release_after_run()
    before = gc.get_threshold()
    heap.freeze_for_run()
    try:
        assert gc.get_threshold() == before
        heap.no_full_collections()
        assert gc.get_threshold() == (before[0], before[1], heap.NO_FULL)
        heap.executing()
        assert gc.get_threshold() == before
        heap.executing()  # twice: nothing more
        assert gc.get_threshold() == before
        heap.no_full_collections()
        heap.release_after_run()
        assert gc.get_threshold() == before
    finally:
        heap.release_after_run()
        gc.set_threshold(*before)


def _executing_child(queue: "multiprocessing.Queue[tuple[int, int, int]]") -> None:
    queue.put(gc.get_threshold())
    heap.executing()
    queue.put(gc.get_threshold())


def test_a_forked_worker_collects_fully_once_it_executes() -> None:
    heap.release_after_run()
    before = gc.get_threshold()
    heap.freeze_for_run()
    heap.no_full_collections()
    try:
        ctx = multiprocessing.get_context("fork")
        queue: "multiprocessing.Queue[tuple[int, int, int]]" = ctx.Queue()
        p = ctx.Process(target=_executing_child, args=(queue,))
        p.start()
        inherited, working = queue.get(timeout=60), queue.get(timeout=60)
        p.join(60)
        assert inherited[2] == heap.NO_FULL and working == before
        assert gc.get_threshold()[2] == heap.NO_FULL  # the dispatching parent: still off
    finally:
        heap.release_after_run()
    assert gc.get_threshold() == before


def test_in_a_doit_run_actions_collect_and_dispatch_does_not(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A serial run of a small workspace, then a no-op: its action ran with the thresholds of
    before the run, the no-op's dispatch (doit found every task up to date) without full
    collections, and both runs give them back."""
    from rclverify.app import progress, task_actions
    from rclverify.cli.commands import main
    ws = tmp_path / "ws"
    shutil.copytree(Path(__file__).parent.parent / "data" / "newcomer", ws)
    before = gc.get_threshold()
    seen: dict[str, list[int]] = {"action": [], "skipped": []}
    stage_check = task_actions.stage_check

    def check(*args: Any, **kwargs: Any) -> Any:
        seen["action"].append(gc.get_threshold()[2])
        return stage_check(*args, **kwargs)

    skip = progress.ProgressReporter.skip_uptodate

    def skipped(self: Any, task: Any) -> None:
        seen["skipped"].append(gc.get_threshold()[2])
        skip(self, task)

    monkeypatch.setattr(task_actions, "stage_check", check)
    monkeypatch.setattr(progress.ProgressReporter, "skip_uptodate", skipped)
    assert main(["verify", "-w", str(ws), "-n", "1"]) == 0  # a run that completed (its findings: --strict)
    assert seen["action"] == [before[2]] and gc.get_threshold() == before
    seen["skipped"].clear()
    assert main(["verify", "-w", str(ws), "-n", "1"]) == 0  # a run that completed (its findings: --strict)
    assert seen["action"] == [before[2]]  # the check task did not run again
    assert seen["skipped"] and set(seen["skipped"]) == {heap.NO_FULL}
    assert gc.get_threshold() == before
