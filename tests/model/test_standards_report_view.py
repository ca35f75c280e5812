"""The report as the standards mapping reads it (model/plan/standards/report_view.py): one conversion, parts
the report does not hold read as empty, a value of another type refused."""
from __future__ import annotations

import msgspec
import pytest

from rclverify.model.plan.standards.field_data import figures
from rclverify.model.plan.standards.report_view import ReportView, TargetView, evidence_view, report_view

ROW = {"obligation": "A.g1.hoare", "backend": "hoare", "kind": "proof", "status": "discharged",
       "strength": {"kind": "proof", "doubt": 0.0}, "tool": "hoare", "tool_version": "1", "explanation": "not read"}


def test_parts_read_typed_and_absent_parts_empty() -> None:
    view = report_view({"evidence": [ROW], "nodes": [{"name": "A", "guarantees": [{"index": 1, "status": "discharged"}]}],
                        "summary": {"status": "failed"}, "system": None, "findings": None})
    (row,) = view.evidence
    assert (row.obligation, row.kind, row.strength and row.strength.kind) == ("A.g1.hoare", "proof", "proof")
    assert view.nodes[0].guarantees and view.nodes[0].guarantees[0].index == 1
    assert view.summary.status == "failed"
    assert view.findings == () and view.system.connections is None  # written null: read as absent
    empty = report_view({})  # control: a report holding nothing reads as empty, the workspace pending
    assert (empty.evidence, empty.requirements, empty.summary.status) == ((), (), "pending")


def test_a_bare_list_of_evidence_rows_is_a_report_of_those_rows() -> None:
    view = report_view([ROW, {**ROW, "obligation": "B.g1.hoare"}])
    assert [e.obligation for e in view.evidence] == ["A.g1.hoare", "B.g1.hoare"] and view.nodes == ()
    assert report_view(view) is view and evidence_view(view.evidence[0]) is view.evidence[0]


def test_a_value_of_another_type_is_refused() -> None:
    with pytest.raises(msgspec.ValidationError, match=r"\$\.obligations\[0\]\.guarantee"):
        report_view({"obligations": [{"id": "A.g1.hoare", "node": "A", "guarantee": "one"}]})
    # control: the same row with its guarantee a number
    assert isinstance(report_view({"obligations": [{"id": "A.g1.hoare", "node": "A", "guarantee": 1}]}), ReportView)


def test_a_targets_statistics_read_typed_as_the_figures_show_them() -> None:
    stats = {"environment": "lab", "origin": "operation", "counts": {"runs": 30, "violating_runs": 0, "seconds": 1.5},
             "target": {"bound": 0.1, "level": 0.95, "per": "run", "text": "at most 10 %", "guarantee": 1},
             "decision": {"n": 30, "k": 0, "bound": 0.0950, "level": 0.95, "status": "discharged",
                          "target": {"bound": 0.1, "level": 0.95, "per": "run", "text": "at most 10 %"}}}
    (row,) = report_view([{**ROW, "backend": "monitors", "statistics": stats}]).evidence
    s = row.statistics
    assert s is not None and s.decision is not None and isinstance(s.target, TargetView)
    assert (s.environment, s.decision.n, s.decision.target.bound) == ("lab", 30, 0.1)
    assert figures(s) == figures(stats) == {"n": "30", "violations": "0", "target": "10 %", "confidence": "95 %",
                                            "bound": "9.5 %", "environment": "lab", "origin": "operation"}
    # control: a requirement's runs row (its target in words, no decision) reads its counts and its own bound
    runs = {"environment": "lab", "origin": "operation", "counts": {"runs": 4, "violating_runs": 1}, "bound": 0.5,
            "level": 0.9, "target": "at most 1 %", "status": "pending"}
    assert figures(runs) == {"n": "4", "violations": "1", "target": "at most 1 %", "confidence": "90 %",
                             "bound": "50 %", "environment": "lab", "origin": "operation"}
    with pytest.raises(msgspec.ValidationError, match=r"\$\.decision\.n"):
        figures({**stats, "decision": {"n": "thirty"}})
