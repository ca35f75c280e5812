"""Decide an SMT-LIB2 script with cvc5, from its text alone.

The script is the one rclverify keeps for every Z3 query (``*.smt2`` under
``artifacts/``, written by Z3's printer, :func:`rclverify.semantics.query.smtlib_benchmark`).
cvc5 (PyPI ``cvc5``, the solver's own Python API) parses it with its
SMT-LIB 2.6 front end (``cvc5.InputParser``) and runs its commands; nothing
of rclverify's model is used, so the answer is independent of the encoder
that wrote the text.

Rules (SMT-LIB 2.6 standard, section 4.2; cvc5 options reference):

* a script without ``set-logic`` is run under ``ALL`` (Z3 writes none);
* a script with several queries joined by ``(reset)`` (a side condition's
  local check and its check in context) is answered by its last one, the
  query the recorded verdict rests on, which alone is given to cvc5 (cvc5
  stops producing proofs at ``(reset)``);
* the budget is cvc5's deterministic resource limit per check
  (``rlimit-per``, :data:`RLIMIT`), so the answer does not depend on the
  machine's load; a wall-clock limit (:data:`WALL_S`) is only a safety net;
* on ``unsat``, the proof is produced (``produce-proofs``) in cvc5's CPC
  format and re-checked step by step by cvc5's internal proof checker
  (``check-proofs``): a proof that does not check raises inside cvc5 and
  is reported as ``error``, never as ``unsat``;
* a :class:`Session` decides many quantifier-free scripts in one solver,
  each in its own ``push``/``pop`` scope (docs/second-solver.md, "One
  solver for many queries"): a proof-producing cvc5 solver costs about
  8 ms to make (it loads its rewrite-rule database), a scoped query about
  1.5 ms.  Quantified scripts, scripts that set the logic or options or
  reset, and any answer other than ``sat``/``unsat`` go to a fresh solver,
  so every recorded answer and proof is that of a fresh solver.
"""
from __future__ import annotations

import re
import time
from dataclasses import dataclass
from typing import Any

from rclverify.records.crosscheck_records import Cvc5Answer

#: cvc5 resource units per check: some 150k units a second on the case
#: study's heaviest quantified query, so about 10 s of work, the Z3 budget.
RLIMIT = 1_500_000
#: Wall-clock safety net per check, in milliseconds: some sixty times the
#: budget's time on an idle core, so that on a loaded machine the budget
#: (which answers ``unknown (RESOURCEOUT)`` the same everywhere) runs out
#: first; when the net fires cvc5 answers ``unknown (TIMEOUT)``, never
#: another verdict.
WALL_MS = 600_000


@dataclass(frozen=True)
class Decision:
    """cvc5's answer to one script.

    ``answer``   ``sat`` / ``unsat`` / ``unknown`` / ``error`` (cvc5 rejected
                 the script or its proof did not check);
    ``reason``   cvc5's reason for ``unknown`` (``INCOMPLETE``,
                 ``RESOURCEOUT``, ...) or the error message; '' otherwise;
    ``proof``    the checked proof (CPC text) on ``unsat``, else '';
    ``proof_checked`` the proof was re-checked by cvc5's proof checker;
    ``version``  cvc5's version; ``duration_s`` wall time in seconds.
    """

    answer: str
    reason: str
    proof: str
    proof_checked: bool
    version: str
    duration_s: float

    def row(self) -> Cvc5Answer:
        """The decision as the second-solver record keeps it (the proof's
        path, ``proof``, is the caller's to fill in)."""
        return {"answer": self.answer, "reason": self.reason, "proof_checked": self.proof_checked,
                "version": self.version, "duration_s": round(self.duration_s, 4), "proof": ""}


def version() -> str:
    """cvc5's version string, '' when the package is not installed."""
    try:
        import cvc5  # deferred: optional or conditional (inside a block)
    except ImportError:
        return ""
    return str(getattr(cvc5, "__version__", "")) or "unknown"


