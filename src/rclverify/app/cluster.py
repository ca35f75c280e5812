"""Running backend jobs on a Dask distributed cluster.

``rclverify verify --cluster ADDRESS``, or ``RCLVERIFY_CLUSTER=ADDRESS doit
verify``, sends every backend job -- one obligation's ``run``: a Z3 check,
a Dafny run, an AJPF run, a property test -- to the Dask scheduler at
``ADDRESS`` (``tcp://host:8786``) instead of running it in the doit process.
Everything else (check, calculus, health, export, report) stays local: those
stages are cheap and write the artifacts the jobs read.

The worker rebuilds the obligation's :class:`~rclverify.backends.base.NodeTarget`
from the workspace files and runs the backend exactly as a local run does;
the evidence record comes back as JSON and the local process writes it into
the workspace's evidence store (``artifacts/evidence/<id>.json``, atomically).
The record is therefore byte for byte the one a local run writes, except the
timing fields ``started`` and ``duration_s``.

A worker that sees the workspace at the same absolute path as the local
process (a shared file system, or a cluster on this machine), with the same
plan and contracts, runs the job in place.  A worker that does not (another
machine, or a worker started with ``RCLVERIFY_CLUSTER_ISOLATED=1``) answers
that it needs the files; the local process then sends the workspace's
sources once per run and each job's share of ``artifacts/`` with the job,
the worker runs it in a copy in its own working folder, and the files the
job wrote come back with the record (:mod:`rclverify.app.cluster_files`).
"""
from __future__ import annotations

import json
import os
import warnings
from pathlib import Path
from typing import Any

from rclverify.records.records import Evidence
from rclverify.records.store import EvidenceStore
from rclverify.records.records import Obligation
from rclverify.records.store import read_json
from rclverify.semantics.world import fresh as fresh_z3
from rclverify.stages.workspace import Workspace
from rclverify.core.atomic import atomic_write_bytes

#: Environment variable read by the ``evidence`` tasks of ``doit verify``.
CLUSTER_ENV = "RCLVERIFY_CLUSTER"
#: Set on a worker whose file system is not the submitting machine's: never run a job in place.
ISOLATED_ENV = "RCLVERIFY_CLUSTER_ISOLATED"
#: The answer of a worker that cannot see the workspace.
NEEDS_FILES = "rclverify-needs-files"
#: Seconds to wait for the scheduler before the job fails.
CONNECT_TIMEOUT_S = 30

_CLIENTS: dict[str, Any] = {}
_WORKER_WORKSPACES: dict[tuple[str, str, str], Any] = {}
#: Per (address, workspace root): the scattered sources (digest, future) once the cluster asked for files.
_SHIPPED: dict[tuple[str, str], tuple[str, Any]] = {}


class ClusterError(Exception):
    """The scheduler cannot be reached or the job could not be run there."""


def address() -> str | None:
    """The cluster address from :data:`CLUSTER_ENV`, or ``None`` (run locally)."""
    value = os.environ.get(CLUSTER_ENV, "").strip()
    return value or None


def _in_place(root: str, plan_file: str, key: str) -> bool:
    """Can this worker run the job in the submitting process's own folder?"""
    if os.environ.get(ISOLATED_ENV, "").strip() not in ("", "0"):
        return False
    if (root, plan_file, key) in _WORKER_WORKSPACES:
        return True
    path = Path(root)
    if not (path / plan_file).is_file():
        return False
    from rclverify.app import cluster_files  # deferred: start-up (loads rclverify.app.cluster_files, io and more only when called)
    try:
        return cluster_files.digest(path) == key
    except cluster_files.ShippingError:
        return False


def _working_folder() -> Path:
    """The worker's own working folder (Dask's ``local_directory``), else the temporary folder."""
    try:
        from dask.distributed import get_worker  # deferred: optional or conditional (inside a block)
        return Path(get_worker().local_directory)
    except (ImportError, ValueError):
        import tempfile  # deferred: optional or conditional (inside a block)
        return Path(tempfile.gettempdir())


def remote_run(root: str, plan_file: str, key: str, node: str, obligation_id: str,
               shipped: tuple[str, bytes, dict[str, bytes]] | None = None) -> str:
    """The job a worker runs: the backend of one exported obligation.

    ``key`` is the sha256 of the workspace's sources
    (:func:`rclverify.app.cluster_files.digest`).  Without ``shipped``, runs
    in the workspace at ``root`` when this worker sees the same sources
    there, else returns :data:`NEEDS_FILES`.  With ``shipped`` (the
    sources' digest and archive, the node's artifact files), runs in the
    worker's copy (:mod:`rclverify.app.cluster_files`).

    Returns JSON text: ``{"evidence": record, "files": {path: base64}}``
    (the files the job wrote under ``artifacts/``; none when run in place),
    or :data:`NEEDS_FILES`.  Writes no evidence (the submitting process does).
    The workspace is loaded once per worker and sources' digest.
    """
    import base64  # deferred: start-up (loads base64 only when called)

    from rclverify.app import cluster_files  # deferred: start-up (loads rclverify.app.cluster_files, io and more only when called)
    files: dict[str, str] = {}
    if shipped is None:
        if not _in_place(root, plan_file, key):
            return NEEDS_FILES
        where = Path(root)
    else:
        name, blob, own = shipped
        where = cluster_files.materialise(_working_folder(), name, blob)
        cluster_files.place(where, own)
    before = cluster_files.listing(where, node) if shipped is not None else {}
    ev = _run_here(str(where), plan_file, key, node, obligation_id)
    if shipped is not None:
        files = {rel: base64.b64encode(data).decode() for rel, data in cluster_files.changed_files(where, node, before).items()}
    return json.dumps({"evidence": ev.to_json(), "files": files})


