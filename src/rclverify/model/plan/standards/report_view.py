"""The parts of a report the standards mapping reads, typed (docs/standards.md, "Scope").

The mapping (:mod:`.mapping`, :mod:`.field_data`, :mod:`.reviews`) reads
a report's JSON object, or any part of it (a hand-made report, a bare list
of evidence rows): :func:`report_view` converts it once into
:class:`ReportView` (``msgspec.convert``), whose fields are those the
mapping reads, each defaulted, so a part the report does not hold reads
as empty; every other key is ignored.  The fields' names and meanings are
the report records' (records/evidence_rows.py, records/findings.py,
records/requirement_rows.py, ...); an evidence row's ``statistics`` and a
requirement's runs rows are read as :class:`StatisticsView` (the fields of a
statistical target's decision, docs/statistics.md, that
:func:`.field_data.figures` shows).  Raises :class:`msgspec.ValidationError` for
a value of another type than the report's (a bug of the caller).
"""
from __future__ import annotations

from typing import Any, Mapping, Sequence

import msgspec


class _View(msgspec.Struct, frozen=True, kw_only=True):
    """A part of the report as the mapping reads it (unknown keys ignored)."""


class StrengthView(_View, frozen=True, kw_only=True):
    """An evidence row's ``strength`` (docs/confidence.md): its kind."""

    kind: str | None = None


class TargetView(_View, frozen=True, kw_only=True):
    """A statistical target as its decision states it (records/statistics.py ``TargetJson``): the
    violation probability ``bound`` it asks and the target in words."""

    bound: float | None = None
    text: str = ""


class DecisionView(_View, frozen=True, kw_only=True):
    """A target's decision (records/statistics.py ``decide``): ``n`` trials counted, ``k`` violating, the
    upper ``bound`` at confidence ``level``, and the ``target``."""

    n: int | None = None
    k: int | None = None
    bound: float | None = None
    level: float | None = None
    target: TargetView = TargetView()


class CountsView(_View, frozen=True, kw_only=True):
    """The counts of a set of runs (records/statistics.py ``count_runs``): the runs and the violating ones."""

    runs: int | None = None
    violating_runs: int | None = None


class StatisticsView(_View, frozen=True, kw_only=True):
    """An evidence row's ``statistics`` (as its backend wrote it) or a requirement's runs row
    (records/statistics_rows.py ``RequirementRuns``): the runs' ``environment`` and ``origin``, their
    ``counts``, the ``decision`` against a target (an evidence row's), the ``target`` (a requirement's in
    words, an evidence row's as its JSON), the ``bound`` and ``level`` (a requirement's) and ``status``
    (a requirement's target decided)."""

    environment: str = ""
    origin: str = ""
    counts: CountsView | None = None
    decision: DecisionView | None = None
    target: str | TargetView | None = None
    bound: float | None = None
    level: float | None = None
    status: str | None = None


class EvidenceView(_View, frozen=True, kw_only=True):
    """An ``evidence[]`` row: the obligation, who produced it, its kind and status, what it states."""

    obligation: str = ""
    backend: str = ""
    kind: str | None = None
    status: str | None = None
    tool: str = ""
    tool_version: str = ""
    #: ``[field, value]`` rows (a review's reviewer, author, independence, ...)
    figures: tuple[Any, ...] | None = None
    strength: StrengthView | None = None
    #: as the backend wrote it (docs/statistics.md); ``None`` when absent
    statistics: StatisticsView | None = None


class ObligationView(_View, frozen=True, kw_only=True):
    """An ``obligations[]`` row: its id, node and guarantee (0: the whole contract)."""

    id: str = ""
    node: str = ""
    guarantee: int = 0


class GuaranteeView(_View, frozen=True, kw_only=True):
    """A node's guarantee: its 1-based index and status."""

    index: int = 0
    status: str = ""


class NodeView(_View, frozen=True, kw_only=True):
    """A ``nodes[]`` row: the node's name and guarantees."""

    name: str = ""
    guarantees: tuple[GuaranteeView, ...] | None = None


