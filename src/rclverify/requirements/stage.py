"""The ``requirements`` stage: check every requirement, write its record.

Writes ``artifacts/requirements/<ID>.json`` (the record of
:func:`.check.check_requirement` plus its ``fingerprint``),
``artifacts/requirements/<ID>.smt2`` (the query) and
``artifacts/requirements/index.json`` (``{id: sha256 of the record}``, in
requirement order: the report tasks depend on it).  A requirement whose
fingerprint (its statements, the contract snapshots of its cone, the system
model) equals the recorded one is not checked again, so editing one
contract re-checks only the requirements whose cone contains that node.
Records of requirements no longer in the plan are removed.
"""
from __future__ import annotations

import hashlib
import json
import re
from typing import TYPE_CHECKING, Any

from ..evidence.store import atomic_write_text, write_json

if TYPE_CHECKING:
    from ..workspace import Workspace

DIR = "artifacts/requirements"
INDEX = f"{DIR}/index.json"
_SAFE = re.compile(r"[^A-Za-z0-9_.-]+")


def record_path(req_id: str) -> str:
    """Workspace-relative path of a requirement's record."""
    return f"{DIR}/{_SAFE.sub('_', req_id)}.json"


def _read(path: Any) -> Any:
    try:
        with open(path, "rb") as fh:
            return json.loads(fh.read())
    except (OSError, ValueError):
        return None


def stage_requirements(ws: "Workspace", *, force: bool = False) -> list[tuple[dict[str, Any], bool]]:
    """Check the requirements of ``ws`` (module docstring).  Returns
    ``(record, checked_now)`` per requirement, in plan order (the plan's,
    then the Doorstop items').  Raises ``RclError`` for contracts or a plan
    that do not check."""
    from ..plan.load import all_requirements
    import z3

    from ..logic.world import fresh
    from ..cache import code_stamp
    from .check import check_requirement, cone_of, fingerprint, formals_of
    code = f"{code_stamp()} z3 {z3.get_version_string()}"
    checked, model, plan = ws.checked, ws.model, ws.plan
    model_text = (ws.root / ws.MODEL).read_text(encoding="utf-8") if (ws.root / ws.MODEL).is_file() else \
        json.dumps(model.to_json(), sort_keys=True)
    snaps: dict[str, str] = {}

    def snap(n: str) -> str:
        if n not in snaps:
            p = ws.root / ws.snapshot(n)
            snaps[n] = p.read_text(encoding="utf-8") if p.is_file() else ""
        return snaps[n]
    out: list[tuple[dict[str, Any], bool]] = []
    index: dict[str, str] = {}
    keep = set()
    for req in all_requirements(plan):
        formal, assuming = formals_of(req, checked)
        cone = cone_of([formal, *assuming], model) if formal is not None else []
        fp = fingerprint(req, [snap(n) for n in cone], model_text if formal is not None else "", code)
        rel = record_path(req.id)
        keep.add(rel.rsplit("/", 1)[1])
        old = None if force else _read(ws.root / rel)
        if old is not None and old.get("fingerprint") == fp:
            rec, now = old, False
        else:
            fresh()  # each check in the same Z3 state whatever ran before it (logic/world.py)
            rec = check_requirement(req, checked, model, plan)
            smt2 = rec.pop("smt2", None)
            if smt2 is not None:
                rec["smt2"] = rel[:-5] + ".smt2"
                atomic_write_text(ws.root / rec["smt2"], smt2)
                keep.add(rec["smt2"].rsplit("/", 1)[1])
            rec["fingerprint"] = fp
            write_json(ws.root / rel, rec)
            now = True
        if rec.get("smt2"):
            keep.add(rec["smt2"].rsplit("/", 1)[1])
        index[req.id] = hashlib.sha256((ws.root / rel).read_bytes()).hexdigest()
        out.append((rec, now))
    write_json(ws.root / INDEX, index)
    keep.add("index.json")
    for old_file in (ws.root / DIR).glob("*"):
        if old_file.is_file() and old_file.name not in keep:
            old_file.unlink()
    return out


def read_records(ws: "Workspace") -> dict[str, dict[str, Any]]:
    """The records named by ``index.json`` (``{}`` before the stage ran), by requirement id."""
    index = _read(ws.root / INDEX) or {}
    out = {}
    for rid in index:
        rec = _read(ws.root / record_path(rid))
        if rec is not None:
            out[rid] = rec
    return out
