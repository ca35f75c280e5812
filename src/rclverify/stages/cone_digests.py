"""A node's cone digest: Merkle hashes over the strongly connected components of the system model.

A side condition decided in context reads the contracts of its node's whole
upstream cone, and a derived property reads the environment conjuncts of
the cone's assumptions (docs/calculus.md); a change anywhere upstream must
make them stale.  One digest file per node (:meth:`rclverify.stages.workspace.Workspace.cone`)
holds two sha256s computed here, so a chain of N nodes hashes N files, not
N*N/2 snapshots (docs/integrity.md).
"""
from __future__ import annotations

import hashlib
from typing import Any, Mapping


def _merkle(model: Any, leaf: Mapping[str, str]) -> dict[str, str]:
    """``{node: sha256}`` over the strongly connected components of
    ``model``, producers first: a component's digest is the sha256 of its
    members' ``leaf`` values and of the sorted digests of the components
    feeding it.  It changes whenever the leaf of any node of the upstream
    cone changes.  O(nodes + links)."""
    comp: dict[str, tuple[str, ...]] = {n: (n,) for n in model.nodes}
    for loop in model.loops:
        for n in loop:
            comp[n] = tuple(loop)
    feeds: dict[tuple[str, ...], set[tuple[str, ...]]] = {}
    for c in set(comp.values()):
        feeds[c] = {comp[p] for m in c for p in model.producers(m)} - {c}
    digest: dict[tuple[str, ...], str] = {}
    for root in dict.fromkeys(comp[n] for n in model.nodes):  # iterative post-order over the component DAG
        if root in digest:
            continue
        stack = [(root, iter(sorted(feeds[root])))]
        while stack:
            c, it = stack[-1]
            for f in it:
                if f not in digest:
                    stack.append((f, iter(sorted(feeds[f]))))
                    break
            else:
                stack.pop()
                if c not in digest:
                    h = hashlib.sha256()
                    for m in c:
                        h.update(f"{m} {leaf[m]}\n".encode())
                    h.update(b"--\n")
                    for d in sorted(digest[f] for f in feeds[c]):
                        h.update(d.encode() + b"\n")
                    digest[c] = h.hexdigest()
    return {n: digest[comp[n]] for n in model.nodes}


def cone_digests(model: Any, snapshot_sha: Mapping[str, str], env_sha: Mapping[str, str]) -> dict[str, str]:
    """``{node: text}``: for every node of ``model`` (a
    :class:`~rclverify.model.system.model.SystemModel`) the text of its cone
    digest file (:meth:`Workspace.cone`), two lines: ``env <sha256>``, a
    digest of the environment conjuncts of the assumptions of its upstream
    cone (``env_sha``: node -> sha256 of their text; the derived property
    reads them), and ``cone <sha256>``, a digest of the snapshots of its
    whole upstream cone (``snapshot_sha``: node -> sha256 of its snapshot;
    side conditions in context read them, docs/calculus.md).  Merkle hashes
    over the cone's strongly connected components (:func:`_merkle`): one
    file per node, not N*N/2 snapshots along a chain.  Which line a node's
    ``compose`` stage depends on is :mod:`rclverify.app.conetask`'s business."""
    env, full = _merkle(model, env_sha), _merkle(model, snapshot_sha)
    return {n: f"env {env[n]}\ncone {full[n]}\n" for n in model.nodes}
