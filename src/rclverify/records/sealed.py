"""Sealed JSON records: every record under ``artifacts/`` that a report reads.

An evidence record carries its seal, ``record_sha256`` (:data:`.store.SEAL`:
the sha256 of the record's other keys in :func:`.store.dumps`), written in
the same atomic write as the record (docs/integrity.md).  The other records
the report, ``rclverify status``, the argument and the bundle read get the
same treatment here: requirement checks (``artifacts/requirements/``),
contract health findings (``artifacts/health/``), side conditions and
derived properties (``artifacts/calculus/``), stage provenance
(``artifacts/provenance/``), exported obligations (``artifacts/obligations/``:
each node's list and each obligation's own file), the diagnoses, lint diagnostics, the
grounding and the last run's summary.

A record is a JSON object.  :func:`write_sealed` adds the seal;
:func:`read_sealed` returns the record without it and a problem sentence
when it cannot be believed: its content does not match its seal, it has no
seal, or it cannot be read.  Readers show such a record as ``error``
("altered outside rclverify"), never with what it says, and the doit task
that writes it runs again (:func:`targets_intact`).  The seal detects hand
edits and damage; it is not a signature against someone who recomputes it.
"""
from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path
from typing import Any, Mapping

from rclverify.records.store import SEAL, _sealed_text, atomic_write_text, seal_of, sealed_dumps

#: Workspace-relative directories and files whose JSON records are sealed (:func:`is_sealed_path`).
SEALED_DIRS = ("artifacts/requirements/", "artifacts/health/", "artifacts/calculus/", "artifacts/provenance/",
               "artifacts/obligations/", "artifacts/deadlines/", "artifacts/crosscheck/", "artifacts/diagnosis/",
               "artifacts/nodl/")
SEALED_FILES = ("artifacts/check/diagnostics.json", "artifacts/report/summary.json", "artifacts/ros/grounding.json",
                "artifacts/check/index.json")


def is_sealed_path(rel: str) -> bool:
    """Whether the workspace-relative POSIX path ``rel`` names a record written sealed."""
    return rel.endswith(".json") and (rel in SEALED_FILES or rel.startswith(SEALED_DIRS))


def sealed(record: Mapping[str, object]) -> dict[str, object]:
    """``record`` (a JSON object, without a seal) with its seal added."""
    body = {k: v for k, v in record.items() if k != SEAL}
    return {**body, SEAL: seal_of(body)}


def write_sealed(path: Path, record: Mapping[str, object], *, durable: bool = False) -> bool:
    """Write ``record`` sealed, atomically (the text of :func:`.store.write_json`
    of :func:`sealed`, encoded once: :func:`.store.sealed_dumps`); returns
    ``True`` when the file changed.  Raises ``OSError``."""
    return atomic_write_text(path, sealed_dumps(record), durable=durable)


def check_text(text: str, what: str = "record") -> tuple[dict[str, Any] | None, str]:
    """``(record without its seal, problem)`` of the JSON text ``text``.

    ``problem`` is ``""`` when the seal holds, else a sentence beginning
    with ``what`` ("requirement record ...") saying why the record cannot be
    believed; the record is then still returned when it parses as an
    object (callers name what it claims, never show it as a result)."""
    try:
        raw = json.loads(text)
    except ValueError as exc:
        return None, f"{what} unreadable ({exc.__class__.__name__}): altered outside rclverify"
    if not isinstance(raw, dict):
        return None, f"{what} is not a JSON object: altered outside rclverify"
    body = {k: v for k, v in raw.items() if k != SEAL}
    if SEAL not in raw:
        return body, f"{what} altered outside rclverify: it carries no seal (rclverify seals every record it writes)"
    if not _sealed_text(text, raw[SEAL]) and not _sealed_last(text, raw[SEAL]) and raw[SEAL] != seal_of(raw):
        return body, (f"{what} altered outside rclverify: its content does not match the sha256 rclverify wrote "
                      "with it (run `doit verify` to produce it again)")
    return body, ""


def _sealed_last(text: str, seal: Any) -> bool:
    """As :func:`.store._sealed_text` for a record whose seal is its last
    key (``{"findings", "node", "record_sha256"}``): the text without the
    seal line, and without the comma that then ends the line before it, is
    :func:`.store.dumps` of the body.  ``False`` only means "not decided
    here"."""
    if not isinstance(seal, str):
        return False
    tail = f',\n  "{SEAL}": "{seal}"\n}}\n'
    if not text.endswith(tail):
        return False
    body = text[:-len(tail)] + "\n}\n"
    return hashlib.sha256(body.encode("utf-8")).hexdigest() == seal


