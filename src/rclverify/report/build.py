"""Roll the pipeline's artifacts up into the assurance report, built once from named passes.

Traceability: requirement -> node -> guarantee -> obligation -> evidence.
Roll-up takes the worst status of the children
(:data:`rclverify.records.records.SEVERITY`); nothing is shown as verified
while any of its evidence is failed, pending, stale or missing:

* obligation: its evidence's *current* status (report/evidence_rows.py);
* guarantee, node, side condition, derived property: report/contract_rows.py;
* requirement: worst of the guarantees that support it and of the side
  conditions of their nodes, with its Z3 check's verdict and its deadline
  (report/requirement_rows.py, report/deadlines.py);
* the NoDL documents' check: report/nodl.py (its errors fail ``--strict``);
* near misses and the margins over runs: report/near_misses.py (warnings:
  they fail ``--strict``), report/margin_rows.py;
* the summary and the ``--strict`` gate: report/summary_rows.py.

Each pass returns its part and changes nothing it was given; the parts
become the report in report/assemble.py, one step after another, and
:func:`build_report` says the order.  The report's shape is
docs/assurance.schema.json (records/report_schema.py).
"""
from __future__ import annotations

from typing import Any, Callable, Mapping, NamedTuple, Sequence

import msgspec
from msgspec.structs import replace
import z3

from rclverify import __version__
from rclverify.model.plan.load import all_requirements
from rclverify.model.plan.standards.field_data import unstated_origins
from rclverify.model.system.model import cycles_kept
from rclverify.records.records import Obligation, worst
from rclverify.records.report_record import AssuranceReport
from rclverify.records.row import decode_rows
from rclverify.records.side_condition_rows import SideConditionRow
from rclverify.records.summary_rows import Meta, Summary, SystemView
from rclverify.report import assemble
from rclverify.report.confidence_rows import confidence_part
from rclverify.report.cex_cone import side_condition_view
from rclverify.report.contract_rows import (GuaranteeStatuses, contract_records, derived_rows, environment_rows,
                                          node_part)
from rclverify.stages.contract_texts import ContractTexts
from rclverify.report.culprits import marked_nodes
from rclverify.report.deadlines import deadline_rows, fold_into, strict_ok as deadlines_ok
from rclverify.report.margin_rows import margin_rows
from rclverify.report.near_misses import near_miss_rows
from rclverify.report.evidence_rows import evidence_part
from rclverify.report.expected import expected_rows
from rclverify.report.finding_rows import acknowledged_rows, finding_rows, grounding_row, lint_rows
from rclverify.report.nodl import blocks_strict as nodl_blocks, nodl_inputs, nodl_problems, nodl_row
from rclverify.report.problems import group_problems
from rclverify.report.records import inputs_sha256, node_obligations
from rclverify.report.requirement_rows import requirement_rows
from rclverify.report.severity import blocking
from rclverify.report.standards_rows import standards_part
from rclverify.report.statistics import statistics_part
from rclverify.report.summary_rows import grounding_problems, headline, problem_sentences, status_counts, strict_gate
from rclverify.report.templating import anchor
from rclverify.report.unverified import unverified_guarantees
from rclverify.report.view import decoded_parts, problem_items
from rclverify.stages.crosscheck.apply import SecondSolver, load as load_second_solver
from rclverify.stages.design import blocks_strict as design_blocks, design_problems, design_row
from rclverify.stages.diagnoses import read_diagnoses
from rclverify.stages.instances import blocks_strict as instances_block, instance_problems, instance_statuses, instances_row
from rclverify.stages.requirements import read_records
from rclverify.stages.provenance import current_snapshot_hashes, stale_stages
from rclverify.stages.workspace import Workspace


class Inputs(NamedTuple):
    """What every pass reads: each node's texts, the obligations (an
    altered list is one placeholder, ``altered``: its id -> why), the
    current input sha256s (``hashes``, a memo the passes may add file
    hashes to; ``made_from``: a copy taken first, for ``meta.inputs_sha256``),
    the stages made from another contract text, the second solver's verdicts."""
    texts: ContractTexts
    obligations: list[Obligation]
    altered: dict[str, str]
    hashes: dict[str, str]
    made_from: dict[str, str]
    stale: dict[str, set[str]]
    second: SecondSolver


def read_inputs(ws: Workspace) -> Inputs:
    """The :class:`Inputs` of ``ws``: sealed records (an obligation list altered outside rclverify is one
    error row), each node's snapshot taken from the current contracts and plan, so that evidence of
    another contract text is stale even when no check ran since the edit."""
    texts = ContractTexts(ws)  # each node's RCL and LaTeX texts, kept by its file's sha256
    obligations: list[Obligation] = []
    altered: dict[str, str] = {}
    for n in ws.checked.nodes:
        obs, why = node_obligations(ws, n)
        obligations.extend(obs)
        if why:
            altered[obs[0].id] = why
    hashes = current_snapshot_hashes(ws, texts)  # taken once per file: nothing changes while the report is built
    return Inputs(texts, obligations, altered, hashes, dict(hashes), stale_stages(ws, hashes),
                  load_second_solver(ws.root))


