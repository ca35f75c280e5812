"""The pipeline's stages as plain functions over a workspace's artifacts.

Each stage reads its inputs (the RCL files, the plan, earlier stages' JSON
under ``artifacts/``) and writes its own outputs atomically; no stage reaches
into another's internals.  doit (:mod:`rclverify.app.tasks`) and the CLI
(:mod:`rclverify.cli.commands`) both call these functions.

Artifact layout (workspace-relative)::

    artifacts/check/diagnostics.json     lint warnings of the contracts
    artifacts/contracts/<Node>.json      canonical snapshot of one node's contract,
                                         the shared context, its facts and plan entries
    artifacts/system/model.json|.dot     the system model
    artifacts/calculus/<Node>.json       rule instances, side conditions, derived property (sealed)
    artifacts/calculus/<Node>.sc<k>.smt2 each side condition as SMT-LIB2
    artifacts/health/<Node>.json         contract health findings ({"node", "findings"}, sealed)
    artifacts/obligations/<Node>.json    exported obligations of the node ({"obligations"}, sealed)
    artifacts/evidence/<obligation>.json one evidence record per obligation
    artifacts/requirements/<ID>.json     a requirement's Z3 check (proved/refuted/...)
    artifacts/deadlines/index.json       the end-to-end deadlines decided by rule D3 (sealed),
                                         each query as artifacts/deadlines/<ID>.smt2
    artifacts/nodl/index.json            the NoDL documents of nodl/ against the contracts and each
                                         other (sealed; stages/nodl.py, run by the nodl task)
    artifacts/diagnosis/index.json       one diagnosis per problem of the report, repairs checked
                                         by Z3, with the digest of the report they explain (sealed)
"""
from __future__ import annotations

import hashlib

import dataclasses
from pathlib import Path
from typing import TYPE_CHECKING, Any, Mapping, Sequence, TypeGuard, cast

from rclverify.records.records import Evidence, Obligation
from rclverify.records.sealed import write_sealed
from rclverify.records.store import EvidenceStore, atomic_write_text, dumps, write_obligations
from rclverify.records.ties import tie_query
from rclverify.semantics.world import fresh as fresh_z3
from rclverify.lang.errors import RclError, error
# The workspace and what is derived from it without a stage live below the report
# (rclverify.stages.workspace, rclverify.stages.provenance); re-exported here for the stages' callers.
from rclverify.stages.workspace import PLAN, REPORT_PARTS, TaskIndex, Workspace, read_artifact  # noqa: F401
from rclverify.stages.cone_digests import cone_digests
from rclverify.stages.provenance import (drop_old_provenance, environment_sha, node_snapshots, record_provenance,
                                         stage_inputs, write_check_index)
from rclverify.records.sealed import read_sealed

if TYPE_CHECKING:
    from rclverify.calculus.health.checks import Finding
    from rclverify.records.findings import HealthFinding
    from rclverify.model.plan.model import EvidenceEntry
    from rclverify.records.report_record import AssuranceReport
    from rclverify.records.composition_records import CheckRecord, CompositionRecord
    from rclverify.records.stage_records import DeadlineRecord, DiagnosisRecord, RequirementRecord

# The parser, type checker, calculus, health checks, lint and backends are
# imported where a stage uses them: a doit run that reuses the cached
# workspace and runs no such stage (a no-op) never needs them (docs/scale.md).

def stage_check(ws: Workspace) -> CheckRecord:
    """Parse, type-check, resolve the plan, lint; write snapshots (:func:`node_snapshots`)
    and the system model.

    Returns the diagnostics JSON (lint warnings).  Raises RclError/PlanError.
    """
    from rclverify.stages.contract_texts import ContractTexts  # deferred: start-up (loads rclverify.core.cache, rclverify.lang.ast and more only when called)
    checked, model = ws.checked, ws.model
    texts = ContractTexts(ws)  # each file's lint and each node's RCL text, kept by the file's sha256
    warnings = [w for s in checked.specs for w in texts.lint(s)]
    # units across connections: a missing unit (warning), a mismatch (an error row at the producer's end, the run
    # going on)
    from rclverify.model.system.units import producer_diagnostics  # deferred: start-up (loads rclverify.lang.ast, rclverify.lang.printer and more only when called)
    warnings += [d.to_json() for d in producer_diagnostics(checked, model.links)]
    from rclverify.model.system.services import unserved  # deferred: start-up (loads rclverify.lang.ast, rclverify.lang.types and more only when called)
    warnings += [d.to_json() for d in unserved(checked)]  # a call no node answers (W-unserved)
    write_sealed(ws.path(ws.DIAGNOSTICS), {"warnings": warnings})
    hashes: dict[str, str] = {}
    for name, snap in node_snapshots(ws, texts).items():
        text = dumps(snap)
        atomic_write_text(ws.path(ws.snapshot(name)), text)
        hashes[ws.snapshot(name)] = hashlib.sha256(text.encode("utf-8")).hexdigest()
    for name, text in cone_digests(model, {n: hashes[ws.snapshot(n)] for n in checked.nodes},
                                   environment_sha(ws)).items():
        _write_if_changed(ws.path(ws.cone(name)), text)  # unchanged: doit and the node's compose stage see no edit
        hashes[ws.cone(name)] = hashlib.sha256(text.encode("utf-8")).hexdigest()
    try:
        texts.save()
    except OSError:
        pass  # a cache that cannot be written is not written: the texts are made again next time
    text = dumps(model.to_json())
    atomic_write_text(ws.path(ws.MODEL), text)
    hashes[ws.MODEL] = hashlib.sha256(text.encode("utf-8")).hexdigest()
    write_check_index(ws, hashes)  # the report then needs not make every snapshot again
    drop_old_provenance(ws)
    return cast("CheckRecord", {"warnings": warnings})


