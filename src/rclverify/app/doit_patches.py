"""Three changes rclverify makes to doit's internals, installed once per process by :func:`rclverify.app.tasks.build_tasks`.

:func:`use_linear_implicit_task_dep` replaces doit's quadratic scan for the
task dependencies that file dependencies imply (docs/decisions.md, "doit");
:func:`guard_dep_writes` turns a failed write of doit's task state (a full
disk) into one plain line; :func:`release_in_order` makes ``doit -n N``
start the tasks that waited for one task in the order they began to wait.  Each checks the doit method it wraps or replaces
(``pyproject.toml`` pins the doit versions it was checked against;
tests/app/test_tasks_doit.py holds the replacement equal to doit's own).
"""
from __future__ import annotations

import inspect
import os
import sys
from typing import Any, Callable, Sequence


def linear_implicit_task_dep(targets: dict[str, str], task: Any, deps_list: Sequence[str]) -> None:
    """doit's ``TaskControl.add_implicit_task_dep`` with a set for the
    membership test: the same task dependencies in the same order.  doit's
    own tests ``name not in task.task_dep`` on a list, which is quadratic
    for a task whose file dependencies are the targets of thousands of
    tasks (each report task of a 1000-node system: 5,000 file dependencies
    from 3,000 tasks, a seventh of a second per task per run)."""
    have = set(task.task_dep)
    for dep in deps_list:
        name = targets.get(dep)
        if name is not None and name not in have:
            task.task_dep.append(name)
            have.add(name)


def use_linear_implicit_task_dep() -> None:
    """Install :func:`linear_implicit_task_dep` in doit (idempotent), when
    doit's own has the signature it replaces (``pyproject.toml`` pins the
    doit versions it was checked against; ``tests/app/test_tasks_doit.py``
    compares the two)."""
    from doit.control import TaskControl  # deferred: start-up (loads doit only when called)
    current = TaskControl.add_implicit_task_dep
    if current is linear_implicit_task_dep:
        return
    if list(inspect.signature(current).parameters) == ["targets", "task", "deps_list"]:
        DOIT_IMPLICIT_TASK_DEP.append(current)
        TaskControl.add_implicit_task_dep = staticmethod(linear_implicit_task_dep)


#: doit's own implicit-dependency scan, once replaced (for the test that compares the two).
DOIT_IMPLICIT_TASK_DEP: list[Callable[..., None]] = []


def guard_dep_writes() -> None:
    """Make a full disk (or a read-only workspace) while doit writes its task
    state end the run with one plain line and exit code 1, instead of doit's
    traceback (``sqlite3.OperationalError: database or disk is full``, exit
    3).  Wraps the writing methods of ``doit.dependency.SqliteDB`` (the store
    :func:`rclverify.app.tasks.doit_config` selects: ``dump`` at the end of a run, ``remove`` when
    a task fails) once per process; what the run wrote is complete (every
    write is atomic), only doit's record of it is lost, so its tasks run
    again next time.  ``SystemExit`` passes through doit's own handler."""
    import sqlite3  # deferred: start-up (loads sqlite3 only when called)
    from doit.dependency import SqliteDB  # deferred: start-up (loads doit only when called)

    def guard(method: Callable[..., Any]) -> Callable[..., Any]:
        def guarded(self: Any, *args: Any) -> Any:
            try:
                return method(self, *args)
            except (sqlite3.Error, OSError) as exc:
                print(f"error: cannot save doit's task state in {os.path.basename(self.name)}: {exc} (free some "
                      "space or make the workspace writable, and run again); what this run wrote is complete, and "
                      "its tasks run again next time", file=sys.stderr)
                raise SystemExit(1) from None
        guarded._rclverify_guarded = True  # type: ignore[attr-defined]
        return guarded
    for name in ("dump", "remove"):
        method = getattr(SqliteDB, name, None)
        if method is None:  # another doit: leave its store as it is (docs/decisions.md, "Where rclverify reaches into doit")
            continue
        if not getattr(method, "_rclverify_guarded", False):
            setattr(SqliteDB, name, guard(method))


class _InOrder(dict):  # type: ignore[type-arg]
    """A set that iterates in the order its items were added (the two
    operations doit uses on an ``ExecNode``'s ``waiting_me``: ``add`` and
    iteration; ``in`` and ``len`` as a dict's)."""

    def add(self, item: Any) -> None:
        self[item] = None


def release_in_order() -> None:
    """Make doit's parallel runner start the tasks that waited for one task
    in the order they began to wait, i.e. the order of ``verify``'s task
    dependencies (app/task_table.py: ``node`` first, then ``health``, then
    the requirements).  doit keeps the tasks waiting for a task in a set of
    ``ExecNode`` objects (``waiting_me``), so when ``check`` ended the
    order they started in was that of the objects' hashes (their memory
    addresses): a run sometimes began with the requirements and one node's
    long health checks on the two processes while the quick ``node`` tasks,
    which the evidence tasks are created after, waited 5 s (CHANGELOG.md,
    "Speed round nine").  Installed once per process (idempotent); with a doit
    whose ``ExecNode`` does not start with an empty set there, nothing is
    changed (docs/decisions.md, "Where rclverify reaches into doit")."""
    from doit.control import ExecNode  # deferred: start-up (loads doit only when called)
    init = ExecNode.__init__
    if getattr(init, "_rclverify_in_order", False):
        return

    def ordered_init(self: Any, task: Any, parent: Any) -> None:
        init(self, task, parent)
        if type(self.waiting_me) is set and not self.waiting_me:
            self.waiting_me = _InOrder()
    ordered_init._rclverify_in_order = True  # type: ignore[attr-defined]
    ExecNode.__init__ = ordered_init
