"""An end-to-end deadline's row of the report, defined once: :class:`DeadlineRow`,
its chain's hops (:class:`DeadlineHop`) and a hop's time margin
(:class:`HopTimeMargin`).

The report's ``deadlines[]`` holds one row per ``deadline:`` of the plan
(rule D3, report/deadlines.py): the deadline stage's decision
(records/stage_records.py ``DeadlineRecord``) with its status in the roll-up,
each hop of its chain with its guarantee's evidence status and the
monitors' deadline records of its node, and the time margins the runs
measured (report/chain_margins.py).  A requirement's row holds its
deadline's row too (:class:`~rclverify.records.requirement_rows.RequirementRow`
``deadline``); the margins over runs give a timed guarantee's smallest time
margin as a :class:`HopTimeMargin` (records/margin_rows.py).

The rules (docs/decisions.md, "One definition per record"):

* These classes are the only statement of the rows' fields.  The report
  pass builds them and writes :meth:`~rclverify.records.row.Row.to_json`; a
  field at ``UNSET`` is not written (a deadline not decided has no
  ``solvers``; a hop measured by a run has no ``timing``).  A reader decodes
  the JSON object with :meth:`~rclverify.records.row.Row.of`.
* The first seven fields of :class:`DeadlineHop` are the deadline stage's
  hop (records/stage_records.py ``DeadlineHop``, the sealed record's
  shape); tests/records/test_record_shapes.py holds the two to one list of keys.
* Each is one entry of the schema's ``$defs`` (``deadline``,
  ``deadline_hop``, ``hop_time_margin``), generated from the class
  (records/schema_gen.py ``DEFS``); tests/records/test_record_shapes.py
  fails when the file and the classes differ.
* Every field of :class:`DeadlineRow` and of :class:`DeadlineHop` is read by
  the deadlines' renderers (report/templates/parts/deadlines.{html,md}.j2,
  filters ``deadline_rows`` and ``hop_rows``) or named in :data:`INTERNAL`
  or :data:`HOP_INTERNAL` with the reason it is not shown;
  tests/records/test_record_shapes.py fails otherwise.
"""
from __future__ import annotations

from typing import Annotated, Any

import msgspec

from rclverify.records.row import DOC, Row
from rclverify.records.shared_rows import GuaranteeRefRow
from rclverify.records.solvers_rows import Solvers
from rclverify.records.statuses import DeadlineVerdict, EvidenceStatus

_DOC = DOC


class HopTimeMargin(Row, frozen=True, forbid_unknown_fields=True):
    """A hop's smallest time margin over its node's recorded runs (docs/semantics.md, "Time margin of a chain")."""

    margin_s: Annotated[float | None, _DOC(
        description="The hop's deadline less its latest answer's delay, seconds; null when no trigger was "
                    "answered.")]
    margin_ns: Annotated[int | None, _DOC(description="The same in integer nanoseconds.")]
    obligation: Annotated[str, _DOC(description="The monitors obligation whose run measured it.")]
    trigger_where: Annotated[str, _DOC(description="The trigger it was measured on.")]
    answer_where: Annotated[str, _DOC(description="The answer it was measured on.")]
    answers: Annotated[int, _DOC(description="Triggers answered, over every run.")]
    unanswered: Annotated[int, _DOC(description="Triggers never answered, over every run (they have no margin).")]


class DeadlineHop(GuaranteeRefRow, frozen=True, omit_defaults=True, forbid_unknown_fields=True):
    """One timed guarantee of a deadline's chain (report/deadlines.py)."""

    trigger: Annotated[str, _DOC(description="Its trigger, in.x.")]
    outputs: Annotated[list[str], _DOC(description="The outputs it answers with.")]
    within_s: Annotated[str, _DOC(description="Its deadline in seconds, an exact fraction.")]
    within: Annotated[str, _DOC(description="Its deadline as the reader writes it.")]
    loc: Annotated[str, _DOC(description="file:line:col of the guarantee.")]
    status: Annotated[EvidenceStatus | msgspec.UnsetType, _DOC(
        description="Its evidence status.")] = msgspec.UNSET
    timing: Annotated[str | msgspec.UnsetType, _DOC(
        description="Why its deadline counts as measured by no run, when so.")] = msgspec.UNSET
    monitors: Annotated[list[dict[str, Any]] | msgspec.UnsetType, _DOC(
        description="The deadline records of its node's monitors evidence.")] = msgspec.UNSET
    time_margin: Annotated[HopTimeMargin | None | msgspec.UnsetType, _DOC(
        description="Its smallest time margin on the runs, null when no run measured it.")] = msgspec.UNSET


class DeadlineRow(Row, frozen=True, omit_defaults=True, forbid_unknown_fields=True):
    """An end-to-end deadline decided by rule D3 (docs/requirements.md)."""

    requirement: Annotated[str, _DOC(description="The requirement's id.")]
    path: Annotated[list[str], _DOC(description="The nodes of the chain, in order.")]
    within: Annotated[str, _DOC(description="The bound, as written.")]
    source: Annotated[str, _DOC(description="file:line:col of the RCL or plan text (1-based line and column)")]
    verdict: Annotated[DeadlineVerdict, _DOC(description="What the proof found.")]
    status: Annotated[EvidenceStatus | msgspec.UnsetType, _DOC(
        description="Its status in the roll-up.")] = msgspec.UNSET
    evidence_status: Annotated[EvidenceStatus | msgspec.UnsetType, _DOC(
        description="Worst status of the timed guarantees it rests on.")] = msgspec.UNSET
    reason: Annotated[str | msgspec.UnsetType, _DOC(description="Why, in one sentence.")] = msgspec.UNSET
    chain: Annotated[list[DeadlineHop] | msgspec.UnsetType, _DOC(
        description="One row per timed guarantee of the chain.")] = msgspec.UNSET
    total: Annotated[str | None | msgspec.UnsetType, _DOC(description="The chain's summed bound.")] = msgspec.UNSET
    time_margin: Annotated[str | None | msgspec.UnsetType, _DOC(
        description="The chain's measured margin: the bound less every hop's worst measured latency, summed (ms); "
                    "null unless every hop has a margin and no unanswered trigger.")] = msgspec.UNSET
    time_margin_ns: Annotated[int | None | msgspec.UnsetType, _DOC(
        description="The same in integer nanoseconds.")] = msgspec.UNSET
    stamps: Annotated[list[Any] | msgspec.UnsetType, _DOC(
        description="The time stamps the monitors check.")] = msgspec.UNSET
    smt2: Annotated[str | msgspec.UnsetType, _DOC(
        description="Path of the SMT-LIB2 query, empty when none.")] = msgspec.UNSET
    solvers: Annotated[Solvers | None | msgspec.UnsetType, _DOC(
        description="The second solver's agreement, null when not asked.")] = msgspec.UNSET


#: The fields of :class:`DeadlineRow` no deadline renderer shows, each with the reason.
INTERNAL: dict[str, str] = {
    "evidence_status": "the worst status of the chain's hops, each shown on its hop and folded into status, shown",
    "time_margin_ns": "the measured margin shown (time_margin) in integer nanoseconds, for exact comparison by tools",
}

#: The fields of :class:`DeadlineHop` no deadline renderer shows, each with the reason.
HOP_INTERNAL: dict[str, str] = {
    "within_s": "the hop's deadline shown (within) as an exact fraction of seconds, which the sum (total) adds up",
}


__all__ = ["DeadlineHop", "DeadlineRow", "HOP_INTERNAL", "HopTimeMargin", "INTERNAL"]
