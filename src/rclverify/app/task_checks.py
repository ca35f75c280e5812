"""What decides whether a ``doit verify`` task runs again: its ``uptodate`` checks and the files it depends on.

Used by :mod:`rclverify.app.task_table` when it defines the tasks: the
files a plan evidence entry names (:func:`entry_inputs`), the files of the
plan's ``ros:`` section (:func:`ros_fingerprint`), the versions of the code
and tools that make the results (:func:`z3_version`,
:func:`tool_fingerprint`), and the ``uptodate`` checks of an evidence
record (:class:`RecordIntact`), of the report's files
(:class:`TargetsAsWritten`) and of ``verify --strict``
(:func:`strict_uptodate`).  doit's ``uptodate`` protocol: a callable given
the task and its saved values, answering whether the task is up to date.
"""
from __future__ import annotations

import glob
import inspect
import os
import shutil
from pathlib import Path
from typing import Any, Mapping

from rclverify import __version__
from rclverify.model.plan.declarations import DECLARATIONS
from rclverify.model.plan.paths import config_strings
from rclverify.model.plan.ros_section import RosSection
from rclverify.records.store import EvidenceStore


def ros_fingerprint(root: Path, section: RosSection | Mapping[str, Any]) -> list[tuple[str, int, int, int]]:
    """(path, size, mtime_ns, ctime_ns) of every file under the ``ros:``
    section's paths: the grounding task runs again when one changes (the
    scan's own cache then re-parses only the changed files).  The change
    time is set by every write and every ``utime``, so an edit that keeps
    the size and restores the modification time is a change too."""
    ros = RosSection.of(section)
    out: list[tuple[str, int, int, int]] = []
    for rel in (*ros.workspaces, *ros.launch, *ros.bags):
        top = root / rel
        files = [top] if top.is_file() else sorted(p for p in top.rglob("*") if p.is_file()) if top.is_dir() else []
        for p in files:
            try:
                st = p.stat()
            except OSError:
                continue
            out.append((str(p.relative_to(root)), st.st_size, st.st_mtime_ns, st.st_ctime_ns))
    if ros.mapping:
        p = root / ros.mapping
        if p.is_file():
            st = p.stat()
            out.append((ros.mapping, st.st_size, st.st_mtime_ns, st.st_ctime_ns))
    return out


#: The signature of an ``uptodate`` callable given doit's task and its saved values.  doit calls
#: ``inspect.signature`` on every uptodate callable of every task on every run; a class's own
#: ``__signature__`` (PEP 362) answers it at once.
UPTODATE_SIGNATURE = inspect.Signature([inspect.Parameter("task", inspect.Parameter.POSITIONAL_OR_KEYWORD),
                                        inspect.Parameter("values", inspect.Parameter.POSITIONAL_OR_KEYWORD)])


def _stats(paths: list[str], changed: bool = True) -> list[list[int]] | None:
    """``[mtime_ns, size, ctime_ns]`` of each of ``paths`` (``[mtime_ns,
    size]`` when ``changed`` is false), or ``None`` when one is missing: what
    an ``uptodate`` check saves with doit's task values after the task ran
    and compares on the next run, without reading a file.  The change time
    is set by every write and every ``utime``: a file rewritten with its
    size and modification time kept differs too."""
    out = []
    for path in paths:
        try:
            st = os.stat(path)
        except OSError:
            return None
        out.append([st.st_mtime_ns, st.st_size, st.st_ctime_ns] if changed else [st.st_mtime_ns, st.st_size])
    return out


class TargetsAsWritten:
    """doit ``uptodate`` check of a report task: its files are the ones it
    wrote last.  ``rclverify report`` renders the same files from the
    artifacts as they are, without doit; after a record altered by hand it
    shows that record as ``error``.  When the alteration was then undone
    (or ``doit verify`` made the record again, byte for byte), the report
    task's inputs were what it last read, doit called it up to date, and the
    report kept the ``error`` of a record that was intact again (a false
    alarm; found by tests/report/test_hardening_greens.py).  After the task ran the
    size, modification and change times of each target are saved with doit's task
    values; any other write (or a missing file) makes it run again.  A stat
    a file, no read: nothing on a no-op run."""

    __signature__ = UPTODATE_SIGNATURE
    KEY = "_targets_stat"

    def __call__(self, task: Any, values: Mapping[str, object]) -> bool:
        targets = list(task.targets)
        task.value_savers.append(lambda: {self.KEY: _stats(targets)})
        now = _stats(targets)
        return now is not None and values.get(self.KEY) == now


