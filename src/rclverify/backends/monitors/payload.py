"""The monitors backend's evidence payload, defined once: :class:`MonitorsPayload`.

An evidence record's ``details`` (records/records.py ``Evidence.details``)
is its backend's own JSON object.  The monitors backend (:mod:`.backend`,
one recorded run; :mod:`.runset`, a plan entry's target over its runs)
builds a :class:`MonitorsPayload` and writes :meth:`MonitorsPayload.details`:

* ``monitoring`` (:class:`MonitoringBlock`): the node's verdicts on the run,
  its first violations, the run's digest and span, and per guarantee its
  smallest space margin (:class:`SpaceMargin`; docs/semantics.md, "Margins");
* ``statistics`` (:class:`RunStatistics`): what the run saw, or the run
  set's counts and decision (docs/statistics.md);
* ``deadlines`` (:class:`DeadlineBlock`): the deadline verdicts and per timed
  guarantee its smallest time margin (:class:`TimeMarginItem`);
* ``calls``, ``periods``, ``declarations``, ``lifecycle``, ``not_judged``: the
  node's calls, periodic outputs, declarations, lifecycle gate and what the
  run did not judge, as their JSON objects (docs/monitors.md).

A reader decodes the record's ``details`` once, by its ``backend``
(``backends/payloads.py`` :func:`~rclverify.backends.payloads.payload_of`, or
:func:`monitors_payload`, ``None`` for a record that is not this payload),
and reads attributes mypy checks.  A top-level part the run did not produce
is left out of the JSON (``None``); inside a part, a key written on some
records only is :data:`msgspec.UNSET` when absent (so the JSON holds exactly
the keys the backend wrote); a key no field declares is refused.  The
defaults are those of a record written before the field existed (a run's
``margins`` kept only the smallest: ``lowest`` unset; a run without an
identity: ``sha256`` unset).
"""
from __future__ import annotations

from typing import Any, Mapping

import msgspec
from msgspec import UNSET, UnsetType

from rclverify.backends.payload_base import EvidencePayload

#: a number as the run wrote it: an int stays an int (decoding it as ``float`` would write ``2.0`` for ``2``)
Number = int | float


