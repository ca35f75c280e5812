"""Obligation and evidence records (shared/DESIGN.md, "Evidence").

Both are plain, JSON-serialisable frozen dataclasses, each defined once:
``to_json`` writes every field through msgspec's encoding and ``from_json``
reads it back through msgspec's decoding into the class, which refuses a
missing field or a value of another type (an evidence record also a key its
class does not declare); the two round-trip
exactly, and keys are sorted when written so that artifacts are
byte-for-byte reproducible.

Statuses, from best to worst (roll-up takes the worst child):

``discharged``  the backend checked the obligation and it holds;
``pending``     exported, but the external tool or the manual step is
                outstanding (``explanation`` gives the reason);
``inconclusive`` the tool answered unknown, timed out, or could not prove
                the claim but showed no counterexample (never proved; an
                unproved claim is not a failed one);
``stale``       an input changed after the evidence was produced;
``error``       the tool itself broke;
``failed``      the tool showed the obligation does not hold
                (``counterexample`` when there is one: a proof backend
                fails an obligation only with a refutation or a replayed
                run).

Kinds of evidence: ``proof``, ``model checking``, ``testing``,
``experiment``, ``review``, ``monitoring``.

Both sets, and ``unverified`` (a guarantee no obligation covers, never a
record's status), are defined once in :mod:`rclverify.records.statuses`.
"""
from __future__ import annotations

import hashlib
import re
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any, Mapping, Sequence

import msgspec

#: Severity order used by every roll-up; larger is worse (defined with the vocabulary).
from rclverify.records.statuses import RECORD_STATUSES, SEVERITY as SEVERITY

#: Roll-up status for a parent with no evidence at all.
MISSING = "pending"


def worst(statuses: Sequence[str], empty: str = MISSING) -> str:
    """Return the worst status of ``statuses`` (``empty`` when there are none).

    Raises ``KeyError`` for a string that is not a status.
    """
    if not statuses:
        return empty
    return max(statuses, key=SEVERITY.__getitem__)  # a C-level key: the report ranks the long cones of a chain


_ID_SAFE = re.compile(r"[^A-Za-z0-9_.-]+")


def make_obligation_id(node: str, guarantee: int, backend: str, instance: str = "") -> str:
    """Stable obligation id ``<node>.g<k>.<backend>[.<instance>]``.

    ``guarantee`` is the 1-based index of the guarantee clause in the node;
    ``instance`` names the part of it (a conjunct, a waypoint instance, ...)
    and is made file-name safe.
    """
    parts = [node, f"g{guarantee}", backend]
    if instance:
        parts.append(_ID_SAFE.sub("_", instance).strip("_"))
    return ".".join(parts)


@dataclass(frozen=True)
class SourceRef:
    """Where an obligation comes from in RCL: ``file:line:col``."""

    file: str
    line: int
    col: int

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.col}"


@dataclass(frozen=True)
class Obligation:
    """A proof obligation exported to a backend: the one definition of an
    exported obligation's record (``artifacts/obligations/``), written by
    :meth:`to_json` and read by :meth:`from_json` through msgspec.  A frozen
    dataclass rather than a ``msgspec.Struct``: backends derive obligations
    with :func:`dataclasses.replace`, and the kept caches' safe loader admits
    dataclasses (core/cache/safeload.py); msgspec encodes and decodes it all
    the same.

    ``id``           stable id (see :func:`make_obligation_id`);
    ``node``         the node name; ``guarantee`` the 1-based guarantee index;
    ``backend``      backend name (``hoare``, ``dafny``, ``ajpf`` ...);
    ``kind``         evidence kind the backend produces;
    ``instance``     which part of the guarantee ('' for the whole clause);
    ``statement``    the obligation in human-readable form (RCL or the
                     backend's notation);
    ``source``       RCL location of the guarantee clause;
    ``artifact``     path (relative to the workspace) it was rendered to;
    ``inputs``       workspace-relative paths of the files its evidence
                     depends on (hashed into the evidence record);
    ``data``         backend-specific, JSON-serialisable payload.
    """

    id: str
    node: str
    guarantee: int
    backend: str
    kind: str
    statement: str
    source: SourceRef
    instance: str = ""
    artifact: str = ""
    inputs: tuple[str, ...] = ()
    data: Mapping[str, Any] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        """The obligation as its JSON object: msgspec's encoding of this
        class, every field (``inputs`` a list, ``data`` a plain object), so
        a field added here is in every record written."""
        out: dict[str, Any] = msgspec.to_builtins(self, enc_hook=_plain)
        out["inputs"] = list(self.inputs)
        return out

    @staticmethod
    def from_json(d: Mapping[str, Any]) -> "Obligation":
        """The obligation of its JSON object ``d``, decoded into this class
        by msgspec.  Raises :class:`msgspec.ValidationError` (a
        ``ValueError``) for a missing field or a value of another type."""
        return msgspec.convert(d, Obligation)


