"""The records the diagnosis builds and reads, as types.

What a diagnosis writes (the record, its culprits, counterexample rows and
repairs) is sealed, so its types are :mod:`rclverify.records.stage_records`'
(``DiagnosisEntry``, ``Culprit``, ``CexRow``, ``Repair``); the report rows
it reads are :mod:`rclverify.records.report_schema`'s (:class:`ReportRows`:
the parts of the report it reads).  Here too are the parts only the
diagnosis passes between its own functions and its cache
(``artifacts/cache/diagnosis.pickle``, kept as JSON).
"""
# No ``from __future__ import annotations``: Python 3.11 reads ``NotRequired`` only from evaluated
# annotations (with string annotations every key would count as required).
from collections.abc import Mapping
from typing import NotRequired, TypedDict, cast

from rclverify.diagnosis.edits import Edit
from rclverify.records.report_schema import (DeadlineJson, EvidenceJson, FindingJson, LintJson, NodeJson, ObligationJson,
                                             RequirementJson, SideConditionJson, SystemJson)
from rclverify.records.stage_records import Repair


class ReportRows(TypedDict):
    """The parts of the report dict the diagnosis reads (the report without diagnoses,
    report/build.py ``undiagnosed_report``; a whole :class:`~rclverify.records.report_schema.Report`
    is one too)."""
    system: SystemJson
    requirements: list[RequirementJson]
    nodes: list[NodeJson]
    side_conditions: list[SideConditionJson]
    findings: list[FindingJson]
    obligations: list[ObligationJson]
    evidence: list[EvidenceJson]
    lint: list[LintJson]
    deadlines: list[DeadlineJson]


#: The keys of :class:`ReportRows`.
ROW_KEYS: tuple[str, ...] = tuple(ReportRows.__annotations__)


def report_rows(report: Mapping[str, object]) -> ReportRows:
    """``report`` (a report dict, without diagnoses or with) as the :class:`ReportRows` the
    diagnosis reads.  Raises ``ValueError`` naming the parts it lacks."""
    missing = [k for k in ROW_KEYS if k not in report]
    if missing:
        raise ValueError(f"report lacks {', '.join(missing)}")
    return cast(ReportRows, report)


class Strengthening(TypedDict):
    """A guarantee whose one edit lets Z3 prove a refuted requirement (diagnosis/blame.py
    ``requirement_culprits``, ``temporal_culprits``): ``how`` ``bound`` | ``threshold`` | ``conclusion``
    | ``offset``, the text ``old`` and ``new``, ``implementable`` ``proved`` or ``inconclusive``;
    a threshold's edit also names the ``threshold`` and whether it is now ``inclusive``."""
    node: str
    guarantee: int
    edit: Edit
    how: str
    old: str
    new: str
    implementable: str
    threshold: NotRequired[str]
    inclusive: NotRequired[bool]


class CulpritRow(TypedDict):
    """A :class:`Strengthening` as the diagnosis cache keeps it (diagnosis/requirement.py): the
    guarantee's ``text`` and ``source``, the edit as a ``repair`` Z3 checked."""
    node: str
    guarantee: int
    how: str
    old: str
    new: str
    text: str
    source: str
    repair: Repair


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
