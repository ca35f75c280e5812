"""What ties a kept SMT-LIB2 query to the statement it decides, and a kept
cvc5 proof to the query it proves (docs/second-solver.md, "Re-checking a
bundle").

A query whose answer discharges something (a side condition, a health
check, a requirement and its consistency and vacuity queries, a deadline,
a Hoare triple's verification conditions) ends with one comment line,
written with it:

``; rclverify: decides <kind> "<id>", statement sha256 <hex>``

where ``<hex>`` is :func:`statement_sha256` of the item's kind, id and the
fields of its sealed record row that state what is decided
(:data:`STATEMENT_FIELDS`: the formula, the premises, the contract
snapshots' sha256, never the verdict).  A cvc5 proof kept beside it ends
with ``; rclverify: proof of the query with sha256 <hex>``, the sha256 of
the query's text (:func:`tie_proof`).  Both are SMT-LIB comments, so the
solvers read the same script.  The id is written as a JSON string (escaped,
one line), so no text of the plan can end the comment.

Like a record's seal, the line ties a query to its statement against a
copy or a swap; it is not a signature against a hand that writes a query
and its line anew (docs/integrity.md).
"""
from __future__ import annotations

import hashlib
import json
from typing import Mapping

from rclverify.records.store import dumps

_REQUIREMENT = ("id", "formal", "source", "cone", "used", "assuming", "inputs")

#: The fields of each kind's record row that state what its query decides (what is asked, never what
#: was found): the side-condition row of ``artifacts/calculus/<Node>.json``, the finding of
#: ``artifacts/health/<Node>.json``, the requirement record (for its consistency and vacuity queries
#: too), the deadline row of ``artifacts/deadlines/index.json``, the Hoare obligation of
#: ``artifacts/obligations/<Node>.json``.  A field a row lacks counts as ``null``.
STATEMENT_FIELDS: dict[str, tuple[str, ...]] = {
    "side-condition": ("id", "node", "rule", "source", "conjunct", "hypotheses", "links", "context"),
    "health": ("id", "node", "check", "guarantee", "witness"),
    "requirement": _REQUIREMENT,
    "consistency": _REQUIREMENT,
    "vacuity": _REQUIREMENT,
    "deadline": ("requirement", "path", "within_s", "chain", "loc", "inputs"),
    "hoare": ("id", "statement"),
}

_QUERY = "; rclverify: decides "
_PROOF = "; rclverify: proof of the query with sha256 "


def statement_sha256(kind: str, item_id: str, row: Mapping[str, object]) -> str:
    """The sha256 (hex) of :func:`.store.dumps` of ``{"kind", "id",
    "statement"}``, the statement being ``row``'s :data:`STATEMENT_FIELDS`
    of ``kind``.  Raises ``KeyError`` for a kind not in the table."""
    statement = {k: row.get(k) for k in STATEMENT_FIELDS[kind]}
    return hashlib.sha256(dumps({"kind": kind, "id": item_id, "statement": statement}).encode("utf-8")).hexdigest()


def query_tie(kind: str, item_id: str, row: Mapping[str, object]) -> str:
    """The last line (without its newline) of the query of item ``kind``
    ``item_id`` whose record row is ``row`` (module docstring)."""
    return f"{_QUERY}{kind} {json.dumps(item_id)}, statement sha256 {statement_sha256(kind, item_id, row)}"


def tie_query(text: str, kind: str, item_id: str, row: Mapping[str, object]) -> str:
    """``text`` (an SMT-LIB2 script) with :func:`query_tie` as its last line."""
    return _end(text) + query_tie(kind, item_id, row) + "\n"


def proof_tie(query_sha256: str) -> str:
    """The last line (without its newline) of the proof of the query whose
    text has sha256 ``query_sha256``."""
    return f"{_PROOF}{query_sha256}"


def tie_proof(proof: str, query_sha256: str) -> str:
    """``proof`` (cvc5's proof text) with :func:`proof_tie` as its last line."""
    return _end(proof) + proof_tie(query_sha256) + "\n"


def _end(text: str) -> str:
    return text if not text or text.endswith("\n") else text + "\n"


def last_line(text: str) -> str:
    """The last line of ``text`` that is not empty, without its newline ('' when none)."""
    return text.rstrip("\n").rsplit("\n", 1)[-1].rstrip("\r")


def said_tie(text: str) -> str:
    """What the tie line at the end of ``text`` says, for a message: the
    part after ``; rclverify: ``, or ``"no tie line"``."""
    line = last_line(text)
    return line[len("; rclverify: "):] if line.startswith((_QUERY, _PROOF)) else "no tie line"
