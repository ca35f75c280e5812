"""What each stage of a workspace was made from, and what makes a result
stale (docs/integrity.md): each node's snapshot of the contracts and the
plan (:func:`node_snapshots`), the hashes the current inputs give
(:func:`current_snapshot_hashes`, :func:`current_model_hash`,
:func:`state_hashes`, :func:`cone_hashes`), the check index that spares the
report from making every snapshot again (:func:`write_check_index`), and
the record of the files each ``compose`` and ``health`` stage read
(:func:`record_provenance`, :func:`stage_inputs`) that :func:`stale_stages`
compares with them.

Below the stages and the report, beside :mod:`rclverify.stages.workspace`
(whose :class:`~rclverify.stages.workspace.Workspace` every function reads):
:mod:`rclverify.app.pipeline` writes the snapshots and records,
:mod:`rclverify.report.build` and :mod:`rclverify.report.records` compare.
"""
from __future__ import annotations

import hashlib
import os
from typing import Any, Mapping, Sequence

from rclverify.records.records import hash_inputs
from rclverify.records.store import SEAL, atomic_write_text, dumps, seal_of, sealed_dumps
from rclverify.stages.cone_digests import cone_digests
from rclverify.stages.workspace import Workspace, read_artifact


def node_snapshots(ws: Workspace, texts: Any) -> dict[str, dict[str, Any]]:
    """The snapshot of every node of ``ws`` (``{node: snapshot}``, source order):
    everything the node's own stages (compose, health, export) and its
    evidence read of the contracts and the plan, locations included.

    A snapshot holds the node's canonical RCL text, the shared context, its
    plan facts (text and location), instance range, evidence entries,
    replacement, and the source locations of the node, of each assumption and
    guarantee and of every value the plan gives for the node (so a comment
    that moves a guarantee, or a plan edit that moves an entry, changes the
    snapshot, and whatever shows those locations is made again).
    ``stage_check`` writes them (``artifacts/contracts/<Node>.json``); the
    report recomputes them from the current files to find evidence produced
    from another contract text (:func:`current_snapshot_hashes`).  ``texts``
    is the run's :class:`~rclverify.stages.contract_texts.ContractTexts` (the caller's: it
    sits above this module).
    Raises RclError/PlanError for contracts or a plan that do not check."""
    from rclverify.lang import ast  # deferred: start-up (loads rclverify.lang.ast, fractions only when called)
    from rclverify.lang.printer import to_rcl  # deferred: start-up (loads rclverify.lang.ast, rclverify.lang.printer and more only when called)
    checked, plan = ws.checked, ws.plan
    context_text = to_rcl(ast.Spec(tuple(c for s in checked.specs for c in s.contexts), ()))
    plan_locs: dict[str, dict[str, str]] = {}  # node -> {value path under nodes.<node>: "line:col"}
    for path, loc in plan.locs.items():
        if len(path) > 1 and path[0] == "nodes":
            plan_locs.setdefault(str(path[1]), {})["/".join(map(str, path[2:]))] = f"{loc.line}:{loc.col}"
    out: dict[str, dict[str, Any]] = {}
    for name, cn in checked.nodes.items():
        tx = texts.node(cn.node)
        out[name] = {
            "node": name, "rcl": tx["rcl"], "context": context_text,
            "facts": [f.text for f in plan.facts.get(name, ())],
            "fact_sources": [str(f.loc) for f in plan.facts.get(name, ())],
            "instances": list(plan.instances[name]) if name in plan.instances else None,
            "evidence": [dict(e.config) for e in plan.evidence.get(name, ())],
            "replacement": plan.replacements[name][0] if name in plan.replacements else None,
            "source": f"{cn.node.loc.file}:{cn.node.loc.line}",
            "sources": {"node": str(cn.node.loc), "assumptions": [src for _, src in tx["assumptions"]],
                        "guarantees": [src for _, src in tx["guarantees"]]},
            "plan_locations": dict(sorted(plan_locs.get(name, {}).items())),
        }
    return out


def environment_sha(ws: Workspace) -> dict[str, str]:
    """``{node: sha256 of the text of the environment conjuncts of its assumption}``."""
    from rclverify.calculus.compose import environment_texts  # deferred: start-up (loads lark, yaml and more only when called)
    return {n: hashlib.sha256("\n".join(environment_texts(ws.checked, ws.model, n)).encode("utf-8")).hexdigest()
            for n in ws.checked.nodes}


