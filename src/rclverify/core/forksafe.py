"""Whether this process may fork a child that runs Python code.

A child forked from a process with other threads gets a copy of every lock
as it was at the fork; a lock another thread held then stays held in the
child, which hangs at its first use.  So rclverify forks (the second
solver's second process, the workspace cache's background save) only when
no other thread runs, with one exception: the feeder threads of
``multiprocessing`` queues, which a ``doit -n`` worker process always has
(doit's result queue).  ``multiprocessing`` resets such a queue's thread
state in every child it starts (its after-fork hooks), and a child of
rclverify's never uses doit's queues; without the exception the second
solver of a ``doit -n 2`` run never split (13 s on one core of
the 1000-node system, the other core idle).
"""
from __future__ import annotations

import os
import threading

#: The name ``multiprocessing.queues.Queue`` gives its feeder thread (CPython's Lib/multiprocessing/queues.py).
FEEDER = "QueueFeederThread"


def fork_is_safe() -> bool:
    """``True`` where ``os.fork`` exists and every thread but the main one
    is a ``multiprocessing`` queue's feeder (:data:`FEEDER`)."""
    if not hasattr(os, "fork"):
        return False
    main = threading.main_thread()
    return all(t is main or t.name == FEEDER for t in threading.enumerate())
