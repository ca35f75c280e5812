"""The ``review`` backend: a node's guarantees checked by a recorded code review.

The paper verifies the Localisation node by code review: the message type
the node publishes can carry only one position at a time (shared/reference
lines 1307-1317).  This backend records such a review as evidence:

* ``export`` reads the plan entry ``{backend: review, record: <yaml>}``,
  validates the record (:mod:`.record`) and exports one obligation per
  guarantee, whose inputs are the record and every reviewed file (so editing
  a reviewed file makes the evidence ``stale``);
* ``run`` judges the record against the checklist generated from the
  guarantee (:func:`.record.judge`): all yes and verdict pass with the
  reviewed files unchanged -> ``discharged``; a no or a fail -> ``failed``
  with the question; unanswered -> ``pending``; a changed file -> ``stale``.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

from rclverify.model.plan.declarations import declared_in
from rclverify.model.plan.standards.identity import confusable
from rclverify.records.records import Evidence, Obligation, SourceRef, make_obligation_id
from rclverify.model.plan.errors import PlanError, plan_error
from rclverify.model.plan.paths import escape_reason
from rclverify.model.plan.yamlguard import load_located, read_yaml_text
from rclverify.lang import ast
from rclverify.lang.errors import Diagnostic
from rclverify.backends.base import NodeTarget, Stopwatch, make_evidence
from rclverify.backends.review.payload import ReviewPayload
from rclverify.backends.review.record import Question, RecordError, ReviewRecord, assumption_text, checklist, judge, parse_record

#: this backend's name and evidence kind, as its declaration.yaml states them
_DECLARED = declared_in(__file__)
NAME, KIND = _DECLARED.name, _DECLARED.evidence_kind


def read_record(root: Path, config: Any, loc: Any) -> tuple[str, ReviewRecord]:
    """(workspace-relative path, record) of a plan entry; ``loc(*path)`` locates
    its values.  Raises :class:`PlanError` for a missing or malformed record."""
    rel = config.get("record")
    if not isinstance(rel, str):
        l = loc()
        raise plan_error(l.file, l.line, l.col, "review: name the review record (record: <file>.yaml)")
    l = loc("record")
    if not (root / rel).is_file():
        raise plan_error(l.file, l.line, l.col, f"review record {rel!r} does not exist "
                         "(write a blank one with `rclverify review NODE -o FILE`)", "E-io")
    text = read_yaml_text(root / rel, rel)
    try:
        record = parse_record(text, rel)
    except RecordError as exc:
        raise plan_error(l.file, l.line, l.col, f"review record: {exc}") from None
    check_reviewed_paths(root, rel, text, record)
    check_names(rel, text, record)
    return rel, record


def check_names(rel: str, text: str, record: ReviewRecord) -> None:
    """Refuse a record whose ``reviewer``, ``author`` or an alias could be spelt to look like another name
    (mixed scripts, an invisible character: :func:`~rclverify.model.plan.standards.identity.confusable`).
    Raises :class:`PlanError` at the name in the record (``rel:line:col``), naming why."""
    named: list[tuple[tuple[str | int, ...], str]] = [(("reviewer",), record.reviewer), (("author",), record.author)]
    named += [(("author_aliases", i), a) for i, a in enumerate(record.author_aliases)]
    named += [(("reviewer_aliases", i), a) for i, a in enumerate(record.reviewer_aliases)]
    bad = [(path, name, why) for path, name in named for why in [confusable(name)] if why is not None]
    if not bad:
        return
    _, locs = load_located(text, rel)
    diags: list[Diagnostic] = []
    for path, name, why in bad:
        at = locs.get(path, locs.get(path[:1], ast.Loc(rel, 1, 1)))
        diags.extend(plan_error(at.file, at.line, at.col, f"review record: {'.'.join(map(str, path))} {name!r}: "
                                f"{why}; write the name in one script without invisible characters",
                                "E-plan").diagnostics)
    raise PlanError(diags)


def check_reviewed_paths(root: Path, rel: str, text: str, record: ReviewRecord) -> None:
    """Refuse a record whose ``files:`` name a file outside the workspace
    (absolute, ``..``, a backslash, or a symbolic link leading out; the
    rules of :mod:`rclverify.model.plan.paths`): the reviewed files are inputs of
    the evidence and must be in the assessor's bundle.  Raises
    :class:`PlanError` listing each, located at the path in the record
    (``rel:line:col``)."""
    bad = [(i, p, why) for i, (p, _) in enumerate(record.files)
           for why in [escape_reason(root, p) or ("uses '\\' as a separator; write paths with '/'" if "\\" in p else None)]
           if why is not None]
    if not bad:
        return
    _, locs = load_located(text, rel)
    diags: list[Diagnostic] = []
    for i, p, why in bad:
        at = locs.get(("files", i, "path"), locs.get(("files", i), ast.Loc(rel, 1, 1)))
        diags.extend(plan_error(at.file, at.line, at.col, f"reviewed file {p!r} {why}; a review record may list "
                                "only files inside the workspace", "E-path").diagnostics)
    raise PlanError(diags)


def _load(target: NodeTarget) -> tuple[str, ReviewRecord]:
    rel, rec = read_record(target.root, target.config, lambda *p: target.config_loc(*p))
    if rec.node != target.node.name:
        l = target.config_loc("record")
        raise plan_error(l.file, l.line, l.col, f"review record {rel} is about node {rec.node!r}, not {target.node.name!r}")
    return rel, rec


class ReviewBackend:
    """Code review evidence (``kind`` ``review``).  Paper: lines 1307-1317."""

    name = NAME
    kind = KIND

    def export(self, target: NodeTarget) -> list[Obligation]:
        """One obligation per guarantee.  Raises :class:`PlanError` (located)."""
        rel, rec = _load(target)
        questions = checklist(target.node)
        files = {p for p, _ in rec.files}
        out = []
        for k, g in enumerate(target.node.node.guarantees, 1):
            qs = [q for q in questions if q.guarantee == k]
            out.append(Obligation(
                id=make_obligation_id(target.node.name, k, NAME, f"e{target.index}"), node=target.node.name,
                guarantee=k, backend=NAME, kind=KIND, statement=" ".join(f"[{q.id}] {q.question}" for q in qs),
                source=SourceRef(g.loc.file, g.loc.line, g.loc.col), instance=f"e{target.index}",
                inputs=tuple(sorted({rel, *files, *target.contract_files, target.plan_file})),
                data={"record": rel, "questions": [q.id for q in qs]}))
        return out

    def run(self, obligation: Obligation, target: NodeTarget) -> Evidence:
        """Judge the record for the obligation's guarantee (never raises for a user problem)."""
        clock = Stopwatch()
        try:
            rel, rec = _load(target)
        except PlanError as exc:
            return make_evidence(target, obligation, "error", tool="review record", tool_version="-", clock=clock,
                                 explanation=f"the review record no longer checks: {exc}", log=str(exc))
        qs: list[Question] = [q for q in checklist(target.node) if q.guarantee == obligation.guarantee]
        status, explanation, details = judge(rec, qs, target.root, assumption_text(target.node))
        details["record"] = rel
        details["figures_table"] = ([["reviewer", rec.reviewer], ["author", rec.author or "(not named)"],
                                     ["independence", rec.independence or ("(not stated)" if rec.author else "(not shown)")],
                                     *([["author aliases", "; ".join(rec.author_aliases)]] if rec.author_aliases else []),
                                     *([["reviewer aliases", "; ".join(rec.reviewer_aliases)]]
                                       if rec.reviewer_aliases else []),
                                     ["date", rec.date], ["scope", rec.scope],
                                     ["verdict", rec.verdict or "(none)"]]
                                    + [[f"{q['id']} ({q['location']})", f"{q['answer'] or 'unanswered'}: {q['question']}"
                                        + (f" -- {q['note']}" if q["note"] else "")] for q in details["checklist"]]
                                    + [["file", f"{p} sha256 {h}"] for p, h in rec.files])
        return make_evidence(target, obligation, status, tool="review record", tool_version=rel, clock=clock,
                             explanation=explanation, details=ReviewPayload.checked(details),
                             log="\n".join(f"{q['id']}: {q['answer']}" for q in details["checklist"]))