class Facts(NamedTuple):
    """What the summary and ``meta`` need of the row passes beside the rows:
    each node's status, the sentences of altered records, the requirement
    check records, each obligation's evidence inputs, whether every deadline
    is proved, and (asked only when the rest of the gate holds) whether
    every guarantee is discharged."""
    node_status: dict[str, str]
    altered: list[str]
    checks: dict[str, Any]
    evidence_inputs: dict[str, object]
    deadlines_ok: bool
    guarantees_discharged: Callable[[], bool]


def _rows(ws: Workspace, inp: Inputs) -> tuple[dict[str, Any], Facts]:
    """The report's rows, pass by pass (the module docstring), and the :class:`Facts` the summary needs."""
    names = list(ws.checked.nodes)
    ev = evidence_part(ws, inp.obligations, inp.altered, inp.hashes, inp.second)
    comps, health = contract_records(ws, names, inp.stale, inp.second)
    # a counterexample shows the nodes involved only: the consumer and the producers of the linked variables
    recorded = [sc for n in names for sc in comps[n].get("side_conditions", [])]
    side_conditions = [side_condition_view(sc) for sc in decode_rows(SideConditionRow, recorded)]
    sc_status = {n: worst([sc["status"] for sc in comps[n].get("side_conditions", [])], empty="discharged")
                 for n in names}
    g_status = GuaranteeStatuses(inp.obligations, ev.status, health)
    nodes = node_part(ws, inp.texts, comps, g_status, sc_status)
    checks = read_records(ws, inp.hashes)  # sealed and hashed: altered -> error, other inputs -> stale
    checks = {k: inp.second.requirement(v) or v for k, v in checks.items()}
    deadlines = deadline_rows(ws, inp.hashes, g_status, ev.obligations, inp.second)  # rule D3
    requirements = fold_into(requirement_rows(ws, inp.texts, checks, g_status, sc_status, ev.declared), deadlines)
    findings, lint, acknowledgements = acknowledged_rows(ws, finding_rows(names, health, recorded),
                                                          lint_rows(ws))
    return {"requirements": requirements, "nodes": nodes.nodes, "side_conditions": side_conditions,
            "derived_properties": derived_rows(ws, comps, nodes, sc_status), "findings": findings,
            "obligations": ev.obligations, "evidence": ev.evidence,
            "environment_assumptions": environment_rows(comps, names),
            "pending": ev.pending, "lint": lint, "expected_verdicts": expected_rows(ws.plan, ev.obligations),
            "grounding": grounding_row(ws), "nodl": nodl_row(ws),
            # the instances stage reads the obligations' JSON objects
            "instances": instances_row(ws, [o.to_json() for o in ev.obligations]), "design": design_row(ws),
            "unverified": unverified_guarantees(ws.plan, nodes.nodes),
            "deadlines": deadlines, "acknowledgements": acknowledgements,
            "near_misses": near_miss_rows(ws, ev.obligations),
            "margins": margin_rows(ws, ev.obligations)}, Facts(
        nodes.status, ev.altered, checks, ev.inputs, deadlines_ok(deadlines),
        lambda: all(g_status(name, k) == "discharged" for name, cn in ws.checked.nodes.items()
                    for k in range(1, len(cn.node.guarantees) + 1)))


def _first_report(ws: Workspace, inp: Inputs, rows: dict[str, Any], facts: Facts) -> AssuranceReport:
    """The report of the row passes: meta, summary and system around ``rows`` (the parts after them
    empty, the summary's second solver and diagnoses too, until report/assemble.py puts them in)."""
    plan = ws.plan
    meta = Meta("rclverify", __version__, plan.name or ws.root.resolve().name, plan.file, list(plan.contracts),
                z3.get_version_string(), False,
                inputs_sha256(ws, inp.made_from, facts.evidence_inputs, facts.checks, nodl_inputs(ws, rows["nodl"])))
    system = SystemView.of(ws.model.view(
        facts.node_status, cycles_kept(ws.model, ws.path("artifacts/cache/system-cycles.pickle"))))
    # the summary written below; the second solver's counts and the diagnoses by report/assemble.py
    unsaid = Summary(status="pending", counts={}, problems=[], headline="", solvers={}, diagnoses=[])
    draft = AssuranceReport.of({"meta": meta, "summary": unsaid, "system": system, **rows, "statistics": [],
                                "standards": [], "diagnoses": [], "problems": []})
    counts = status_counts(draft.obligations)
    overall = worst([r.status for r in draft.requirements] + list(facts.node_status.values())
                    + [d.status for d in draft.derived_properties] + instance_statuses(rows["instances"]))
    strict_ok = strict_gate(draft, facts.guarantees_discharged, facts.deadlines_ok) \
        and not nodl_blocks(draft.nodl) and not instances_block(rows["instances"]) and not design_blocks(rows["design"])
    problems = problem_sentences(draft, facts.altered) + grounding_problems(draft.grounding) + nodl_problems(draft.nodl) \
        + design_problems(rows["design"]) \
        + instance_problems(rows["instances"])
    summary = replace(unsaid, status=overall, counts=counts, problems=problems,
                      headline=headline(draft.obligations, counts, draft.side_conditions, draft.findings,
                                        draft.unverified))
    return replace(draft, meta=replace(meta, strict_ok=strict_ok), summary=summary)


