"""The second-solver stage: every discharging item decided again by cvc5.

Writes (docs/second-solver.md):

* ``artifacts/crosscheck/index.json`` (sealed): one row per
  :class:`~.items.Item` with the sha256 of its SMT-LIB2 script, Z3's
  recorded verdict and answer, cvc5's answer (version, reason, duration),
  the path of its checked proof and the :func:`agreement`;
* ``artifacts/crosscheck/proofs/<sha256>.proof``: cvc5's proof of each
  ``unsat`` answer, in cvc5's CPC format, checked by cvc5's proof checker,
  its last line naming the sha256 of the query it proves
  (:func:`rclverify.records.ties.tie_proof`).

Answers are keyed by the script's sha256, cvc5's version and the budget
(:data:`.cvc5_decide.RLIMIT`, deterministic), and re-used from the last
index when all three are the same: an incremental run equals a clean one.
"""
from __future__ import annotations

import hashlib
import os
from pathlib import Path
from typing import Any, Iterable, cast

import msgspec

from rclverify.core import cpus as cpus_now
from rclverify.core.forksafe import fork_is_safe
from rclverify.records.sealed import read_sealed, write_sealed
from rclverify.records.crosscheck_records import CrosscheckRecord, Cvc5Answer
from rclverify.records.statuses import Agreement
from rclverify.records.store import atomic_write_text
from rclverify.records.ties import proof_tie, tie_proof
from rclverify.stages.crosscheck.cvc5_decide import RLIMIT, Decision, Session, decide, version
from rclverify.stages.crosscheck.items import WITNESS, Item, discharging_items

DIR = "artifacts/crosscheck"
INDEX = f"{DIR}/index.json"

#: What each agreement makes of the item's verdict in the report.
#: ``two solvers`` / ``one solver`` keep it; ``disagree`` and
#: ``inconclusive`` (cvc5 answered unknown on a proof) make it inconclusive.
DOWNGRADES = frozenset({"disagree", "inconclusive"})


def agreement(expects: str, d: Cvc5Answer | None) -> tuple[str, str]:
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


#: Scripts to decide from which the stage splits them between two processes (below that, a second
#: process's start and its own cvc5 solver cost more than it saves).
SPLIT_MIN = 200


def stage_crosscheck(root: Path, nodes: Iterable[str], *, split_min: int = SPLIT_MIN) -> CrosscheckRecord:
    """Decide every discharging item of the workspace at ``root`` again
    with cvc5 and write the stage's record (module docstring); returns the
    index written.  When ``split_min`` or more scripts are not in the last
    index and the process may run on two CPUs, the second half of them is
    decided in a forked process beside the first (:func:`_decide_scripts`;
    every answer and proof is that of a fresh solver, so the index is the
    same either way).  Raises ``OSError`` when a file cannot be written; a
    script that cannot be read gives the row ``error``."""
    ver = version()
    old, why = read_sealed(root / INDEX, "second-solver record")
    cache = {r["key"]: r["cvc5"] for r in (old or {}).get("items", []) if not why and isinstance(r, dict)
             and isinstance(r.get("cvc5"), dict) and isinstance(r.get("key"), str)}
    keep: set[str] = set()
    pending = [_lookup(root, it, ver, cache) for it in discharging_items(root, nodes)]
    todo = [(text, it.smt2, it.every) for it, row, text, d in pending if ver and d is None and text is not None]
    decided = iter(_decide_scripts(todo, split_min))
    rows = [_finish(root, it, row, next(decided) if ver and d is None and text is not None else d, keep)
            for it, row, text, d in pending]
    index = {"solver": {"name": "cvc5", "version": ver, "rlimit": RLIMIT} if ver else None,
             "counts": _counts(rows), "items": rows}
    write_sealed(root / INDEX, index)
    proofs = root / DIR / "proofs"
    for f in proofs.glob("*.proof") if proofs.is_dir() else []:
        if f.name not in keep:
            f.unlink()
    return cast(CrosscheckRecord, index)