def cone_hashes(ws: Workspace, hashes: Mapping[str, str]) -> dict[str, str]:
    """``{artifacts/cones/<Node>.sha256: sha256 of its text}`` for the
    snapshot hashes ``hashes`` (artifact path -> sha256, as
    :func:`current_snapshot_hashes` gives them)."""
    texts = cone_digests(ws.model, {n: hashes[ws.snapshot(n)] for n in ws.checked.nodes}, environment_sha(ws))
    return {ws.cone(n): hashlib.sha256(t.encode("utf-8")).hexdigest() for n, t in texts.items()}


def check_input_files(ws: Workspace) -> list[str]:
    """The workspace-relative files the snapshots and the system model are
    made from: the plan, its contract files and the replacement contract
    files (what :attr:`Workspace.checked` reads), in that order."""
    index = ws.index
    return [ws.plan_file, *index.contracts, *sorted(set(index.replacement.values()) - set(index.contracts))]


def check_inputs(ws: Workspace) -> dict[str, str]:
    """``{file: sha256}`` of each of :func:`check_input_files`."""
    from rclverify.core.cache import file_digest  # deferred: start-up (loads rclverify.core.cache, fractions and more only when called)
    return {f: file_digest(ws.path(f)) for f in check_input_files(ws)}


def write_check_index(ws: Workspace, hashes: dict[str, str]) -> None:
    """Record, after ``check`` wrote the snapshots and the model, their
    sha256s (``hashes``: artifact path -> sha256) with the rclverify code
    and the sha256 of each file they were made from (:func:`check_inputs`),
    sealed as evidence records are, in :attr:`Workspace.CHECK_INDEX`.
    Raises ``OSError``."""
    from rclverify.core.cache import code_stamp  # deferred: start-up (loads rclverify.core.cache, fractions and more only when called)
    body = {"code": code_stamp(), "inputs": check_inputs(ws), "hashes": hashes}
    atomic_write_text(ws.path(ws.CHECK_INDEX), sealed_dumps(body))


def current_snapshot_hashes(ws: Workspace, texts: Any) -> dict[str, str]:
    """``{artifacts/contracts/<Node>.json: sha256}`` of the snapshots the
    current contract and plan files give (:func:`node_snapshots`), whatever
    the snapshot files under ``artifacts/`` say, and the same for the system
    model (:func:`current_model_hash`): the hashes an evidence record's
    ``input_hashes`` are compared with, so evidence produced from another
    contract text is ``stale`` even when no ``check`` ran since the edit
    (``rclverify report``).

    When the check index (:func:`write_check_index`) was written by this
    code (and carries its seal, as evidence records do) from files that
    still have the same sha256s, its hashes are the ones the files give
    (snapshots and model are pure functions of those files and the code)
    and are returned without making every snapshot again (0.45 s of each
    report task at 1000 nodes).  Raises like :func:`node_snapshots`."""
    from rclverify.core.cache import code_stamp  # deferred: start-up (loads rclverify.core.cache, fractions and more only when called)
    kept = read_artifact(ws, ws.CHECK_INDEX, None)
    if (isinstance(kept, dict) and kept.get("code") == code_stamp() and isinstance(kept.get("hashes"), dict)
            and kept.get(SEAL) == seal_of(kept) and kept.get("inputs") == check_inputs(ws)):
        return {**kept["hashes"], **state_hashes(ws)}
    snaps = {ws.snapshot(n): hashlib.sha256(dumps(snap).encode("utf-8")).hexdigest()
             for n, snap in node_snapshots(ws, texts).items()}
    return {**snaps, **cone_hashes(ws, snaps), **current_model_hash(ws), **state_hashes(ws)}


def state_hashes(ws: Workspace) -> dict[str, str]:
    """``{"state:<Node>": sha256}`` of every node's declarations in the
    plan's ``state:`` (:func:`rclverify.model.plan.state.state_sha256`): a
    requirement record holds those of its cone's nodes, so a ``state:`` edit
    shows it stale in ``rclverify report`` before the requirements stage ran."""
    from rclverify.model.plan.state import state_key, state_sha256  # deferred: start-up (loads rclverify.lang.ast, rclverify.lang.types and more only when called)
    return {state_key(n): state_sha256(ws.plan.states, n) for n in ws.checked.nodes}


def record_provenance(ws: Workspace, node: str, stage: str, inputs: Sequence[str]) -> None:
    """Record in ``artifacts/provenance/<stage>/<node>.json`` (``{stage:
    {path: sha256}}``, sealed) the sha256 of each workspace-relative file in
    ``inputs``, after ``stage`` of ``node`` wrote its outputs from them (a
    stage killed before that records nothing).  The report compares them with
    the inputs' current hashes (:func:`stale_stages`), so the side conditions
    or health findings of a contract edited since are shown ``stale``, never
    with the status of the old text (``rclverify report`` runs no stage).
    Each stage has a file of its own and writes it whole: ``node:<Node>``
    (compose) and ``health:<Node>`` run at once in ``doit -n 2``, and a
    shared file read, changed and written by both would lose one's record.
    Raises ``OSError`` when the file cannot be written."""
    from rclverify.records.sealed import write_sealed  # deferred: start-up (loads rclverify.records.sealed only when called)
    write_sealed(ws.path(ws.provenance(node, stage)), {stage: hash_inputs(ws.root, list(inputs))})


