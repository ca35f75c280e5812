"""The report's requirement rows: each requirement's support, its Z3 check's verdict and its status.

A requirement's ``verdict`` is what the Z3 check of its formal statement
decided (calculus/requirements/rollup.py); its ``status`` is the evidence
roll-up shown (the worst of the guarantees that support it and of their
nodes' side conditions; only ``met`` is ``discharged``): records/statuses.py,
"verdict and status".  An end-to-end deadline is rolled in afterwards
(report/deadlines.py, rule D3).
"""
from __future__ import annotations

from typing import Any, Callable, Mapping

from rclverify.calculus.requirements.rollup import declaration_evidence, declaration_statuses, roll_up
from rclverify.model.plan.load import all_requirements
from rclverify.records.records import worst
from rclverify.records.requirement_rows import RequirementRow
from rclverify.report.cex_cone import with_trace_view  # a temporal trace cut to what matters
from rclverify.report.contract_rows import GuaranteeStatuses
from rclverify.stages.contract_texts import ContractTexts
from rclverify.stages.workspace import Workspace

#: The fields of a requirement's check record (calculus/requirements/check.py) the report carries.
_CHECK_FIELDS = ("origin", "source", "formal", "assuming", "cone", "used", "traced_not_needed", "consistency",
                 "inconsistent_core", "vacuity", "vacuity_core", "counterexample", "outside_assumptions",
                 "counterexample_note", "failed_to_prevent", "reason", "smt2", "explanation",
                 "solvers",  # the second solver's agreement (stages/crosscheck/apply.py)
                 "consistency_smt2", "consistency_solvers", "recorded_consistency",  # and on the side queries
                 "vacuity_smt2", "vacuity_solvers", "recorded_vacuity",
                 "temporal",  # a temporal requirement's verdict, k, bound and trace (calculus/requirements/temporal_check.py)
                 "traces",  # its recorded runs' verdicts (backends/monitors/temporal_evidence.py)
                 "duration_s")


def current_record(req: Any, record: Mapping[str, Any] | None) -> Mapping[str, Any] | None:
    """``record`` when it was made from ``req``'s current statements (else
    ``None``: not checked yet, e.g. ``rclverify report`` after a plan edit,
    before the ``requirements`` stage ran); an informal requirement needs no
    record."""
    formal = " ".join(req.formal.text.split()) if req.formal else None
    hints = [" ".join(x.text.split()) if x else None for x in (getattr(req, "ranking", None),
                                                                 getattr(req, "invariant", None))]
    if record is not None and record.get("formal") == formal \
            and record.get("assuming", []) == [" ".join(a.text.split()) for a in req.assuming] \
            and [record.get("ranking"), record.get("invariant")] == hints:
        return record
    if formal is None:
        return {"verdict": "informal", "source": f"{req.loc.file}:{req.loc.line}:{req.loc.col}", "origin": req.origin}
    return None


def requirement_check(record: Mapping[str, Any] | None, traced_status: str, g_status: Callable[[str, int], str],
                      sc_status: Mapping[str, str], d_status: Any = None) -> dict[str, Any]:
    """The requirement row's fields from its Z3 check: ``verdict`` (met /
    proved, evidence outstanding / proved from an inconsistency / refuted /
    inconclusive / informal), ``status`` (only ``met`` is ``discharged``),
    ``note`` and the check's details (:mod:`rclverify.calculus.requirements.rollup`)."""
    verdict, status, note = roll_up(record, g_status, sc_status, traced_status, d_status)
    details = dict(with_trace_view({k: (record or {}).get(k) for k in _CHECK_FIELDS}))
    details["declarations"] = declaration_evidence(record, d_status)  # the declarations it used, with their evidence
    return {"status": status, "verdict": verdict, "note": note, "check": details}


def requirement_rows(ws: Workspace, texts: ContractTexts, checks: Mapping[str, Any], g_status: GuaranteeStatuses,
                     sc_status: Mapping[str, str], declared: Mapping[str, list[tuple[str, Any]]]) -> list[RequirementRow]:
    """One row per requirement of ``ws``'s plan (module docstring), each
    a :class:`~rclverify.records.requirement_rows.RequirementRow` (the later passes' fields at their
    defaults): its support
    (the guarantees it is traced to, with their statuses), then its check's
    fields (:func:`requirement_check`).  ``checks``: requirement id -> its
    check record (sealed, stale and second solver applied); ``declared``:
    node -> the records that judged its declarations.  Raises
    :class:`msgspec.ValidationError` when a check's verdict or status is
    outside the vocabulary (a bug of the roll-up)."""
    rows: list[RequirementRow] = []
    for r in all_requirements(ws.plan):
        support: list[dict[str, Any]] = []  # SupportRow's fields, checked when the row is decoded below
        for s in r.support:
            for k in s.guarantees:
                text, src = texts.node(ws.checked.nodes[s.node].node)["guarantees"][k - 1]
                support.append({"node": s.node, "guarantee": k, "text": text, "source": src,
                                "status": g_status(s.node, k), "obligations": g_status.obligations(s.node, k)})
        st = worst([x["status"] for x in support] + [sc_status[x["node"]] for x in support]) if support else "pending"
        got = requirement_check(current_record(r, checks.get(r.id)), st, g_status, sc_status,
                                declaration_statuses(declared, ws.checked))
        rows.append(RequirementRow.of({"id": r.id, "text": r.text, "verdict": got["verdict"], "status": got["status"],
                                       "note": got["note"], "support": support,
                                       "check": got["check"]}))
    return rows
