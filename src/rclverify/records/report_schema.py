"""The assurance report as its JSON object: :class:`Report`, the dict-shaped view of
:class:`rclverify.records.report_record.AssuranceReport`, for the readers of a report's JSON.

Every part of the report is defined once as a msgspec Struct (the modules
beside this one: :mod:`rclverify.records.findings`, ``node_rows``,
``deadline_rows`` and the others), and docs/assurance.schema.json is
generated from them (:mod:`rclverify.records.schema_gen`).  The report's
passes (report/build.py) build and return those records, and the report is
an :class:`~rclverify.records.report_record.AssuranceReport` from its first
pass to the renderers (docs/records.md); its JSON object is made once, when
it is written (report/render.py ``render_json``), or read from a stored
report.  :class:`Report` lists the top-level keys of that object, held to
:class:`~rclverify.records.report_record.AssuranceReport`'s fields by
tests/report/test_report_vocabulary.py.

:func:`as_report` checks a report's JSON object (its top-level keys and the
summary status) and gives it as a :class:`Report`, so a reader typed on
:class:`Report` never reads a report that lacks a part.
"""
from typing import Any, Mapping, TypedDict, cast

from rclverify.records import report_record
from rclverify.records.statuses import EVIDENCE_STATUSES


class Report(TypedDict):
    """``reports/assurance.json`` (docs/assurance.schema.json) as its JSON object: each part the encoding
    of its record (:class:`~rclverify.records.report_record.AssuranceReport`'s field of the same name)."""
    meta: dict[str, Any]
    summary: dict[str, Any]
    system: dict[str, Any]
    requirements: list[dict[str, Any]]
    nodes: list[dict[str, Any]]
    side_conditions: list[dict[str, Any]]
    derived_properties: list[dict[str, Any]]
    findings: list[dict[str, Any]]
    obligations: list[dict[str, Any]]
    evidence: list[dict[str, Any]]
    environment_assumptions: list[dict[str, Any]]
    pending: list[dict[str, Any]]
    lint: list[dict[str, Any]]
    expected_verdicts: list[dict[str, Any]]
    grounding: dict[str, Any] | None
    nodl: dict[str, Any] | None
    instances: dict[str, Any] | None
    design: dict[str, Any] | None
    unverified: list[dict[str, Any]]
    deadlines: list[dict[str, Any]]
    acknowledgements: list[dict[str, Any]]
    near_misses: list[dict[str, Any]]
    margins: list[dict[str, Any]]
    statistics: list[dict[str, Any]]
    standards: list[dict[str, Any]]
    diagnoses: list[dict[str, Any]]
    problems: list[dict[str, Any]]


#: The report's top-level keys, in the order build_report writes them (the fields of its one definition).
REPORT_KEYS: tuple[str, ...] = report_record.REPORT_KEYS


def as_report(report: Mapping[str, Any]) -> Report:
    """``report`` (a report's JSON object: :meth:`AssuranceReport.to_json
    <rclverify.records.row.Row.to_json>`, or a stored report) as a :class:`Report`.  Raises ``ValueError`` naming the missing
    top-level keys, or a ``summary.status`` outside the evidence statuses:
    a report without a part is a bug of the build, never shown."""
    missing = [k for k in REPORT_KEYS if k not in report]
    if missing:
        raise ValueError(f"report lacks {', '.join(missing)}")
    status = report["summary"].get("status")
    if status not in EVIDENCE_STATUSES:
        raise ValueError(f"report summary status {status!r} is not an evidence status")
    return cast(Report, report)
