"""A cache of a workspace's task index, loaded plan and parsed contracts.

Every ``doit`` run starts by loading the workspace (:func:`rclverify.app.tasks.build_tasks`
needs the node names, the plan's evidence entries and the system model to
define the tasks).  For a system of 1000 nodes that is about 3 s of YAML
reading and parsing -- the whole budget of a no-op run.  The
result is therefore kept in ``artifacts/cache/workspace.pickle`` and reused
when nothing it was computed from changed:

* the sha256 of the plan file, of every contract file it lists and of
  the workspace's own standard profiles it names (docs/standards.md),
* what every path the plan names resolves to (every symbolic link followed:
  the plan's ``path_targets``, :mod:`rclverify.model.plan.paths`), resolved
  again on every run, so a link retargeted since (outside the workspace,
  say) loads and checks the plan anew, as a clean run does,
* the workspace's absolute path and the plan's path,
* the rclverify code (the salt of the kind ``workspace``,
  :func:`rclverify.core.cache.keys.salt`: name, size and modification time of
  every file of the package, and the Python version).

When a file changed, the parsed contract files whose text is unchanged and
an unchanged plan are still reused (see :func:`restore`); a damaged or
missing cache, another code version or another path means a normal load.  Only workspaces that load without error are cached, so
an error is always reported from the files themselves.  The file has the
format of every kept file (:mod:`rclverify.core.cache.store`): it is written
atomically and is a pure speed-up: deleting ``artifacts/cache`` is always
safe.  Reading it never runs code from it (:mod:`rclverify.core.cache.safeload`):
a file naming a class rclverify does not keep is a miss.

A no-op run needs only the :class:`~rclverify.app.pipeline.TaskIndex` (node
names, producers, plan entries) to define its tasks; the plan and the
parsed contracts are unpickled only when a task first needs them
(``Workspace.deferred``).
"""
from __future__ import annotations

import atexit
import os
from typing import Any, BinaryIO

from rclverify.core.cache.keys import file_digest, resolved_paths, salt
from rclverify.core.cache.safeload import load
from rclverify.core.cache.shapes import WorkspaceInputs
from rclverify.core.cache.store import open_stream, write_stream
from rclverify.core.cache.heap import no_collection
from rclverify.core.forksafe import fork_is_safe

CACHE = "artifacts/cache/workspace.pickle"
KIND = "workspace"


def _inputs(ws: Any, contracts: tuple[str, ...], known: dict[str, str] | None = None,
            paths: Any = None) -> WorkspaceInputs:
    """What ``ws``'s (a :class:`rclverify.stages.workspace.Workspace`) cache was
    computed from.  ``known`` gives sha256s of contract files already taken
    in this run (by :func:`restore`, before the files were parsed).
    ``paths``: the plan paths whose targets are kept (a mapping of them, or
    their names): each resolved now (:func:`_resolved`)."""
    known = known or {}
    root = str(ws.root.resolve())
    return {"root": root, "plan_file": ws.plan_file,
            "plan": file_digest(f"{root}/{ws.plan_file}"),
            "contracts": {c: known[c] if c in known else file_digest(f"{root}/{c}") for c in contracts},
            "paths": _resolved(root, paths)}


def _own_profiles(plan: Any) -> tuple[str, ...]:
    """The workspace's own standard profile files the plan read (``standards:``, docs/standards.md),
    and a requirements file it read into itself (a FRET export, ``requirements_from: {fret: FILE}``;
    a Doorstop folder is read anew on every use): hashed with the contract files, so an edited
    profile or export loads the plan anew; the built-in profiles are package data
    (``Profile.builtin``), covered by the code's salt."""
    root = getattr(plan, "root", None)
    read = tuple(str(f) for f, _ in getattr(plan, "requirements_from", ()) if root is not None and (root / f).is_file())
    return tuple(str(c.profile.file) for c in getattr(plan, "standards", ())
                 if not getattr(c.profile, "builtin", False)) + read


def _resolved(root: str, paths: Any) -> dict[str, str] | None:
    """What each path of ``paths`` (a mapping or a collection of
    workspace-relative strings) leads to now (:func:`~.keys.resolved_paths`),
    or ``None`` when ``paths`` is not one (a cache that kept none: never
    equal to a plan's)."""
    if not isinstance(paths, (dict, list, tuple)) or not all(isinstance(v, str) for v in paths):
        return None
    return resolved_paths(root, paths)


def _open(ws: Any) -> BinaryIO | None:
    return open_stream(ws.root / CACHE, KIND, salt(KIND))