def _run_here(root: str, plan_file: str, key: str, node: str, obligation_id: str) -> Evidence:
    """One obligation's backend run in the workspace at ``root`` (loaded once per worker and ``key``)."""
    from rclverify.backends import get_backend  # deferred: start-up (loads rclverify.backends, importlib only when called)
    from rclverify.core.cache import workspace as wscache  # deferred: start-up (loads rclverify.core.cache, fractions and more only when called)
    ws = _WORKER_WORKSPACES.get((root, plan_file, key))
    if ws is None:
        ws = Workspace(Path(root), plan_file)
        wscache.restore(ws)
        _WORKER_WORKSPACES.clear()
        _WORKER_WORKSPACES[(root, plan_file, key)] = ws
    o = Obligation.from_json(read_json(ws.path(ws.obligation(node, obligation_id))))
    fresh_z3()  # as a local run does (pipeline.stage_run): the same Z3 state for every job
    with warnings.catch_warnings():
        # the worker's own threads (Dask's heartbeats) draw from `random` while a property test generates
        # its examples, and Hypothesis takes that for a strategy using `random` (ours do not: a local run
        # never warns); the warning would print the whole workspace's repr in the worker's log
        warnings.filterwarnings("ignore", message="Do not use the `random` module inside strategies")
        return get_backend(o.backend).run(o, ws.target(node, int(o.data.get("entry", 0))))


def _client(addr: str) -> Any:
    client = _CLIENTS.get(addr)
    if client is None:
        try:
            from dask.distributed import Client  # deferred: optional or conditional (inside a block)
        except ImportError:
            from rclverify.core.extras import missing_message  # deferred: optional or conditional (inside a block)
            raise ClusterError(missing_message("dask", "verification on a Dask cluster")) from None
        try:
            client = Client(addr, timeout=CONNECT_TIMEOUT_S, set_as_default=False)  # type: ignore[no-untyped-call]
        except (OSError, TimeoutError, ValueError) as exc:
            raise ClusterError(f"cannot reach the Dask scheduler at {addr}: {exc}") from None
        _CLIENTS[addr] = client
    return client


def _shipment(addr: str, client: Any, ws: Any, node: str) -> tuple[str, Any, dict[str, bytes]]:
    """The job's ``shipped`` argument: the sources scattered once per (address, workspace), the node's files."""
    from rclverify.app import cluster_files  # deferred: start-up (loads rclverify.app.cluster_files, io and more only when called)
    root = ws.root.resolve()
    have = _SHIPPED.get((addr, str(root)))
    if have is None:
        have = (_sources_digest(root), client.scatter(cluster_files.archive(root), hash=False))
        _SHIPPED[(addr, str(root))] = have
    return have[0], have[1], cluster_files.node_files(root, node)


_DIGESTS: dict[str, str] = {}


def _sources_digest(root: Path) -> str:
    """The sources' digest, taken once per process (a doit run's processes see one version of the sources)."""
    key = str(root)
    if key not in _DIGESTS:
        from rclverify.app import cluster_files  # deferred: optional or conditional (inside a block)
        _DIGESTS[key] = cluster_files.digest(root)
    return _DIGESTS[key]


def run_on_cluster(addr: str, ws: Any, node: str, obligation_id: str) -> Evidence:
    """Run one obligation's backend job on the cluster at ``addr`` and store
    the returned evidence record in ``ws``'s evidence store, and the files
    the job wrote (when it ran in a worker's copy) in ``ws``'s artifacts.

    ``ws`` is the local :class:`~rclverify.stages.workspace.Workspace`.  Raises
    :class:`ClusterError` when the scheduler cannot be reached, the
    workspace cannot be sent, or the job raised on the worker.
    """
    import base64  # deferred: start-up (loads base64 only when called)

    from rclverify.app import cluster_files  # deferred: start-up (loads rclverify.app.cluster_files, io and more only when called)
    root = str(ws.root.resolve())
    client = _client(addr)
    text = None
    try:
        key = _sources_digest(ws.root.resolve())
        for attempt in range(2):
            shipped = None
            if attempt or (addr, root) in _SHIPPED:
                shipped = _shipment(addr, client, ws, node)
            future = client.submit(remote_run, root, ws.plan_file, key, node, obligation_id, shipped, pure=False,
                                   key=f"rclverify-run-{obligation_id}-{os.urandom(4).hex()}")
            text = future.result()
            if text != NEEDS_FILES:
                break
    except cluster_files.ShippingError as exc:
        raise ClusterError(str(exc)) from None
    except Exception as exc:  # the job's own exception, re-raised by dask
        raise ClusterError(f"the job for {obligation_id} failed on the cluster at {addr}: "
                           f"{type(exc).__name__}: {exc}") from None
    if text is None or text == NEEDS_FILES:
        raise ClusterError(f"the job for {obligation_id} found no workspace on the cluster at {addr}")
    answer = json.loads(text)
    for rel, data in sorted(answer["files"].items()):
        target = ws.root / rel
        if not target.resolve().is_relative_to(ws.root.resolve()):
            raise ClusterError(f"the job for {obligation_id} sent back a file outside the workspace: {rel}")
        atomic_write_bytes(target, base64.b64decode(data))
    ev = Evidence.from_json(answer["evidence"])
    EvidenceStore(ws.root).put(ev)
    return ev
