"""The report's rows of findings: contract health and scale findings, lint diagnostics, the plan's
acknowledgements of warnings, and the grounding in the robot's software.

Each function returns its rows and changes nothing it was given (the
acknowledgement pass marks copies of the findings and lint rows).
"""
from __future__ import annotations

from typing import Any, Mapping, Sequence, cast

from rclverify.calculus.scale import scale_findings
from rclverify.model.plan.acknowledged import apply_acknowledgements
from rclverify.records.report_schema import AcknowledgementRow, FindingRow, LintRow
from rclverify.records.stage_records import HealthFinding
from rclverify.report.records import diagnostics as read_diagnostics, grounding as read_grounding
from rclverify.stages.workspace import Workspace


def finding_rows(nodes: Sequence[str], health: Mapping[str, Sequence[Mapping[str, Any]]],
                 side_conditions: Sequence[Mapping[str, Any]]) -> list[dict[str, Any] | HealthFinding]:
    """The health findings of ``nodes`` in their order, then the side
    conditions whose ranges lie a power of ten apart (a warning, calculus/scale.py)."""
    rows: list[dict[str, Any] | HealthFinding] = [dict(f) for n in nodes for f in health[n]]
    return rows + scale_findings(list(side_conditions))


def lint_rows(ws: Workspace) -> list[dict[str, Any]]:
    """The diagnostics of the contract and plan text (artifacts/check/diagnostics.json), ``location`` file:line:col."""
    return [{"severity": d["severity"], "location": f"{d['file']}:{d['line']}:{d['col']}", "message": d["message"],
             "code": d.get("code", "")} for d in read_diagnostics(ws)]


def acknowledged_rows(ws: Workspace, findings: Sequence[Mapping[str, Any]], lint: Sequence[Mapping[str, Any]]
                      ) -> tuple[list[FindingRow], list[LintRow], list[AcknowledgementRow]]:
    """``(findings, lint, acknowledgements)``: new finding and lint rows
    marked with what each warning flags (``flagged``, ``sha256``) and the
    plan's answer to it (``acknowledged``), and one row per acknowledgement
    of the plan with its status (model/plan/acknowledged.py; docs/plan.md)."""
    f_rows, l_rows = [dict(f) for f in findings], [dict(x) for x in lint]
    acks = apply_acknowledgements(ws.plan.acknowledged, f_rows, l_rows, ws.checked)
    return cast(list[FindingRow], f_rows), cast(list[LintRow], l_rows), cast(list[AcknowledgementRow], acks)


def grounding_row(ws: Workspace) -> dict[str, Any] | None:
    """The grounding in the robot's software (docs/ros.md) with its drawing's
    SVG text (``svg_text``, ``None`` when unreadable); ``None`` when the plan
    names no ROS software."""
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
    return {**grounding, "svg_text": svg_text}