def _write_if_changed(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` atomically unless the file already holds it."""
    try:
        if path.read_text(encoding="utf-8") == text:
            return
    except (OSError, UnicodeDecodeError):
        pass
    atomic_write_text(path, text)


def stage_graph(ws: Workspace) -> str:
    """Write the system model as Graphviz DOT (``artifacts/system/model.dot``,
    the model without statuses) and return its text.  Not part of ``check``:
    only ``doit graph`` and ``rclverify graph`` need it, and finding the
    model's loops for it took a fifth of the check stage of a 1000-node
    system.  Raises ``RclError`` for contracts or a plan that do not check."""
    from rclverify.report.diagram import system_dot  # deferred: start-up (loads jinja2, rclverify.core.cache and more only when called)
    dot = system_dot(ws.model.view({}))
    atomic_write_text(ws.path(ws.DOT), dot)
    return dot


def stage_compose(ws: Workspace, node: str) -> CompositionRecord:
    """Apply the calculus to ``node``; writes its JSON and one .smt2 per side condition."""
    fresh_z3()  # the same Z3 state whatever ran before in this process (semantics/world.py)
    from rclverify.calculus.compose import compose_node, composition_json  # deferred: start-up (loads lark, yaml and more only when called)
    from rclverify.calculus import summary  # deferred: start-up (loads z3 only when called)
    summary.use_directory(ws.path("artifacts/cache/summaries"))  # the other worker's and earlier runs' summaries
    try:
        comp = compose_node(ws.checked, ws.model, node, facts=plan_facts(ws))
    finally:
        summary.use_directory(None)  # this workspace's only: a later computation in the process keeps its own
    paths = [f"artifacts/calculus/{sc.id}.smt2" for sc in comp.side_conditions]
    out = composition_json(comp, paths)
    if not _is_composition(out):
        raise ValueError(f"the composition of {node} has no node or side conditions")
    for sc, rel, row in zip(comp.side_conditions, paths, out["side_conditions"]):
        atomic_write_text(ws.path(rel), tie_query(sc.smt2, "side-condition", sc.id, row))  # records/ties.py
    write_sealed(ws.path(ws.calculus(node)), out)
    # after: a killed stage records nothing; the cone is an input of what it wrote only when a side
    # condition was decided in context (the doit task re-runs on any change of the cone: derived property)
    record_provenance(ws, node, "compose", stage_inputs(ws, node, "compose",
                                                        any(sc.context for sc in comp.side_conditions)))
    return out


def _is_composition(record: Mapping[str, object]) -> TypeGuard[CompositionRecord]:
    """Does ``record`` (calculus/compose.py ``composition_json``) name its node and list its side conditions?"""
    return isinstance(record.get("node"), str) and isinstance(record.get("side_conditions"), list)


def plan_facts(ws: Workspace) -> dict[str, list[Any]]:
    """The plan's environment facts per node, as RCL formulas (what the
    calculus reads for side conditions in context; each node's facts are
    part of its snapshot)."""
    return {n: [f.expr for f in fs] for n, fs in ws.plan.facts.items()}


def health_findings(ws: Workspace, node: str) -> list[HealthFinding]:
    """The contract health findings of ``node`` (``calculus.health.finding.Finding``
    objects, its replacement's refinement finding last), from a fresh Z3 state;
    writes nothing (:func:`stage_health` records them)."""
    fresh_z3()  # the same Z3 state whatever ran before in this process (semantics/world.py)
    from rclverify.calculus.health.checks import check_node  # deferred: start-up (loads lark, yaml and more only when called)
    from rclverify.stages.interface_bounds import output_bounds  # deferred: start-up (as above)
    facts = [(f.expr, f.loc) for f in ws.plan.facts.get(node, ())]
    found: list[HealthFinding] = check_node(ws.checked, node, facts, ws.plan.instances.get(node),
                                            bounds=output_bounds(ws.root, ws.plan, ws.checked.nodes[node]))
    if node in ws.plan.replacements:
        found.append(replacement_finding(ws, node))
    return found


def stage_health(ws: Workspace, node: str) -> list[HealthFinding]:
    """Run the contract health checks of ``node``; keep each query a check
    decided as ``artifacts/health/<id>.smt2`` (``<id>.witness.smt2`` for a
    witness's), seal the findings with those paths in ``smt2`` and
    ``witness_smt2`` (records/findings.py) and return them as sealed."""
    from msgspec.structs import replace  # deferred: start-up (loads msgspec only when called)
    findings: list[HealthFinding] = []
    for f in health_findings(ws, node):
        kept = replace(f, smt2=f"artifacts/health/{f.id}.smt2" if f.smt2 else "",
                       witness_smt2=f"artifacts/health/{f.id}.witness.smt2" if f.witness_smt2 else "")
        row = kept.to_json()
        for path, text in ((kept.smt2, f.smt2), (kept.witness_smt2, f.witness_smt2)):
            if text:  # each ends naming the finding it decides (records/ties.py)
                atomic_write_text(ws.path(path), tie_query(text, "health", f.id, row))
        findings.append(kept)
    write_sealed(ws.path(ws.health(node)), {"node": node, "findings": [f.to_json() for f in findings]})
    record_provenance(ws, node, "health", stage_inputs(ws, node, "health"))
    return findings


def replacement_finding(ws: Workspace, node: str) -> Finding:
    """Check that the plan's replacement contract for ``node`` refines it
    (paper lines 1667-1700, interchangeability).

    Raises :class:`RclError` (located at the plan's ``replacement`` entry, or
    in the replacement file) when it cannot be read, does not check, lacks the
    node, or has a different interface.
    """
    from rclverify.calculus.refinement import check_refinement, merge_envs, split_spec  # deferred: start-up (loads lark, yaml and more only when called)
    from rclverify.calculus.health.checks import refinement_finding  # deferred: start-up (loads lark, yaml and more only when called)
    from rclverify.lang.parser import parse_text  # deferred: start-up (loads lark, rclverify.core.cache and more only when called)
    from rclverify.lang.typecheck import check  # deferred: start-up (loads lark, rclverify.core.cache and more only when called)
    spec, loc = ws.plan.replacements[node]
    rel, name = split_spec(spec)
    from rclverify.lang.source import decode_text  # deferred: start-up (loads rclverify.lang.ast, rclverify.lang.source and more only when called)
    try:
        text = decode_text((ws.root / rel).read_bytes(), rel)
    except OSError as exc:
        raise RclError([error(loc, f"cannot read replacement contract {rel!r}: {exc.strerror or exc}", "E-io")]) from None
    other = check([parse_text(text, rel)])
    if name is None and len(other.nodes) == 1:
        name = next(iter(other.nodes))
    if name is None or name not in other.nodes:
        raise RclError([error(loc, f"{rel} has no node {name!r}; it has {', '.join(other.nodes) or 'none'}", "E-plan")])
    return refinement_finding(node, spec, check_refinement(ws.checked.nodes[node], other.nodes[name],
                                                           merge_envs(ws.checked, other),
                                                           facts=[f.expr for f in ws.plan.facts.get(node, ())],
                                                           instances=ws.plan.instances.get(node)))


def stage_export(ws: Workspace, node: str) -> list[Obligation]:
    """Export ``node``'s obligations for every evidence entry of the plan;
    returns them as sealed (records/records.py ``Obligation``).

    The export starts a fresh Z3 context (semantics/world.py) unless every
    entry's backend says its export reads no Z3 state (``export_reads_z3_state
    = False``: what it writes follows from the structure of the terms it
    builds, never from a solver or a term's id; the Hoare backend): then its
    terms go into the context already there, and a node task saves one of
    its three contexts (docs/scale.md)."""
    from rclverify.backends import get_backend  # deferred: start-up (loads rclverify.backends, importlib only when called)
    if any(getattr(get_backend(e.backend), "export_reads_z3_state", True) for e in ws.plan.evidence.get(node, ())):
        fresh_z3()  # the same Z3 state whatever ran before in this process (semantics/world.py)
    obligations = []
    shared = set(ws.plan.contracts) | {ws.plan.file}
    snapshot = ws.snapshot(node)
    first_entry: dict[str, EvidenceEntry] = {}  # obligation id -> the entry that gave it
    for entry in ws.plan.evidence.get(node, ()):
        backend = get_backend(entry.backend)
        for o in backend.export(ws.target(node, entry.index)):
            if o.id in first_entry and first_entry[o.id] is not entry:
                from rclverify.model.plan.errors import plan_error  # deferred: optional or conditional (inside a block)
                here = ws.plan.locs.get(("nodes", node, "evidence", entry.index, "backend"), entry.loc)
                there = first_entry[o.id]
                raise plan_error(here.file, here.line, here.col,
                                 f"this {entry.backend} entry of {node} gives obligation {o.id}, which the entry at "
                                 f"{there.loc.file}:{there.loc.line}:{there.loc.col} gives too (the obligations of an "
                                 "entry are named by its file's name): rename one file or keep one entry")
            first_entry[o.id] = entry
            # Evidence about a node depends on that node's contract, the shared
            # context and its plan entries -- exactly its snapshot -- not on the
            # whole contract and plan files, which other nodes share.
            inputs = tuple(sorted({snapshot, *(i for i in o.inputs if i not in shared)}))
            obligations.append(dataclasses.replace(o, inputs=inputs, data={**o.data, "entry": entry.index}))
    write_obligations(ws.path(ws.obligations(node)), obligations)
    keep = set()
    for o in obligations:  # rewritten only when changed, so only changed obligations re-run
        write_sealed(ws.path(ws.obligation(node, o.id)), o.to_json())
        keep.add(f"{o.id}.json")
    for old in ws.path(f"artifacts/obligations/{node}").glob("*.json"):
        if old.name not in keep:
            old.unlink()
    return obligations


def ast_loc(rel: str) -> Any:
    """Line 1, column 1 of the workspace file ``rel`` (a located error about a whole record)."""
    from rclverify.lang.ast import Loc  # deferred: start-up (loads rclverify.lang.ast, fractions only when called)
    return Loc(rel, 1, 1)


def stage_run(ws: Workspace, node: str, obligation_id: str) -> Evidence:
    """Run the backend of one exported obligation and store its evidence record
    atomically (an earlier record is replaced only by a complete new one).
    Raises ``RclError`` when the obligation's record was altered outside
    rclverify (its seal does not hold): the backend is never run on it."""
    fresh_z3()  # the same Z3 state whatever ran before in this process (semantics/world.py)
    from rclverify.backends import get_backend  # deferred: start-up (loads rclverify.backends, importlib only when called)
    rel = ws.obligation(node, obligation_id)
    raw, altered = read_sealed(ws.path(rel), "obligation record")
    if altered or raw is None:  # never run a backend on an obligation rclverify did not export
        raise RclError([error(ast_loc(rel), altered or "no such obligation: run `doit verify`", "E-io")])
    o = Obligation.from_json(raw)
    ev = get_backend(o.backend).run(o, ws.target(node, int(o.data.get("entry", 0))))
    EvidenceStore(ws.root).put(ev)
    return ev


def stage_requirements(ws: Workspace, *, force: bool = False) -> list[tuple[RequirementRecord, bool]]:
    """Check every requirement with Z3; see :mod:`rclverify.stages.requirements`."""
    from rclverify.stages.requirements import stage_requirements as run  # deferred: start-up (loads rclverify.stages.requirements only when called)
    return run(ws, force=force)


def stage_deadlines(ws: Workspace) -> list[DeadlineRecord]:
    """Decide every end-to-end deadline with Z3 (rule D3); see
    :mod:`rclverify.stages.deadlines`.  Returns the records written."""
    from rclverify.stages.deadlines import stage_deadlines as run  # deferred: start-up (loads yaml, z3 and more only when called)
    return run(ws)[1]


def stage_diagnosis(ws: Workspace, report: Mapping[str, object] | None = None) -> DiagnosisRecord:
    """The diagnosis stage: explain every problem of the report dict without
    diagnoses (``report``, else built now:
    :func:`rclverify.report.build.undiagnosed_report`) with repairs checked
    by Z3 (:func:`rclverify.diagnosis.build.diagnose`) and write the sealed
    record ``artifacts/diagnosis/index.json``
    (:mod:`rclverify.stages.diagnoses`).  Returns the record.  Raises
    ``RclError`` for contracts or a plan that do not check, ``OSError``
    when the record cannot be written."""
    from rclverify.diagnosis.build import diagnose  # deferred: start-up (loads z3, lark and more only when called)
    from rclverify.diagnosis.shapes import report_rows  # deferred: start-up (loads rclverify.diagnosis only when called)
    from rclverify.report.build import undiagnosed_report  # deferred: start-up (loads jinja2, lark and more only when called)
    from rclverify.stages.diagnoses import report_digest, write_diagnoses  # deferred: start-up (loads rclverify.stages.diagnoses only when called)
    if report is None:
        report = undiagnosed_report(ws)
    digest = report_digest(report)  # taken first: the records explain the report as it was given
    return write_diagnoses(ws, digest, diagnose(ws, report_rows(report)))


def diagnosed(ws: Workspace, report: dict[str, Any] | None = None) -> AssuranceReport:
    """The report of ``ws``, decoded: ``report`` (the report without diagnoses,
    else built now) with the diagnosis stage's record for it, the stage run
    first when that record is missing, altered or made from another report
    (:func:`rclverify.stages.diagnoses.read_diagnoses`): every report the
    orchestrator builds explains its problems.  The report built now is
    finished from its record, its JSON object only digested and diagnosed.  Raises as
    :func:`stage_diagnosis`."""
    from rclverify.report.build import diagnosed_report, undiagnosed_json, undiagnosed_record  # deferred: start-up (loads jinja2, lark and more only when called)
    from rclverify.stages.diagnoses import read_diagnoses  # deferred: start-up (loads rclverify.stages.diagnoses only when called)
    record: AssuranceReport | None = None
    if report is None:
        record = undiagnosed_record(ws)
        report = undiagnosed_json(record)
    diagnoses, _ = read_diagnoses(ws, report)
    if diagnoses is None:
        diagnoses = cast("list[dict[str, Any]]", stage_diagnosis(ws, report)["diagnoses"])
    return diagnosed_report(report if record is None else record, diagnoses)


def stage_report(ws: Workspace, parts: Sequence[str] = tuple(REPORT_PARTS),
                 report: AssuranceReport | None = None, undiagnosed: dict[str, Any] | None = None) -> tuple[AssuranceReport, list[Path]]:
    """Build the report of ``ws`` (unless ``report`` gives it: from
    ``undiagnosed``, the report without diagnoses, when given, with the
    diagnosis stage's record, the stage run first when it is not current:
    :func:`diagnosed`) and write
    the files of ``parts`` under ``reports/`` (:mod:`rclverify.report.parts`:
    ``html`` is ``assurance.{html,json}``, the CI formats and the argument's
    SVG; ``text`` is ``assurance.md`` and the rest of the argument).  Graphviz
    layouts, compiled templates and rendered pieces of the report are kept
    under ``artifacts/cache/`` for the next run (a pure speed-up: the files
    are the same without them, docs/scale.md).  Returns the report (decoded) and
    the paths written; raises ``RclError`` for contracts or a plan that do
    not check, ``KeyError`` for an unknown part and ``OSError`` when a file
    cannot be written."""
    from rclverify.report import layoutcache  # deferred: start-up (loads rclverify.core.cache, rclverify.report and more only when called)
    from rclverify.report.fragments import FragmentCache  # deferred: start-up (loads rclverify.core.cache, rclverify.report and more only when called)
    from rclverify.report.parts import FRAGMENTS, write_part  # deferred: start-up (loads jinja2, markupsafe and more only when called)
    from rclverify.core.cache.keys import user_cache_dir  # deferred: start-up (loads rclverify.core.cache and more only when called)
    from rclverify.report.render import use_bytecode_cache  # deferred: start-up (loads jinja2, markupsafe and more only when called)
    if report is None:
        report = diagnosed(ws, undiagnosed)
    layoutcache.use_directory(ws.path("artifacts/cache/layout"))
    use_bytecode_cache(user_cache_dir("templates"))  # compiled code: never in the workspace (docs/scale.md)
    out = ws.path("reports")
    paths: list[Path] = []
    for part in parts:
        fragments = FragmentCache(ws.path(FRAGMENTS[part]))
        paths += write_part(report, out, part, fragments, within=ws.root)
        fragments.save()
        if part == "html":  # with assurance.json: what verify prints
            from rclverify.report.summary import summary_data  # deferred: optional or conditional (inside a block)
            write_sealed(ws.path(ws.SUMMARY), summary_data(report))
    # the one fragment cache of the single report task of earlier versions (38 MB at 1000 nodes)
    ws.path("artifacts/cache/report-fragments.pickle").unlink(missing_ok=True)
    return report, paths