def drop_old_provenance(ws: Workspace) -> None:
    """Remove ``artifacts/provenance/<Node>.json``, the record of both stages
    that versions before the split into ``node:`` and ``health:`` tasks wrote:
    nothing reads it, and a bundle would carry it.  Called by the check stage
    (which an upgrade runs again, its code having changed), not by every
    stage of every node.  Raises ``OSError`` when a file cannot be removed."""
    folder = ws.path("artifacts/provenance")
    for old in (folder.glob("*.json") if folder.is_dir() else ()):
        old.unlink(missing_ok=True)


def stage_inputs(ws: Workspace, node: str, stage: str, in_context: bool = True) -> list[str]:
    """The workspace-relative files the contents of ``stage`` (``compose`` or
    ``health``) of ``node`` are made from: its snapshot, for ``compose`` its
    producers' snapshots, its cone digest (:meth:`Workspace.cone`: side
    conditions in context read the whole upstream cone; not with
    ``in_context=False``: the record of a composition whose side conditions
    were all decided locally, which the rest of the cone cannot change;
    :mod:`rclverify.app.conetask` reads which the record lists) and the system
    model, for ``health`` the plan's replacement contract file if any and
    the files its output sequences' bounds are read from
    (:func:`rclverify.stages.interface_bounds.bound_inputs`).
    (Export's are the inputs of each obligation, hashed into its
    evidence.)"""
    if stage == "compose":
        return [ws.snapshot(node), *(ws.snapshot(p) for p in ws.model.producers(node)),
                *([ws.cone(node)] if in_context else []), ws.MODEL]
    from rclverify.stages.interface_bounds import bound_inputs  # deferred: start-up (loads z3 only when called)
    repl = ws.plan.replacements.get(node)
    return [ws.snapshot(node)] + ([repl[0].rpartition(":")[0]] if repl else []) + bound_inputs(ws.root, ws.plan,
                                                                                             ws.checked.nodes[node])


def stale_stages(ws: Workspace, current: dict[str, str]) -> dict[str, set[str]]:
    """``{node: {stage, ...}}`` for every node of ``ws`` whose ``compose`` or
    ``health`` artifacts were made from files other than those the current
    contracts and plan give: a recorded hash differs from ``current`` (path
    -> sha256; :func:`current_snapshot_hashes` plus :func:`current_model_hash`;
    other files are hashed here and added to it), or nothing was recorded.
    Nodes with no artifacts yet are left out."""
    from rclverify.records.sealed import read_sealed  # deferred: start-up (loads rclverify.records.sealed only when called)
    out: dict[str, set[str]] = {}
    for n in ws.checked.nodes:
        for stage, artifact in (("compose", ws.calculus(n)), ("health", ws.health(n))):
            if not os.path.exists(os.path.join(ws.root, artifact)):
                continue
            rec, altered = read_sealed(ws.path(ws.provenance(n, stage)))
            if altered:  # sealed (records/sealed.py): what an altered record says is not believed
                rec = None
            made = rec.get(stage) if isinstance(rec, dict) else None
            allowed = [set(stage_inputs(ws, n, stage))] + ([set(stage_inputs(ws, n, stage, False))]
                                                           if stage == "compose" else [])
            if not isinstance(made, dict) or set(made) not in allowed:
                out.setdefault(n, set()).add(stage)
                continue
            missing = [p for p in made if p not in current]
            if missing:
                current.update(hash_inputs(ws.root, missing))
            if any(current[p] != h for p, h in made.items()):
                out.setdefault(n, set()).add(stage)
    return out


def current_model_hash(ws: Workspace) -> dict[str, str]:
    """``{artifacts/system/model.json: sha256}`` of the model the current
    contracts and plan give (what ``check`` would write)."""
    return {ws.MODEL: hashlib.sha256(dumps(ws.model.to_json()).encode("utf-8")).hexdigest()}


__all__ = ["check_input_files", "check_inputs", "cone_hashes", "current_model_hash", "current_snapshot_hashes",
           "drop_old_provenance", "environment_sha", "node_snapshots", "record_provenance", "stage_inputs",
           "stale_stages", "state_hashes", "write_check_index"]
