"""The workspace: its root, plan and checked contracts, loaded lazily, and
what is derived from them without running a stage.

Below the stages and the report: :mod:`rclverify.app.pipeline` (the stages),
:mod:`rclverify.report` (the roll-up), :mod:`rclverify.core.cache.workspace` and
:mod:`rclverify.stages.contract_texts` (kept between runs) all read a
:class:`Workspace`; this module imports none of them (the layers of
``tests/project/test_layers.py``).  It holds:

* :class:`Workspace` and :class:`TaskIndex` (what defining doit's tasks needs);
* the artifact paths and :func:`read_artifact`;
* each node's snapshot (:func:`node_snapshots`) and the hashes the current
  inputs give (:func:`current_snapshot_hashes`, :func:`current_model_hash`),
  the record of what each stage was made from (:func:`record_provenance`,
  :func:`stale_stages`): what makes a result stale (docs/integrity.md);
* :data:`REPORT_PARTS`, the report's files by doit task.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import os
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Mapping, Sequence, cast

from rclverify.records.store import dumps
from rclverify.lang.errors import RclError
from rclverify.stages.cone_digests import cone_digests as cone_digests  # also where app/pipeline.py finds it
from rclverify.records.store import atomic_write_text, sealed_dumps, SEAL, seal_of
from rclverify.records.records import hash_inputs

if TYPE_CHECKING:
    from rclverify.backends.base import NodeTarget
    from rclverify.model.plan.load import Plan
    from rclverify.lang import ast
    from rclverify.lang.errors import Diagnostic
    from rclverify.lang.types import Checked
    from rclverify.model.system.model import SystemModel

PLAN = "contracts/plan.yaml"


def _parse(text: str, rel: str) -> ast.Spec:
    """The syntax tree of the contract file ``rel`` whose text is ``text``:
    kept by a process that keeps its start-up (:mod:`rclverify.core.cache.startup`,
    keyed by ``rel`` and ``text``), else parsed.  Raises :class:`RclError`
    on a syntax error (never kept: it is always reported from the text)."""
    from rclverify.core.cache.startup import active  # deferred: start-up (loads rclverify.core.cache.store only when called)
    from rclverify.lang.ast import Spec  # deferred: start-up (what a kept entry must be)
    kept = active()
    spec = kept.get("contract", rel, text) if kept is not None else None
    if isinstance(spec, Spec):
        return spec
    from rclverify.lang.parser import parse_text  # deferred: start-up (loads lark, rclverify.core.cache and more only when called)
    spec = parse_text(text, rel)
    if kept is not None:
        kept.put("contract", spec, rel, text)
    return spec


@dataclass(frozen=True)
class TaskIndex:
    """What defining a workspace's doit tasks needs of its loaded plan and
    model (:func:`rclverify.app.tasks.build_tasks`), small enough to be read on
    every run: a no-op run of a large system reads this and not the checked
    contracts (:mod:`rclverify.core.cache.workspace`, docs/scale.md).

    ``nodes`` in source order; ``producers[n]`` the nodes feeding ``n`` (system
    model, rule R3's premises); ``contracts`` the plan's contract files;
    ``replacement[n]`` the file of ``n``'s replacement contract (plan
    ``replacements``); ``entries[n]`` the config mappings of ``n``'s plan
    evidence entries, in plan order (the files they name are dependencies of
    the export stage of ``node:n``).  Paths are workspace-relative strings.
    """

    nodes: tuple[str, ...]
    producers: dict[str, tuple[str, ...]]
    contracts: tuple[str, ...]
    replacement: dict[str, str]
    entries: dict[str, tuple[Any, ...]]
    #: The plan's ``requirements_from`` Doorstop folders (their files are inputs of ``requirements``).
    requirement_dirs: tuple[str, ...] = ()
    #: The plan's ``ros:`` section (docs/ros.md): what the ``ground`` task reads; empty: no such task.
    ros: dict[str, Any] = dataclasses.field(default_factory=dict)
    #: The nodes on the paths of the plan's end-to-end deadlines (rule D3) and every node between their
    #: ends (the worst path, :func:`rclverify.calculus.worst_path.nodes_between`): their snapshots are the
    #: inputs of the ``deadlines`` task; empty: the plan has no deadline and there is no such task.
    deadline_nodes: tuple[str, ...] = ()
    #: The workspace's own standard profile files the plan names (docs/standards.md): inputs of ``report``.
    profiles: tuple[str, ...] = ()
    #: Per node with an output sequence, the files its bounds are read from (the mapping and its ``.msg``
    #: files, :func:`rclverify.stages.interface_bounds.bound_inputs`): inputs of ``health:<node>``.
    bound_inputs: dict[str, tuple[str, ...]] = dataclasses.field(default_factory=dict)


@dataclass
class Workspace:
    """A workspace root plus its plan; loads and checks lazily (cached).

    Raises :class:`~rclverify.lang.errors.RclError` (or PlanError) from the
    properties when the contracts or the plan are wrong.
    """

    root: Path
    plan_file: str = PLAN
    #: Parsed contract files of an earlier load, ``rel -> (sha256 of the text, Spec)``;
    #: a file whose text has the same hash is not parsed again (see :mod:`rclverify.core.cache.workspace`).
    parsed: dict[str, tuple[str, ast.Spec]] = dataclasses.field(default_factory=dict, repr=False, compare=False)
    #: Set by :func:`rclverify.core.cache.workspace.restore`: fills ``plan`` and ``parsed``
    #: from the cache the first time the plan or the checked contracts are needed.
    deferred: Callable[["Workspace"], None] | None = dataclasses.field(default=None, repr=False, compare=False)
    #: Set by :func:`rclverify.core.cache.workspace.restore`: the sha256 of each contract file it found, taken
    #: before any file was parsed; :func:`rclverify.core.cache.workspace.save` writes them into the new cache.
    cache_shas: dict[str, str] | None = dataclasses.field(default=None, repr=False, compare=False)
    #: Nodes that may be declared by their interface only (``rclverify quotient``; the type checker's
    #: ``interface_only``); no stage of the pipeline loads a workspace with any.
    interface_only: tuple[str, ...] = ()
    #: Review records (workspace-relative) that may be missing: the one ``rclverify review NODE -o FILE``
    #: is about to write (before, the plan's check refused the command that creates it)
    missing_ok: tuple[str, ...] = ()

    def path(self, rel: str) -> Path:
        return self.root / rel

    def _run_deferred(self) -> None:
        """Run the deferred cache load (once): it may fill ``plan`` and ``parsed``."""
        if self.deferred is not None:
            load, self.deferred = self.deferred, None
            load(self)

    @cached_property
    def plan(self) -> Plan:
        self._run_deferred()
        cached = self.__dict__.get("plan")
        if cached is not None:
            return cast("Plan", cached)
        from rclverify.model.plan.load import load_plan  # deferred: start-up (loads yaml, rclverify.lang.ast and more only when called)
        return load_plan(self.root, self.plan_file)

    @cached_property
    def index(self) -> TaskIndex:
        """The :class:`TaskIndex` of the loaded workspace (raises like :attr:`model`)."""
        from rclverify.calculus.worst_path import nodes_between  # deferred: start-up (loads yaml, z3 and more only when called)
        from rclverify.stages.interface_bounds import bound_inputs  # deferred: as above
        plan, model = self.plan, self.model
        return TaskIndex(
            nodes=tuple(self.checked.nodes), producers={n: tuple(model.producers(n)) for n in self.checked.nodes},
            contracts=tuple(plan.contracts), replacement={n: r[0].rpartition(":")[0] for n, r in plan.replacements.items()},
            entries={n: tuple(e.config for e in es) for n, es in plan.evidence.items()},
            requirement_dirs=tuple(d for d, _ in plan.requirements_from),
            ros=dict(getattr(plan, "ros", None) or {}),
            # every node between a deadline's ends: the slowest path may leave the named one
            deadline_nodes=tuple(dict.fromkeys(n for d in plan.deadlines for n in nodes_between(model, d.path))),
            profiles=tuple(c.profile.file for c in plan.standards if not c.profile.builtin),
            bound_inputs={n: tuple(fs) for n, cn in self.checked.nodes.items()
                          if (fs := bound_inputs(self.root, plan, cn))})

    @cached_property
    def checked(self) -> Checked:
        self._run_deferred()
        from rclverify.model.plan.load import resolve  # deferred: start-up (loads yaml, rclverify.lang.ast and more only when called)
        from rclverify.lang.source import read_text as read_source  # deferred: start-up (loads rclverify.lang.ast, rclverify.lang.source and more only when called)
        from rclverify.lang.typecheck import check  # deferred: start-up (loads lark, rclverify.core.cache and more only when called)
        plan = self.plan
        specs = []
        diags: list[Diagnostic] = []
        for rel in plan.contracts:  # parsed under their workspace-relative names
            try:
                text = read_source(self.root / rel, rel)
            except RclError as exc:
                diags.extend(exc.diagnostics)
                continue
            sha = hashlib.sha256(text.encode("utf-8")).hexdigest()
            if rel in self.parsed and self.parsed[rel][0] == sha:
                specs.append(self.parsed[rel][1])
                continue
            try:
                spec = _parse(text, rel)
            except RclError as exc:
                diags.extend(exc.diagnostics)
                continue
            self.parsed[rel] = (sha, spec)
            specs.append(spec)
        if diags:
            raise RclError(diags)
        c = check(specs, self.interface_only)
        from rclverify.semantics.definedness import constant_faults  # deferred: start-up (loads the evaluator only when called)
        undefined = constant_faults(c)  # a constant dividing by zero, at its definition (docs/rcl-language.md)
        if undefined:
            raise RclError(undefined)
        from rclverify.model.plan.errors import PlanError  # deferred: start-up (loads rclverify.lang.ast, rclverify.model and more only when called)
        try:
            resolve(self.plan, c)
        except PlanError as exc:
            raise PlanError(list(exc.diagnostics) + self._entry_diagnostics(c)) from None
        entry_diags = self._entry_diagnostics(c)
        if entry_diags:
            raise PlanError(entry_diags)
        return c

    def _entry_diagnostics(self, c: Checked) -> list[Diagnostic]:
        """The backends' check-time validation of the plan's entries (experiment
        data, review records, trace mappings): run here, above both the plan and
        the backends, so that no plan module imports backend code."""
        from rclverify.backends.entry_checks import check_entries  # deferred: start-up (loads yaml, rclverify.backends and more only when called)
        diags = check_entries(self.plan, c)
        return [d for d in diags if not any(f"review record {r!r} does not exist" in d.message for r in self.missing_ok)]

    @cached_property
    def model(self) -> SystemModel:
        from rclverify.model.system.model import build  # deferred: start-up (loads yaml, rclverify.lang.ast and more only when called)
        return build(self.checked, self.plan.connections)

    def node_names(self) -> list[str]:
        if "index" in self.__dict__:
            return list(self.index.nodes)
        return list(self.checked.nodes)

    # -- artifact paths ---------------------------------------------------------------
    @staticmethod
    def snapshot(node: str) -> str:
        return f"artifacts/contracts/{node}.json"

    @staticmethod
    def cone(node: str) -> str:
        """The digest of ``node``'s upstream cone's snapshots (:func:`cone_digests`):
        an input of its ``compose`` stage, whose in-context side conditions read the whole cone."""
        return f"artifacts/cones/{node}.sha256"

    @staticmethod
    def calculus(node: str) -> str:
        return f"artifacts/calculus/{node}.json"

    @staticmethod
    def health(node: str) -> str:
        return f"artifacts/health/{node}.json"

    @staticmethod
    def obligations(node: str) -> str:
        return f"artifacts/obligations/{node}.json"

    @staticmethod
    def obligation(node: str, obligation_id: str) -> str:
        """One obligation's own record: the input of its evidence task."""
        return f"artifacts/obligations/{node}/{obligation_id}.json"

    @staticmethod
    def evidence(obligation_id: str) -> str:
        return f"artifacts/evidence/{obligation_id}.json"

    @staticmethod
    def provenance(node: str, stage: str) -> str:
        """What ``stage`` (``compose`` or ``health``) of the node was made from
        (:func:`record_provenance`): one file a stage, because the two stages
        are tasks of their own that may run at once in two doit processes."""
        return f"artifacts/provenance/{stage}/{node}.json"

    MODEL = "artifacts/system/model.json"
    #: What ``check`` wrote the snapshots and the model from, and their sha256s (:func:`write_check_index`).
    CHECK_INDEX = "artifacts/check/index.json"
    DOT = "artifacts/system/model.dot"
    DIAGNOSTICS = "artifacts/check/diagnostics.json"
    #: What ``verify`` prints (:func:`rclverify.report.summary.summary_data`), written with the report.
    SUMMARY = "artifacts/report/summary.json"

    def target(self, node: str, index: int) -> NodeTarget:
        from rclverify.backends.base import NodeTarget  # deferred: start-up (loads yaml, rclverify.backends and more only when called)
        from rclverify.model.plan.mapping_file import plan_mapping  # deferred: start-up (as NodeTarget)
        entry = self.plan.evidence[node][index]
        return NodeTarget(
            root=self.root.resolve(), checked=self.checked, node=self.checked.nodes[node], config=entry.config,
            facts=tuple(f.expr for f in self.plan.facts.get(node, ())), contract_files=self.plan.contracts,
            plan_file=self.plan.file, artifacts=(self.root / "artifacts" / entry.backend / node).resolve(), index=index,
            plan_locs=self.plan.locs, mapping=plan_mapping(self.plan, node, entry.config))


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


#: The report's files under ``reports/`` in two parts, each written by a doit task of its own
#: (:mod:`rclverify.report.parts`; ``argument.svg`` only when the argument is laid out).  Here, not
#: there: the task definitions of every run name these files, and the report modules import jinja2.
REPORT_PARTS: dict[str, tuple[str, ...]] = {
    "html": ("assurance.html", "assurance.json", "assurance.sarif", "assurance.junit.xml", "argument.svg"),
    "text": ("assurance.md", "argument.json", "argument.gsn.yaml", "argument.dot"),
}


def read_artifact(ws: Workspace, rel: str, default: Any = None) -> Any:
    """JSON of an artifact, or ``default`` when it does not exist yet.  (The
    path is joined as text and the bytes decoded by ``json``: the report
    reads thousands of artifacts, and ``pathlib`` was a third of that.)"""
    try:
        with open(os.path.join(ws.root, rel), "rb") as fh:
            return json.loads(fh.read())
    except FileNotFoundError:
        return default
