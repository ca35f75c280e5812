"""``rclverify bundle --recheck ARCHIVE``: every stored query decided again
from the bundle alone, by both solvers (docs/second-solver.md).

Nothing of a workspace is read and no contract is parsed: the archive's
sealed records name the items that discharge something
(:func:`.items.discharging_items`), the second-solver record
(``artifacts/crosscheck/index.json``) names each item's query and its
sha256, and each query's SMT-LIB2 text is in the archive.  For each item:

* the query in the archive must be the one that was decided (its sha256
  is the record's): an edited query is named;
* the query must be tied to the statement the sealed record states, and
  each kept proof to its query (:mod:`.ties`): a query borrowed from
  another item, or two proofs swapped, are named;
* Z3 (from the text, a fresh solver, the query budget) must give the
  answer the record's verdict rests on, and cvc5 the answer it recorded:
  an opposite answer is named;
* an item that the second-solver record does not list is named, and so
  is a sealed record whose seal does not hold (an edited verdict).

A ``unknown`` from either solver is reported (the verdict could not be
re-established within the budget here) but is not a contradiction.
"""
from __future__ import annotations

import hashlib
from dataclasses import dataclass

from rclverify.records.sealed import check_text, is_sealed_path
from rclverify.stages.crosscheck.cvc5_decide import Session, decide, version
from rclverify.stages.crosscheck.stage import INDEX
from rclverify.stages.crosscheck.ties import TAIL_BYTES, bundle_items, index_rows, is_tied, tie_problems

#: Z3's budget per query in the re-check, in resource steps (as the query module's 10 s budget).
Z3_RLIMIT = 20_000_000


@dataclass(frozen=True)
class Recheck:
    """The outcome: ``checked`` items re-decided, ``problems`` (sentences
    naming an item: rc 1), ``notes`` (an answer not re-established)."""

    checked: int
    problems: list[str]
    notes: list[str]


def z3_answer(text: str, every: bool = False) -> str:
    """Z3's answer (``sat``/``unsat``/``unknown``/``error``) to the last
    query of the SMT-LIB2 script ``text`` (queries are joined by
    ``(reset)``), from the text alone in a fresh context; with ``every``,
    to each ``(push 1)`` ... ``(pop 1)`` scope of it (a Hoare triple's
    conditions): ``unsat`` when all are, else the first other answer."""
    if every:
        import re  # deferred: optional or conditional (inside a block)
        blocks = re.findall(r"\(push 1\)\n(.*?)\(pop 1\)", text, flags=re.S) or text.split("\n(reset)\n")
        answers = [z3_answer(b) for b in blocks]
        return next((a for a in answers if a != "unsat"), "unsat" if answers else "error")
    import z3  # deferred: start-up (loads z3 only when called)
    last = text.split("\n(reset)\n")[-1]
    ctx = z3.Context()
    s = z3.Solver(ctx=ctx)
    s.set("rlimit", Z3_RLIMIT)
    try:
        s.from_string(last)
        return str(s.check())
    except z3.Z3Exception:
        return "error"


def recheck_members(members: dict[str, bytes]) -> Recheck:
    """Re-decide the items of an archive's ``members`` (name -> bytes, as
    :func:`rclverify.report.bundle.archive.verify_bundle` keeps them).
    Raises ``OSError`` when the records cannot be read back (a private
    temporary folder, :func:`.ties.bundle_items`)."""
    problems: list[str] = []
    notes: list[str] = []
    rows, why = index_rows(members.get(INDEX))
    if rows is None:
        return Recheck(0, [f"{INDEX}: {why}" if why else
                           f"{INDEX}: not in the bundle: no second-solver record to re-check against"], [])
    for name in sorted(members):  # a verdict edited in a sealed record: its seal no longer holds
        if is_sealed_path(name):
            _, bad = check_text(members[name].decode("utf-8", "replace"), "record")
            if bad:
                problems.append(f"{name}: {bad}")
    items = bundle_items(members)
    # each query tied to the statement it claims to decide, each proof to its query (stages/crosscheck/ties.py)
    tied, untied = tie_problems(items, rows, members, {n: b[-TAIL_BYTES:] for n, b in members.items() if is_tied(n)})
    problems += tied
    has_cvc5 = bool(version())
    session = Session() if has_cvc5 else None
    for i, it in enumerate(items):
        label = f"{it.kind} {it.id}"
        row = rows.get((it.kind, it.id))
        if row is None:
            problems.append(f"{label}: recorded {it.verdict} but not in {INDEX}: never decided by the second solver")
            continue
        data = members.get(it.smt2)
        if i in untied or data is None:
            continue
        if hashlib.sha256(data).hexdigest() != row.sha256 or row.smt2 != it.smt2:
            problems.append(f"{label}: its query {it.smt2} was edited after it was decided "
                            f"(sha256 differs from {INDEX})")
            continue
        text = data.decode("utf-8", "replace")
        z = z3_answer(text, it.every)
        if z != it.expects:
            (notes if z in ("unknown", "error") else problems).append(
                f"{label}: recorded {it.verdict} (Z3 {it.expects}); Z3 now answers {z} on {it.smt2}")
        recorded = row.cvc5.answer if row.cvc5 is not None else None
        if has_cvc5 and recorded in ("sat", "unsat"):
            c = decide(text, it.smt2, proofs=recorded == "unsat", every=it.every, session=session)
            if c.answer != recorded:
                (notes if c.answer in ("unknown", "error") else problems).append(
                    f"{label}: cvc5 recorded {recorded}, now answers {c.answer} on {it.smt2}")
    if not has_cvc5:
        notes.append("cvc5 is not installed: the second solver's answers were not re-decided (pip install cvc5)")
    return Recheck(len(items), problems, notes)
