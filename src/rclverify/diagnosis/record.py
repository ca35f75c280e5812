"""A diagnosis record (:mod:`.build`'s module docstring gives its keys) and
the text and source of the guarantee a record names.

A record is built as the report's
:class:`~rclverify.records.problem_rows.DiagnosisRow` (its culprits,
counterexample rows and repairs the diagnosis stage's own records,
:mod:`rclverify.records.stage_records`' ``Culprit``, ``CexRow`` and
``Repair``, which that row leaves open) and handed to the stage as its JSON
object (:func:`entry`).
"""
from __future__ import annotations

from typing import Any, Sequence, cast

import msgspec

from rclverify.diagnosis.shapes import ReportRows
from rclverify.records.problem_rows import DiagnosisRow
from rclverify.records.stage_records import CexRow, Culprit, DiagnosisEntry, Repair
from rclverify.records.statuses import AnyStatus

_OPEN = list[dict[str, Any]]  # a DiagnosisRow's culprits, counterexample and repairs: the stage's records


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
                        culprits=cast(_OPEN, list(culprits or [])),
                        counterexample=cast(_OPEN, list(counterexample or [])),
                        repairs=cast(_OPEN, [r for r in repairs if r]), guarantee=guarantee, related=[],
                        not_offered=not_offered, joins=joins, lint=lint, passes_through=passes_through,
                        consequence_of=consequence_of, requirement=requirement)


def with_culprits(rec: DiagnosisRow, node: str, sentence: str, culprits: Sequence[Culprit],
                  repairs: Sequence[Repair]) -> DiagnosisRow:
    """``rec`` naming ``culprits`` of ``node`` in ``sentence``, with their ``repairs``."""
    return msgspec.structs.replace(rec, node=node, sentence=sentence, culprits=cast(_OPEN, list(culprits)),
                                   repairs=cast(_OPEN, list(repairs)))


def entry(rec: DiagnosisRow) -> DiagnosisEntry:
    """``rec`` as its JSON object, the stage's sealed record's item (the fields in the order declared,
    those at ``UNSET`` left out)."""
    return cast(DiagnosisEntry, rec.to_json())
