"""An evidence row's ``monitoring`` as its readers decode it: :class:`MonitoredRun`, with
:class:`Violation` and :class:`AssumptionViolation`.

The report's evidence row keeps the monitors' run as its JSON object
(records/evidence_rows.py ``EvidenceRow.monitoring``: the payload's
``monitoring`` part encoded, backends/monitors/payload.py
``MonitoringBlock``; ``{}`` for another backend).  A reader decodes it once
with :meth:`MonitoredRun.of` and reads the attributes it declares: the run,
its verdict counts, the events read and its span, the first violation and
the first violated assumption (backends/monitors/shapes.py ``Violation``
and ``AssumptionViolation`` give their keys), the violations kept.  The view
declares what is read; a key it does not declare is ignored (the payload's
own Struct refuses one when the record is read, report/evidence_rows.py), a
key written ``null`` is read at its default.
"""
from __future__ import annotations

import msgspec

from rclverify.records.row import View

#: a number as the run wrote it (an int stays an int)
Number = int | float


class Violation(msgspec.Struct, frozen=True):
    """A ``violated`` verdict: where and when (``time`` in seconds, as written), the guarantee (1-based)
    and its formula, why, the values read, and the question it answered when there was one."""

    where: str | None = None
    time: Number | None = None
    guarantee: int | None = None
    formula: str = ""
    reason: str = ""
    values: dict[str, object] | None = None
    trigger_where: str | None = None
    trigger_time: Number | None = None


class AssumptionViolation(msgspec.Struct, frozen=True):
    """The first question that violated the node's assumption: where and when, the assumption and who is
    blamed (the node's producers, or the environment)."""

    where: str | None = None
    time: Number | None = None
    assumption: str = ""
    blame: str | None = None


class MonitoredRun(View, frozen=True):
    """What is read of an evidence row's ``monitoring`` (module docstring; ``{}`` for a record of another
    backend), decoded by :meth:`~rclverify.records.row.View.of`."""

    trace: str | None = None
    counts: dict[str, int] = {}  #: verdicts by word (satisfied, violated, ...)
    events_read: int = 0
    duration_s: Number | None = None  #: the run's span in trace time, s (``None``: not measured)
    first_violation: Violation | None = None
    first_assumption_violation: AssumptionViolation | None = None
    violations: list[Violation] = []
    violations_dropped: int = 0


__all__ = ["AssumptionViolation", "MonitoredRun", "Violation"]
