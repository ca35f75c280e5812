"""The report's rows of the margins the runs measured, defined once: a near
miss (:class:`NearMissRow`), a guarantee's margins over every recorded run
(:class:`MarginRow`) and a figure of them given by bounds
(:class:`MarginBounds`).

``near_misses[]`` (report/near_misses.py; docs/monitors.md, "Near misses")
holds each guarantee held on its runs with a margin below the plan's
near-miss threshold: ``kind`` ``value`` (a space margin, in ``unit``) or
``time`` (a deadline's time margin, s).  ``margins[]`` (report/margin_rows.py;
docs/semantics.md, "Margins over runs") holds, per guarantee judged with
margins, the smallest over the runs (``margin``, ``None`` when infinite,
then ``holds`` its side, or when no answer had one) on the run ``trace`` at
the answer ``time``/``where``; the counts summed over the ``runs``; the
figures over the ``count`` answers with a margin, ``kept`` of them
recorded; a timed guarantee's smallest time margin
(:class:`~rclverify.records.deadline_rows.HopTimeMargin`); the plot of the
kept margins per run (``plot_svg``) or why none (``plot_note``).

The rules (docs/decisions.md, "One definition per record"):

* These classes are the only statement of the rows' fields.  The report
  passes build them and write :meth:`~rclverify.records.row.Row.to_json`; a
  field at ``UNSET`` is not written (a guarantee judged on one run has no
  plot and no note).  A reader decodes the JSON object with
  :meth:`~rclverify.records.row.Row.of`.
* Each is one entry of the schema's ``$defs`` (``near_miss``,
  ``margins_over_runs``, ``margin_bounds``), generated from the class
  (records/schema_gen.py ``DEFS``); tests/records/test_record_shapes.py
  fails when the file and the classes differ.
* Every field of :class:`NearMissRow` is read by the near misses' renderers
  (report/templates/assurance.{html,md}.j2, filter ``near_miss_rows``) or
  named in :data:`NEAR_MISS_INTERNAL` with the reason it is not shown; the
  same holds for :class:`MarginRow` (report/templates/parts/margins.{html,md}.j2,
  filter ``margin_rows``) and :data:`INTERNAL`; tests/records/test_record_shapes.py
  fails otherwise.
"""
from __future__ import annotations

from typing import Annotated, Literal

import msgspec

from rclverify.records.deadline_rows import HopTimeMargin
from rclverify.records.row import DOC, Row
from rclverify.records.shared_rows import GuaranteeRefRow

_DOC = DOC


class NearMissRow(GuaranteeRefRow, frozen=True, forbid_unknown_fields=True):
    """A guarantee held on its runs with a margin below the plan's near-miss threshold (docs/monitors.md, "Near misses")."""

    kind: Annotated[Literal["value", "time"], _DOC(description="value: a space margin; time: a deadline's time margin.")]
    margin: Annotated[float, _DOC(description="The smallest margin on the run (in unit; seconds for time).")]
    threshold: Annotated[float, _DOC(description="The plan's threshold, in the same unit.")]
    unit: Annotated[str, _DOC(description="The deciding comparison's unit (s for time; empty: none declared).")]
    atom: Annotated[str, _DOC(description="The comparison that decided a space margin (empty for time).")]
    where: Annotated[str, _DOC(description="The message (the answer) it was measured on.")]
    time: Annotated[float | None, _DOC(description="That message's time stamp, seconds.")]
    trace: Annotated[str, _DOC(description="The run.")]
    obligation: Annotated[str, _DOC(description="The monitors obligation.")]
    source: Annotated[str, _DOC(description="file:line:col of the guarantee.")]
    threshold_source: Annotated[str, _DOC(description="file:line:col of the plan's near_miss.")]


class MarginBounds(Row, frozen=True, forbid_unknown_fields=True):
    """A figure of the answers' margins given by the bounds the runs' kept margins prove (docs/semantics.md, "Margins over runs"): equal where they decide it."""

    low: Annotated[float | None, _DOC(
        description="The least the figure can be: its rank with every answer a run did not record at that run's "
                    "largest recorded margin; null when infinite.")]
    high: Annotated[float | None, _DOC(
        description="The most the figure can be: its rank among the recorded margins; null when infinite (the "
                    "rank falls past them, or on answers held without a distance).")]


