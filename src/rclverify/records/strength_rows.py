"""The strength of a piece of evidence and the weakest premise behind a
confidence, defined once: :class:`Strength` and :class:`LimitedBy`.

The confidence pass (report/confidence_rows.py, docs/confidence.md) gives
every evidence row, side condition and guarantee of the report a
``strength`` (report/argument/strength.py: its kind and its doubt, the
probability that a claim resting on it alone is false), and every node,
derived property and formal requirement a ``confidence`` with the premise
that limits it (``limited_by``).

The rules (docs/decisions.md, "One definition per record"):

* These classes are the only statement of the two objects' fields.  The
  confidence pass builds them and writes :meth:`~rclverify.records.row.Row.to_json`
  into the report's rows; a field at ``UNSET`` is not written (a guarantee's
  strength has no ``detail``, only a side condition's names its
  ``solvers``).  A reader decodes the JSON object with
  :meth:`~rclverify.records.row.Row.of` (or through the row that holds it,
  e.g. :class:`~rclverify.records.evidence_rows.EvidenceRow`).
* Each is one entry of the schema's ``$defs`` (``strength``,
  ``limited_by``), generated from the class (records/schema_gen.py
  ``DEFS``); every row that holds one refers to that entry.
  tests/records/test_record_shapes.py fails when the file and the classes differ.
"""
from __future__ import annotations

from typing import Annotated

import msgspec

from rclverify.records.row import DOC, Row

_DOC = DOC


class Strength(Row, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """How strong a piece of evidence is (docs/confidence.md)."""

    # keyword-only: written in the order the confidence pass always wrote them (kind, detail, solvers, doubt)
    kind: Annotated[str, _DOC(description="proof, bounded, statistical, tested, observed, reviewed or assumed.")]
    detail: Annotated[str | msgspec.UnsetType, _DOC(description="Why this strength, one sentence.")] = msgspec.UNSET
    solvers: Annotated[int | msgspec.UnsetType, _DOC(
        description="How many solvers agreed (side conditions).")] = msgspec.UNSET
    doubt: Annotated[float, _DOC(ge=0, le=1, description="The doubt the evidence leaves, 0 (none) to 1 (nothing "
                                                         "established).")]


class LimitedBy(Row, frozen=True, forbid_unknown_fields=True):
    """The premise with the largest doubt (docs/confidence.md)."""

    label: Annotated[str, _DOC(description="The premise, e.g. 'Navigation guarantee 1'.")]
    kind: Annotated[str, _DOC(description="Its strength kind.")]
    doubt: Annotated[float, _DOC(description="Its doubt, 0 to 1.")]
    sentence: Annotated[str | msgspec.UnsetType, _DOC(
        description="The premise named in a sentence (requirements).")] = msgspec.UNSET


__all__ = ["LimitedBy", "Strength"]
