"""A diagnosis record (:mod:`.build`'s module docstring gives its keys) and
the text and source of the guarantee a record names.
"""
from __future__ import annotations

from typing import Sequence

from rclverify.diagnosis.shapes import ReportRows
from rclverify.records.stage_records import CexRow, Culprit, DiagnosisEntry, Repair


def guarantee_source(report: ReportRows, node: str, k: int | None) -> tuple[str, str]:
    """``(text, "file:line:col")`` of guarantee ``k`` (1-based) of ``node`` in
    ``report``'s nodes; ``("", "")`` when there is none."""
    for n in report["nodes"]:
        if n["name"] == node and k is not None and 1 <= k <= len(n["guarantees"]):
            g = n["guarantees"][k - 1]
            return g["text"], g["source"]
    return "", ""


def diagnosis_record(id: str, kind: str, node: str, status: str, sentence: str, *, culprits: list[Culprit] | None = None,
            counterexample: list[CexRow] | None = None, repairs: Sequence[Repair | None] = (),
            guarantee: int | None = None) -> DiagnosisEntry:
    """A diagnosis record (module docstring); ``related`` is filled in by :func:`_diagnose`."""
    return {"id": id, "kind": kind, "node": node, "status": status, "sentence": sentence,
            "culprits": culprits if culprits is not None else [],
            "counterexample": counterexample if counterexample is not None else [],
            "repairs": [r for r in repairs if r], "guarantee": guarantee, "related": []}
