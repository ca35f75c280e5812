"""The NoDL part of the report (``nodl``; docs/nodl.md, stages/nodl.py) as
types: the static reading of its ``docs/assurance.schema.json`` part, held
to it key by key by ``tests/report/test_report_vocabulary.py`` through
:class:`~rclverify.records.report_schema.Report`."""
# No ``from __future__ import annotations``: Python 3.11 reads ``NotRequired`` only from evaluated
# annotations (with string annotations every key would count as required).
from typing import Literal, NotRequired, TypedDict


class NodlPlaceRow(TypedDict):
    """A place a NoDL finding involves (``$defs/nodl_place``): file, line, column (1-based)."""
    file: str
    line: int
    col: int


class NodlFindingRow(TypedDict):
    """A finding of the NoDL check (``nodl.findings[]``; docs/nodl.md, "Findings"), at every place it involves."""
    code: str
    severity: Literal["error", "warning"]
    message: str
    places: list[NodlPlaceRow]


class NodlSideConditionRow(TypedDict):
    """A parameter's declared constraints against an assumption of its node (``nodl.side_conditions[]``)."""
    node: str
    parameter: str
    conjunct: str
    status: Literal["proved", "refuted", "inconclusive"]
    model: dict[str, str]


class NodlRow(TypedDict):
    """The workspace's NoDL documents against its contracts and each other (``nodl``; stages/nodl.py)."""
    documents: dict[str, list[str]]
    parts: list[str]
    findings: list[NodlFindingRow]
    counts: dict[str, int]
    side_conditions: list[NodlSideConditionRow]
    inputs: dict[str, str]
    stale: NotRequired[str]
    altered: NotRequired[str]


__all__ = ["NodlFindingRow", "NodlPlaceRow", "NodlRow", "NodlSideConditionRow"]
