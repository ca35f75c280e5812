"""A cone summary's two Z3 steps, from SMT-LIB text alone (calculus/summary.py).

:func:`eliminate`: ``exists hidden. and(bodies)`` without the quantifier
(Z3's ``qe2``, model-based projection, then ``qe``: Loos-Weispfenning /
Fourier-Motzkin for the reals, Cooper for the integers, exact for linear
arithmetic).  :func:`implied`: Z3's proof that a formula is implied by the
premises it was made from, with the labels of the premises its unsat core
used.  Both run in the Z3 context the caller gives (a fresh one of the
summary's own, so the text made depends on nothing the process did before),
each bounded by :data:`QE_MS` (Z3's steps decide; the clock is a net).
"""
from __future__ import annotations

import re
from typing import Mapping, Sequence

import z3

from rclverify.targets.smtlib import quote
from rclverify.semantics import wallclock
from rclverify.semantics.connectives import conj
from rclverify.semantics.retry import has_quantifier

#: Budget of each quantifier elimination and each check of a summary (milliseconds).
QE_MS = 2_000


def eliminate(ctx: z3.Context, decls: str, bodies: Sequence[str], hidden: Sequence[str],
               sorts: Mapping[str, str] | None = None) -> str | None:
    """``exists hidden. and(bodies)`` without the quantifier, as SMT-LIB
    text (Z3 context ``ctx``); ``None`` when ``qe`` leaves a quantifier or
    gives up.  ``sorts``: each name's SMT-LIB sort (``Real``, ``Int``,
    ``Bool``), so the names the bodies mention are bound without walking
    the parsed formula (:func:`_bound`)."""
    fs = z3.parse_smt2_string(decls + "".join(f"(assert {b})\n" for b in bodies), ctx=ctx)
    body = conj(*fs) if len(fs) else z3.BoolVal(True, ctx)
    if hidden:
        xs = _bound(ctx, fs, bodies, hidden, sorts)
        if xs:
            body = z3.Exists(xs, body)
    for qe in ("qe2", "qe"):  # model-based projection first: a clean conjunction, and faster (docs/calculus.md)
        g = z3.Goal(ctx=ctx)
        g.add(body)
        try:
            out = z3.TryFor(z3.Then("simplify", qe, "simplify", ctx=ctx), QE_MS, ctx=ctx)(g).as_expr()
        except z3.Z3Exception:
            continue
        if not has_quantifier(out):
            return " ".join(out.sexpr().split())  # one line: the scripts quote it in a comment
    return None


#: The Z3 sort of each SMT-LIB sort name of :data:`rclverify.targets.smtlib.SORTS`.
_Z3_SORTS = {"Real": z3.RealSort, "Int": z3.IntSort, "Bool": z3.BoolSort}


def _bound(ctx: z3.Context, fs: Sequence[z3.ExprRef], bodies: Sequence[str], hidden: Sequence[str],
           sorts: Mapping[str, str] | None) -> list[z3.ExprRef]:
    """The constants of ``hidden`` that ``bodies`` mention, in ``hidden``'s
    order: read off the text's tokens when every name is a simple SMT-LIB
    symbol of a sort in ``sorts`` (the same constants Z3 parsed: a constant
    is its name and sort), else found by walking the parsed ``fs`` (walking
    the terms through Z3's Python objects was a tenth of a summary)."""
    if sorts is not None and all(sorts.get(h) in _Z3_SORTS and not any(c in h for c in " \t\n()|") for h in hidden):
        # a name is one token, bare (as Z3 prints it in a summary) or quoted (as targets/smtlib.py writes it)
        tokens = set(_TOKEN.findall(" ".join(bodies)))
        return [z3.Const(h, _Z3_SORTS[sorts[h]](ctx)) for h in hidden if h in tokens or quote(h) in tokens]
    consts = {str(c): c for f in fs for c in _constants(f)}
    return [consts[h] for h in hidden if h in consts]


#: An SMT-LIB2 token that is not a parenthesis: a simple symbol, numeral or keyword.
_TOKEN = re.compile(r"[^\s()]+")


def _constants(f: z3.ExprRef) -> list[z3.ExprRef]:
    out, todo, seen = [], [f], set()
    while todo:
        x = todo.pop()
        if x.get_id() in seen:
            continue
        seen.add(x.get_id())
        if z3.is_const(x) and x.decl().kind() == z3.Z3_OP_UNINTERPRETED:
            out.append(x)
        elif z3.is_app(x):
            todo.extend(x.children())
    return out


def implied(ctx: z3.Context, decls: str, premises: Sequence[tuple[str, str]], axioms: Sequence[str],
             formula: str) -> list[str] | None:
    """The labels of ``premises`` an unsat core of ``premises and axioms
    and not formula`` uses (Z3 context ``ctx``), or ``None`` unless Z3
    answers unsat."""
    lits = "".join(f"(declare-fun |s!{k}| () Bool)\n" for k in range(len(premises)))
    text = (decls + lits + "".join(f"(assert (=> |s!{k}| {b}))\n" for k, (_, b) in enumerate(premises))
            + "".join(f"(assert {a})\n" for a in axioms) + f"(assert (not {formula}))\n")
    s = z3.Solver(ctx=ctx)
    wallclock.limit(s, QE_MS)  # steps decide, the clock is a net
    s.set("unsat_core", True)
    s.add(z3.parse_smt2_string(text, ctx=ctx))
    lit = [z3.Bool(f"s!{k}", ctx) for k in range(len(premises))]
    if s.check(*lit) != z3.unsat:
        return None
    core = {str(c) for c in s.unsat_core()}
    return [label for k, (label, _) in enumerate(premises) if f"s!{k}" in core]
