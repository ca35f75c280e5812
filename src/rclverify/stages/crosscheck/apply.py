"""The second solver's verdicts folded into what the report shows.

Every side condition, health finding and requirement record the report
reads gets ``solvers``: ``{"agreement", "why", "cvc5", "proof", "smt2"}``
from the sealed ``artifacts/crosscheck/index.json``
(:mod:`.stage`).  Where the two solvers disagree, or cvc5 answered
``unknown`` to what Z3 proved, the item reads ``inconclusive`` with both
answers, never discharged or proved (docs/second-solver.md).
An item the stage did not see (it ran before the item was decided, or its
record is altered) reads ``one solver`` with the reason.
"""
from __future__ import annotations

from typing import Any, Callable, Mapping, TypeVar

import msgspec

from rclverify.stages.crosscheck.items import witness_query
from rclverify.stages.crosscheck.stage import DOWNGRADES
import hashlib
from rclverify.stages.crosscheck.stage import CrosscheckSeen, read_crosscheck
from rclverify.stages.crosscheck.items import SIDE_ANSWERS
from rclverify.records.solvers_rows import Solvers

#: A record the second solver's verdict is folded into (a side-condition row, a health finding, a
#: requirement or deadline record): given back as it is when nothing changes, else a new dict.
Row = TypeVar("Row", bound=Mapping[str, object])

_STAGE_MISSING = "the second-solver stage has not decided it (run `doit verify`)"
_NO_QUERY = ("no single SMT-LIB2 query is kept for this verdict (a temporal proof by BMC, k-induction or a "
             "ranking function; a scan instance by instance), so the second solver has none to decide")
_OTHER_TEXT = ("the second solver decided another text of this query (its sha256 differs from the query's now): "
               "this one is Z3's alone until the second-solver stage runs again (run `doit verify`)")


