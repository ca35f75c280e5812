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

Pure readings of a report dict (``reports/assurance.json``) and of the digests given; nothing raises for
a well-formed report.
"""
from __future__ import annotations

from typing import Any, Mapping

from rclverify.model.plan.standards.field_data import figures
from rclverify.records.standards_rows import ClauseRow, ProfileOrigin, StandardRow, rows_of as standard_rows

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


def header_rows(report: Mapping[str, Any], report_sha256: str, written: str,
                files_sha256: Mapping[str, str]) -> list[list[str]]:
    """The header of an export of ``report``: ``[what, value]`` rows (the module docstring).
    ``report_sha256``: the hex sha256 of the report file's bytes; ``written``: when it was written
    (ISO 8601, UTC); ``files_sha256``: workspace-relative file -> hex sha256 of the plan and contract
    files now (``"missing"`` for one that is gone)."""
    meta = report.get("meta") or {}
    solvers = (report.get("summary") or {}).get("solvers") or {}
    rows = [["read from", "reports/assurance.json"], ["report sha256", report_sha256],
            ["report written (UTC)", written], ["rclverify version", str(meta.get("version", ""))],
            ["Z3 version", str(meta.get("z3_version", ""))],
            ["second solver (cvc5)", ", ".join(f"{k}: {v}" for k, v in solvers.items()) or "not run"],
            ["plan", f"{meta.get('plan', '')} sha256 {files_sha256.get(str(meta.get('plan', '')), 'missing')}"]]
    rows += [["contract", f"{c} sha256 {files_sha256.get(str(c), 'missing')}"] for c in meta.get("contracts") or ()]
    rows.append(["inputs sha256", str(meta.get("inputs_sha256", ""))])
    for standard in standard_rows(report.get("standards") or ()):
        rows.append(["standard", f"{standard.edition} ({standard.profile}): {origin_cell(standard.origin)}, "
                                 f"profile sha256 {standard.origin.sha256}"])
    rows.append(["note", "a traceability aid, not a compliance claim (docs/standards.md)"])
    return rows


def _statistics(report: Mapping[str, Any], clause: ClauseRow) -> dict[str, str]:
    """The figures of the statistical targets in ``scope``, column by column, ``"; "``-joined."""
    evidence = {str(e.get("obligation")): e for e in report.get("evidence") or ()}
    req_runs = {f"target of requirement {rq.get('id')} ({t.get('environment')}, {t.get('origin')})": t
                for rq in report.get("requirements") or () for t in rq.get("statistics") or ()}
    found: list[dict[str, str]] = []
    for x in clause.scope:
        if x.kind != "target":
            continue
        item = x.item
        stats = req_runs.get(item) or (evidence.get(item.removeprefix("target ")) or {}).get("statistics")
        if isinstance(stats, Mapping):
            found.append(figures(stats))
    return {k: "; ".join(f[k] for f in found) for k in STAT_KEYS}


def _covering(report: Mapping[str, Any], covered_by: list[str], digests: Mapping[str, str]) -> str:
    """The evidence that covers a clause: each record with its sha256 and the date its tool started."""
    evidence = {str(e.get("obligation")): e for e in report.get("evidence") or ()}
    out = []
    for ob in covered_by:
        e = evidence.get(str(ob))
        said = [] if e is None else ([f"sha256 {digests[str(ob)]}"] if str(ob) in digests else []) + (
            [f"started {e['started']}"] if e.get("started") else [])
        out.append(f"{ob} ({', '.join(said)})" if said else str(ob))
    return "; ".join(out)


def matrix_rows(report: Mapping[str, Any], digests: Mapping[str, str] | None = None) -> list[list[str]]:
    """The compliance matrix of ``report``: :data:`MATRIX_COLUMNS` then one row per clause, standard by
    standard in the plan's order, clause by clause in the profile's.  ``digests``: obligation -> hex sha256
    of its evidence record file, shown beside each record that covers a clause with the time its tool
    started (an obligation without a digest is shown without one)."""
    out = [list(MATRIX_COLUMNS)]
    for standard in standard_rows(report.get("standards") or ()):
        out += [_clause_row(report, standard, clause, digests or {}) for clause in standard.clauses]
    return out


def _clause_row(report: Mapping[str, Any], standard: StandardRow, clause: ClauseRow,
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


def _supports(report: Mapping[str, Any]) -> dict[str, list[str]]:
    """What covers an item of a clause (an obligation, a side condition, ``requirement <id>``) -> the
    clauses it helps cover, each as ``<edition> <clause>``."""
    out: dict[str, list[str]] = {}
    for standard in standard_rows(report.get("standards") or ()):
        for clause in standard.clauses:
            for ob in clause.covered_by:
                out.setdefault(ob, []).append(f"{standard.edition} {clause.id}")
    return out


def trace_rows(report: Mapping[str, Any]) -> list[list[str]]:
    """The trace matrix of ``report``: :data:`TRACE_COLUMNS` then requirement -> guarantee -> obligation ->
    evidence rows (a guarantee without an obligation, or an obligation without a record, is one row with
    the missing cells empty), the obligations of guarantees no requirement names, each requirement's
    proof by Z3 with the premises it used, and each side condition; each row with the clauses it helps
    cover."""
    evidence = {str(e.get("obligation")): e for e in report.get("evidence") or ()}
    guarantee_status = {(str(n.get("name")), int(g.get("index", 0))): str(g.get("status", ""))
                        for n in report.get("nodes") or () for g in n.get("guarantees") or ()}
    obligations: dict[tuple[str, int], list[Mapping[str, Any]]] = {}
    for o in report.get("obligations") or ():
        obligations.setdefault((str(o.get("node")), int(o.get("guarantee", 0))), []).append(o)
    supports = _supports(report)
    z3 = f"Z3 {(report.get('meta') or {}).get('z3_version', '')}".strip()
    out = [list(TRACE_COLUMNS)]
    traced: set[tuple[str, int]] = set()

    def rows_of(rid: str, verdict: str, key: tuple[str, int]) -> None:
        obs = obligations.get(key, []) + ([] if key[1] == 0 else obligations.get((key[0], 0), []))
        for o in obs or [{}]:
            e = evidence.get(str(o.get("id")), {}) if o else {}
            out.append([rid, verdict, key[0], f"g{key[1]}", guarantee_status.get(key, ""), str(o.get("id", "")),
                        str(o.get("backend", "")), str(o.get("kind", "")), str(e.get("status", "")),
                        _tool(e), "", "; ".join(supports.get(str(o.get("id", "")), []))])

    for rq in report.get("requirements") or ():
        for sp in rq.get("support") or ():
            key = (str(sp.get("node")), int(sp.get("guarantee", 0)))
            traced.add(key)
            rows_of(str(rq.get("id")), str(rq.get("verdict", "")), key)
    for key in sorted(set(guarantee_status) - traced):
        rows_of("", "", key)
    for rq in report.get("requirements") or ():
        check = rq.get("check")
        if not isinstance(check, Mapping):
            continue
        used = "; ".join(f"{u.get('label') or u.get('kind')}: {u.get('text', '')}" for u in check.get("used") or ()
                         if isinstance(u, Mapping))
        out.append([str(rq.get("id")), str(rq.get("verdict", "")), ", ".join(map(str, check.get("cone") or ())), "",
                    "", f"requirement {rq.get('id')}", "z3", "proof", str(rq.get("status", "")), z3, used,
                    "; ".join(supports.get(f"requirement {rq.get('id')}", []))])
    for sc in report.get("side_conditions") or ():
        out.append(["", "", str(sc.get("node", "")), "", "", f"side condition {sc.get('id')}", "z3", "proof",
                    str(sc.get("status", "")), z3, "", "; ".join(supports.get(str(sc.get("id")), []))])
    return out


def _tool(e: Mapping[str, Any]) -> str:
    """An evidence record's tool and version, the tool named once when the version starts with it."""
    tool, version = str(e.get("tool", "")), str(e.get("tool_version", ""))
    return version if version.startswith(tool) else f"{tool} {version}".strip()


__all__ = ["MATRIX_COLUMNS", "STAT_KEYS", "TRACE_COLUMNS", "header_rows", "matrix_rows", "origin_cell", "trace_rows"]