class MarginRow(GuaranteeRefRow, frozen=True, omit_defaults=True, forbid_unknown_fields=True):
    """A guarantee's margins over every recorded run: the smallest, where, and the distribution of its answers' margins (docs/semantics.md, "Margins over runs")."""

    formula: Annotated[str, _DOC(description="The guarantee's text.")]
    source: Annotated[str, _DOC(description="The guarantee's place, file:line:col (empty when unknown).")]
    margin: Annotated[float | None, _DOC(
        description="The smallest space margin over every run (in unit); null when infinite (see holds) or when "
                    "no answer had one.")]
    holds: Annotated[bool | None, _DOC(
        description="For an infinite smallest margin, its side (true: +inf); else null.")]
    unit: Annotated[str, _DOC(description="The deciding comparison's unit (empty: none declared).")]
    atom: Annotated[str, _DOC(description="The comparison that decided the smallest margin.")]
    trace: Annotated[str, _DOC(description="The run the smallest margin was measured on.")]
    obligation: Annotated[str, _DOC(description="That run's monitors obligation.")]
    time: Annotated[float | None, _DOC(
        description="The time stamp of the answer with the smallest margin, seconds; null when no answer had "
                    "one.")]
    where: Annotated[str, _DOC(description="That answer's message (empty when no answer had a margin).")]
    runs: Annotated[int, _DOC(description="Runs that judged the guarantee with margins.")]
    answers: Annotated[int, _DOC(description="Answers that gave the guarantee a margin, over every run.")]
    undefined: Annotated[int, _DOC(description="Answers that gave it none, over every run.")]
    count: Annotated[int, _DOC(
        description="The answers the figures cover: every answer with a margin on every run (answers).")]
    kept: Annotated[int, _DOC(
        description="Of those, the answers whose margin the runs recorded (each run's smallest, at most 256, and "
                    "the ones held without a distance).")]
    min: Annotated[MarginBounds, _DOC(description="The smallest margin of the count answers (decided: low equals "
                                                  "high).")]
    p5: Annotated[MarginBounds, _DOC(
        description="The 5 % quantile of the count answers' margins: the ceil(0.05 count)-th smallest.")]
    p50: Annotated[MarginBounds, _DOC(
        description="The median of the count answers' margins: the ceil(0.5 count)-th smallest.")]
    time_margin: Annotated[HopTimeMargin | None, _DOC(
        description="For a triggered by ... within guarantee, its smallest time margin over the runs "
                    "(docs/semantics.md, \"Time margin\"); null for an untimed guarantee.")]
    plot_svg: Annotated[str | msgspec.UnsetType, _DOC(
        description="The margins each run kept, drawn per run (inline SVG, matplotlib; the plots extra), for a "
                    "guarantee judged on two runs or more.")] = msgspec.UNSET
    plot_note: Annotated[str | msgspec.UnsetType, _DOC(
        description="Why a guarantee judged on two runs or more has no plot.")] = msgspec.UNSET


_OBLIGATION = ("names the monitors evidence of the run shown (trace); the row links to the guarantee, whose row lists "
               "its obligations and their evidence")

#: The fields of :class:`NearMissRow` no near-miss renderer shows, each with the reason.
NEAR_MISS_INTERNAL: dict[str, str] = {"obligation": _OBLIGATION}

#: The fields of :class:`MarginRow` no margins renderer shows, each with the reason.
INTERNAL: dict[str, str] = {
    "formula": "the guarantee's text, shown in its node's section, which the row links to; the row shows the "
               "comparison (atom) that decided the smallest margin",
    "obligation": _OBLIGATION,
    "min": "the bounds of the smallest margin, which are equal (decided) and shown as margin",
}


__all__ = ["INTERNAL", "MarginBounds", "MarginRow", "NEAR_MISS_INTERNAL", "NearMissRow"]
