"""When the collector looks at a run's heap (heap.py): the collector's state
is always given back, and only a doit worker freezes what it inherited."""
from __future__ import annotations

import gc
import multiprocessing

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


def test_a_run_heap_is_given_back_after_the_run() -> None:
    heap.release_after_run()  # a build_tasks of an earlier test without a doit run to end it
    assert gc.get_freeze_count() == 0
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