class _Part(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """A part of the payload: every field written (``UNSET`` ones left out), an undeclared key refused."""


class SpaceMargin(_Part, frozen=True):
    """A guarantee's smallest space margin on one run (``monitoring.margins[]``,
    backends/monitors/verdicts.py ``GuaranteeMargin.to_json``): ``margin`` in ``unit``,
    ``null`` when infinite (``holds`` then says on which side) or when no answer had
    one (``answers`` 0); ``lowest`` the run's smallest margins kept (``null``: ``-inf``)."""

    guarantee: int
    formula: str = ""
    margin: Number | None = None
    holds: bool | None = None
    unit: str = ""
    atom: str = ""
    arithmetic: str = ""
    event: int = -1
    time: Number | None = None  #: the answer's time, s
    where: str = ""
    question: str = ""
    answers: int = 0
    undefined: int = 0
    lowest: list[Number | None] | UnsetType = UNSET
    trace: str | UnsetType = UNSET  #: the run, when the margins were written with it


class MonitoringBlock(_Part, frozen=True):
    """The node's verdicts on one run (``details["monitoring"]``,
    backends/monitors/summary.py ``monitoring_details``); the first
    violations, the assumption's verdict and the tolerance are their JSON
    objects (backends/monitors/shapes.py names their keys)."""

    trace: str = ""
    sha256: str = ""
    events_read: int = 0
    node_events: int = 0
    horizon_s: Number = 0.0
    counts: dict[str, int] = {}
    first_violation: dict[str, Any] | None = None
    first_assumption_violation: dict[str, Any] | None = None
    first_inconclusive: dict[str, Any] | None = None
    assumption: dict[str, Any] | None = None
    semantics: dict[str, int] = {}
    first_inexact: dict[str, Any] | None = None
    tolerance: dict[str, Any] | None = None
    tools: str = ""
    violations: list[dict[str, Any]] = []
    violations_dropped: int = 0
    unasked: int = 0
    duration_s: Number | None = None  #: the run's span in trace time, s (``None``: not measured)
    margins: list[SpaceMargin] = []
    stamp_order: str | UnsetType = UNSET  #: why the stamps were read in another order, when they were
    source: dict[str, Any] | UnsetType = UNSET  #: which source and middleware heard a live run


class RunStatistics(_Part, frozen=True):
    """What one run saw (backends/monitors/runset.py ``run_counts``) or, for a
    run set, its counts over the runs and the decision against the entry's
    target (``target``, ``counts``, ``decision``, ``runs``): only the keys
    written are set."""

    environment: str | UnsetType = UNSET
    origin: str | UnsetType = UNSET
    trace: str | UnsetType = UNSET
    sha256: str | UnsetType = UNSET  #: the run's identity (backends/monitors/run_identity.py)
    files_sha256: str | UnsetType = UNSET
    recorded: str | UnsetType = UNSET
    status: str | UnsetType = UNSET
    answers: int | UnsetType = UNSET
    violations: int | UnsetType = UNSET
    inconclusive: int | UnsetType = UNSET
    seconds: Number | UnsetType = UNSET
    violations_per_guarantee: dict[str, int] | UnsetType = UNSET
    per_guarantee_complete: bool | UnsetType = UNSET
    target: dict[str, Any] | UnsetType = UNSET
    counts: dict[str, Any] | UnsetType = UNSET
    decision: dict[str, Any] | UnsetType = UNSET
    runs: list[dict[str, Any]] | UnsetType = UNSET


class TimeMarginItem(_Part, frozen=True):
    """A timed guarantee's smallest time margin on one run (``deadlines.time_margins[]``,
    backends/monitors/time_margins.py ``TimeMargin.to_json``): ``margin`` s and
    ``margin_ns`` (the deadline less the answer's stamp), ``null`` when no trigger was answered."""

    guarantee: int
    margin: Number | None = None
    margin_ns: int | None = None
    trigger_where: str = ""
    answer_where: str = ""
    answer: Number | None = None  #: the answer's stamp, s
    answers: int = 0
    unanswered: int = 0


class DeadlineBlock(_Part, frozen=True):
    """The node's deadline verdicts on one run (``details["deadlines"]``,
    backends/monitors/deadline_records.py ``DeadlineResult.to_json``)."""

    node: str = ""
    counts: dict[str, int] = {}
    first_false: dict[str, Any] | None = None
    unaccepted: dict[str, int] = {}
    first_unaccepted: dict[str, Any] | None = None
    time_margins: list[TimeMarginItem] = []


class MonitorsPayload(EvidencePayload, frozen=True, tag="monitors"):
    """A monitored run's (or run set's) evidence payload (module docstring)."""

    monitoring: MonitoringBlock | None = None
    statistics: RunStatistics | None = None
    deadlines: DeadlineBlock | None = None
    calls: dict[str, Any] | None = None  #: the node's served calls judged and the log's call counts
    periods: dict[str, Any] | None = None  #: the node's periodic outputs on the run
    declarations: list[dict[str, Any]] | None = None  #: the node's declarations judged on the run
    lifecycle: dict[str, Any] | None = None  #: a managed node's lifecycle gate
    not_judged: list[dict[str, Any]] | None = None  #: what the run did not judge, each with the reason


def monitors_payload(backend: str, details: Mapping[str, Any]) -> MonitorsPayload | None:
    """The payload of an evidence record of ``backend`` whose ``details`` are ``details``, decoded once;
    ``None`` for another backend's record or one whose details are not this payload (the report's evidence
    pass shows that record as error, report/evidence_rows.py)."""
    if backend != "monitors":
        return None
    try:
        return msgspec.convert({**details, "backend": "monitors"}, MonitorsPayload)
    except (msgspec.ValidationError, TypeError):
        return None


__all__ = ["DeadlineBlock", "MonitoringBlock", "MonitorsPayload", "RunStatistics", "SpaceMargin", "TimeMarginItem",
           "monitors_payload"]