def undiagnosed_record(ws: Workspace) -> AssuranceReport:
    """Read every artifact of ``ws`` and return the report up to its
    diagnoses (``diagnoses``, ``problems`` and ``summary.diagnoses`` empty).  The passes, in order:
    the rows (:func:`_rows`), the summary around them, the statistics table
    (report/statistics.py, docs/statistics.md), the second solver's counts,
    strength and confidence (report/confidence_rows.py), the evidence
    mapped onto the plan's standards (report/standards_rows.py), the
    ``--strict`` gate with every severity (report/severity.py).  Raises
    ``RclError`` for contracts or a plan that do not check."""
    inp = read_inputs(ws)
    report = _first_report(ws, inp, *_rows(ws, inp))
    plan = ws.plan
    report = assemble.with_statistics(report, statistics_part(report, plan, {r.id: r.target for r in all_requirements(plan)}))
    report = assemble.with_solvers(report, inp.second.counts(), inp.second.problem)
    confidence = confidence_part(report, [(l.from_node, l.to_node) for l in ws.model.links],
                                 {r.id: r.strength for r in all_requirements(plan) if r.strength})
    report = assemble.with_confidence(report, confidence)
    standards = standards_part(plan.standards, report,  # docs/standards.md
                               unstated_origins(e for es in plan.evidence.values() for e in es))
    report = assemble.with_standards(report, standards)
    # one severity per finding: --strict fails on every error and warning, health and lint warnings included
    return assemble.with_strict(report, report.meta.strict_ok and confidence.ok
                                and not inp.second.problem and not blocking(report)
                                and standards["ok"])


def undiagnosed_json(report: AssuranceReport) -> dict[str, Any]:
    """``report`` (:func:`undiagnosed_record`) as the JSON object the diagnosis stage reads and digests
    (:func:`rclverify.stages.diagnoses.report_digest`): without ``diagnoses``, ``problems`` and
    ``summary.diagnoses``."""
    out: dict[str, Any] = msgspec.to_builtins(report)
    del out["diagnoses"], out["problems"], out["summary"]["diagnoses"]
    return out


def undiagnosed_report(ws: Workspace) -> dict[str, Any]:
    """The JSON object of :func:`undiagnosed_record` (:func:`undiagnosed_json`): what the diagnosis stage
    explains (:func:`rclverify.app.pipeline.stage_diagnosis`).  Raises ``RclError`` for contracts or a
    plan that do not check."""
    return undiagnosed_json(undiagnosed_record(ws))


def diagnosed_report(report: AssuranceReport | Mapping[str, Any], diagnoses: Sequence[Mapping[str, Any]] | None,
                     why: str = "") -> AssuranceReport:
    """The finished report: ``report`` (:func:`undiagnosed_record`, or its JSON object
    :func:`undiagnosed_report`, decoded here) with
    ``diagnoses`` (the diagnosis stage's records for it,
    :func:`rclverify.stages.diagnoses.read_diagnoses`), the problems grouped
    by root cause (report/problems.py) and the culprit nodes marked
    (report/culprits.py).  ``diagnoses`` is ``None`` when they are not
    current: the report then explains no problem and ``why`` (one
    sentence) is among ``summary.problems``.  Raises
    :class:`msgspec.ValidationError` (a ``ValueError``) for a part of
    another shape: a bug of the build, never shown."""
    draft = decoded_parts(report)
    if diagnoses is None:
        draft = replace(draft, summary=replace(draft.summary, problems=[*draft.summary.problems, f"Diagnoses: {why}"]))
    draft = assemble.with_diagnoses(replace(draft, problems=[]), list(diagnoses or []))
    problems = group_problems(draft, problem_items(draft), anchor)
    return replace(draft, problems=problems, nodes=marked_nodes(draft.nodes, problems))


def build_report(ws: Workspace) -> AssuranceReport:
    """Read every artifact of ``ws`` and return the report (see render.py):
    an :class:`~rclverify.records.report_record.AssuranceReport`, the record
    docs/assurance.schema.json is generated from: :func:`undiagnosed_record` with
    the diagnosis stage's sealed record (artifacts/diagnosis/index.json)
    when it was made from that report, else with no diagnosis and a
    sentence saying why among ``summary.problems`` (the report diagnoses
    nothing itself: :func:`rclverify.app.pipeline.stage_report` runs the
    stage first).  Raises ``RclError`` for contracts or a plan that do not
    check."""
    report = undiagnosed_record(ws)
    return diagnosed_report(report, *read_diagnoses(ws, undiagnosed_json(report)))
