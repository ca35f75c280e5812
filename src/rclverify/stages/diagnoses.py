"""The ``diagnosis`` stage's sealed record: one diagnosis per problem of the report, read by the report.

``artifacts/diagnosis/index.json`` is ``{"report_sha256", "diagnoses"}``:
``diagnoses`` the records :func:`rclverify.diagnosis.build.diagnose` made
(problems explained, repairs checked by Z3; docs/diagnosis.md), as JSON;
``report_sha256`` the :func:`report_digest` of the report dict without
diagnoses they were made from (:func:`rclverify.report.build.undiagnosed_report`).  That dict holds
every artifact and input hash the diagnoses read (the contract and plan
files' sha256 in ``meta.inputs_sha256``, every evidence and requirement
record), so a record is current exactly when the report being built now
has the same digest.  The stage itself (build the dict, diagnose, seal) is
the orchestrator's (:func:`rclverify.app.pipeline.stage_diagnosis`): the
report reads this record and never diagnoses.
"""
from __future__ import annotations

import hashlib
import json
from typing import TYPE_CHECKING, Any, Mapping, cast

import msgspec

from rclverify.records.problem_rows import DiagnosisRow
from rclverify.records.sealed import read_sealed, write_sealed
from rclverify.records.store import dumps

if TYPE_CHECKING:
    from rclverify.records.stage_records import DiagnosisEntry, DiagnosisRecord
    from rclverify.stages.workspace import Workspace

DIR = "artifacts/diagnosis"
INDEX = f"{DIR}/index.json"
_RUN = "run `doit verify` or `rclverify report` to explain them again"


#: Keys of the report that say when and how long a record's run took: no diagnosis reads them, and
#: two runs of the same inputs differ in them, so the digest leaves them out (incremental equals clean).
TIMING_KEYS = frozenset({"duration_s", "started"})


def _strip(row: Mapping[str, Any]) -> Mapping[str, Any]:
    """``row`` without :data:`TIMING_KEYS`, in itself and in the mappings it holds (a requirement's
    ``check``, an evidence row's ``monitoring``); ``row`` itself when it has none (no copy)."""
    if TIMING_KEYS.isdisjoint(row) and not any(isinstance(v, dict) and not TIMING_KEYS.isdisjoint(v)
                                               for v in row.values()):
        return row
    return {k: ({a: b for a, b in v.items() if a not in TIMING_KEYS} if isinstance(v, dict) else v)
            for k, v in row.items() if k not in TIMING_KEYS}


def _without_timing(report: Mapping[str, Any]) -> dict[str, Any]:
    """``report`` with :data:`TIMING_KEYS` left out of its rows (each list of rows, and the mappings a
    row holds: where the report's records keep their timings), copying only the rows that have one."""
    return {k: [_strip(r) if isinstance(r, dict) else r for r in v] if isinstance(v, list) else v
            for k, v in report.items()}


def report_digest(report: Mapping[str, object]) -> str:
    """The sha256 (hex) of the compact JSON of ``report`` (the report dict
    without diagnoses) less its :data:`TIMING_KEYS`, keys sorted: encoded by
    msgspec (5x faster than the standard library, the same bytes for the
    report's values), by :func:`json.dumps` for a value msgspec does not
    encode.  Raises ``TypeError`` for a value JSON cannot hold."""
    stable = _without_timing(report)
    try:
        data = msgspec.json.encode(stable, order="sorted")
    except (TypeError, msgspec.EncodeError):
        data = json.dumps(stable, sort_keys=True, ensure_ascii=False, separators=(",", ":")).encode("utf-8", "surrogatepass")
    return hashlib.sha256(data).hexdigest()


def write_diagnoses(ws: "Workspace", digest: str, diagnoses: list["DiagnosisEntry"]) -> "DiagnosisRecord":
    """Seal ``diagnoses`` (:func:`rclverify.diagnosis.build.diagnose` of the
    report dict without diagnoses whose :func:`report_digest` is ``digest``)
    into :data:`INDEX`, atomically, and return the record as a reader gets
    it back (JSON: a record made now and one read later are the same data).
    Raises ``OSError`` when it cannot be written."""
    record = json.loads(dumps({"report_sha256": digest, "diagnoses": diagnoses}))
    write_sealed(ws.path(INDEX), record)
    return cast("DiagnosisRecord", record)


def read_diagnoses(ws: "Workspace", report: Mapping[str, object]) -> tuple[list[dict[str, Any]] | None, str]:
    """``(diagnoses, problem)`` of :data:`INDEX` for ``report`` (the report
    dict without diagnoses being built now): the records, each decoded into
    :class:`~rclverify.records.problem_rows.DiagnosisRow` and written as its
    JSON object, and ``""`` when the record is current; ``None`` and one sentence saying why the
    problems are not explained when it is missing, altered outside
    rclverify (its seal does not hold), malformed (a record the class does
    not decode), or made from another
    report (its ``report_sha256`` differs)."""
    body, why = read_sealed(ws.path(INDEX), "diagnosis record")
    if why:
        return None, f"{INDEX}: {why}"
    if body is None:
        return None, f"the problems are not explained: the diagnosis stage has not run ({INDEX} is missing); {_RUN}"
    try:  # each record as the report's row (records/problem_rows.py): the fields in the order declared
        rows = [DiagnosisRow.of(d).to_json() for d in body["diagnoses"]]
    except (KeyError, TypeError, msgspec.ValidationError):
        return None, f"{INDEX}: diagnosis record malformed: altered outside rclverify"
    if body.get("report_sha256") != report_digest(report):
        return None, (f"the problems are not explained: {INDEX} was made from other artifacts than this report "
                      f"(the contracts, plan or evidence changed since the diagnosis stage ran); {_RUN}")
    return rows, ""