class FindingView(_View, frozen=True, kw_only=True):
    """A ``findings[]`` row (a health check): its id, node, guarantee (``None``: the node's), check, status."""

    id: str = ""
    node: str | None = None
    guarantee: int | None = None
    check: str | None = None
    status: str | None = None


class SideConditionView(_View, frozen=True, kw_only=True):
    """A ``side_conditions[]`` row: its id, the node it is of, its verdict and status."""

    id: str | None = None
    node: str | None = None
    verdict: str | None = None
    status: str | None = None


class DeadlineView(_View, frozen=True, kw_only=True):
    """A requirement's ``deadline``: its verdict."""

    verdict: str | None = None


class SupportView(_View, frozen=True, kw_only=True):
    """A requirement's ``support`` row: a node and one of its guarantees."""

    node: str = ""
    guarantee: int = 0


class RequirementView(_View, frozen=True, kw_only=True):
    """A ``requirements[]`` row: its id, status, verdict, deadline, statistical targets and support."""

    id: str | None = None
    status: str | None = None
    verdict: str | None = None
    deadline: DeadlineView | None = None
    #: its targets over recorded runs, as the statistics pass wrote them (docs/statistics.md)
    statistics: tuple[StatisticsView, ...] | None = None
    support: tuple[SupportView, ...] | None = None


class UnverifiedView(_View, frozen=True, kw_only=True):
    """An ``unverified[]`` row: a guarantee no obligation covers."""

    node: str | None = None
    guarantee: int | None = None


class ConnectionView(_View, frozen=True, kw_only=True):
    """A ``system.connections[]`` row: the nodes it links."""

    from_node: str | None = None
    to_node: str | None = None


class SystemView(_View, frozen=True, kw_only=True):
    """The report's ``system``: its connections."""

    connections: tuple[ConnectionView, ...] | None = None


class SummaryView(_View, frozen=True, kw_only=True):
    """The report's ``summary``: the workspace's status."""

    status: str = "pending"


class ReportView(_View, frozen=True, kw_only=True):
    """The parts of a report the mapping reads, each empty when the report does not hold it."""

    evidence: tuple[EvidenceView, ...] = ()
    obligations: tuple[ObligationView, ...] = ()
    nodes: tuple[NodeView, ...] = ()
    findings: tuple[FindingView, ...] = ()
    side_conditions: tuple[SideConditionView, ...] = ()
    requirements: tuple[RequirementView, ...] = ()
    unverified: tuple[UnverifiedView, ...] = ()
    system: SystemView = SystemView()
    summary: SummaryView = SummaryView()


def _present(report: Mapping[str, Any]) -> dict[str, object]:
    """``report`` without the parts written as ``null`` (read as absent, as the mapping always has)."""
    return {k: v for k, v in report.items() if v is not None}


def report_view(report: ReportView | Mapping[str, Any] | Sequence[Mapping[str, Any]]) -> ReportView:
    """``report`` (a report's JSON object or a part of it; a bare list of evidence rows reads as a report
    of those rows alone) as a :class:`ReportView` (the module docstring for what raises)."""
    if isinstance(report, ReportView):
        return report
    data = _present(report) if isinstance(report, Mapping) else {"evidence": list(report)}
    return msgspec.convert(data, ReportView)


def statistics_view(s: StatisticsView | Mapping[str, Any]) -> StatisticsView:
    """A target's statistics (its JSON object, or its view) as a :class:`StatisticsView`."""
    return s if isinstance(s, StatisticsView) else msgspec.convert(_present(s), StatisticsView)


def evidence_view(row: EvidenceView | Mapping[str, Any]) -> EvidenceView:
    """An evidence row (its JSON object, or its view) as an :class:`EvidenceView`."""
    return row if isinstance(row, EvidenceView) else msgspec.convert(_present(row), EvidenceView)


__all__ = ["ConnectionView", "CountsView", "DeadlineView", "DecisionView", "EvidenceView", "FindingView",
           "GuaranteeView", "NodeView", "ObligationView", "ReportView", "RequirementView", "SideConditionView",
           "StatisticsView", "StrengthView", "SummaryView", "SupportView", "SystemView", "TargetView",
           "UnverifiedView", "evidence_view", "report_view", "statistics_view"]