class RecordIntact:
    """doit ``uptodate`` check of an evidence task: its record is as rclverify
    wrote it.  A record changed by anything else (a hand edit of its status)
    makes the task run again, so ``doit verify`` produces the evidence anew
    instead of believing it (the report of a run that does not re-run it,
    ``rclverify report``, shows it as ``error``: evidence altered).

    Cheap on a no-op run: after the task ran, the record's size and
    modification time are saved with doit's task values; while they are the
    same the record is not read.  Otherwise its seal is checked
    (:meth:`rclverify.records.store.EvidenceStore.read`), which is what
    proves a record intact (an altered one reads ``error`` in every
    report).  Not its change time: an intact record whose stat differs is
    read on every run until its task runs again, and a copied or restored
    workspace (a CI cache) gives every file a new change time."""

    __signature__ = UPTODATE_SIGNATURE

    def __call__(self, task: Any, values: Mapping[str, object]) -> bool:
        target = task.targets[0]

        def saved() -> dict[str, list[int] | None]:
            stats = _stats([target], changed=False)
            return {"_record_stat": stats[0] if stats else None}
        task.value_savers.append(saved)
        now = _stats([target], changed=False)
        if now is None:
            return False
        if values.get("_record_stat") == now[0]:
            return True
        root, _, name = target.rpartition("/artifacts/evidence/")
        try:
            ev, problem = EvidenceStore(Path(root)).read(name[:-len(".json")])
        except Exception as exc:  # noqa: BLE001 - whatever the file holds, the task produces it again
            ev, problem = None, f"evidence record unreadable ({exc.__class__.__name__}): altered outside rclverify"
        if problem:
            print(f"{os.path.relpath(target, root)}: {problem}: producing it again")
            return False
        return ev is not None


def strict_uptodate(task: Any, values: Any) -> bool:
    """``verify`` is up to date unless ``--strict`` asks for the check again.  ``doit list --status``
    asks without parsing the task's options (``task.options`` is ``None``): no ``--strict`` then."""
    return not bool((task.options or {}).get("strict"))


def entry_inputs(config: Any, root: Path, seen: dict[str, tuple[str, ...]]) -> list[str]:
    """Workspace files named in a plan evidence entry (strings that are existing paths).

    The values of tool keys (``dafny: PATH``, ``mcapl_home``, ``options``:
    :data:`rclverify.model.plan.entries.TOOL_KEYS`) name installed tools, not
    workspace files, and are never file dependencies (an absolute tool path
    joined to the workspace root was a dependency on a file that does not
    exist, a doit DependencyError); nor is any absolute path (the plan check
    refuses those everywhere else).

    ``seen`` memoises the files of each path string across calls (the
    entries of many nodes name the same program or directory: one stat or
    directory walk per distinct string; one import walk per Python file,
    which entries name with different callables, ``file.py:n0``)."""
    out: set[str] = set()

    def files(v: str) -> tuple[str, ...]:
        if v not in seen:
            p = root / v
            py = v.rsplit(":", 1)[0] if ":" in v else v
            if py.endswith(".py") and (root / py).is_file():
                # a Python implementation (`file.py:callable`): the file and every workspace module it imports,
                # so that a changed helper exports the obligations, and their inputs, again
                from rclverify.backends.property_tests.closure import import_closure  # deferred: optional or conditional (inside a block)
                k = "\0" + py  # the closure is the file's, whatever callable follows the colon (one walk per file)
                if k not in seen:
                    seen[k] = tuple(import_closure(root, py)[0])
                seen[v] = seen[k]
            elif not p.exists():
                seen[v] = ()
            elif p.is_dir():
                seen[v] = tuple(os.path.relpath(f, root) for f in glob.glob(str(p / "**" / "*"), recursive=True)
                                if os.path.isfile(f))
            else:
                seen[v] = (v,)
        return seen[v]

    for _, v in config_strings(dict(config)):
        if "/" in v and not os.path.isabs(v):
            out.update(files(v))
    return sorted(out)


def z3_version() -> str:
    """The installed z3-solver's version (from its metadata: importing Z3 costs a no-op run
    a fifth of a second).  Every verdict comes from Z3, so another version makes them again."""
    from importlib.metadata import PackageNotFoundError, version  # deferred: start-up (loads importlib only when called)
    try:
        return version("z3-solver")
    except PackageNotFoundError:
        return "-"


def tool_fingerprint() -> dict[str, str | None]:
    """The tools the backends run, as found now: rclverify's version, the path of ``dot``, and each
    tool the backends' declarations name (``tools[]``: a command's path on ``PATH``, or the first set
    of its environment variables; ``None`` when absent).  Another value makes every evidence record
    again (the evidence tasks' ``config_changed``)."""
    found: dict[str, str | None] = {"rclverify": __version__, "dot": shutil.which("dot")}
    for d in DECLARATIONS.values():
        for t in d.tools:
            found[t.name] = shutil.which(t.which) if t.which else next(
                (os.environ[v] for v in t.env if os.environ.get(v)), None)
    return found
