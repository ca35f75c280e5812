"""The report's rows of findings: contract health and scale findings, lint diagnostics, the plan's
acknowledgements of warnings, and the grounding in the robot's software.

Each function returns its rows and changes nothing it was given (the
acknowledgement pass marks the findings' JSON objects and copies of the lint rows).
"""
from __future__ import annotations

from typing import Any, Mapping, Sequence

from rclverify.calculus.scale import scale_findings
from rclverify.model.plan.acknowledged import apply_acknowledgements
from rclverify.records.findings import FindingRow
from rclverify.records.grounding_rows import GroundingRow
from rclverify.records.lint_rows import AcknowledgementRow, LintRow
from rclverify.report.records import diagnostics as read_diagnostics, grounding as read_grounding
from rclverify.stages.workspace import Workspace


def finding_rows(nodes: Sequence[str], health: Mapping[str, Sequence[FindingRow]],
                 side_conditions: Sequence[Mapping[str, Any]]) -> list[FindingRow]:
    """The health findings of ``nodes`` in their order, then the side
    conditions whose ranges lie a power of ten apart (a warning, calculus/scale.py)."""
    return [f for n in nodes for f in health[n]] + [FindingRow.of(f) for f in scale_findings(list(side_conditions))]


def lint_rows(ws: Workspace) -> list[dict[str, Any]]:
    """The diagnostics of the contract and plan text (artifacts/check/diagnostics.json), ``location`` file:line:col."""
    return [{"severity": d["severity"], "location": f"{d['file']}:{d['line']}:{d['col']}", "message": d["message"],
             "code": d.get("code", "")} for d in read_diagnostics(ws)]


def acknowledged_rows(ws: Workspace, findings: Sequence[FindingRow], lint: Sequence[Mapping[str, Any]]
                      ) -> tuple[list[FindingRow], list[LintRow], list[AcknowledgementRow]]:
    """``(findings, lint, acknowledgements)``: new finding and lint rows, each marked with what a warning
    flags (``flagged``, ``sha256``) and the plan's answer to it
    (``acknowledged``), and one row per acknowledgement of the plan with its
    status (model/plan/acknowledged.py; docs/plan.md).  Each marked row
    is decoded into its class (:class:`~rclverify.records.findings.FindingRow`,
    :class:`~rclverify.records.lint_rows.LintRow`,
    :class:`~rclverify.records.lint_rows.AcknowledgementRow`), so the report
    holds no key the class does not declare (:class:`msgspec.ValidationError`
    otherwise: a bug of the build).  The acknowledgements' matching (model/plan/acknowledged.py) reads
    and gives the records."""
    return apply_acknowledgements(ws.plan.acknowledged, findings, [LintRow.of(x) for x in lint], ws.checked)


def grounding_row(ws: Workspace) -> GroundingRow | None:
    """The grounding in the robot's software (docs/ros.md) with its drawing's
    SVG text (``svg_text``, ``None`` when unreadable), decoded into
    :class:`~rclverify.records.grounding_rows.GroundingRow`;
    ``None`` when the plan names no ROS software.  Raises
    :class:`msgspec.ValidationError` for a record of another shape (a bug:
    the stage seals what it writes)."""
    if not getattr(ws.plan, "ros", None):
        return None
    grounding = read_grounding(ws, "artifacts/ros/grounding.json")
    if grounding is None:
        return None
    svg_rel = (grounding.get("drawing") or {}).get("svg")
    try:
        svg_text = ws.path(svg_rel).read_text(encoding="utf-8") if svg_rel else None
    except OSError:
        svg_text = None
    return GroundingRow.of({**grounding, "svg_text": svg_text})
