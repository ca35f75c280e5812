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

Requirement: the workers see the workspace at the same absolute path as the
local process (a shared file system, or a cluster on this machine), since a
job reads the contracts, the plan and the backend inputs, hashes them into
the evidence and renders the backend's artifacts next to them.
"""
from __future__ import annotations

import hashlib
import json
import os
import warnings
from pathlib import Path
from typing import Any

from rclverify.records.records import Evidence
from rclverify.records.store import EvidenceStore

#: Environment variable read by the ``evidence`` tasks of ``doit verify``.
CLUSTER_ENV = "RCLVERIFY_CLUSTER"
#: Seconds to wait for the scheduler before the job fails.
CONNECT_TIMEOUT_S = 30

_CLIENTS: dict[str, Any] = {}
_WORKER_WORKSPACES: dict[tuple[str, str, str], Any] = {}


class ClusterError(Exception):
    """The scheduler cannot be reached or the job could not be run there."""


def address() -> str | None:
    """The cluster address from :data:`CLUSTER_ENV`, or ``None`` (run locally)."""
    value = os.environ.get(CLUSTER_ENV, "").strip()
    return value or None


def workspace_key(root: Path, plan_file: str, contracts: tuple[str, ...]) -> str:
    """sha256 over the plan and contract files: a worker reloads its cached
    workspace when it differs (a long-lived worker outlives a contract edit)."""
    h = hashlib.sha256()
    for rel in (plan_file, *contracts):
        h.update(rel.encode() + b"\0")
        try:
            h.update(hashlib.sha256((root / rel).read_bytes()).digest())
        except OSError:
            h.update(b"-")
    return h.hexdigest()


def remote_run(root: str, plan_file: str, key: str, node: str, obligation_id: str) -> str:
    """The job a worker runs: the backend of one exported obligation.

    Returns the evidence record as JSON text; writes no evidence (the
    submitting process does).  The workspace is loaded once per worker and
    ``key`` (see :func:`workspace_key`).
    """
    from rclverify.core.cache import workspace as wscache
    from rclverify.backends import get_backend
    from rclverify.records.records import Obligation
    from rclverify.records.store import read_json
    from rclverify.semantics.world import fresh as fresh_z3
    from rclverify.stages.workspace import Workspace
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
        ev = get_backend(o.backend).run(o, ws.target(node, int(o.data.get("entry", 0))))
    return json.dumps(ev.to_json())


def _client(addr: str) -> Any:
    client = _CLIENTS.get(addr)
    if client is None:
        from dask.distributed import Client
        try:
            client = Client(addr, timeout=CONNECT_TIMEOUT_S, set_as_default=False)  # type: ignore[no-untyped-call]
        except (OSError, TimeoutError, ValueError) as exc:
            raise ClusterError(f"cannot reach the Dask scheduler at {addr}: {exc}") from None
        _CLIENTS[addr] = client
    return client


def run_on_cluster(addr: str, ws: Any, node: str, obligation_id: str) -> Evidence:
    """Run one obligation's backend job on the cluster at ``addr`` and store
    the returned evidence record in ``ws``'s evidence store.

    ``ws`` is the local :class:`~rclverify.app.pipeline.Workspace`.  Raises
    :class:`ClusterError` when the scheduler cannot be reached or the job
    raised on the worker.
    """
    root = str(ws.root.resolve())
    key = workspace_key(ws.root, ws.plan_file, tuple(ws.plan.contracts))
    client = _client(addr)
    future = client.submit(remote_run, root, ws.plan_file, key, node, obligation_id, pure=False,
                           key=f"rclverify-run-{obligation_id}-{os.urandom(4).hex()}")
    try:
        text = future.result()
    except Exception as exc:  # the job's own exception, re-raised by dask
        raise ClusterError(f"the job for {obligation_id} failed on the cluster at {addr}: "
                           f"{type(exc).__name__}: {exc}") from None
    ev = Evidence.from_json(json.loads(text))
    EvidenceStore(ws.root).put(ev)
    return ev
