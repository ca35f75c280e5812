"""The rows of the report's statistics, defined once: :class:`StatisticsRow` and :class:`RequirementRuns`.

The report's ``statistics[]`` table (report/statistics.py, docs/statistics.md)
has three kinds of row, told apart by ``kind``:

* ``runs``: the monitored runs of a node under one environment tag and
  origin, each counted once by its content digest, with the one-sided
  Clopper-Pearson bound at ``level`` (records/statistics.py); fills
  ``node``, ``environment``, ``origin``, ``counts``, ``recorded``,
  ``level``, ``bound`` (``null``: no judged run) and ``note``;
* ``target``: a statistical target's decision as its evidence record gives
  it; fills ``node``, ``obligation``, ``backend``, ``status``, ``target``
  and the decision's figures;
* ``requirement``: a requirement's runs under one environment tag
  (:class:`RequirementRuns`) with its ``requirement``.

A requirement's row carries its own :class:`RequirementRuns`
(``requirements[].statistics[]``, records/requirement_rows.py).

The rules (docs/decisions.md, "One definition per record"): these classes
are the only statement of the rows' fields; report/statistics.py builds
them and writes every field, at its default (``""``, ``null``, ``{}``) where
the row's kind has nothing to say; the ``statistics`` items of
docs/assurance.schema.json are generated from :class:`StatisticsRow`
(records/schema_gen.py); every field is read by the statistics table's
renderers (report/templates/parts/statistics.{html,md}.j2, which decode the
rows with the ``statistics_rows`` filter) or named in :data:`INTERNAL`;
tests/records/test_record_shapes.py fails otherwise.
"""
from __future__ import annotations

from typing import Annotated, Any, Iterable, Literal, Mapping

from rclverify.records.row import DOC, Row
from rclverify.records.statuses import EvidenceStatus

_DOC = DOC  # a field's description, as the generated JSON Schema shows it

#: The counts of a set of runs (records/statistics.py ``count_runs`` without its digests): runs, violating,
#: undecided and unjudged runs, duplicates, answers, violations, inconclusive answers (integers), seconds.
Counts = dict[str, int | float]


class RequirementRuns(Row, frozen=True, forbid_unknown_fields=True):
    """A requirement's recorded runs under one environment tag and origin, decided against its target
    when it states one."""

    environment: Annotated[str, _DOC(description="The runs' operating conditions (the plan entry's "
                                                 "environment:).")]
    origin: Annotated[str, _DOC(description="Where the runs come from (operation, trials, harness).")]
    counts: Annotated[Counts, _DOC(description="The runs counted, each digest once (docs/statistics.md).")]
    bound: Annotated[float, _DOC(ge=0, le=1, description="The one-sided upper bound on the probability that a "
                                                         "run violates the requirement, at level.")]
    level: Annotated[float, _DOC(gt=0, lt=1, description="The bound's confidence level (the target's, else "
                                                         "0.95).")]
    note: Annotated[str, _DOC(description="Why the bound is the trivial 1 (the stats extra missing), \"\" "
                                          "otherwise.")] = ""
    target: Annotated[str | None, _DOC(description="The requirement's target in words, null without one.")] = None
    status: Annotated[EvidenceStatus | None, _DOC(description="The target's decision, null without a "
                                                              "target.")] = None
    explanation: Annotated[str, _DOC(description="The decision in words, \"\" without a target.")] = ""
    runs_needed: Annotated[int | None, _DOC(description="Further clean runs that would meet the target, null "
                                                        "when none would or without a target.")] = None
    sprt: Annotated[str | None, _DOC(description="Wald's SPRT's state (accept, continue, reject), null without "
                                                 "a target.")] = None


class StatisticsRow(Row, frozen=True, forbid_unknown_fields=True):
    """A row of the statistics table: a node's runs, a target's decision or a requirement's runs
    (module docstring); the fields its kind does not fill at their defaults."""

    kind: Annotated[Literal["runs", "target", "requirement"], _DOC(description="What the row counts.")]
    environment: Annotated[str, _DOC(description="The runs' operating conditions (the plan entry's "
                                                 "environment:).")]
    origin: Annotated[str, _DOC(description="Where the runs come from (operation, trials, harness).")]
    counts: Annotated[Counts | None, _DOC(description="The runs counted, each digest once; null when a "
                                                      "target's record has none.")]
    level: Annotated[float | None, _DOC(description="The bound's confidence level, null when not computed.")]
    bound: Annotated[float | None, _DOC(description="The one-sided upper bound on the probability of a "
                                                    "violation, null when none is drawn.")]
    node: Annotated[str, _DOC(description="The node whose runs or target it is, \"\" for a requirement's "
                                          "row.")] = ""
    requirement: Annotated[str, _DOC(description="The requirement's id, \"\" for another kind.")] = ""
    obligation: Annotated[str, _DOC(description="The target's obligation, \"\" for another kind.")] = ""
    backend: Annotated[str, _DOC(description="The target's backend, \"\" for another kind.")] = ""
    recorded: Annotated[dict[str, int], _DOC(description="How many runs were recorded live, from bags, as "
                                                         "other logs.")] = {}
    note: Annotated[str, _DOC(description="Why no bound, or why the trivial one, \"\" otherwise.")] = ""
    target: Annotated[str | None, _DOC(description="The target in words, null without one.")] = None
    status: Annotated[EvidenceStatus | None, _DOC(description="The target's decision, null without a "
                                                              "target.")] = None
    explanation: Annotated[str, _DOC(description="The decision in words, \"\" when none.")] = ""
    runs_needed: Annotated[int | None, _DOC(description="Further clean runs that would meet the target, null "
                                                        "when none would or without a target.")] = None
    sprt: Annotated[str | None, _DOC(description="Wald's SPRT's state (accept, continue, reject), null without "
                                                 "a target.")] = None


def rows_of(rows: Iterable[StatisticsRow | Mapping[str, Any]]) -> list[StatisticsRow]:
    """The report's ``statistics[]`` (JSON objects) decoded, in order
    (:meth:`StatisticsRow.of` for what raises)."""
    return [StatisticsRow.of(r) for r in rows]


#: The fields of :class:`StatisticsRow` no statistics renderer shows, each with the reason.
INTERNAL: dict[str, str] = {
    "kind": "the first column says what a row counts by what it names (a requirement, an obligation, "
            "a node's every run)",
    "backend": "the obligation's id shown names its backend (<node>.g<k>.<backend>...)",
}


__all__ = ["Counts", "INTERNAL", "RequirementRuns", "StatisticsRow", "rows_of"]
