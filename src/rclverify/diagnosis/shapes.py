"""The records the diagnosis builds and reads, as types.

What a diagnosis writes (the record, its culprits, counterexample rows and
repairs) is sealed, so its types are :mod:`rclverify.records.stage_records`'
(``DiagnosisEntry``, ``Culprit``, ``CexRow``, ``Repair``); the report parts
it reads are the report's records (:class:`ReportRows`: the parts of
:class:`~rclverify.records.report_record.AssuranceReport` it reads, each
decoded into its Struct and read by attribute).  Here too are the parts
only the diagnosis passes between its own functions and its cache
(``artifacts/cache/diagnosis.pickle``, kept as JSON).
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any, TypedDict, cast

import msgspec

from rclverify.diagnosis.edits import Edit
from rclverify.records.deadline_rows import DeadlineRow
from rclverify.records.evidence_rows import EvidenceRow
from rclverify.records.findings import FindingRow
from rclverify.records.lint_rows import LintRow
from rclverify.records.node_rows import NodeRow
from rclverify.records.obligations import ObligationRow
from rclverify.records.report_record import AssuranceReport
from rclverify.records.requirement_rows import RequirementRow
from rclverify.records.row import decode_rows
from rclverify.records.side_condition_rows import SideConditionRow
from rclverify.records.stage_records import Repair
from rclverify.records.summary_rows import SystemView


class ReportRows(msgspec.Struct, frozen=True):
    """The parts of the report the diagnosis reads, decoded (:func:`report_rows`): the fields of
    :class:`~rclverify.records.report_record.AssuranceReport` of the same names."""
    system: SystemView
    requirements: list[RequirementRow]
    nodes: list[NodeRow]
    side_conditions: list[SideConditionRow]
    findings: list[FindingRow]
    obligations: list[ObligationRow]
    evidence: list[EvidenceRow]
    lint: list[LintRow]
    deadlines: list[DeadlineRow]


#: The fields of :class:`ReportRows`.
ROW_KEYS: tuple[str, ...] = ReportRows.__struct_fields__


def report_rows(report: ReportRows | AssuranceReport | Mapping[str, Any]) -> ReportRows:
    """The :class:`ReportRows` of ``report``: itself; the parts of an
    :class:`~rclverify.records.report_record.AssuranceReport`; or the parts
    of a report's JSON object (the report without diagnoses, report/build.py
    ``undiagnosed_report``, or a whole one) decoded into their records.
    Raises ``ValueError`` naming the parts a JSON object lacks,
    :class:`msgspec.ValidationError` (a ``ValueError``) for a part of
    another shape."""
    if isinstance(report, ReportRows):
        return report
    if isinstance(report, AssuranceReport):
        return ReportRows(*(getattr(report, k) for k in ROW_KEYS))
    missing = [k for k in ROW_KEYS if k not in report]
    if missing:
        raise ValueError(f"report lacks {', '.join(missing)}")
    return ReportRows(
        system=SystemView.of(report["system"]),
        requirements=decode_rows(RequirementRow, report["requirements"]),
        nodes=decode_rows(NodeRow, report["nodes"]),
        side_conditions=decode_rows(SideConditionRow, report["side_conditions"]),
        findings=decode_rows(FindingRow, report["findings"]),
        obligations=decode_rows(ObligationRow, report["obligations"]),
        evidence=decode_rows(EvidenceRow, report["evidence"]),
        lint=decode_rows(LintRow, report["lint"]),
        deadlines=decode_rows(DeadlineRow, report["deadlines"]))


class Strengthening(msgspec.Struct, frozen=True, kw_only=True):
    """A guarantee whose one edit lets Z3 prove a refuted requirement (diagnosis/blame.py
    ``requirement_culprits``, ``temporal_culprits``): guarantee ``guarantee`` (1-based) of ``node``,
    ``how`` ``bound`` | ``threshold`` | ``conclusion`` | ``offset``, the text ``old`` and ``new``,
    ``implementable`` ``proved`` or ``inconclusive``; a threshold's edit also names the ``threshold``
    and whether it is now ``inclusive`` (``""`` and ``False`` for the others).  Passed between the
    diagnosis' functions only, never kept."""
    node: str
    guarantee: int
    edit: Edit
    how: str
    old: str
    new: str
    implementable: str
    threshold: str = ""
    inclusive: bool = False


class CulpritRow(msgspec.Struct, frozen=True):
    """A :class:`Strengthening` as the diagnosis cache keeps it (diagnosis/requirement.py): the
    guarantee's ``text`` and ``source``, the edit as a ``repair`` Z3 checked
    (:class:`~rclverify.records.stage_records.Repair`).  Kept as its JSON object
    (:func:`culprit_rows_json`) and read back with :func:`culprit_rows`."""
    node: str
    guarantee: int
    how: str
    old: str
    new: str
    text: str
    source: str
    repair: dict[str, Any]

    def repair_record(self) -> Repair:
        """:attr:`repair` as the diagnosis record's repair."""
        return cast(Repair, self.repair)


def culprit_rows_json(rows: list[CulpritRow]) -> list[object]:
    """``rows`` as the JSON objects the diagnosis cache keeps."""
    out: list[object] = msgspec.to_builtins(rows)
    return out


def culprit_rows(kept: object) -> list[CulpritRow]:
    """The rows the diagnosis cache gave back (:func:`culprit_rows_json`; ``None``: none) decoded.
    Raises :class:`msgspec.ValidationError` for a kept value of another shape."""
    return msgspec.convert(kept or [], list[CulpritRow])


class ProducerCulprits(TypedDict):
    """The producer guarantees whose strengthening discharges a failed side condition
    (diagnosis/blame.py ``side_condition_culprits`` as the cache keeps it): ``[producer, index]``
    pairs, and how many candidates Z3 could not decide."""
    culprits: list[list[str | int]]
    undecided: int


class SideConditionRepairs(TypedDict):
    """The repairs of a failed side condition (diagnosis/sidecond.py ``side_condition_repairs``) and the
    sentences of those Z3 showed do not work."""
    repairs: list[Repair]
    not_offered: list[str]
