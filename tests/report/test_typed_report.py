"""The report as one decoded value from the build to the files: :class:`AssuranceReport` read by key for the
readers not yet on attributes, its JSON written once from it, its HTML and Markdown the same whether the
renderers are handed the decoded report or its JSON object, and a report of an earlier version or before
its diagnoses decoded with the parts it lacks empty (report/view.py ``decoded_report``, ``decoded_parts``).
In-process, no pipeline run: each report is written by hand and completed (tests/records/_typed_rows.py).
"""
from __future__ import annotations

from typing import Any

import msgspec
import pytest

from _typed_rows import typed_report
from rclverify.records.report_record import AssuranceReport
from rclverify.report.diagram import Rendering
from rclverify.report.render import render_html, render_json, render_markdown
from rclverify.report.view import decoded_parts, decoded_report

#: a small report's parts: one node with a failed guarantee, its obligation and evidence, a refuted side condition
_PARTS: dict[str, Any] = {
    "meta": {"tool": "rclverify", "version": "9.9.9", "workspace": "mini", "plan": "contracts/plan.yaml",
             "contracts": ["contracts/a.rcl"], "z3_version": "4.13", "strict_ok": False, "inputs_sha256": "ab" * 32},
    "summary": {"status": "failed", "counts": {"failed": 1}, "problems": ["one failed"], "headline": "one failed",
                "solvers": {}, "diagnoses": []},
    "nodes": [{"name": "N", "source": "contracts/a.rcl:1:1", "status": "failed", "guarantees": [
        {"index": 1, "text": "out.y >= 0", "source": "contracts/a.rcl:4:3", "status": "failed",
         "obligations": ["N.g1.property_tests"]}]}],
    "obligations": [{"id": "N.g1.property_tests", "node": "N", "guarantee": 1, "backend": "property_tests",
                     "kind": "testing", "instance": "", "statement": "out.y >= 0", "source": "contracts/a.rcl:4:3",
                     "artifact": "", "status": "failed"}],
    "evidence": [{"obligation": "N.g1.property_tests", "backend": "property_tests", "kind": "testing",
                  "status": "failed", "tool": "hypothesis", "tool_version": "6", "started": "2026-01-02T03:04:05Z",
                  "duration_s": 0.5, "explanation": "y = -1 breaks it", "counterexample": {"in.x": "-1"},
                  "artifacts": [], "log_excerpt": ""}],
}


@pytest.fixture(scope="module")
def report() -> AssuranceReport:
    return typed_report(_PARTS)


def test_a_part_is_read_by_attribute_and_its_json_object_is_a_copy(report: AssuranceReport) -> None:
    """The report is read by attribute; its JSON object (``to_json``) is made anew, and reading the report
    by key is no longer possible (issue 112: the readers read records)."""
    body = report.to_json()
    assert body["summary"]["headline"] == "one failed" == report.summary.headline
    assert body["nodes"] == [n.to_json() for n in report.nodes] and isinstance(body["nodes"][0], dict)
    assert body["grounding"] is None is report.grounding
    with pytest.raises(TypeError, match="not subscriptable"):
        report["summary"]  # type: ignore[index]
    assert not hasattr(report, "get")
    # the JSON object is built anew: changing it leaves the report as it was
    body["nodes"][0]["status"] = "discharged"
    assert report.nodes[0].status == "failed" and report.to_json()["nodes"][0]["status"] == "failed"


def test_the_files_are_the_same_from_the_decoded_report_and_from_its_json(report: AssuranceReport) -> None:
    body = report.to_json()
    assert render_json(report) == render_json(body)
    assert render_markdown(report) == render_markdown(body)
    drawn = Rendering(None, "not laid out here")  # no Graphviz run: the layout is not what is compared
    html = render_html(report, rendering=drawn)
    assert html == render_html(body, rendering=drawn) and "y = -1 breaks it" in html
    # the control: another evidence explanation shows in every file
    other = msgspec.structs.replace(report, evidence=[msgspec.structs.replace(report.evidence[0],
                                                                              explanation="y = -2 breaks it")])
    assert render_json(other) != render_json(report) and "y = -2 breaks it" in render_markdown(other)


def test_a_report_of_an_earlier_version_or_before_its_diagnoses_decodes(report: AssuranceReport) -> None:
    body = report.to_json()
    earlier = {k: v for k, v in body.items() if k not in ("unverified", "margins", "near_misses")}
    assert decoded_report(earlier) == report
    before = {k: v for k, v in body.items() if k not in ("diagnoses", "problems")}
    before["summary"] = {k: v for k, v in body["summary"].items() if k != "diagnoses"}
    assert decoded_parts(before).evidence == report.evidence
    # the required parts stay required: a report without its nodes is refused, not read as empty
    with pytest.raises(msgspec.ValidationError, match="nodes"):
        decoded_report({k: v for k, v in body.items() if k != "nodes"})
