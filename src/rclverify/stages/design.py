"""The ``design`` stage: the monitoring fields of the Autoware System Designer design the plan names
(``design: DIR``) decided against the workspace's contracts along each chain (docs/nodl.md, "The design
stage"), written as one sealed record the report reads.

The check is :func:`rclverify.model.nodl.design_timing.check_timing`, the one ``rclverify import
autoware-design --check`` runs: each ``timeout``, ``error_rate`` and ``warn_rate`` of a trigger proved
(the contracts' periods and deadlines bound the gap below the field's limit), refuted (``design-timeout``,
``design-error-rate`` errors, ``design-warn-rate`` a warning, located at the design's field and at each
contract clause of the chain) or undecided (``design-undecided``), with ``design-missing`` and
``design-unwired`` as there.

Writes ``artifacts/design/index.json``: ``design`` (the folder), ``system`` (its name), ``nodes`` and
``wires`` (counts of the flattened design), ``decided`` (one row per field: ``node``, ``trigger``,
``field``, ``limit_s`` and ``bound_s`` as exact fractions in text, ``limit`` and ``bound`` in ms as the
report shows them, ``status``, ``why``, ``steps``: the
contract clauses the bound adds up, each ``text`` and ``at``; ``at``: the field's place in the design), ``findings`` (code, severity, message,
``places``), ``counts`` (per severity) and ``inputs``: the sha256 of the plan, its contract files and every
design file.  Places are shown from the workspace root.  The record is sealed
(:mod:`rclverify.records.sealed`); :func:`read_design_record` shows one whose seal does not hold as one
error (``design-record``), and one made from other files than the current ones ``stale``.  The check is
static and cheap (exact rationals, no solver), so the stage decides everything again each time it runs:
the record is a pure function of its inputs.
"""
from __future__ import annotations

from fractions import Fraction
from pathlib import Path
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from rclverify.lang import ast
from rclverify.model.nodl.design import read_design
from rclverify.model.nodl.design_read import design_files
from rclverify.model.nodl.design_timing import check_timing
from rclverify.records.design_rows import DesignRow
from rclverify.records.records import hash_inputs
from rclverify.records.sealed import read_sealed, write_sealed

if TYPE_CHECKING:
    from rclverify.stages.workspace import Workspace

DIR = "artifacts/design"
INDEX = f"{DIR}/index.json"


def design_inputs(root: Path, folder: str) -> list[str]:
    """The workspace-relative paths of the design files under ``folder`` (the plan's ``design``) at
    ``root``, sorted: the files :func:`read_design` reads; empty when there is none."""
    base = root / folder
    if not base.is_dir():
        return []
    return sorted((Path(folder) / p.relative_to(base)).as_posix() for p, _ in design_files(base))


def _inputs(ws: "Workspace") -> list[str]:
    """The files a record is made from: the plan, its contract files and the design's files."""
    return sorted({ws.plan.file, *ws.plan.contracts, *design_inputs(ws.root, ws.plan.design)})


def _place(loc: ast.Loc, prefix: str) -> dict[str, Any]:
    """A place shown from the workspace root (``prefix``: the root's path as the reader showed it, ``/`` ended)."""
    file = loc.file[len(prefix):] if loc.file.startswith(prefix) else loc.file
    return {"file": file, "line": loc.line, "col": loc.col}


def _ms(seconds: Fraction) -> str:
    """``350 ms``: a gap as the report shows it (the exact fraction is kept beside it)."""
    return f"{float(seconds) * 1000:g} ms"


