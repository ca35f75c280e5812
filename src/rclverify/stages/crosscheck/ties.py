"""Is each kept query the query of the statement it claims to decide, and
each kept proof the proof of its query?  Decided from a bundle's members
without a solver (``bundle --verify`` and ``bundle --recheck``;
docs/second-solver.md, "Re-checking a bundle").

For each discharging item of the sealed records (:func:`.items.discharging_items`):

* its query must be in the bundle and end with the tie line of the item's
  statement as the sealed record states it
  (:func:`rclverify.records.ties.query_tie`): a query copied from another
  item, or made from another statement, is named;

for each row of the second-solver record (``artifacts/crosscheck/index.json``):

* a kept proof must be at ``artifacts/crosscheck/proofs/<sha256 of its
  query>.proof``, be in the bundle and end naming that sha256
  (:func:`rclverify.records.ties.proof_tie`): two proofs swapped between
  items are named;
* a row that reads ``two solvers`` on cvc5's ``unsat`` must keep a proof.
"""
from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Mapping

from rclverify.records.sealed import check_text
from rclverify.records.ties import last_line, proof_tie, query_tie, said_tie, statement_sha256
from rclverify.stages.crosscheck.items import Item, discharging_items
from rclverify.stages.crosscheck.stage import DIR, INDEX, CrosscheckSeen, Cvc5Seen, seen_rows

#: How many last bytes of a query or proof member ``--verify`` keeps: its tie line is among them.
TAIL_BYTES = 4096


def is_tied(name: str) -> bool:
    """Whether the bundle member ``name`` is a kept query or proof, whose
    last line ties it (:mod:`rclverify.records.ties`)."""
    return name.startswith("artifacts/") and name.endswith((".smt2", ".proof"))


def bundle_items(records: Mapping[str, bytes]) -> list[Item]:
    """The discharging items of the JSON records among ``records`` (member
    name -> bytes), read as the stage reads a workspace's: the records are
    written to a private temporary folder, nothing else.  Raises
    ``OSError`` when it cannot be written."""
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        for name, content in records.items():
            if name.startswith("artifacts/") and name.endswith(".json"):
                p = root / name
                p.parent.mkdir(parents=True, exist_ok=True)
                p.write_bytes(content)
        nodes = sorted(p.stem for p in (root / "artifacts/calculus").glob("*.json"))
        return discharging_items(root, nodes)


def index_rows(raw: bytes | None) -> tuple[dict[tuple[str, str], CrosscheckSeen] | None, str]:
    """``(rows by (kind, id), problem)`` of the second-solver record's bytes
    ``raw``, each row decoded into :class:`~.stage.CrosscheckSeen` by
    :func:`~.stage.seen_rows`, as :func:`~.stage.read_crosscheck` does (a
    row that does not decode is left out): ``(None, "")`` when there is none, ``(None, why)`` when its seal
    does not hold."""
    if raw is None:
        return None, ""
    index, why = check_text(raw.decode("utf-8", "replace"), "second-solver record")
    if why or index is None:
        return None, why or "unreadable"
    return seen_rows(index.get("items")), ""


def tie_problems(items: list[Item], rows: Mapping[tuple[str, str], CrosscheckSeen] | None,
                 present: Mapping[str, object], tails: Mapping[str, bytes]) -> tuple[list[str], set[int]]:
    """``(problems, untied)``: one sentence naming the item for each query
    that is missing or not tied to its item's statement and each proof not
    tied to its row's query (module docstring), and the positions in
    ``items`` of the items whose query is missing or untied.  ``present``:
    the bundle's member names (any mapping keyed by them); ``tails``: the
    last bytes (:data:`TAIL_BYTES` or more) of each query and proof member.
    ``rows`` ``None``: no second-solver record to read, no proof checked."""
    problems: list[str] = []
    untied: set[int] = set()
    for i, it in enumerate(items):
        label = f"{it.kind} {it.id}"
        if it.smt2 not in present:
            problems.append(f"{label}: its query {it.smt2} is not in the bundle")
            untied.add(i)
            continue
        text = tails.get(it.smt2, b"").decode("utf-8", "replace")
        if last_line(text) != query_tie(it.kind, it.id, it.row):
            problems.append(f"{label}: its query {it.smt2} is not the query of this {it.kind}: it ends "
                            f"'{said_tie(text)}', while the sealed record's statement has sha256 "
                            f"{statement_sha256(it.kind, it.id, it.row)}")
            untied.add(i)
    for (kind, item_id), row in sorted((rows or {}).items()):
        problem = _proof_problem(row, present, tails)
        if problem:
            problems.append(f"{kind} {item_id}: {problem}")
    return problems, untied


def _proof_problem(row: CrosscheckSeen, present: Mapping[str, object], tails: Mapping[str, bytes]) -> str:
    """Why the proof ``row`` of the second-solver record keeps cannot be
    believed to prove its query, or ''."""
    c = row.cvc5 or Cvc5Seen()
    proof, sha = c.proof, row.sha256 or ""
    if not proof:
        if c.answer == "unsat" and row.agreement == "two solvers":
            return f"recorded as proved by both solvers, but {INDEX} keeps no proof of its query"
        return ""
    where = f"{DIR}/proofs/{sha}.proof"
    if proof != where:
        return f"its proof {proof} is not the proof of its query (the query's sha256 is {sha}: {where})"
    if proof not in present:
        return f"its proof {proof} is not in the bundle"
    text = tails.get(proof, b"").decode("utf-8", "replace")
    if last_line(text) != proof_tie(sha):
        return (f"its proof {proof} was made for another query: it ends '{said_tie(text)}', while its query's "
                f"sha256 is {sha}")
    return ""