def _plain(x: object) -> object:
    """A mapping other than a dict (an obligation's ``data`` may be one) as a dict, for msgspec's encoder
    (its ``enc_hook``).  Raises ``TypeError`` for any other value msgspec cannot encode."""
    if isinstance(x, Mapping):
        return dict(x)
    raise TypeError(f"cannot encode {type(x).__name__}")


@dataclass(frozen=True)
class Evidence:
    """The result of one backend run (or import) for one obligation: the one
    definition of an evidence record (``artifacts/evidence/<id>.json``,
    records/store.py), written by :meth:`to_json` and read by
    :meth:`from_json` through msgspec.  A frozen dataclass rather than a
    ``msgspec.Struct``: backends derive records with
    :func:`dataclasses.replace`, and the kept caches' safe loader admits
    dataclasses (core/cache/safeload.py).

    ``started`` is an ISO-8601 UTC timestamp; ``duration_s`` in seconds.
    ``input_hashes`` maps each workspace-relative input path to the sha256
    hex digest it had when the evidence was produced (used for staleness).
    ``artifacts`` are workspace-relative paths produced; ``log`` is the tool
    output (possibly truncated, the full log then lives in an artifact);
    ``counterexample`` is a JSON-serialisable mapping of names to values, or
    ``None``; ``explanation`` is a sentence for the report; ``details`` the
    backend's JSON-serialisable payload (figures, examples, monitoring,
    statistics, declarations ..., read by report/evidence_rows.py).
    """

    obligation: str
    backend: str
    kind: str
    status: str
    tool: str
    tool_version: str
    started: str
    duration_s: float
    input_hashes: Mapping[str, str] = field(default_factory=dict)
    artifacts: tuple[str, ...] = ()
    log: str = ""
    counterexample: Mapping[str, Any] | None = None
    explanation: str = ""
    details: Mapping[str, Any] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        """The record as its JSON object: msgspec's encoding of this class,
        every field (``artifacts`` a list, ``input_hashes`` sorted by path),
        so a field added here is in every record written."""
        out: dict[str, Any] = msgspec.to_builtins(self, enc_hook=_plain)
        out["artifacts"] = list(self.artifacts)
        out["input_hashes"] = dict(sorted(self.input_hashes.items()))
        return out

    @staticmethod
    def from_json(d: Mapping[str, Any]) -> "Evidence":
        """The record of the JSON object ``d``, decoded into this class by
        msgspec.  Raises ``TypeError`` when ``d`` is not an object (a record
        file holding ``[]`` or ``null``), ``ValueError`` (msgspec's
        :class:`msgspec.ValidationError` among them) for a missing field, a
        key no field declares, a value of another type or a status that is
        no record's (records/statuses.py ``RECORD_STATUSES``)."""
        if not isinstance(d, Mapping):
            raise TypeError(f"an evidence record is a JSON object, not {type(d).__name__}")
        undeclared = sorted(set(d) - set(_EVIDENCE_FIELDS))
        if undeclared:
            raise ValueError(f"an evidence record has no field {', '.join(map(repr, undeclared))}")
        if d.get("status") not in RECORD_STATUSES:  # never ``unverified``: a guarantee's status only
            raise ValueError(f"unknown evidence status {d.get('status')!r}")
        return msgspec.convert(dict(d), Evidence)


#: The fields of :class:`Evidence`, in the order declared.
_EVIDENCE_FIELDS: tuple[str, ...] = tuple(f.name for f in fields(Evidence))


def sha256_file(path: Path) -> str:
    """Hex sha256 of a file's bytes; ``"missing"`` when it does not exist."""
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest()
    except FileNotFoundError:
        return "missing"


def hash_inputs(root: Path, inputs: Sequence[str]) -> dict[str, str]:
    """Map each workspace-relative path in ``inputs`` to its sha256 (sorted)."""
    return {p: sha256_file(root / p) for p in sorted(set(inputs))}
