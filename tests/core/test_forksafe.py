"""core/forksafe.py: forking is safe without other threads, or with only multiprocessing queue feeders."""
from __future__ import annotations

import multiprocessing
import threading

from rclverify.core.forksafe import FEEDER, fork_is_safe


def test_a_queue_feeder_allows_the_fork_another_thread_does_not() -> None:
    base = [t for t in threading.enumerate() if t is not threading.main_thread() and t.name != FEEDER]
    if base:  # a test worker that runs other threads already (an earlier module's): nothing to tell here
        assert not fork_is_safe()
        return
    assert fork_is_safe()
    q = multiprocessing.get_context("fork").Queue()
    q.put("x")  # starts the queue's feeder thread
    assert any(t.name == FEEDER for t in threading.enumerate())
    assert fork_is_safe()
    stop = threading.Event()
    other = threading.Thread(target=stop.wait, name="other")
    other.start()
    try:
        assert not fork_is_safe()
    finally:
        stop.set()
        other.join()
        q.get()
        q.close()
        q.join_thread()
    assert fork_is_safe()
