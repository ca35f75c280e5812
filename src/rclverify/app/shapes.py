"""The orchestrator's own records, as types: a doit task dictionary.

doit reads a task as a dictionary (doit's "Task definition"); the task
creators of :mod:`rclverify.app.task_table` build them and doit alone reads
them, so only the keys this package writes are typed here, each with what
it holds.
"""
# No ``from __future__ import annotations``: the keys are read from evaluated annotations.
from collections.abc import Callable, Sequence
from typing import TypedDict


class DoitParam(TypedDict):
    """A command-line parameter of a task (doit's ``params`` entry): ``doit verify --strict``."""
    name: str
    long: str
    type: type
    default: object
    help: str


class DoitTask(TypedDict, total=False):
    """One doit task (or, with ``name`` ``None``, the group of a task family and its ``doc``): its
    ``actions`` (a callable and its arguments), the files it reads (``file_dep``) and writes
    (``targets``), the tasks it waits for (``task_dep``), what keeps it up to date (``uptodate``:
    ``False``, doit's ``config_changed`` or a check callable), and how doit shows and cleans it."""
    basename: str
    name: str | None
    doc: str
    actions: list[tuple[Callable[..., object], Sequence[object]]]
    file_dep: list[str]
    targets: list[str]
    task_dep: list[str]
    uptodate: Sequence[object]
    params: list[DoitParam]
    verbosity: int
    clean: bool
