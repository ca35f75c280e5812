"""The second-solver stage: every discharging item decided again by cvc5.

Writes (docs/second-solver.md):

* ``artifacts/crosscheck/index.json`` (sealed): one row per
  :class:`~.items.Item` with the sha256 of its SMT-LIB2 script, Z3's
  recorded verdict and answer, cvc5's answer (version, reason, duration),
  the path of its checked proof and the :func:`agreement`;
* ``artifacts/crosscheck/proofs/<sha256>.proof``: cvc5's proof of each
  ``unsat`` answer, in cvc5's CPC format, checked by cvc5's proof checker.

Answers are keyed by the script's sha256, cvc5's version and the budget
(:data:`.cvc5_decide.RLIMIT`, deterministic), and re-used from the last
index when all three are the same: an incremental run equals a clean one.
"""
from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Any, Iterable

from rclverify.records.sealed import read_sealed, write_sealed
from rclverify.records.store import atomic_write_text
from rclverify.stages.crosscheck.cvc5_decide import RLIMIT, Decision, Session, decide, version
from rclverify.stages.crosscheck.items import WITNESS, Item, discharging_items

DIR = "artifacts/crosscheck"
INDEX = f"{DIR}/index.json"

#: What each agreement makes of the item's verdict in the report.
#: ``two solvers`` / ``one solver`` keep it; ``disagree`` and
#: ``inconclusive`` (cvc5 answered unknown on a proof) make it inconclusive.
DOWNGRADES = frozenset({"disagree", "inconclusive"})


def agreement(expects: str, d: dict[str, Any] | None) -> tuple[str, str]:
    """``(agreement, why)`` of Z3's answer ``expects`` (``unsat``/``sat``)
    and cvc5's decision ``d`` (a row's ``cvc5`` object, ``None`` when cvc5
    is not installed).

    * ``two solvers``: cvc5 gave the same answer (with a checked proof
      for ``unsat``);
    * ``disagree``: cvc5 gave the opposite answer, or an ``unsat`` whose
      proof did not check;
    * ``inconclusive``: a proof (``unsat``) on which cvc5 answered
      ``unknown`` within its budget;
    * ``one solver``: cvc5 could not take the script (``error``: a
      construct it rejects), is not installed, or answered ``unknown`` to a
      satisfiable query, whose certificate is Z3's witness (cvc5 is
      incomplete for quantified satisfiability).
    """
    if d is None:
        return "one solver", "cvc5 is not installed (pip install cvc5)"
    ans, why = str(d.get("answer")), str(d.get("reason") or "")
    if ans == "error":
        return "one solver", f"cvc5 cannot take the query: {why}"
    if ans == expects:
        if ans == "unsat" and not d.get("proof_checked"):
            return "disagree", "cvc5 answered unsat but its proof did not check"
        return "two solvers", f"Z3 and cvc5 {d.get('version', '')} both answer {ans}"
    if ans == "unknown":
        if expects == "unsat":
            return "inconclusive", f"cvc5 answered unknown ({why or 'no reason'}) where Z3 proved it"
        return "one solver", f"cvc5 answered unknown ({why or 'no reason'}); Z3's witness stands alone"
    return "disagree", f"Z3 answered {expects}, cvc5 {ans}"


def confirm_proof(text: str) -> tuple[str, str]:
    """``(agreement, why)`` of cvc5 with a proof (Z3's ``unsat``) of the
    SMT-LIB2 script ``text``, decided now (``rclverify refines``)."""
    return agreement("unsat", decide(text).row() if version() else None)


def stage_crosscheck(root: Path, nodes: Iterable[str]) -> dict[str, Any]:
    """Decide every discharging item of the workspace at ``root`` again
    with cvc5 and write the stage's record (module docstring); returns the
    index written.  Raises ``OSError`` when a file cannot be written; a
    script that cannot be read gives the row ``error``."""
    ver = version()
    old, why = read_sealed(root / INDEX, "second-solver record")
    cache = {r["key"]: r["cvc5"] for r in (old or {}).get("items", []) if not why and isinstance(r, dict)
             and isinstance(r.get("cvc5"), dict) and isinstance(r.get("key"), str)}
    rows: list[dict[str, Any]] = []
    keep: set[str] = set()
    session = Session() if ver else None
    for it in discharging_items(root, nodes):
        rows.append(_row(root, it, ver, cache, keep, session))
    index = {"solver": {"name": "cvc5", "version": ver, "rlimit": RLIMIT} if ver else None,
             "counts": _counts(rows), "items": rows}
    write_sealed(root / INDEX, index)
    proofs = root / DIR / "proofs"
    for f in proofs.glob("*.proof") if proofs.is_dir() else []:
        if f.name not in keep:
            f.unlink()
    return index


def _row(root: Path, it: Item, ver: str, cache: dict[str, dict[str, Any]], keep: set[str],
         session: Session | None = None) -> dict[str, Any]:
    row: dict[str, Any] = {"kind": it.kind, "id": it.id, "smt2": it.smt2, "verdict": it.verdict,
                           "z3": it.expects}
    try:
        text = (root / it.smt2).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        row.update(sha256="", key="", cvc5=None, agreement="disagree",
                   why=f"{it.smt2} cannot be read ({exc.__class__.__name__}): the verdict has no query")
        return row
    sha = hashlib.sha256(text.encode("utf-8")).hexdigest()
    key = f"{sha}:{ver}:{RLIMIT}" + (":every" if it.every else "")
    row.update(sha256=sha, key=key)
    proof_rel = f"{DIR}/proofs/{sha}.proof"
    d = cache.get(key) if ver else None
    if d is not None and d.get("proof") and not (root / proof_rel).is_file():
        d = None  # its proof is gone: decide again
    if d is None and ver:
        dec: Decision = decide(text, it.smt2, every=it.every, session=session)
        d = dec.row()
        if dec.proof:
            atomic_write_text(root / proof_rel, dec.proof)
            d["proof"] = proof_rel
    if d is not None and d.get("proof"):
        keep.add(Path(d["proof"]).name)
    row["cvc5"] = d
    row["agreement"], row["why"] = agreement(it.expects, d)
    if it.via == WITNESS:
        row["via"] = WITNESS
        row["why"] += (" on the witness query: the output terms written out answer every admissible input, which"
                       " implies the contract is realizable")
    return row


def _counts(rows: list[dict[str, Any]]) -> dict[str, int]:
    out: dict[str, int] = {}
    for r in rows:
        out[r["agreement"]] = out.get(r["agreement"], 0) + 1
    return dict(sorted(out.items()))


def read_crosscheck(root: Path) -> tuple[dict[tuple[str, str], dict[str, Any]], str]:
    """``(rows by (kind, id), problem)`` of the stage's record: ``({}, "")``
    before it ran; ``({}, why)`` when its seal does not hold (the caller
    then reads every item as decided by one solver and says why)."""
    body, why = read_sealed(root / INDEX, "second-solver record")
    if why or body is None:
        return {}, why
    return {(str(r.get("kind")), str(r.get("id"))): r for r in body.get("items", []) if isinstance(r, dict)}, ""