def _lookup(root: Path, it: Item, ver: str, cache: dict[str, Cvc5Answer]
            ) -> tuple[Item, dict[str, Any], str | None, Cvc5Answer | Decision | None]:
    """``(item, row, script text, decision)`` of ``it``: the decision kept in
    the last index under the script's key (``None`` when cvc5 must decide it,
    or when the script cannot be read: then ``text`` is ``None`` and the row
    is complete)."""
    row: dict[str, Any] = {"kind": it.kind, "id": it.id, "smt2": it.smt2, "verdict": it.verdict,
                           "z3": it.expects}
    try:
        text = (root / it.smt2).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        row.update(sha256="", key="", cvc5=None, agreement="disagree",
                   why=f"{it.smt2} cannot be read ({exc.__class__.__name__}): the verdict has no query")
        return it, row, None, None
    sha = hashlib.sha256(text.encode("utf-8")).hexdigest()
    key = f"{sha}:{ver}:{RLIMIT}" + (":every" if it.every else "")
    row.update(sha256=sha, key=key)
    d = cache.get(key) if ver else None
    if d is not None and d.get("proof") and not proof_tied(root / f"{DIR}/proofs/{sha}.proof", sha):
        d = None  # its proof is gone, or does not name its query (written by an earlier rclverify): decide again
    return it, row, text, d


def proof_tied(path: Path, query_sha256: str) -> bool:
    """Whether the proof file ``path`` exists and its last line names the
    query ``query_sha256`` (:func:`rclverify.records.ties.proof_tie`); only
    its last bytes are read."""
    line = proof_tie(query_sha256).encode("utf-8")
    try:
        with open(path, "rb") as f:
            f.seek(0, os.SEEK_END)
            f.seek(max(0, f.tell() - len(line) - 2))
            return f.read().rstrip(b"\r\n").endswith(b"\n" + line)
    except OSError:
        return False


def _finish(root: Path, it: Item, row: dict[str, Any], d: Cvc5Answer | Decision | None,
            keep: set[str]) -> dict[str, Any]:
    """The row of ``it`` with cvc5's decision ``d`` (kept, or just made: its
    proof is written then) and the agreement."""
    if "agreement" in row:  # the script could not be read
        return row
    if isinstance(d, Decision):
        dec, d = d, d.row()
        if dec.proof:
            proof_rel = f"{DIR}/proofs/{row['sha256']}.proof"
            atomic_write_text(root / proof_rel, tie_proof(dec.proof, row["sha256"]))
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


def _decide_scripts(todo: list[tuple[str, str, bool]], split_min: int) -> list[Decision]:
    """cvc5's decision of each ``(text, name, every)`` script, in order: in
    this process, or, for ``split_min`` scripts or more on a machine that
    gives this process two CPUs, one of them free (:func:`_other_cpu_free`),
    and can fork, the second half in a forked
    child beside the first half here (cvc5's Python API holds the GIL, so a
    thread would not run beside it), unless this process runs other
    threads.  Each half has its own shared solver
    (:class:`~.cvc5_decide.Session`), whose answers and proofs equal a fresh
    solver's, so the decisions are those of the serial path."""
    half = len(todo) // 2
    # a process with other threads (the live progress line of a serial run on a terminal) is not forked: a lock
    # one of them holds would stay held in the child (core/forksafe.py; a doit -n worker's queue feeder excepted)
    if len(todo) < max(2, split_min) or not fork_is_safe() or not _other_cpu_free():
        return _decide_block(todo)
    import multiprocessing  # deferred: optional or conditional (inside a block)
    from concurrent.futures import ProcessPoolExecutor  # deferred: optional or conditional (inside a block)
    with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("fork")) as pool:
        second = pool.submit(_in_child, todo[half:])
        first = _decide_block(todo[:half])
        return first + second.result()


