"""The workspace: its root, plan and checked contracts, loaded lazily, and
what is derived from them without running a stage.

Below the stages and the report: :mod:`rclverify.app.pipeline` (the stages),
:mod:`rclverify.report` (the roll-up), :mod:`rclverify.core.cache.workspace` and
:mod:`rclverify.stages.contract_texts` (kept between runs) all read a
:class:`Workspace`; this module imports none of them (the layers of
``tests/project/test_layers.py``).  It holds:

* :class:`Workspace` and :class:`TaskIndex` (what defining doit's tasks needs);
* the artifact paths and :func:`read_artifact`;
* :data:`REPORT_PARTS`, the report's files by doit task.

Each node's snapshot, the hashes the current inputs give and the record of
what each stage was made from (what makes a result stale) are
:mod:`rclverify.stages.provenance`'s.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import os
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, cast

from rclverify.lang.errors import RclError

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
    #: The plan's ``design`` folder (docs/nodl.md, "The design stage"): what the ``design`` task reads; empty: no such task.
    design: str = ""


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
                          if (fs := bound_inputs(self.root, plan, cn))},
            design=plan.design)

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
            plan_locs=self.plan.locs, mapping=plan_mapping(self.plan, node, entry.config),
            instances=tuple(self.plan.node_instances.get(node, ())))


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
