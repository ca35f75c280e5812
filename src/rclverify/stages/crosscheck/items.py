"""The items a second solver re-decides, read from the sealed stage records.

An item is one recorded Z3 answer that discharges something, with the
SMT-LIB2 file it was decided from:

=================  ======================================  =========  ========
kind               record                                  verdict    expects
=================  ======================================  =========  ========
``side-condition`` ``artifacts/calculus/<Node>.json``      discharged unsat
``requirement``    ``artifacts/requirements/<ID>.json``    proved     unsat
``consistency``    the same, ``consistency_smt2``          consistent sat
                                                           inconsist. unsat
``vacuity``        the same, ``vacuity_smt2``              non-vac.   sat
                                                           vacuous    unsat
``deadline``       ``artifacts/deadlines/index.json``      proved     unsat
``health``         ``artifacts/health/<Node>.json``        ok         sat/unsat
``hoare``          ``artifacts/evidence/<Obligation>.json`` discharged unsat, each
=================  ======================================  =========  ========

A health check reads ``ok`` on a satisfiable query (an assumption that can
be met, a consistent contract, a guarantee that can fire: Z3's witness is
its certificate) except the replacement check and realizability, which
read ``ok`` on a proof.  A realizable contract with a witness (output
terms answering every admissible input, :mod:`rclverify.calculus.health.realizer`)
is decided from the witness's query instead (``witness_smt2``): it has no
quantifier, and its unsat implies the realizability query's.  A proved requirement's consistency and vacuity answers are items
too (its ``met`` rests on the satisfiable ones, its ``proved vacuously`` or
``from an inconsistency`` on the unsatisfiable ones).  A record whose seal does not hold gives no item: the report already
shows it ``error``.  A Hoare obligation's script holds one query per
verification condition; all must be ``unsat``.  Dafny proofs are not
items (Dafny's own Boogie/Z3 run is the evidence).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Iterable, Mapping

import msgspec

from rclverify.records.findings import HealthFinding
from rclverify.records.sealed import read_sealed
from rclverify.stages.requirements import record_path
from rclverify.records.sealed import obligation_list
from rclverify.records.store import EvidenceStore

#: Health checks whose ``ok`` is an ``unsat`` answer (a proof); every other
#: check's ``ok`` is a satisfiable answer with Z3's witness.
PROOF_CHECKS = frozenset({"replacement-refines", "realizable"})

#: :attr:`Item.via` of a realizable contract decided from its witness.
WITNESS = "witness"

#: A proved requirement's side queries (``calculus/requirements/check.py``): their decided verdicts and Z3's
#: answer behind each.
SIDE_ANSWERS = {"consistency": {"consistent": "sat", "inconsistent": "unsat"},
                "vacuity": {"non-vacuous": "sat", "vacuous": "unsat"}}


@dataclass(frozen=True)
class Item:
    """One discharging answer: ``kind`` (table above), ``id`` (the side
    condition's, requirement's or finding's id), ``smt2`` (workspace-relative
    path of its script), ``verdict`` (the recorded one), ``expects``
    (``unsat`` or ``sat``: Z3's answer that gave the verdict)."""

    kind: str
    id: str
    smt2: str
    verdict: str
    expects: str
    #: the verdict rests on every check-sat of the script (a Hoare triple's conditions), not only its last
    every: bool = False
    #: what the script is when it is not the verdict's own query: ``witness`` (a realizable contract's
    #: witness query, whose unsat implies the verdict's; calculus/health/realizer.py)
    via: str = ""
    #: the record row that states what the script decides (its statement: rclverify.records.ties)
    row: Mapping[str, object] = field(default_factory=dict, compare=False, hash=False, repr=False)


def discharging_items(root: Any, nodes: Iterable[str]) -> list[Item]:
    """Every :class:`Item` of the workspace at ``root`` (a ``Path``) for
    ``nodes``, in a fixed order (node order, then requirements and
    deadlines by id).  Reads sealed records only; never raises for a
    missing or altered record (it gives no item)."""
    out: list[Item] = []
    for n in nodes:
        body, why = read_sealed(root / f"artifacts/calculus/{n}.json", "side-condition record")
        for sc in _rows(body, why, "side_conditions"):
            if sc.get("status") == "discharged" and _path(sc.get("smt2")):
                out.append(Item("side-condition", str(sc.get("id")), sc["smt2"], "discharged", "unsat", row=sc))
        body, why = read_sealed(root / f"artifacts/health/{n}.json", "contract health record")
        for f in _findings(body, why):
            row = f.to_json()
            witness = witness_query(row)
            if f.status == "ok" and witness is not None:
                # the witness's quantifier-free query, which implies realizability (calculus/health/realizer.py)
                out.append(Item("health", f.id, witness, "ok", "unsat", every=True, via=WITNESS, row=row))
            elif f.status == "ok" and _path(f.smt2):
                proof = f.check in PROOF_CHECKS  # both sides of a replacement (joined by a reset) must hold
                out.append(Item("health", f.id, f.smt2, "ok", "unsat" if proof else "sat", every=proof, row=row))
    index, why = read_sealed(root / "artifacts/requirements/index.json", "requirement index")
    records = index.get("records") if isinstance(index, dict) and not why else None
    for rid in sorted(records) if isinstance(records, dict) else []:
        rec, why = read_sealed(root / record_path(rid), "requirement record")
        if rec and not why and rec.get("verdict") == "proved" and _path(rec.get("smt2")):
            out.append(Item("requirement", rid, rec["smt2"], "proved", "unsat", row=rec))
            for side, answers in SIDE_ANSWERS.items():
                verdict = rec.get(side)
                if verdict in answers and _path(rec.get(f"{side}_smt2")):
                    out.append(Item(side, rid, rec[f"{side}_smt2"], str(verdict), answers[verdict], row=rec))
    out.extend(_hoare_items(root, nodes))
    body, why = read_sealed(root / "artifacts/deadlines/index.json", "deadline record")
    for d in sorted(_rows(body, why, "results"), key=lambda d: str(d.get("requirement"))):
        if d.get("status") == "proved" and _path(d.get("smt2")):
            out.append(Item("deadline", str(d.get("requirement")), d["smt2"], "proved", "unsat", row=d))
    return out


def witness_query(finding: Any) -> str | None:
    """The script the second solver decides for a health ``finding`` (a JSON
    object) instead of its ``smt2``: a realizable contract's witness query
    (``witness_smt2``), else ``None``."""
    if not isinstance(finding, dict) or finding.get("check") != "realizable":
        return None
    path = finding.get("witness_smt2")
    return path if _path(path) else None


def _findings(body: Any, why: str) -> list[HealthFinding]:
    """The findings of a sealed health record, decoded into their one
    definition (records/findings.py); none when the record is missing,
    altered or does not decode."""
    try:
        return msgspec.convert(_rows(body, why, "findings"), list[HealthFinding])
    except msgspec.ValidationError:
        return []


def _rows(body: Any, why: str, key: str) -> list[dict[str, Any]]:
    rows = body.get(key) if isinstance(body, dict) and not why else None
    return [r for r in rows if isinstance(r, dict)] if isinstance(rows, list) else []


def _path(p: Any) -> bool:
    return isinstance(p, str) and p.startswith("artifacts/") and p.endswith(".smt2") and ".." not in p


def _hoare_items(root: Any, nodes: Iterable[str]) -> list[Item]:
    """A discharged Hoare obligation's verification conditions (its ``.smt2``
    artifact: one ``push``/``pop`` scope per condition, all ``unsat``)."""
    store = EvidenceStore(root)
    out: list[Item] = []
    for n in nodes:
        records, problem = obligation_list(root / f"artifacts/obligations/{n}.json")
        for o in records or [] if not problem else []:
            if o.get("backend") != "hoare":
                continue
            ev, altered = store.read(str(o.get("id")))
            if ev is None or altered or ev.status != "discharged":
                continue
            for a in ev.artifacts:
                if _path(a):
                    out.append(Item("hoare", ev.obligation, a, "discharged", "unsat", every=True, row=o))
    return out
