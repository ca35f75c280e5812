"""Contract health, realizability decided by a witness: an implementation's
outputs (docs/semantics.md, "Realizability over bounded output sequences").

A contract ``(A, G)`` is realizable when some output answers every input the
assumption admits (:mod:`.realizable`).  An implementation whose outputs are
the terms ``w(in)`` (one RCL term over the inputs per output: what a
straight-line node computes, the outputs of a proved implementation) is such
an answer (so is an answer of a simple shape for outputs that are all
sequences, :func:`rclverify.calculus.health.realizable._sequence_answers`)
when the quantifier-free-over-the-outputs query

    A(in) and F_in(in) and not (typing(w(in)) and fits(w(in)) and F_out(in, w(in)) and G(in, w(in)))

is unsat (``typing``: every NATURAL part of each term ``>= 0``, a
sequence's items by a quantifier over its positions,
:func:`natural_typing`; ``fits``: a sequence the interface bounds
(:class:`.bounded.Bound`) has a length its field carries).  The terms are
then an instance of the realizability statement's ``exists out``, and the
finding is ``ok``, decided by the witness: the record keeps the terms
(``witness``) and this query (``witness_smt2``), which has no quantifier
over the outputs, so the second solver decides it where the quantified
query over a sequence left cvc5 ``unknown``.  Terms that do not answer
(``sat``), or that Z3 cannot decide within the budget, decide nothing.
"""
from __future__ import annotations

import time
from typing import Mapping, Sequence

import z3

from rclverify.calculus.health.bounded import Bound
from rclverify.calculus.health.finding import Finding
from rclverify.calculus.health.shape import outputs_mentioned
from rclverify.lang import ast
from rclverify.lang.types import CheckedNode, Type
from rclverify.semantics.connectives import conj
from rclverify.semantics.encode import Encoder
from rclverify.semantics.natural import natural_typing
from rclverify.semantics.query import satisfiable
from rclverify.lang.printer import expr_to_rcl

#: Budget of the witness query (milliseconds' worth of Z3 resource steps).
WITNESS_MS = 2_000


def implemented(enc: Encoder, cn: CheckedNode, outs: Sequence[tuple[str, z3.ExprRef, Type]],
                given: Sequence[z3.BoolRef], body: Sequence[z3.BoolRef], terms: Mapping[str, ast.Expr],
                bounds: Mapping[str, Bound], with_facts: bool, source: str = "the implementation") -> Finding | None:
    """The ``ok`` realizability finding of node ``cn`` decided by the witness
    ``terms`` (output name -> RCL term over the inputs), or ``None`` when
    they do not answer every admissible input, are not decided, leave an
    output out or mention an output.  ``outs``: ``(name, Z3 constant,
    type)`` of the constrained outputs; ``given``: the formulas over the
    inputs; ``body``: the facts over outputs and the guarantees, over the
    output constants; ``with_facts``: the plan states environment facts
    (the message says so); ``source`` names where the terms come from in
    the message (``the implementation``, ``the answer``)."""
    if any(v not in terms or outputs_mentioned(terms[v], cn) for v, _, _ in outs):
        return None
    t0 = time.perf_counter()
    try:
        ws = [(o, enc.term(terms[v], cn)) for v, o, _ in outs]
    except Exception:  # noqa: BLE001 - a term the encoder refuses (ill-typed for its output): no witness
        return None
    fits: list[z3.BoolRef] = []
    for (v, _, t), (_, w) in zip(outs, ws):
        cs, exact = natural_typing(w, t, quantified=True)
        if not exact:
            return None
        fits += cs
        if v in bounds:
            b = bounds[v]
            fits.append(z3.Length(w) == b.max_len if b.fixed else z3.Length(w) <= b.max_len)
    answered = z3.substitute(conj(*fits, *body) if len(fits) + len(body) > 1 else (fits + list(body))[0], *ws)
    comment = f"health {cn.name}: does the implementation's output leave an admissible input unanswered? (unsat: " \
              "it answers every one)"
    r = satisfiable([*((f"given {k + 1}", g) for k, g in enumerate(given)), ("not answered", z3.Not(answered))],
                    enc, timeout_ms=WITNESS_MS, comment=comment, retry=False)
    if r.status != "unsat":
        return None
    text = ", ".join(f"out.{v} = {expr_to_rcl(terms[v])}" for v, _, _ in outs)
    admits = " and the environment facts admit" if with_facts else " admits"
    return Finding(f"{cn.name}.realizable", cn.name, "realizable", None, "ok",
                   f"The contract of {cn.name} can be implemented: every input its assumption{admits} has an output "
                   f"satisfying every guarantee. Decided by a witness: {source} {text} answers every one "
                   "of them (Z3 checked it: the witness query is unsat).",
                   "Realizability (forall in. A(in) -> exists out. G(in, out)) follows from the implementation's "
                   f"outputs ({source}), an instance of exists out that Z3 proved answers every admissible input"
                   + ("".join(f"; out.{v} fits its interface ({b.text()})" for v, b in bounds.items()
                              if any(v == name for name, _, _ in outs)))
                   + ". The witness query below has no quantifier over the outputs.",
                   None, None, round(time.perf_counter() - t0, 4), smt2=r.smt2,
                   witness={f"out.{v}": expr_to_rcl(terms[v]) for v, _, _ in outs}, witness_smt2=r.smt2)


__all__ = ["WITNESS_MS", "implemented"]
