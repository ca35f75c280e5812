"""The ``nodl`` stage: a workspace's NoDL documents checked against its
contracts and each other (docs/nodl.md), written as one sealed record the
report reads.

Discovery is the rule of ``rclverify nodl check`` without ``--nodl``: the
documents are the files ``*.nodl.yaml``, ``*.nodl.yml`` and ``*.nodl.json``
directly in the folder ``nodl/`` beside ``contracts/``
(:func:`document_files`), each with the documents it includes.  A workspace
with none has no ``nodl`` stage and its report's ``nodl`` is ``null``.
``nodl://`` includes have no install prefix here (the plan names none), so
such an include is a located error, as it is in ``nodl check`` without
``--ament-prefix``.

Writes ``artifacts/nodl/index.json`` (:class:`~rclverify.records.stage_records.NodlRecord`):
the findings of :func:`rclverify.model.nodl.check.check` (``nodl-missing``,
``nodl-extra``, ``nodl-type``, ``nodl-connect-type``, ``nodl-qos``,
``nodl-parameter``, ``nodl-parameter-assume``, ``nodl-node``), each with
every place it involves, their counts per severity, the parameters' side
conditions as Z3 decided them, and ``inputs``: the sha256 of the plan, its
contract files and every document file read (includes too).  The record is
sealed (:mod:`rclverify.records.sealed`); :func:`read_nodl` shows one whose
seal does not hold as one error, and one made from other files than the
current ones ``stale``.  The check is static and cheap (a Z3 query per
parameter side condition), so the stage decides everything again each time it
runs: the record is a pure function of its inputs.
"""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from rclverify.model.nodl.check import FOLDER, check, document_files
from rclverify.records.records import hash_inputs
from rclverify.records.sealed import read_sealed, write_sealed

if TYPE_CHECKING:
    from rclverify.records.stage_records import NodlFinding, NodlRecord
    from rclverify.stages.workspace import Workspace

DIR = "artifacts/nodl"
INDEX = f"{DIR}/index.json"


def documents(root: Path) -> list[str]:
    """The workspace-relative paths of the NoDL documents the stage reads at ``root`` (module
    docstring), sorted; empty when there is none (the stage then does not run)."""
    return [f"{FOLDER}/{p.name}" for p in document_files(root / FOLDER)]


def _inputs(ws: "Workspace", read: list[str]) -> list[str]:
    """The files a record is made from: the plan, its contract files and the documents ``read``."""
    return sorted({ws.plan.file, *ws.plan.contracts, *read})


def stage_nodl(ws: "Workspace") -> "NodlRecord":
    """Check ``ws``'s NoDL documents (module docstring) and write the stage's sealed record;
    returns it.  Raises ``RclError`` (located ``file:line:col``) for contracts or a plan that do
    not check and for a document that cannot be read (not YAML or JSON, against the schema, an
    include not resolved or cycling); ``OSError`` when the record cannot be written."""
    res = check(ws.checked, ws.root)
    read = sorted({f for d in [*res.documents.values(), *res.parts] for f in d.files})
    findings: list[NodlFinding] = [{"code": f.code, "severity": f.severity, "message": f.message,
                                    "places": [{"file": loc.file, "line": loc.line, "col": loc.col}
                                               for loc in f.locs]} for f in res.findings]
    record: NodlRecord = {
        "documents": {n: list(d.files) for n, d in sorted(res.documents.items())},
        "parts": [d.file for d in res.parts],
        "findings": findings,
        "counts": {"error": res.errors, "warning": len(res.findings) - res.errors},
        "side_conditions": [{"node": s.node, "parameter": s.parameter, "conjunct": s.conjunct, "status": s.status,
                             "model": dict(s.model)} for s in res.sides],
        "inputs": hash_inputs(ws.root, _inputs(ws, read)),
    }
    write_sealed(ws.path(INDEX), record)
    return record


def read_nodl(ws: "Workspace") -> dict[str, object] | None:
    """The stage's record as the report shows it: ``None`` when the workspace has no NoDL
    document; when it has some and no record was made, or the record was made from other files
    than the current ones, the record (or an empty one) with ``stale`` (a sentence); when its seal
    does not hold, a record of one error (``nodl-record``) at the record's first line."""
    now = documents(ws.root)
    if not now:
        return None
    body, why = read_sealed(ws.path(INDEX), "NoDL record")
    if why:
        return {"documents": {}, "parts": [], "side_conditions": [], "inputs": {},
                "counts": {"error": 1, "warning": 0}, "altered": f"{INDEX}: {why}",
                "findings": [{"code": "nodl-record", "severity": "error", "message": f"{INDEX}: {why}",
                              "places": [{"file": INDEX, "line": 1, "col": 1}]}]}
    if body is None:
        return {"documents": {}, "parts": [], "findings": [], "side_conditions": [], "inputs": {},
                "counts": {"error": 0, "warning": 0},
                "stale": f"the NoDL documents ({', '.join(now)}) have not been checked yet (run `doit verify`)"}
    made = body.get("inputs")
    read = [p for p in made if p not in (ws.plan.file, *ws.plan.contracts)] if isinstance(made, dict) else []
    current = _inputs(ws, sorted(set(read) | set(now)))
    if not isinstance(made, dict) or set(made) != set(current) or hash_inputs(ws.root, current) != made:
        body["stale"] = (f"{INDEX} was made from other NoDL documents, contracts or plan than the current ones "
                         "(run `doit verify`)")
    return body


__all__ = ["DIR", "INDEX", "documents", "read_nodl", "stage_nodl"]