def _other_cpu_free() -> bool:
    """Whether a second CPU is free for the forked child: the process may
    run on two or more, and over a short window (:func:`~rclverify.core.cpus.idle_cpus`,
    while this process sleeps) its own CPU and at least half of another
    were idle.  On a busy machine the child only waits for a core and costs
    its fork, its copied pages and its own solver (0.13 CPU s of 1.7 for
    the 200-node chain's 1,000 scripts at load 3, the same wall time:
    docs/scale.md).  Where the CPU counters cannot be read, the
    load average of the last minute (this process counts 1) must leave half
    a CPU idle; that figure lags: after a busy phase it keeps a free CPU
    looking busy for a minute."""
    cpus = len(_cpus())
    if cpus < 2:
        return False
    idle = cpus_now.idle_cpus()
    if idle is not None:
        return idle >= 1.5
    try:
        load = os.getloadavg()[0]
    except OSError:  # not known: as before the load was read
        return True
    return load <= cpus - 0.5


def _cpus() -> set[int]:
    return cpus_now.allowed_cpus()


def _in_child(todo: list[tuple[str, str, bool]]) -> list[Decision]:
    """:func:`_decide_block` in the forked child (named here, not passed: the pool pickles what it runs)."""
    return _decide_block(todo)


def _decide_block(todo: list[tuple[str, str, bool]]) -> list[Decision]:
    """The decisions of ``todo`` (:func:`_decide_scripts`) in one session of this process."""
    session = Session()
    return [decide(text, name, every=every, session=session) for text, name, every in todo]


def _counts(rows: list[dict[str, Any]]) -> dict[str, int]:
    out: dict[str, int] = {}
    for r in rows:
        out[r["agreement"]] = out.get(r["agreement"], 0) + 1
    return dict(sorted(out.items()))


class Cvc5Seen(msgspec.Struct, frozen=True):
    """cvc5's answer in a row of the stage's record as its readers read it back
    (:class:`~rclverify.records.crosscheck_records.Cvc5Answer`): a key the row lacks at ``None``
    (``proof``: ``""``)."""

    answer: str | None = None
    reason: str | None = None
    version: str | None = None
    proof_checked: bool | None = None
    proof: str = ""


class CrosscheckSeen(msgspec.Struct, frozen=True):
    """One row of the stage's record as its readers read it back
    (:class:`~rclverify.records.crosscheck_records.CrosscheckRow`): the item, the script's path and the
    sha256 of the text cvc5 decided, the agreement and why, cvc5's answer; ``other_text``: the script at
    that path now holds another text (stages/crosscheck/apply.py ``load``)."""

    kind: str = ""
    id: str = ""
    smt2: str | None = None
    sha256: str | None = None
    agreement: Agreement | None = None
    why: str = ""
    cvc5: Cvc5Seen | None = None
    other_text: bool = False


def read_crosscheck(root: Path) -> tuple[dict[tuple[str, str], CrosscheckSeen], str]:
    """``(rows by (kind, id), problem)`` of the stage's record: ``({}, "")``
    before it ran; ``({}, why)`` when its seal does not hold (the caller
    then reads every item as decided by one solver and says why).  A row
    that does not decode into :class:`CrosscheckSeen` is left out (its item
    then reads as one the stage did not decide)."""
    body, why = read_sealed(root / INDEX, "second-solver record")
    if why or body is None:
        return {}, why
    return seen_rows(body.get("items")), ""


def seen_rows(items: object) -> dict[tuple[str, str], CrosscheckSeen]:
    """The record's ``items`` (its JSON list) as rows by ``(kind, id)``, each decoded into
    :class:`CrosscheckSeen`; a row that does not decode is left out, and ``{}`` when ``items`` is no list."""
    out: dict[tuple[str, str], CrosscheckSeen] = {}
    for r in items if isinstance(items, list) else ():
        try:
            row = msgspec.convert(r, CrosscheckSeen)
        except msgspec.ValidationError:
            continue
        out[(row.kind, row.id)] = row
    return out