def stage_design(ws: "Workspace") -> dict[str, Any]:
    """Decide the monitoring fields of the plan's design against ``ws``'s contracts (module docstring)
    and write the stage's sealed record; returns it.  Raises ``RclError`` (located ``file:line:col``)
    for contracts or a plan that do not check and for a design that cannot be read (``E-design``);
    ``OSError`` when the record cannot be written."""
    prefix = ws.root.as_posix().rstrip("/") + "/"
    design = read_design(ws.root / ws.plan.design)
    findings, decided = check_timing(design, ws.checked, ws.model.links)
    rows = [{"node": d.node, "trigger": d.trigger, "field": d.field, "limit_s": str(d.limit), "limit": _ms(d.limit),
             "bound_s": None if d.bound is None else str(d.bound.seconds),
             "bound": None if d.bound is None else _ms(d.bound.seconds), "status": d.status, "why": d.why,
             "steps": [] if d.bound is None else [{"text": text, "at": _place(loc, prefix)} for text, loc in d.bound.steps],
             "at": None if d.loc is None else _place(d.loc, prefix)}
            for d in decided]
    errors = sum(f.severity == "error" for f in findings)
    record: dict[str, Any] = {
        "design": ws.plan.design, "system": design.name, "nodes": len(design.nodes), "wires": len(design.wires),
        "decided": rows,
        "findings": [{"code": f.code, "severity": f.severity, "message": f.message,
                      "places": [_place(loc, prefix) for loc in f.locs]} for f in findings],
        "counts": {"error": errors, "warning": len(findings) - errors,
                   **{s: sum(d.status == s for d in decided) for s in ("proved", "refuted", "undecided")}},
        "inputs": hash_inputs(ws.root, _inputs(ws)),
    }
    write_sealed(ws.path(INDEX), record)
    return record


def read_design_record(ws: "Workspace") -> dict[str, Any] | None:
    """The stage's record as the report shows it: ``None`` when the plan names no design; when it names one
    and no record was made, or the record was made from other files than the current ones, the record (or
    an empty one) with ``stale`` (a sentence); when its seal does not hold, a record of one error
    (``design-record``) at the record's first line."""
    if not ws.plan.design:
        return None
    empty: dict[str, Any] = {"design": ws.plan.design, "system": "", "nodes": 0, "wires": 0, "decided": [],
                             "findings": [], "inputs": {},
                             "counts": {"error": 0, "warning": 0, "proved": 0, "refuted": 0, "undecided": 0}}
    body, why = read_sealed(ws.path(INDEX), "design record")
    if why:
        return {**empty, "counts": {**empty["counts"], "error": 1}, "altered": f"{INDEX}: {why}",
                "findings": [{"code": "design-record", "severity": "error", "message": f"{INDEX}: {why}",
                              "places": [{"file": INDEX, "line": 1, "col": 1}]}]}
    if body is None:
        return {**empty, "stale": f"the design {ws.plan.design} has not been checked yet (run `doit verify`)"}
    current = _inputs(ws)
    made = body.get("inputs")
    if not isinstance(made, dict) or set(made) != set(current) or hash_inputs(ws.root, current) != made:
        body["stale"] = f"{INDEX} was made from another design, contracts or plan than the current ones (run `doit verify`)"
    return body


def design_row(ws: "Workspace") -> DesignRow | None:
    """The report's ``design``: :func:`read_design_record` decoded into
    :class:`~rclverify.records.design_rows.DesignRow`; ``None`` when the plan names no design.  Raises
    :class:`msgspec.ValidationError` for a record of another shape (a bug: the stage seals what it
    writes)."""
    record = read_design_record(ws)
    return None if record is None else DesignRow.of(record)


def design_problems(row: DesignRow | Mapping[str, Any] | None) -> list[str]:
    """The report's problem sentences of ``row`` (:func:`design_row`, or its JSON object): a stale or altered
    record, each design error (a refuted timeout or error rate, a design node or port without contract) at its
    places.  Raises :class:`msgspec.ValidationError` for a row of another shape."""
    if row is None:
        return []
    d = DesignRow.of(row)
    out = [f"design: {why}" for why in (d.altered, d.stale) if why]
    for f in d.findings:
        if f.severity == "error" and f.code != "design-record":
            at = ", ".join(f"{p.file}:{p.line}:{p.col}" for p in f.places)
            out.append(f"design {f.code}{' at ' + at if at else ''}: {f.message}")
    return out


def blocks_strict(row: DesignRow | Mapping[str, Any] | None) -> bool:
    """Whether ``row`` (:func:`design_row`, or its JSON object) fails ``--strict``: a design error, or a record
    stale or altered."""
    if row is None:
        return False
    d = DesignRow.of(row)
    return bool(d.counts.get("error") or d.stale or d.altered)


__all__ = ["DIR", "INDEX", "blocks_strict", "design_inputs", "design_problems", "design_row", "read_design_record",
           "stage_design"]