def decide(text: str, name: str = "query.smt2", *, rlimit: int = RLIMIT, proofs: bool = True,
           every: bool = False, session: "Session | None" = None) -> Decision:
    """The script ``text`` decided by cvc5 (:func:`_decide_one`, in
    ``session`` where it takes the script: :meth:`Session.takes`); with
    ``every``, each part of it between ``(reset)`` commands in a fresh
    solver (cvc5 stops producing proofs at a reset), the answer ``unsat``
    only when every part's every ``check-sat`` is, else the first other
    part's."""
    parts = text.split("\n(reset)\n") if every else [text]
    if len(parts) == 1:
        return _decide_part(text, name, rlimit, proofs, every, session)
    t0 = time.perf_counter()
    done = [_decide_part(p, name, rlimit, proofs, True, session) for p in parts]
    bad = next((d for d in done if d.answer != "unsat"), None)
    if bad is not None:
        return Decision(bad.answer, bad.reason, "", False, bad.version, time.perf_counter() - t0)
    return Decision("unsat", "", "\n".join(d.proof for d in done), all(d.proof_checked for d in done),
                    done[0].version, time.perf_counter() - t0)


def _decide_part(text: str, name: str, rlimit: int, proofs: bool, every: bool,
                 session: "Session | None") -> Decision:
    part = text if every else text.split("\n(reset)\n")[-1]  # the verdict rests on the last query
    if session is not None and session.takes(part, rlimit, proofs, every):
        d = session.decide(part, name, every)
        if d is not None:
            return d
    return _decide_one(text, name, rlimit=rlimit, proofs=proofs, every=every)


#: What keeps a script out of a shared solver: quantifiers (cvc5's
#: instantiation may depend on terms an earlier query left behind, so the
#: proof could differ from a fresh solver's) and commands that act on the
#: solver beyond a scope.
_UNSCOPED = re.compile(r"\((?:forall|exists|set-logic|set-option|reset|reset-assertions|exit|"
                       r"declare-datatypes?|define-sort|declare-sort)\b")


class Session:
    """One incremental proof-producing cvc5 solver for many scripts.

    :meth:`decide` runs a script between ``(push 1)`` and ``(pop 1)``, so
    its declarations and assertions are gone after it; a fresh solver is
    made after :data:`QUERIES` scripts (cvc5's term tables grow) and after
    any answer other than ``sat``/``unsat``.  Only scripts :meth:`takes`
    admits come here; the caller decides the rest in a fresh solver.
    Answers and proofs equal a fresh solver's on the quantifier-free
    scripts it admits (``tests/stages/test_second_solver.py`` compares them).
    Raises ``ImportError`` when cvc5 is missing.
    """

    QUERIES = 400

    def __init__(self, rlimit: int = RLIMIT) -> None:
        self.rlimit = rlimit
        self._solver: Any = None
        self._used = 0

    def takes(self, text: str, rlimit: int, proofs: bool, every: bool) -> bool:
        """Whether ``text`` may be decided here: proofs asked, the
        session's budget, no quantifier and no solver-level command."""
        return (proofs and rlimit == self.rlimit and _UNSCOPED.search(text) is None
                and text.count("(push") == text.count("(pop"))

    def _fresh(self) -> Any:
        import cvc5  # deferred: start-up (loads cvc5 only when called)
        tm = cvc5.TermManager()
        s = cvc5.Solver(tm)
        for k, v in (("incremental", "true"), ("rlimit-per", str(int(self.rlimit))), ("tlimit-per", str(WALL_MS)),
                     ("produce-proofs", "true"), ("check-proofs", "true"), ("proof-format-mode", "cpc")):
            s.setOption(k, v)
        s.setLogic("ALL")
        self._solver, self._used = (tm, s, cvc5.SymbolManager(tm)), 0
        return self._solver

    def decide(self, text: str, name: str, every: bool) -> Decision | None:
        """The script decided in the shared solver, or ``None`` (decide it
        in a fresh solver) when its answer is not ``sat``/``unsat``."""
        t0 = time.perf_counter()
        if self._solver is None or self._used >= self.QUERIES:
            self._fresh()
        _tm, s, sm = self._solver
        self._used += 1
        try:
            answers, proof_parts = _run(s, sm, "(push 1)\n" + text + "\n(pop 1)\n", name, True)
        except Exception:  # noqa: BLE001 - whatever went wrong, a fresh solver decides it
            self._solver = None
            return None
        if not answers or any(a not in ("sat", "unsat") for a in answers):
            self._solver = None
            return None
        ver = version()
        bad = next((a for a in answers if a != "unsat"), None) if every else (answers[-1] if answers[-1] != "unsat" else None)
        if bad is not None:
            return Decision(bad, "", "", False, ver, time.perf_counter() - t0)
        proof = "\n".join(proof_parts if every else proof_parts[-1:])
        return Decision("unsat", "", proof, bool(proof), ver, time.perf_counter() - t0)


