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


def test_a_command_loads_without_collection_then_runs_on_a_frozen_heap() -> None:
    _unfrozen_start()
    with heap.loading() as loaded:
        assert not gc.isenabled()  # loading: no collection
        loaded()
        assert gc.isenabled() and gc.get_freeze_count() > 0  # running: what was loaded is frozen
        loaded()  # once only
    assert gc.isenabled() and gc.get_freeze_count() == 0  # given back after the block
    with pytest.raises(ValueError):
        with heap.loading() as loaded:
            loaded()
            raise ValueError("a run that fails")
    assert gc.isenabled() and gc.get_freeze_count() == 0
    with pytest.raises(ValueError):
        with heap.loading():
            raise ValueError("bad input while loading")
    assert gc.isenabled() and gc.get_freeze_count() == 0


def test_the_monitor_command_gives_the_collector_back(tmp_path: Path, capsys: Any) -> None:
    """``rclverify monitor`` on a recorded run, run in this process: its start-up loaded without
    collection and frozen for the run (cli/runs.py), the collector as it was after it."""
    from rclverify.cli.commands import main
    _unfrozen_start()
    ws = tmp_path / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/n.rcl").write_text("node N {\n  inputs( a : REAL )\n  outputs( b : REAL )\n"
                                        "  topics( std_msgs/Float64 q matches(in.a), std_msgs/Float64 r matches(out.b) )\n"
                                        "  guarantee( out.b > in.a )\n}\n")
    (ws / "contracts/plan.yaml").write_text("name: n\ncontracts: [contracts/n.rcl]\nnodes:\n  N:\n    evidence: []\n")
    log = ws / "run.jsonl"
    log.write_text('{"topic": "q", "time": 0.0, "data": 1.0}\n{"topic": "r", "time": 0.0, "data": 2.0}\n')
    assert main(["monitor", "-w", str(ws), str(log)]) == 0
    assert gc.isenabled() and gc.get_freeze_count() == 0
    (ws / "contracts/n.rcl").write_text("node N {")  # a contract that does not parse: an error while loading
    assert main(["monitor", "-w", str(ws), str(log)]) != 0
    assert gc.isenabled() and gc.get_freeze_count() == 0
    capsys.readouterr()


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