def read_sealed(path: Path | str, what: str = "record") -> tuple[dict[str, Any] | None, str]:
    """``(record, problem)`` of the sealed record at ``path``: ``(None, "")``
    when there is none, else as :func:`check_text`."""
    try:
        with open(path, "rb") as fh:
            text = fh.read().decode("utf-8")
    except FileNotFoundError:
        return None, ""
    except (OSError, UnicodeDecodeError) as exc:
        return None, f"{what} unreadable ({exc.__class__.__name__}): altered outside rclverify"
    return check_text(text, what)


def obligation_list(path: Path | str) -> tuple[list[dict[str, Any]] | None, str]:
    """``(obligation JSON objects, problem)`` of a node's obligation list
    (``artifacts/obligations/<Node>.json``, :func:`.store.write_obligations`):
    ``(None, "")`` when there is none; the list is ``[]`` with a problem
    sentence when the record's seal does not hold or it is malformed."""
    body, problem = read_sealed(path, "obligation list")
    if body is None and not problem:
        return None, ""
    records = (body or {}).get("obligations")
    if not problem and not (isinstance(records, list) and all(isinstance(o, dict) for o in records)):
        problem = "obligation list malformed: altered outside rclverify"
    return ([] if problem else list(records or [])), problem


def first_altered(root: str, rels: list[str]) -> str | None:
    """The first of the workspace-relative ``rels`` (under ``root``) that
    exists and whose seal does not hold, with the problem: ``"rel: problem"``;
    ``None`` when every one is intact or absent."""
    for rel in rels:
        _, problem = read_sealed(os.path.join(root, rel))
        if problem:
            return f"{rel}: {problem}"
    return None


def _companions(path: str) -> list[str]:
    """The sealed records a doit target stands for besides itself: a node's
    provenance with its calculus record, each obligation's own file with
    the node's obligation list, every requirement record with the
    requirement index."""
    head, sep, rel = path.rpartition("/artifacts/")
    if not sep:
        return []
    for stage, folder in (("compose", "calculus/"), ("health", "health/")):
        if rel.startswith(folder) and rel.count("/") == 1 and rel.endswith(".json"):
            return [f"{head}/artifacts/provenance/{stage}/{rel[len(folder):]}"]
    if rel.startswith("obligations/") and rel.count("/") == 1 and rel.endswith(".json"):
        records, problem = obligation_list(path)
        return [f"{head}/artifacts/obligations/{rel[len('obligations/'):-5]}/{o.get('id')}.json"
                for o in (records or [])] if not problem else []
    if rel == "requirements/index.json":
        index, problem = read_sealed(path)
        records = (index or {}).get("records")
        if problem or not isinstance(records, dict):
            return []
        import re  # deferred: optional or conditional (inside a block)
        return [f"{head}/artifacts/requirements/{re.sub(r'[^A-Za-z0-9_.-]+', '_', str(rid))}.json" for rid in records]
    return []


class TargetsSealed:
    """doit ``uptodate`` check: every sealed record among the task's targets
    (:func:`is_sealed_path`), and those they stand for (a node's provenance
    and each obligation's record, the requirement records of the index), is
    as rclverify wrote it.  A record altered by anything else makes the task
    run again, so ``doit verify`` produces it anew instead of believing it
    (``rclverify report`` shows it as ``error``).

    Cheap on a no-op run: after the task ran, the files' paths, sizes and
    modification times are saved with doit's task values; while every one
    is the same, nothing is read (not even the lists that name the records
    they stand for).  Otherwise every seal is checked."""

    KEY = "_sealed_stat"

    def __call__(self, task: Any, values: Mapping[str, object]) -> bool:
        def sealed_targets() -> list[str]:
            out = []
            for t in task.targets:
                _, sep, rel = str(t).rpartition("/artifacts/")
                if sep and is_sealed_path("artifacts/" + rel):
                    out.append(str(t))
            return out

        def stat_of(f: str) -> list[str | int | None]:
            try:
                st = os.stat(f)
                return [f, st.st_mtime_ns, st.st_size]
            except OSError:
                return [f, None, None]

        def files() -> list[str]:
            return [g for t in sealed_targets() for g in (t, *_companions(t))]

        def stat() -> dict[str, list[list[str | int | None]]]:
            return {self.KEY: [stat_of(f) for f in files()]}
        task.value_savers.append(stat)
        targets = sealed_targets()
        if not targets:
            return True
        saved = values.get(self.KEY)
        if isinstance(saved, list) and {r[0] for r in saved if isinstance(r, list) and r} >= set(targets) \
                and all(isinstance(r, list) and len(r) == 3 and stat_of(r[0]) == r for r in saved):
            return True
        for f in files():
            _, problem = read_sealed(f)
            if problem:
                _, _, rel = f.rpartition("/artifacts/")
                print(f"artifacts/{rel}: {problem}: producing it again")
                return False
        return True
