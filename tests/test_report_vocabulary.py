"""The report's published JSON Schema (docs/assurance.schema.json), the one status vocabulary
(rclverify.records.statuses) and the report's TypedDicts (records/report_schema.py) held in step, and
the stages' own status tables held to the vocabulary.  Nothing here runs the pipeline (the inner
tier); tests/test_report_schema.py validates the reports of a run.
"""
from __future__ import annotations

import typing
from typing import Any

from jsonschema import Draft202012Validator

from _report_schema import SCHEMA
from rclverify.records import records, statuses
from rclverify.records import report_schema as st


def _undescribed(x: Any, where: str = "") -> list[str]:
    """The properties of the schema ``x`` without a description, as paths."""
    out: list[str] = []
    if isinstance(x, dict):
        out += [f"{where}/{k}" for k, v in (x.get("properties") or {}).items() if not v.get("description")]
        for k, v in x.items():
            out += _undescribed(v, f"{where}/{k}")
    elif isinstance(x, list):
        for i, v in enumerate(x):
            out += _undescribed(v, f"{where}/{i}")
    return out


def test_the_schema_is_a_draft_2020_12_schema_with_each_key_described() -> None:
    Draft202012Validator.check_schema(SCHEMA)
    assert SCHEMA["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    assert _undescribed(SCHEMA) == []


def test_the_schema_enums_are_the_vocabulary() -> None:
    for name, words in statuses.VOCABULARY.items():
        assert SCHEMA["$defs"][name]["enum"] == list(words), name
    assert list(statuses.SEVERITY) == list(statuses.EVIDENCE_STATUSES)
    assert records.SEVERITY is statuses.SEVERITY  # the roll-up ranks the vocabulary's order
    assert records.worst(["discharged", "unverified", "pending"]) == "unverified"


def test_the_stages_use_the_vocabulary() -> None:
    from rclverify.stages.crosscheck.stage import DOWNGRADES
    from rclverify.model.plan.expected import VERDICTS as EXPECTED
    from rclverify.lang.errors import Severity as LintSeverity
    from rclverify.report import severity
    from rclverify.report.cones import DERIVATION as _DERIVATION
    from rclverify.report.contract_rows import FINDING_AS as _FINDING_AS
    from rclverify.report.deadlines import STATUS_OF
    from rclverify.calculus.requirements import rollup
    assert rollup.VERDICTS == statuses.REQUIREMENT_VERDICTS
    assert {rollup.MET, rollup.OUTSTANDING, rollup.INCONSISTENT, rollup.VACUOUS} <= set(statuses.REQUIREMENT_VERDICTS)
    assert set(_FINDING_AS) == set(statuses.HEALTH_STATUSES)
    assert set(_FINDING_AS.values()) <= set(statuses.EVIDENCE_STATUSES)
    assert set(_DERIVATION.values()) | {"undecided"} == set(statuses.DERIVATIONS)
    assert set(STATUS_OF) == set(statuses.DEADLINE_VERDICTS)
    assert set(STATUS_OF.values()) <= set(statuses.EVIDENCE_STATUSES)
    assert (severity.ERROR, severity.WARNING, severity.NOTE) == statuses.SEVERITIES
    assert typing.get_args(LintSeverity) == statuses.LINT_SEVERITIES
    assert DOWNGRADES <= set(statuses.AGREEMENTS)
    assert set(EXPECTED) <= set(statuses.RECORD_STATUSES)


#: Each row TypedDict and where the schema describes it.
_ROWS: tuple[tuple[Any, tuple[str, ...]], ...] = (
    (st.Meta, ("meta",)), (st.Summary, ("summary",)),
    (st.NodeRow, ("nodes", "items")), (st.GuaranteeRow, ("nodes", "items", "guarantees", "items")),
    (st.RequirementRow, ("requirements", "items")), (st.SupportRow, ("requirements", "items", "support", "items")),
    (st.SideConditionRow, ("side_conditions", "items")), (st.DerivedPropertyRow, ("derived_properties", "items")),
    (st.FindingRow, ("findings", "items")), (st.ObligationRow, ("obligations", "items")),
    (st.EvidenceRow, ("evidence", "items")), (st.PendingRow, ("pending", "items")), (st.LintRow, ("lint", "items")),
    (st.AcknowledgementRow, ("acknowledgements", "items")), (st.UnverifiedRow, ("unverified", "items")),
    (st.ProblemRow, ("problems", "items")),
)


def test_the_typeddicts_are_the_schema() -> None:
    assert list(st.REPORT_KEYS) == list(SCHEMA["properties"]) == SCHEMA["required"]
    for td, path in _ROWS:
        sub: Any = SCHEMA["properties"]
        for step in path:
            sub = sub[step] if step in sub else sub["properties"][step]
        keys = set(typing.get_type_hints(td))
        assert set(sub["required"]) == set(td.__required_keys__), td.__name__
        assert keys == set(sub["properties"]), (td.__name__, set(sub["properties"]) ^ keys)
