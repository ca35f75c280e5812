"""What a requirement imported from FRET was decided from, sealed in its record.

A requirement's record (``artifacts/requirements/<ID>.json``, sealed by
:mod:`rclverify.records.sealed`) carries its ``text`` (FRET's ``fulltext``)
and, in its ``inputs``, one entry per imported requirement:

* ``fret:<export>#<reqid>``: the sha256 of what the workspace's copy of the
  export says of it: its entry (``fulltext``, ``semantics`` with FRET's
  formalisations ``ptExpanded``/``ftInfAUExpanded``) and the variables of its
  component (their ``idType``, ``dataType``, Lustre ``assignment``, unit),
  JSON with sorted keys (:func:`entry_sha256`);
* ``fret:<export>``: the sha256 of the export's bytes when the record was made,
  shown with it and never compared (an edit of another requirement of the
  export leaves this one's verdict current).

The first is an input like a contract snapshot's hash: the requirements stage
puts it in the record's fingerprint (an edited entry is checked again) and
the report compares it with the current copy (until then the record is
``stale``), so an incremental run gives what a clean one gives.  A
requirement that no longer reads from the export, or whose reqid is no longer
in it, gets ``""`` and is stale as well.
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any, Iterable, Mapping

from rclverify.model.plan.fret.export import component_of

#: The prefix of the inputs this module gives.
PREFIX = "fret:"


def export_of(plan: Any) -> str | None:
    """The workspace-relative path of the export the plan reads (``requirements_from: {fret: PATH}``),
    ``None`` without one.  ``plan`` a :class:`~rclverify.model.plan.model.Plan`."""
    at = plan.locs.get(("requirements_from", "fret"))
    return next((v for v, loc in plan.requirements_from if at is not None and loc == at), None)


def _read(root: Path, rel: str) -> tuple[bytes, Mapping[str, Any] | None]:
    try:
        raw = (root / rel).read_bytes()
    except OSError:
        return b"", None
    try:
        data = json.loads(raw.decode("utf-8-sig"))
    except (UnicodeDecodeError, json.JSONDecodeError):
        return raw, None
    return raw, data if isinstance(data, dict) else {"requirements": data} if isinstance(data, list) else None


def entry_sha256(data: Mapping[str, Any] | None, reqid: str) -> str:
    """The sha256 of requirement ``reqid``'s entry in export ``data`` with its component's variables
    (module docstring); ``""`` when the export has no such requirement."""
    reqs = data.get("requirements") if data is not None else None
    entry = next((r for r in reqs or () if isinstance(r, dict) and r.get("reqid") == reqid), None)
    if entry is None:
        return ""
    comp = component_of(entry)
    assert data is not None
    vars_ = sorted((v for v in data.get("variables") or () if isinstance(v, dict) and v.get("component_name") == comp),
                   key=lambda v: str(v.get("variable_name")))
    text = json.dumps({"requirement": entry, "variables": vars_}, sort_keys=True, ensure_ascii=False)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def sealed_inputs(root: Path, plan: Any, req: Any) -> dict[str, str]:
    """The ``fret:`` inputs of requirement ``req`` (module docstring); ``{}`` when it does not come from the
    plan's FRET export."""
    rel = export_of(plan)
    if rel is None or getattr(req, "origin", None) != rel:
        return {}
    raw, data = _read(root, rel)
    return {f"{PREFIX}{rel}#{req.id}": entry_sha256(data, req.id),
            f"{PREFIX}{rel}": hashlib.sha256(raw).hexdigest()}


def current(root: Path, inputs: Mapping[str, str]) -> dict[str, str]:
    """What each ``fret:`` input of a record's ``inputs`` is now: a requirement's entry digest read again
    from the export (``fret:<export>#<reqid>``); the export's own hash (``fret:<export>``) as recorded,
    since it is shown, never compared."""
    out: dict[str, str] = {}
    read: dict[str, Mapping[str, Any] | None] = {}
    for k, v in inputs.items():
        if not k.startswith(PREFIX):
            continue
        if "#" not in k:
            out[k] = v
            continue
        rel, reqid = k[len(PREFIX):].split("#", 1)
        if rel not in read:
            read[rel] = _read(root, rel)[1]
        out[k] = entry_sha256(read[rel], reqid)
    return out


def compared(inputs: Mapping[str, str]) -> list[str]:
    """The values of ``inputs`` a record is compared on (the export's own hash left out), in key order:
    what the requirements stage adds to a record's fingerprint."""
    return [v for k, v in sorted(inputs.items()) if not (k.startswith(PREFIX) and "#" not in k)]