def restore(ws: Any) -> bool:
    """Fill ``ws``'s task index now, and its plan and parsed contracts on
    first use, from the cache when it is valid for the files on disk.
    Returns whether it did; never raises.

    The cache holds, after its header, what it was computed from, then the
    small :class:`~rclverify.stages.workspace.TaskIndex`, then the large part: the
    plan and the parsed contract files.  The checked contracts and the
    model are not kept: type-checking 1000 parsed nodes and building the
    model take 0.04 s, unpickling them took 0.4 s and pickling them 0.3 s.
    A valid cache sets ``ws.index`` at once and leaves the large part for
    ``ws.deferred`` (:func:`_load_deferred`): a no-op doit run defines its
    tasks from the index alone and never unpickles the contracts.

    When some input changed, what is still valid is reused: the parsed
    contract files whose text is unchanged (``ws.parsed``, checked against
    their sha256 when the workspace loads) and the plan when its own text is
    unchanged and every contract file it lists exists (it is resolved
    against the contracts again).  Editing one contract of a large system
    then re-parses one file.
    """
    wait()  # a save of this process still under way
    fh = _open(ws)
    if fh is None:
        return False
    try:
        with fh:
            kept = load(fh)
            if not isinstance(kept, dict):
                return False
            now = _inputs(ws, tuple(kept.get("contracts", ())), paths=kept.get("paths"))
            ws.cache_shas = now["contracts"]  # taken before any file is parsed: save() reuses them
            if any(kept.get(k) != now[k] for k in ("root", "plan_file")):
                return False
            index = load(fh)
            if kept == now:
                offset = fh.tell()
                ws.__dict__["index"] = index
                ws.deferred = lambda w: _load_deferred(w, kept, offset)
                return True
            plan, parsed = _load_large(fh)
    except Exception:  # a damaged or foreign cache is simply not used  # noqa: BLE001
        return False
    ws.parsed.update(parsed)  # re-validated per file by Workspace.checked
    same_paths = now["paths"] is not None and kept.get("paths") == now["paths"]
    same_profiles = all(kept.get("contracts", {}).get(f) == now["contracts"].get(f) for f in _own_profiles(plan))
    if kept.get("plan") == now["plan"] and same_paths and same_profiles \
            and all((ws.root / c).is_file() for c in plan.contracts):
        ws.__dict__["plan"] = plan
    return False


def _load_large(fh: Any) -> Any:
    with no_collection():  # the loaded objects are all live: collecting during the load only costs time
        return load(fh)


def _load_deferred(ws: Any, kept: WorkspaceInputs, offset: int) -> None:
    """Fill ``ws``'s plan and parsed contracts from the cache that
    :func:`restore` validated, if the cache file is still the one read then
    and the plan file is unchanged; else fill nothing (``ws`` then loads from
    the files, reusing nothing).  A contract file edited since is parsed
    again: ``Workspace.checked`` compares each parsed file's sha256 with the
    file.  Never raises."""
    fh = _open(ws)
    if fh is None:
        return
    try:
        with fh:
            if load(fh) != kept or file_digest(ws.root / ws.plan_file) != kept["plan"]:
                return  # the cache was rewritten or the plan changed since the run started
            fh.seek(offset)
            plan, parsed = _load_large(fh)
    except Exception:  # noqa: BLE001
        return
    ws.__dict__["plan"] = plan  # the cached_property slot
    ws.parsed.update(parsed)  # Workspace.checked type-checks these (0.03 s for 1000 nodes)


def save(ws: Any) -> None:
    """Write the cache for a workspace whose model loaded without error.
    Never raises (a cache that cannot be written is not written).

    The contract files' sha256s are those :func:`restore` took in this
    process, before the files were parsed (a file edited since is then
    parsed again next time), or taken now."""
    try:
        kept = _inputs(ws, tuple(ws.plan.contracts) + _own_profiles(ws.plan), ws.cache_shas)
        kept["paths"] = dict(ws.plan.path_targets)  # as resolved when the plan's paths were checked
        write_stream(ws.root / CACHE, KIND, salt(KIND), [kept, ws.index, (ws.plan, ws.parsed)])
    except Exception:  # noqa: BLE001
        pass


#: Background saves of this process: (pid of the process that forked, pid of the child).
_PENDING: list[tuple[int, int]] = []
#: Whether :func:`wait` is registered to run at exit (once per process).
_registered: list[bool] = []


def save_in_background(ws: Any) -> None:
    """:func:`save` in a forked child process, so that pickling the parsed
    contracts (0.3 s for 1000 nodes, on every run after an edit) overlaps
    with the rest of the run instead of delaying its first task
    (docs/scale.md, "What is kept between runs").  The process that forked waits for the
    child before it exits, and :func:`restore` first waits for it, so a
    run's cache is complete when the run ends, as with :func:`save`.
    Saves in this process where ``fork`` is missing or other threads run
    (forking a threaded process is unsafe: core/forksafe.py).  Never raises."""
    if not fork_is_safe():
        save(ws)
        return
    wait()
    try:
        pid = os.fork()
    except OSError:
        save(ws)
        return
    if pid == 0:  # the child: save, then leave without running the parent's exit handlers
        try:
            save(ws)
        finally:
            os._exit(0)
    if not _registered:
        atexit.register(wait)
        _registered.append(True)
    _PENDING.append((os.getpid(), pid))


def wait() -> None:
    """Wait for the background saves this process started (none in a
    process forked from it).  Never raises."""
    me = os.getpid()
    while _PENDING:
        parent, pid = _PENDING.pop()
        if parent != me:
            continue
        try:
            os.waitpid(pid, 0)
        except OSError:
            pass
