"""The tables an assessor files from a report: the compliance matrix, the trace matrix and the header
that identifies what they were read from (docs/standards.md, "Exports").

* :func:`header_rows`: what the export was read from: the report's sha256 and when it was written, the
  rclverify and Z3 versions, the second solver's counts, the sha256 of the plan and of each contract
  file, the report's ``meta.inputs_sha256`` and each standard profile's origin and sha256.
* :func:`matrix_rows`: one row per clause of each standard (:data:`MATRIX_COLUMNS`): its accepted
  kinds, every item in scope with its state, the evidence that covers it (each record with its sha256
  and the date its tool started), who checked it, the figures of its statistical targets (runs,
  violations, target, confidence, bound, environment, origin), the plan's justification in full, and
  two empty columns for the assessor's decision and comment.
* :func:`trace_rows`: requirement -> guarantee -> obligation -> evidence (:data:`TRACE_COLUMNS`), then
  the guarantees no requirement names, each requirement's own proof with the premises it used, and each
  side condition; every row names the standards' clauses it helps cover.

Pure readings of the decoded report (:class:`~rclverify.records.report_record.AssuranceReport`, the
attributes mypy checks) and of the digests given; nothing raises.  The fields of a standard's row and of
a clause's row the exports do not show are named, with the reason, in
:data:`~rclverify.records.standards_rows.EXPORTS_INTERNAL` and ``CLAUSE_EXPORTS_INTERNAL``
(tests/records/test_record_shapes.py).
"""
from __future__ import annotations

from typing import Mapping

from rclverify.model.plan.standards.field_data import figures
from rclverify.records.evidence_rows import EvidenceRow
from rclverify.records.obligations import ObligationRow
from rclverify.records.report_record import AssuranceReport
from rclverify.records.standards_rows import ClauseRow, ProfileOrigin, StandardRow

#: The compliance matrix's columns.
MATRIX_COLUMNS: tuple[str, ...] = (
    "standard", "level", "profile", "profile origin", "clause", "what it asks", "recommendation", "about",
    "accepted kinds", "independence asked", "items in scope", "items covered", "items in scope and their state",
    "items not covered", "evidence that covers it", "who checked it", "runs (n)", "violations", "target",
    "confidence", "bound", "environment", "origin", "status", "why", "plan's justification", "plan note at",
    "assessor's decision", "comment")
#: The statistical columns, in :data:`MATRIX_COLUMNS`' order (the keys of :func:`~.field_data.figures`).
STAT_KEYS: tuple[str, ...] = ("n", "violations", "target", "confidence", "bound", "environment", "origin")
#: The trace matrix's columns.
TRACE_COLUMNS: tuple[str, ...] = (
    "requirement", "requirement verdict", "node", "guarantee", "guarantee status", "obligation", "backend",
    "kind", "evidence status", "tool", "premises used", "clauses it supports")


def origin_cell(o: ProfileOrigin) -> str:
    """A profile's origin (``standards[].origin``) as one cell."""
    if o.kind == "built-in":
        return f"built-in ({o.edition})"
    return f"workspace file {o.file} sha256 {o.sha256}"


def header_rows(report: AssuranceReport, report_sha256: str, written: str,
                files_sha256: Mapping[str, str]) -> list[list[str]]:
    """The header of an export of ``report``: ``[what, value]`` rows (the module docstring).
    ``report_sha256``: the hex sha256 of the report file's bytes; ``written``: when it was written
    (ISO 8601, UTC); ``files_sha256``: workspace-relative file -> hex sha256 of the plan and contract
    files now (``"missing"`` for one that is gone)."""
    meta = report.meta
    solvers = report.summary.solvers
    rows = [["read from", "reports/assurance.json"], ["report sha256", report_sha256],
            ["report written (UTC)", written], ["rclverify version", meta.version],
            ["Z3 version", meta.z3_version],
            ["second solver (cvc5)", ", ".join(f"{k}: {v}" for k, v in solvers.items()) or "not run"],
            ["plan", f"{meta.plan} sha256 {files_sha256.get(meta.plan, 'missing')}"]]
    rows += [["contract", f"{c} sha256 {files_sha256.get(c, 'missing')}"] for c in meta.contracts]
    rows.append(["inputs sha256", meta.inputs_sha256])
    for standard in report.standards:
        rows.append(["standard", f"{standard.edition} ({standard.profile}): {origin_cell(standard.origin)}, "
                                 f"profile sha256 {standard.origin.sha256}"])
    rows.append(["note", "a traceability aid, not a compliance claim (docs/standards.md)"])
    return rows


def _statistics(report: AssuranceReport, clause: ClauseRow) -> dict[str, str]:
    """The figures of the statistical targets in ``scope``, column by column, ``"; "``-joined."""
    evidence = _evidence(report)
    req_runs = {f"target of requirement {rq.id} ({t.environment}, {t.origin})": t.to_json()
                for rq in report.requirements for t in rq.statistics}
    found: list[dict[str, str]] = []
    for x in clause.scope:
        if x.kind != "target":
            continue
        item = x.item
        ev = evidence.get(item.removeprefix("target "))
        stats = req_runs.get(item) or (None if ev is None else ev.statistics)
        if stats is not None:
            found.append(figures(stats))
    return {k: "; ".join(f[k] for f in found) for k in STAT_KEYS}


def _evidence(report: AssuranceReport) -> dict[str, EvidenceRow]:
    """Obligation id -> its evidence row."""
    return {e.obligation: e for e in report.evidence}


