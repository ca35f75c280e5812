"""The second solver's agreement on a verdict, defined once: :class:`Solvers`.

The report gives every side condition, health finding, requirement check,
deadline and Hoare-triple evidence row the second solver decided (or could
not) a ``solvers`` object (stages/crosscheck/apply.py ``SecondSolver``;
docs/second-solver.md): the agreement, its reason, cvc5's answer, and the
proof certificate and query both solvers read.

The rules (docs/decisions.md, "One definition per record"):

* This class is the only statement of the object's fields.  A row that
  holds one decodes it with the row (e.g.
  :class:`~rclverify.records.findings.FindingRow`) or alone with
  :meth:`~rclverify.records.row.Row.of`; a field at ``UNSET`` is not
  written (an object read from a record that kept neither the proof nor
  the query).
* It is one entry of the schema's ``$defs`` (``solvers``), generated from
  the class (records/schema_gen.py ``DEFS``); every row that
  holds one refers to that entry.  tests/records/test_record_shapes.py fails
  when the file and the class differ.
"""
from __future__ import annotations

from typing import Annotated, Any

import msgspec

from rclverify.records.row import DOC, Row
from rclverify.records.statuses import Agreement

_DOC = DOC


class Solvers(Row, frozen=True, omit_defaults=True, forbid_unknown_fields=True):
    """The second solver's agreement on a verdict (docs/second-solver.md)."""

    agreement: Annotated[Agreement, _DOC(
        description="two solvers: cvc5 gave the same answer; one solver: Z3 alone (with the reason); "
                    "disagree/inconclusive: the verdict is downgraded to inconclusive")]
    why: Annotated[str, _DOC(description="The reason, one sentence.")]
    cvc5: Annotated[dict[str, Any] | None, _DOC(description="cvc5's answer and version, null when it was not asked.")]
    proof: Annotated[str | msgspec.UnsetType, _DOC(
        description="A proof certificate's summary, empty when none.")] = msgspec.UNSET
    smt2: Annotated[str | msgspec.UnsetType, _DOC(
        description="Path of the SMT-LIB2 query both solvers read, empty when none is kept.")] = msgspec.UNSET


__all__ = ["Solvers"]
