"""A side condition's row of the report, defined once: :class:`SideConditionRow`.

The report's ``side_conditions[]`` holds every side condition of every
node's composition (rules R1-R4, docs/calculus.md): the calculus stage's
record (records/composition_records.py ``SideCondition``, sealed in
``artifacts/calculus/<Node>.json``) as the report shows it
(report/contract_rows.py): ``stale`` when made from another contract text,
the second solver's agreement folded in (stages/crosscheck/apply.py), its
Z3 ``model`` cut to the nodes its conjunct involves (report/cex_cone.py,
``model_hidden`` the values left out), and its strength
(report/assemble.py, docs/confidence.md).

The rules (docs/decisions.md, "One definition per record"):

* This class is the only statement of the row's fields.  The report pass
  decodes each record into it (:meth:`~rclverify.records.row.Row.of`; a key
  the class does not declare, or a value of another type, raises
  :class:`msgspec.ValidationError`) and writes
  :meth:`~rclverify.records.row.Row.to_json`; a field at ``UNSET`` is not
  written (no probable scale mismatch, no second solver's answer, no
  strength yet, no value left out of the model).
* The ``side_conditions[]`` items of docs/assurance.schema.json are
  generated from it (records/schema_gen.py); tests/records/test_record_shapes.py
  fails when the file and the class differ.
* Every field is read by a renderer of a node's side conditions
  (report/templates/parts/section.{html,md}.j2, filter
  ``side_condition_rows``) or named in :data:`INTERNAL` with the reason it
  is not shown; tests/records/test_record_shapes.py fails otherwise.
"""
from __future__ import annotations

from typing import Annotated, Any

import msgspec

from rclverify.records.shared_rows import ItemRow
from rclverify.records.row import DOC, Row
from rclverify.records.solvers_rows import Solvers
from rclverify.records.statuses import EvidenceStatus, SideConditionVerdict
from rclverify.records.strength_rows import Strength

_DOC = DOC


class SideConditionRow(ItemRow, frozen=True, kw_only=True, omit_defaults=True, forbid_unknown_fields=True):
    """A side condition of a composition rule, decided by Z3 (docs/calculus.md)."""

    node: Annotated[str, _DOC(description="The consumer node.")]
    rule: Annotated[str, _DOC(description="The composition rule (R1-R4).")]
    conjunct: Annotated[str, _DOC(description="The assumption conjunct it discharges, RCL text.")]
    source: Annotated[str, _DOC(description="file:line:col of the RCL or plan text (1-based line and column)")]
    hypotheses: Annotated[list[str], _DOC(description="The guarantees assumed.")]
    status: Annotated[EvidenceStatus, _DOC(description="discharged, failed, inconclusive, stale or error.")]
    verdict: Annotated[SideConditionVerdict, _DOC(description="Its status, or discharged in context.")]
    duration_s: Annotated[float, _DOC(ge=0, description="Z3's time, seconds.")]
    smt2: Annotated[str, _DOC(description="Path of the SMT-LIB2 query.")]
    model: Annotated[dict[str, Any] | None, _DOC(
        description="Z3's counterexample cut to the nodes involved, null when discharged.")]
    model_hidden: Annotated[int | msgspec.UnsetType, _DOC(
        description="How many values of the counterexample, of nodes the conjunct does not involve, "
                          "model leaves out (report/cex_cone.py); absent when none.")] = msgspec.UNSET
    explanation: Annotated[str, _DOC(description="What the tool found, in words.")]
    variant: Annotated[str, _DOC(description="Which form of the query decided it.")]
    links: Annotated[list[str], _DOC(description="The links it reads.")]
    context: Annotated[dict[str, Any] | None, _DOC(
        description="How the in-context check went (cone, premises used, links opened, the local verdict); "
                    "null when discharged locally.")]
    scale_mismatch: Annotated[list[dict[str, Any]] | msgspec.UnsetType, _DOC(
        description="Probable scale mismatches behind it (a power of ten apart).")] = msgspec.UNSET
    solvers: Annotated[Solvers | msgspec.UnsetType, _DOC(
        description="The second solver's agreement (docs/second-solver.md).")] = msgspec.UNSET
    strength: Annotated[Strength | msgspec.UnsetType, _DOC(
        description="How strong the evidence is (docs/confidence.md).")] = msgspec.UNSET


#: The fields of :class:`SideConditionRow` no side-condition renderer shows, each with the reason.
INTERNAL: dict[str, str] = {
    "node": "the consumer node, whose section of the calculus lists the side condition (report/view.py)",
    "links": "the links it reads, drawn in the system diagram, where a failing side condition marks them",
    "context": "how the in-context check went, read by the diagnosis and the argument; the row shows its outcome "
               "(verdict: in context), the premises it used (hypotheses) and the explanation",
    "scale_mismatch": "each probable mismatch's sentence is part of the explanation shown (calculus/compose.py)",
    "strength": "follows from the status and the second solver's agreement, both shown; the argument's confidence "
                "reads it",
}


__all__ = ["INTERNAL", "SideConditionRow"]
