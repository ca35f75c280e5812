"""The design part of the report, defined once: :class:`DesignRow` (with :class:`DesignFieldRow`,
:class:`DesignStepRow`, :class:`DesignFindingRow` and :class:`DesignPlaceRow`).

``design`` is the design stage's record (artifacts/design/index.json, stages/design.py; docs/nodl.md,
"The design stage") as the report shows it: the monitoring fields of the Autoware System Designer design
the plan names, decided against the contracts, with ``stale`` when the record was made from other files
(or not made yet) and ``altered`` when its seal does not hold; ``null`` when the plan names no design.
The ``design`` part of docs/assurance.schema.json is generated from these classes (records/schema_gen.py).
"""
from __future__ import annotations

from typing import Annotated, Literal

import msgspec

from rclverify.records.shared_rows import WorkspacePlaceRow
from rclverify.records.row import DOC, Row


class DesignPlaceRow(WorkspacePlaceRow, frozen=True, forbid_unknown_fields=True):
    """A place in the workspace: a design file's field or a contract clause."""


class DesignStepRow(Row, frozen=True, forbid_unknown_fields=True):
    """One contract clause a chain's longest gap adds up."""

    text: Annotated[str, DOC(description="The clause (a periodic output, or a guarantee's deadline of its trigger).")]
    at: Annotated[DesignPlaceRow, DOC(description="Where the clause is written.")]


class DesignFieldRow(Row, frozen=True, forbid_unknown_fields=True):
    """A monitoring field of a trigger, decided."""

    node: Annotated[str, DOC(description="The design's node (the contract node of that name).")]
    trigger: Annotated[str, DOC(description="The trigger: in.<input>, or periodic <f> Hz.")]
    field: Annotated[Literal["timeout", "error_rate", "warn_rate"], DOC(description="The monitoring field.")]
    limit_s: Annotated[str, DOC(description="The longest gap the field allows, in seconds, as an exact fraction.")]
    limit: Annotated[str, DOC(description="The same in ms, as shown.")]
    bound_s: Annotated[str | None, DOC(description="The longest gap the contracts let the chain leave, in seconds, as an exact fraction; null when nothing bounds it.")]
    bound: Annotated[str | None, DOC(description="The same in ms, as shown.")]
    status: Annotated[Literal["proved", "refuted", "undecided"], DOC(description="bound <= limit: proved; bound > limit: refuted; no bound: undecided.")]
    why: Annotated[str, DOC(description="Undecided: where the chain breaks; else empty.")]
    steps: Annotated[list[DesignStepRow], DOC(description="The contract clauses the bound adds up, first to last.")]
    at: Annotated[DesignPlaceRow | None, DOC(description="Where the field is written in the design; null when the record does not say.")] = None


class DesignFindingRow(Row, frozen=True, forbid_unknown_fields=True):
    """One design finding (model/nodl/findings.py: the design-* codes), at every place it involves."""

    code: Annotated[str, DOC(description="The finding's code (design-timeout, design-error-rate, design-warn-rate, design-undecided, design-missing, design-unwired, design-record).")]
    severity: Annotated[Literal["error", "warning"], DOC(description="An error fails --strict; a warning does not.")]
    message: Annotated[str, DOC(description="What is wrong, in one sentence.")]
    places: Annotated[list[DesignPlaceRow], DOC(description="The design's field first, then each contract clause.")]


class DesignRow(Row, frozen=True, forbid_unknown_fields=True, omit_defaults=True):
    """The design stage's record (artifacts/design/index.json) as the report shows it."""

    design: Annotated[str, DOC(description="The plan's design folder, workspace-relative.")]
    system: Annotated[str, DOC(description="The design's system (empty when the record was not made).")]
    nodes: Annotated[int, DOC(description="Nodes of the flattened design.")]
    wires: Annotated[int, DOC(description="Wires of the flattened design.")]
    decided: Annotated[list[DesignFieldRow], DOC(description="Every monitoring field of a trigger, decided.")]
    findings: Annotated[list[DesignFindingRow], DOC(description="The findings, refuted fields first as the check gives them.")]
    counts: Annotated[dict[str, int], DOC(description="Findings per severity (error, warning) and fields per verdict (proved, refuted, undecided).")]
    inputs: Annotated[dict[str, str], DOC(description="The sha256 of each file the record was made from.")]
    stale: Annotated[str | msgspec.UnsetType, DOC(
        description="Why the record is not current (made from other files, or not made yet).")] = msgspec.UNSET
    altered: Annotated[str | msgspec.UnsetType, DOC(
        description="Why the record is not believed (its seal does not hold).")] = msgspec.UNSET


__all__ = ["DesignFieldRow", "DesignFindingRow", "DesignPlaceRow", "DesignRow", "DesignStepRow"]