def _covering(report: AssuranceReport, covered_by: list[str], digests: Mapping[str, str]) -> str:
    """The evidence that covers a clause: each record with its sha256 and the date its tool started."""
    evidence = _evidence(report)
    out = []
    for ob in covered_by:
        e = evidence.get(ob)
        said = [] if e is None else ([f"sha256 {digests[ob]}"] if ob in digests else []) + (
            [f"started {e.started}"] if e.started else [])
        out.append(f"{ob} ({', '.join(said)})" if said else ob)
    return "; ".join(out)


def matrix_rows(report: AssuranceReport, digests: Mapping[str, str] | None = None) -> list[list[str]]:
    """The compliance matrix of ``report``: :data:`MATRIX_COLUMNS` then one row per clause, standard by
    standard in the plan's order, clause by clause in the profile's.  ``digests``: obligation -> hex sha256
    of its evidence record file, shown beside each record that covers a clause with the time its tool
    started (an obligation without a digest is shown without one)."""
    out = [list(MATRIX_COLUMNS)]
    for standard in report.standards:
        out += [_clause_row(report, standard, clause, digests or {}) for clause in standard.clauses]
    return out


def _clause_row(report: AssuranceReport, standard: StandardRow, clause: ClauseRow,
                digests: Mapping[str, str]) -> list[str]:
    """A clause's row of the compliance matrix (:data:`MATRIX_COLUMNS`)."""
    level = "" if standard.level is None else f"{standard.level_name.upper()} {standard.level}"
    scope = clause.scope
    stats = _statistics(report, clause)
    return [standard.edition, level, standard.profile, origin_cell(standard.origin),
            clause.id, clause.title, clause.recommendation, clause.about,
            ", ".join(clause.accepts), clause.independence,
            str(len(scope)), str(sum(1 for x in scope if x.covered)),
            "; ".join(f"{x.item}: {x.state}" for x in scope),
            "; ".join(f"{x.item}: {x.detail}" for x in scope if not x.covered),
            _covering(report, clause.covered_by, digests), "; ".join(clause.checked_by),
            *(stats[k] for k in STAT_KEYS),
            clause.status, clause.why, "" if clause.plan is None else str(clause.plan.justification),
            "" if clause.plan is None else str(clause.plan.at), "", ""]


def _supports(report: AssuranceReport) -> dict[str, list[str]]:
    """What covers an item of a clause (an obligation, a side condition, ``requirement <id>``) -> the
    clauses it helps cover, each as ``<edition> <clause>``."""
    out: dict[str, list[str]] = {}
    for standard in report.standards:
        for clause in standard.clauses:
            for ob in clause.covered_by:
                out.setdefault(ob, []).append(f"{standard.edition} {clause.id}")
    return out


def trace_rows(report: AssuranceReport) -> list[list[str]]:
    """The trace matrix of ``report``: :data:`TRACE_COLUMNS` then requirement -> guarantee -> obligation ->
    evidence rows (a guarantee without an obligation, or an obligation without a record, is one row with
    the missing cells empty), the obligations of guarantees no requirement names, each requirement's
    proof by Z3 with the premises it used, and each side condition; each row with the clauses it helps
    cover."""
    evidence = _evidence(report)
    guarantee_status = {(n.name, g.index): g.status for n in report.nodes for g in n.guarantees}
    obligations: dict[tuple[str, int], list[ObligationRow]] = {}
    for o in report.obligations:
        obligations.setdefault((o.node, o.guarantee), []).append(o)
    supports = _supports(report)
    z3 = f"Z3 {report.meta.z3_version}".strip()
    out = [list(TRACE_COLUMNS)]
    traced: set[tuple[str, int]] = set()

    def rows_of(rid: str, verdict: str, key: tuple[str, int]) -> None:
        obs: list[ObligationRow | None] = [*obligations.get(key, []),
                                           *([] if key[1] == 0 else obligations.get((key[0], 0), []))]
        for o in obs or [None]:
            e = None if o is None else evidence.get(o.id)
            oid = "" if o is None else o.id
            out.append([rid, verdict, key[0], f"g{key[1]}", guarantee_status.get(key, ""), oid,
                        "" if o is None else o.backend, "" if o is None else o.kind, "" if e is None else e.status,
                        _tool(e), "", "; ".join(supports.get(oid, []))])

    for rq in report.requirements:
        for sp in rq.support:
            key = (sp.node, sp.guarantee)
            traced.add(key)
            rows_of(rq.id, rq.verdict, key)
    for key in sorted(set(guarantee_status) - traced):
        rows_of("", "", key)
    for rq in report.requirements:
        check = rq.check  # the requirement check's record (calculus/requirements/check.py), JSON as written
        used = "; ".join(f"{u.get('label') or u.get('kind')}: {u.get('text', '')}" for u in check.get("used") or ()
                         if isinstance(u, Mapping))
        out.append([rq.id, rq.verdict, ", ".join(map(str, check.get("cone") or ())), "",
                    "", f"requirement {rq.id}", "z3", "proof", rq.status, z3, used,
                    "; ".join(supports.get(f"requirement {rq.id}", []))])
    for sc in report.side_conditions:
        out.append(["", "", sc.node, "", "", f"side condition {sc.id}", "z3", "proof",
                    sc.status, z3, "", "; ".join(supports.get(sc.id, []))])
    return out


def _tool(e: EvidenceRow | None) -> str:
    """An evidence record's tool and version, the tool named once when the version starts with it
    (``""`` without a record)."""
    tool, version = ("", "") if e is None else (e.tool, e.tool_version)
    return version if version.startswith(tool) else f"{tool} {version}".strip()


__all__ = ["MATRIX_COLUMNS", "STAT_KEYS", "TRACE_COLUMNS", "header_rows", "matrix_rows", "origin_cell", "trace_rows"]
