"""A margin target's trials counted on one run (docs/statistics.md, "Margin targets").

``margin of guarantee K >= M in Q % of answers at L %``
(:func:`rclverify.model.plan.target_text.parse_target`) is a violation
target whose trial fails when it keeps less than ``M`` of guarantee K's space
margin (docs/semantics.md, "Margins"): an answer whose margin is below ``M``
(``per answer``), a run whose smallest margin is (``per run``).  The run's
record keeps, per guarantee, how many answers had a margin (``answers``),
how many had none (``undefined``) and the smallest of the margins
(``lowest``, at most :data:`~.verdicts.KEPT_MARGINS`, ascending; ``null``
for ``-inf``); :func:`of_margin` turns them into the counts
:func:`rclverify.records.statistics.count_runs` reads:

* ``violations``: the kept margins below ``M`` (per run: 1 when any);
* ``inconclusive``: the answers with no margin, the run's undecided
  answers, and, when every kept margin is below ``M`` and more answers
  were judged than kept, those others (their margins are at least the
  largest kept one, which may still be below ``M``): never counted clean
  (a record that kept only the smallest margin: its answers are clean when
  that one is at least ``M``, else one is below and the others undecided);
* ``answers``: the rest of guarantee K's judged answers.

So an answer is counted once, in the run it was judged in, and the run set's
Clopper-Pearson bound (:func:`rclverify.records.statistics.decide`) bounds
the share of answers (or runs) below the margin as it bounds violations.
"""
from __future__ import annotations

from typing import Any, Mapping, Sequence

import msgspec

from rclverify.backends.monitors.payload import SpaceMargin
from rclverify.backends.monitors.verdicts import KEPT_MARGINS


def of_margin(row: Mapping[str, Any], margins: Sequence[SpaceMargin], guarantee: int, least: float,
              per: str) -> dict[str, Any]:
    """The run ``row`` (its ``details.statistics``) counted for the margin
    target ``margin of guarantee {guarantee} >= {least}`` ``per`` answer or
    run, from the run's space margins (its payload's ``monitoring.margins``; module docstring)."""
    m = next((x for x in margins if x.guarantee == guarantee), None)
    unsure = int(row.get("inconclusive") or 0)
    if m is None:  # the guarantee judged on no answer of this run: nothing counted beside its undecided answers
        return {**row, "answers": 0, "violations": 0, "inconclusive": unsure}
    answers, undefined = m.answers, m.undefined
    if m.lowest is not msgspec.UNSET:
        lowest = list(m.lowest)
        below = sum(1 for v in lowest if v is None or v < least)
        unknown = answers - len(lowest) if lowest and below == len(lowest) and len(lowest) >= KEPT_MARGINS else 0
    else:  # a record that kept only the smallest: all clean when it is clean, else the others unknown
        v, holds = m.margin, m.holds
        clean = holds is True if v is None else v >= least
        below, unknown = (0, 0) if clean or not answers else (1, answers - 1)
    if per == "run":
        return {**row, "answers": 1 if answers else 0, "violations": 1 if below else 0,
                "inconclusive": 0 if below else unsure + undefined + unknown}
    return {**row, "answers": answers - unknown, "violations": below, "inconclusive": unsure + undefined + unknown}


__all__ = ["of_margin"]
