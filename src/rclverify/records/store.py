"""Atomic JSON storage of obligations and evidence under ``artifacts/``.

Every write goes to a temporary file in the destination directory and is
moved into place with :func:`os.replace`, so a crash or a failing stage never
leaves a half-written record and never loses the record already there.
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterable, Mapping

if TYPE_CHECKING:  # the stubs type the scanner in _json; json.decoder holds it at run time (C or Python)
    from _json import scanstring
else:
    from json.decoder import scanstring

from rclverify.core.atomic import atomic_write_bytes, atomic_write_text, dumps, read_json, write_json
from rclverify.records.records import Evidence, Obligation, hash_inputs

__all__ = ["atomic_write_bytes", "atomic_write_text", "dumps", "read_json", "write_json"]  # re-exported: the store writes through them


#: The key of an evidence record's seal: the sha256 of the record's other keys (:func:`seal_of`).
SEAL = "record_sha256"


def seal_of(record: Mapping[str, object]) -> str:
    """The seal of an evidence record (its JSON mapping): the sha256 of
    :func:`dumps` of every key but :data:`SEAL` itself, hex."""
    body = {k: v for k, v in record.items() if k != SEAL}
    return hashlib.sha256(dumps(body).encode("utf-8")).hexdigest()


def sealed_dumps(record: Mapping[str, object]) -> str:
    """:func:`dumps` of ``record`` with its seal (:data:`SEAL`,
    :func:`seal_of`) added, the record encoded once: the seal is the
    sha256 of :func:`dumps` of the other keys, and the sealed text is that
    text with the seal's line inserted before the first top-level key that
    sorts after it (:func:`_sealed_text` reads it back by removing that
    line), or after the last key when every key sorts before it (then
    without a trailing comma, the comma going to the line before).
    Encoding twice was a tenth of writing a record (every sealed record,
    every evidence record)."""
    body = {k: v for k, v in record.items() if k != SEAL}
    text = dumps(body)
    seal = hashlib.sha256(text.encode("utf-8")).hexdigest()
    at = text.find('\n  "')  # top-level keys only: indent 2, a nested key's line starts with 4 spaces
    while at >= 0:
        key, end = scanstring(text, at + 4)  # the key's JSON string (escapes, quotes, colons inside it)
        if key > SEAL:
            return f'{text[:at + 1]}  "{SEAL}": "{seal}",\n{text[at + 1:]}'
        at = text.find('\n  "', end)
    if not body:
        return dumps({SEAL: seal})
    return f'{text[:-3]},\n  "{SEAL}": "{seal}"\n}}\n'  # the text ends with the last value, "\n}\n"


def _sealed_text(text: str, seal: Any) -> bool:
    """Whether ``text`` is exactly the record :meth:`EvidenceStore.put` writes
    with ``seal``: the file without its seal line is then :func:`dumps` of
    the sealed body (keys are sorted and ``record_sha256`` is never the
    last key, so the line ends with a comma), and hashing that text decides
    the seal without encoding the record again (a report reads every record:
    0.3 s of each report task at 1000 nodes).  ``False`` only means "not
    decided here": the caller then compares :func:`seal_of` of the content,
    so a record re-formatted but not changed still reads as intact."""
    if not isinstance(seal, str):
        return False
    line = f'  "{SEAL}": "{seal}",\n'
    at = text.find(line)
    if at < 0 or text.find(line, at + 1) >= 0:
        return False
    body = text[:at] + text[at + len(line):]
    return hashlib.sha256(body.encode("utf-8")).hexdigest() == seal


class EvidenceStore:
    """Evidence records under ``<root>/artifacts/evidence/<obligation id>.json``.

    ``root`` is the workspace directory.
    """

    def __init__(self, root: Path) -> None:
        self.root = root
        self.dir = root / "artifacts" / "evidence"

    def path(self, obligation_id: str) -> Path:
        return self.dir / f"{obligation_id}.json"

    def put(self, ev: Evidence) -> Path:
        """Store ``ev`` atomically, replacing the previous record for its
        obligation.  The record carries its own seal (:data:`SEAL`, the
        sha256 of the rest of the record, :func:`seal_of`) in the same atomic
        write, so a record and its seal are never out of step, even after a
        kill; :meth:`read` finds a record changed by anything else."""
        p = self.path(ev.obligation)
        atomic_write_text(p, sealed_dumps(ev.to_json()), durable=True)
        return p

    def read(self, obligation_id: str) -> tuple[Evidence | None, str]:
        """``(record, problem)``: the stored record (``None`` when there is
        none or it cannot be read as a record) and ``""``, or a sentence
        saying why it cannot be believed: it was changed after rclverify
        wrote it (its content does not match its seal), it carries no seal,
        or it is not a readable evidence record."""
        try:
            text = self.path(obligation_id).read_text(encoding="utf-8")
            raw = json.loads(text)
        except FileNotFoundError:
            return None, ""
        except (OSError, ValueError) as exc:
            return None, f"evidence record unreadable ({exc.__class__.__name__}): not written by rclverify"
        try:
            ev = Evidence.from_json({k: v for k, v in raw.items() if k != SEAL} if isinstance(raw, dict) else raw)
        except (ValueError, KeyError, TypeError) as exc:
            return None, f"evidence record malformed ({exc}): altered outside rclverify"
        if not isinstance(raw, dict) or SEAL not in raw:
            return ev, "evidence altered outside rclverify: the record carries no seal (rclverify seals every record it writes)"
        if not _sealed_text(text, raw[SEAL]) and raw[SEAL] != seal_of(raw):
            return ev, ("evidence altered outside rclverify: the record's content does not match the sha256 rclverify "
                        f"wrote with it (it says {ev.status!r}; run `doit verify` to produce it again)")
        return ev, ""

    def get(self, obligation_id: str) -> Evidence | None:
        """The stored record, or ``None`` when there is none, it is
        unreadable, or it was altered outside rclverify (:meth:`read`)."""
        ev, problem = self.read(obligation_id)
        return None if problem else ev

    def all(self) -> list[Evidence]:
        """Every readable record, sorted by obligation id."""
        out = []
        for p in sorted(self.dir.glob("*.json")):
            ev = self.get(p.stem)
            if ev is not None:
                out.append(ev)
        return out

    def current_status(self, ev: Evidence, hashes: dict[str, str] | None = None) -> str:
        """``ev.status``, or ``"stale"`` when any input's sha256 changed since.

        ``hashes`` (workspace-relative path -> sha256), when given, keeps
        the hashes taken across calls: the caller promises the files do not
        change meanwhile (the report reads 2,000 evidence records of a
        1000-node system, most naming the same program file)."""
        if hashes is None:
            now = hash_inputs(self.root, list(ev.input_hashes))
        else:
            missing = [p for p in ev.input_hashes if p not in hashes]
            if missing:
                hashes.update(hash_inputs(self.root, missing))
            now = hashes
        if any(now[p] != h for p, h in ev.input_hashes.items()):
            return "stale"
        return ev.status


def write_obligations(path: Path, obligations: Iterable[Obligation]) -> bool:
    """Write a list of obligations (sorted by id) atomically as a sealed
    record ``{"obligations": [...], "record_sha256": ...}``
    (:mod:`.sealed`): the report believes only the list rclverify wrote."""
    body = {"obligations": [o.to_json() for o in sorted(obligations, key=lambda o: o.id)]}
    return atomic_write_text(path, sealed_dumps(body))


def read_obligations(path: Path) -> list[Obligation]:
    """Read obligations written by :func:`write_obligations`.  Raises
    ``FileNotFoundError``, and ``ValueError`` for a record altered outside
    rclverify (its seal does not hold) or malformed."""
    raw = read_json(path)
    records = raw.get("obligations") if isinstance(raw, dict) else None
    if not isinstance(records, list) or raw.get(SEAL) != seal_of(raw):
        raise ValueError(f"{path}: obligation list altered outside rclverify (its seal does not hold)")
    return [Obligation.from_json(d) for d in records]
