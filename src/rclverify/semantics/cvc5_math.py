"""cvc5's second opinion on a query Z3 left undecided through ``sin``/``cos``/``sqrt``.

Z3 reads RCL's mathematical functions as uninterpreted functions with true
facts (:mod:`.mathfacts`); where its model is not confirmed the verdict is
``inconclusive``.  cvc5 decides the real ``sin``, ``cos`` and ``sqrt`` of its
transcendental extension (incremental linearisation: Cimatti, Griggio,
Irfan, Roveri, Sebastiani, "Incremental Linearization for Satisfiability
and Verification Modulo Nonlinear Arithmetic and Transcendental Functions",
ACM TOCL 2018), whose ``unsat`` is sound.  :func:`refutes_negation` gives it
the same query (its SMT-LIB2 text, ``rcl.sin`` read as cvc5's ``sin``, and so
on) under a deterministic resource limit, :data:`RLIMIT`; only ``unsat`` is
taken (the goal is proved).  A ``sat`` of cvc5 over transcendental
functions is not taken as a refutation: the verdict stays ``inconclusive``.
(cvc5 is also the project's second solver, docs/second-solver.md, which
re-checks Z3's own answers on the same text with the functions
uninterpreted.)
"""
from __future__ import annotations

import re

#: cvc5's resource limit for one query (its ``rlimit-per``: deterministic, independent of the machine's load;
#: under a second on one loaded core for the queries of tests/semantics/test_math_functions.py)
RLIMIT = 20_000

_DECL = re.compile(r"\(declare-fun rcl\.(sqrt|sin|cos) \(Real\) Real\)\n?")
_USE = re.compile(r"\brcl\.(sqrt|sin|cos)\b")


def cvc5_text(smt2: str) -> str:
    """Z3's SMT-LIB2 ``smt2`` of a query as cvc5 reads it: logic ``ALL``,
    ``rcl.sin``/``rcl.cos``/``rcl.sqrt`` as cvc5's ``sin``/``cos``/``sqrt``."""
    body = _USE.sub(lambda m: m.group(1), _DECL.sub("", smt2))
    body = "\n".join(line for line in body.splitlines() if not line.startswith("(set-info"))
    return "(set-logic ALL)\n" + body


def refutes_negation(smt2: str) -> bool:
    """Whether cvc5 answers ``unsat`` to the query ``smt2`` (Z3's text of
    hypotheses and negated goal: the goal is proved) within :data:`RLIMIT`.
    ``False`` when cvc5 cannot read the text, answers otherwise or runs
    out.  Never raises."""
    import cvc5  # deferred: start-up (only a query Z3 left undecided through sin/cos)
    try:
        tm = cvc5.TermManager()
        s = cvc5.Solver(tm)
        s.setOption("rlimit-per", str(RLIMIT))
        parser = cvc5.InputParser(s)
        parser.setStringInput(cvc5.InputLanguage.SMT_LIB_2_6, cvc5_text(smt2), "query")
        symbols = parser.getSymbolManager()
        answers: list[str] = []
        while True:
            cmd = parser.nextCommand()
            if cmd.isNull():
                break
            out = str(cmd.invoke(s, symbols)).strip()
            if out:
                answers.append(out)
        return answers[-1:] == ["unsat"]
    except Exception:  # noqa: BLE001 - any trouble of the second opinion leaves the verdict as it was
        return False


__all__ = ["RLIMIT", "cvc5_text", "refutes_negation"]