class SecondSolver:
    """The stage's rows by ``(kind, id)`` and the record's problem ('' when
    its seal holds or it does not exist yet)."""

    def __init__(self, rows: Mapping[tuple[str, str], CrosscheckSeen], problem: str = "") -> None:
        self.rows = dict(rows)
        self.problem = problem

    def solvers(self, kind: str, item_id: str, smt2: str | None = None) -> Solvers:
        """The ``solvers`` object of one item (module docstring;
        records/solvers_rows.py).  A row whose query text is not the one the
        item names now (another ``smt2`` path) is not believed."""
        r = self.rows.get((kind, item_id))
        if r is None or r.agreement is None or (smt2 is not None and r.smt2 != smt2):
            why = f"second-solver record: {self.problem}" if self.problem else _STAGE_MISSING
            return Solvers(agreement="one solver", why=why, cvc5=None, proof="", smt2=smt2 or "")
        if r.other_text:
            return Solvers(agreement="one solver", why=_OTHER_TEXT, cvc5=None, proof="", smt2=str(r.smt2 or ""))
        c = r.cvc5
        return Solvers(agreement=r.agreement, why=r.why,
                       cvc5=None if c is None else {"answer": c.answer, "reason": c.reason, "version": c.version,
                                                    "proof_checked": c.proof_checked},
                       proof=c.proof if c is not None else "", smt2=str(r.smt2 or ""))

    def _fold(self, row: Row | None, kind: str, id_key: str, status_key: str, good: str,
              downgraded: Callable[[Row, Solvers], dict[str, str]],
              query: str | None = None) -> Row | dict[str, object] | None:
        """``row`` with ``solvers`` when its ``status_key`` reads ``good``;
        then, when the solvers do not agree, ``status_key`` set to
        ``inconclusive`` and the fields ``downgraded(row, solvers)`` gives.
        ``query``: the script the second solver decides for it, when not
        the row's ``smt2`` (a realizable contract's witness query)."""
        if row is None or row.get(status_key) != good:
            return row
        if not row.get("smt2"):  # no query kept (a temporal proof, a scan instance by instance): nothing to re-decide
            return {**row, "solvers": Solvers(agreement="one solver", why=_NO_QUERY, cvc5=None, proof="",
                                              smt2="").to_json()}
        smt2 = row.get("smt2")
        s = self.solvers(kind, str(row.get(id_key)), query or (smt2 if isinstance(smt2, str) else None))
        if s.agreement in DOWNGRADES:
            return {**row, status_key: "inconclusive", "solvers": s.to_json(), **downgraded(row, s)}
        return {**row, "solvers": s.to_json()}

    def side_condition(self, sc: Row) -> Row | dict[str, object]:
        """``sc`` (a side-condition row) with ``solvers``; a discharged one
        the solvers do not agree on is ``inconclusive``."""
        return self._fold(sc, "side-condition", "id", "status", "discharged", lambda r, s: {
            "explanation": f"Not discharged: {s.why} (second solver). Z3 alone: {r.get('explanation', '')}"}) or sc

    def finding(self, f: Row) -> Row | dict[str, object]:
        """A health finding with ``solvers``; an ``ok`` one the solvers do
        not agree on is ``inconclusive``."""
        return self._fold(f, "health", "id", "status", "ok", lambda r, s: {
            "message": f"{r.get('message', '')} Not confirmed: {s.why} (second solver)."}, witness_query(f)) or f

    def requirement(self, rec: Row | None) -> Row | dict[str, object] | None:
        """A requirement record with ``solvers``; a ``proved`` one the
        solvers do not agree on has verdict ``inconclusive`` and the reason.
        A proved one's decided consistency and vacuity answers get
        ``consistency_solvers`` and ``vacuity_solvers``; one the solvers do
        not agree on reads ``undecided`` with the reason (the requirement is
        then ``inconclusive``, calculus/requirements/rollup.py)."""
        out = self._fold(rec, "requirement", "id", "verdict", "proved", lambda r, s: {
            "recorded_verdict": "proved", "reason": f"second solver: {s.why}"})
        if out is None or out.get("verdict") != "proved":
            return out
        for side, answers in SIDE_ANSWERS.items():
            smt2 = out.get(f"{side}_smt2")
            if out.get(side) not in answers or not smt2:
                continue
            s = self.solvers(side, str(out.get("id")), smt2 if isinstance(smt2, str) else None)
            new = {**out, f"{side}_solvers": s.to_json()}
            if s.agreement in DOWNGRADES:
                new.update({side: "undecided", f"recorded_{side}": new[side],
                            f"{side}_reason": f"Z3 found it {new[side]}, but the second solver does not agree: "
                                              f"{s.why}"})
            out = new
        return out

    def deadline(self, d: Row) -> Row | dict[str, object]:
        """A deadline record with ``solvers``; a ``proved`` one the solvers
        do not agree on is ``inconclusive``."""
        return self._fold(d, "deadline", "requirement", "status", "proved", lambda r, s: {
            "reason": f"second solver: {s.why}"}) or d

    def evidence(self, obligation: str, backend: str, status: str) -> tuple[str, Solvers | None]:
        """``(status, solvers)`` of an obligation's evidence: a discharged
        Hoare triple the solvers do not agree on is ``inconclusive``
        (``solvers`` is ``None`` for the other backends)."""
        if backend != "hoare" or status != "discharged":
            return status, None
        s = self.solvers("hoare", obligation)
        return ("inconclusive" if s.agreement in DOWNGRADES else status), s

    def counts(self) -> dict[str, int]:
        """How many items each agreement has (the report's headline)."""
        out: dict[str, int] = {}
        for r in self.rows.values():
            a = "one solver" if r.other_text else str(r.agreement)
            out[a] = out.get(a, 0) + 1
        return dict(sorted(out.items()))


def load(root: Any) -> SecondSolver:
    """The :class:`SecondSolver` of the workspace at ``root`` (a ``Path``).
    A row whose query file now holds another text than the one cvc5
    decided (its ``sha256``; a stage re-wrote it since, the second-solver
    stage not yet) is marked ``other_text``: its agreement is not carried
    over to a query cvc5 never saw, whichever way it went."""

    rows, problem = read_crosscheck(root)
    for key, r in list(rows.items()):
        rel = r.smt2
        try:
            text = (root / rel).read_text(encoding="utf-8") if rel else None
            now = hashlib.sha256(text.encode("utf-8")).hexdigest() if text is not None else ""  # as the stage hashes
        except (OSError, UnicodeDecodeError):
            now = ""
        if now != r.sha256:
            rows[key] = msgspec.structs.replace(r, other_text=True)
    return SecondSolver(rows, problem)