def _decide_one(text: str, name: str = "query.smt2", *, rlimit: int = RLIMIT, proofs: bool = True,
                every: bool = False) -> Decision:
    """Run the SMT-LIB2 script ``text`` in a fresh cvc5 solver.

    ``name`` labels cvc5's messages; ``rlimit`` is the resource budget per
    check; ``proofs`` asks for the checked proof of an ``unsat`` answer.
    ``every``: the answer is that of every ``check-sat`` of the script (a
    Hoare triple's verification conditions, each in a ``push``/``pop``
    scope): ``unsat`` only when all are, with each one's proof; otherwise
    the last one's.  Returns a :class:`Decision`; never raises for a bad
    script (``error`` with cvc5's message).  Raises ``ImportError`` when
    cvc5 is missing.
    """
    import cvc5  # deferred: start-up (loads cvc5 only when called)
    t0 = time.perf_counter()
    ver = version()
    tm = cvc5.TermManager()
    s = cvc5.Solver(tm)
    try:
        s.setOption("rlimit-per", str(int(rlimit)))
        s.setOption("tlimit-per", str(WALL_MS))
        if proofs:
            s.setOption("produce-proofs", "true")
            s.setOption("check-proofs", "true")
            s.setOption("proof-format-mode", "cpc")
        sm = cvc5.SymbolManager(tm)
        if not every:  # the verdict rests on the last query: cvc5 drops proof production at `(reset)`
            text = text.split("\n(reset)\n")[-1]
        script = text if "(set-logic" in text else "(set-logic ALL)\n" + text
        try:
            answers, proof_parts = _run(s, sm, script, name, proofs)
        except _ScriptError as e:
            return Decision("error", str(e), "", False, ver, time.perf_counter() - t0)
        last = answers[-1] if answers else ""
        worst_ = next((a for a in answers if a != "unsat"), "")
        if not last:
            return Decision("error", "the script has no check-sat", "", False, ver, time.perf_counter() - t0)
        answer, _, why = (worst_ if every and worst_ else last).partition(" ")
        proof = ""
        if answer == "unsat" and proofs:
            proof = "\n".join(proof_parts if every else proof_parts[-1:])
        return Decision(answer, why.strip("() "), proof, bool(proof), ver, time.perf_counter() - t0)
    except Exception as e:  # noqa: BLE001 - cvc5's API raises its own exception type for what it rejects
        return Decision("error", str(e).strip().splitlines()[0][:300] if str(e).strip() else type(e).__name__,
                        "", False, ver, time.perf_counter() - t0)


class _ScriptError(Exception):
    """cvc5 answered a command of the script with an ``(error ...)``."""


def _run(s: Any, sm: Any, script: str, name: str, proofs: bool) -> tuple[list[str], list[str]]:
    """Run the SMT-LIB2 ``script``'s commands in cvc5 solver ``s`` (symbol
    manager ``sm``): the answers of its ``check-sat`` commands in order
    (``sat``, ``unsat``, ``unknown (REASON)``) and, with ``proofs``, the
    proof of each ``unsat`` in CPC text, taken at once (a later ``pop`` or
    ``reset`` discards it).  Raises :class:`_ScriptError` with cvc5's error
    output, and whatever cvc5's API raises for a script it rejects."""
    import cvc5  # deferred: start-up (loads cvc5 only when called)
    parser = cvc5.InputParser(s, sm)
    parser.setStringInput(cvc5.InputLanguage.SMT_LIB_2_6, script, name)
    answers: list[str] = []
    proof_parts: list[str] = []
    while True:
        cmd = parser.nextCommand()
        if cmd.isNull():
            return answers, proof_parts
        out = str(cmd.invoke(s, sm) or "").strip()
        if out.startswith("(error"):
            raise _ScriptError(out)
        if out.split(" ", 1)[0] in ("sat", "unsat", "unknown"):
            answers.append(out)
            if out == "unsat" and proofs:
                proof_parts.append("\n".join(_text(s.proofToString(p)) for p in s.getProof()))


def _text(b: bytes | str) -> str:
    return b.decode("utf-8", "replace") if isinstance(b, bytes) else b
