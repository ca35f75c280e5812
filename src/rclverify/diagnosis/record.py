"""A diagnosis record (:mod:`.build`'s module docstring gives its keys) and
the text and source of the guarantee a record names.

A record is built as the report's
:class:`~rclverify.records.problem_rows.DiagnosisRow` (its culprits,
counterexample rows and repairs built by the producers as the diagnosis
stage's JSON objects, :mod:`rclverify.records.stage_records`' ``Culprit``,
``CexRow`` and ``Repair``, and decoded here into
:mod:`rclverify.records.repair_rows`' records) and handed to the stage as its
JSON object (:func:`entry`).
"""
from __future__ import annotations

from typing import Sequence, TypeVar, cast

import msgspec

from rclverify.diagnosis.shapes import ReportRows
from rclverify.records.problem_rows import DiagnosisRow
from rclverify.records.repair_rows import CexTableRow, DiagnosisCulprit, RepairRow
from rclverify.records.stage_records import CexRow, Culprit, DiagnosisEntry, Repair
from rclverify.records.statuses import AnyStatus

P = TypeVar("P", DiagnosisCulprit, CexTableRow, RepairRow)


def _decoded(cls: type[P], items: Sequence[Culprit] | Sequence[CexRow] | Sequence[Repair]) -> list[P]:
    """``items`` (the producers' JSON objects) decoded into ``cls``; raises
    :class:`msgspec.ValidationError` for an item of another shape (a producer's defect)."""
    return [msgspec.convert(x, cls) for x in items]


def guarantee_source(report: ReportRows, node: str, k: int | None) -> tuple[str, str]:
    """``(text, "file:line:col")`` of guarantee ``k`` (1-based) of ``node`` in
    ``report``'s nodes; ``("", "")`` when there is none."""
    for n in report.nodes:
        if n.name == node and k is not None and 1 <= k <= len(n.guarantees):
            g = n.guarantees[k - 1]
            return g.text, g.source
    return "", ""


def diagnosis_record(id: str, kind: str, node: str, status: AnyStatus, sentence: str, *,
                     culprits: Sequence[Culprit] | None = None, counterexample: Sequence[CexRow] | None = None,
                     repairs: Sequence[Repair | None] = (), guarantee: int | None = None,
                     not_offered: list[str] | msgspec.UnsetType = msgspec.UNSET,
                     joins: list[str] | msgspec.UnsetType = msgspec.UNSET,
                     lint: str | msgspec.UnsetType = msgspec.UNSET,
                     passes_through: list[str] | msgspec.UnsetType = msgspec.UNSET,
                     consequence_of: list[str] | msgspec.UnsetType = msgspec.UNSET,
                     requirement: str | msgspec.UnsetType = msgspec.UNSET) -> DiagnosisRow:
    """A diagnosis record (module docstring), each argument the field of that name
    (:class:`~rclverify.records.problem_rows.DiagnosisRow`); the repairs that are ``None`` left
    out; ``related`` is filled in by :func:`rclverify.diagnosis.build.diagnose`."""
    return DiagnosisRow(id, kind, node, status, sentence,
                        culprits=_decoded(DiagnosisCulprit, culprits or []),
                        counterexample=_decoded(CexTableRow, counterexample or []),
                        repairs=_decoded(RepairRow, [r for r in repairs if r]), guarantee=guarantee, related=[],
                        not_offered=not_offered, joins=joins, lint=lint, passes_through=passes_through,
                        consequence_of=consequence_of, requirement=requirement)


def with_culprits(rec: DiagnosisRow, node: str, sentence: str, culprits: Sequence[Culprit],
                  repairs: Sequence[Repair]) -> DiagnosisRow:
    """``rec`` naming ``culprits`` of ``node`` in ``sentence``, with their ``repairs``."""
    return msgspec.structs.replace(rec, node=node, sentence=sentence, culprits=_decoded(DiagnosisCulprit, culprits),
                                   repairs=_decoded(RepairRow, repairs))


def entry(rec: DiagnosisRow) -> DiagnosisEntry:
    """``rec`` as its JSON object, the stage's sealed record's item (the fields in the order declared,
    those at ``UNSET`` left out)."""
    return cast(DiagnosisEntry, rec.to_json())
