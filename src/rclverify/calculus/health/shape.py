"""Contract health, part two: what a guarantee actually constrains.

Three checks per node, each reported only when it finds something (a clean
contract adds no rows to the report):

``tautology`` (``problem``)
    a top-level conjunct of a guarantee that Z3 proves valid on its own:
    it holds whatever the inputs and outputs, so it promises nothing.
``constrains-no-output`` (``problem``)
    a guarantee that mentions no output of the node: it can only restate
    facts about the inputs, never what the node produces (a guarantee is
    about the node's outputs, paper lines 462-495).
``redundant`` (``warning``)
    a conjunct that Z3 proves from the node's assumption and the node's other
    guarantee conjuncts: it adds nothing (often a sign of a copy-paste slip).
    A conjunct of a timed guarantee (``within 20 ms``) is only shown
    redundant by guarantees as tight or tighter, and one of a triggered
    guarantee (``triggered by in.x``) only by guarantees of the same trigger
    (:func:`may_imply`): deleting it must lose no deadline and no trigger.

An output that no guarantee mentions is not reported here: the lint's
``W-unconstrained-output`` (lang/lint.py) is the one place that says it, so
the report does not say it twice (docs/decisions.md, "One finding, one
place").

Conjuncts are the top-level ``and`` operands of each guarantee (a guarantee
``forall(v | P -> Q1 and Q2)`` is one conjunct).  The validity queries run
with a short timeout; an undecided one reports nothing (these checks look
for defects, and never count as evidence that a contract is healthy).
``warning`` findings do not change any status; ``problem`` ones do, like the
other health problems (report/build.py).
"""
from __future__ import annotations

from typing import Sequence

import z3

from rclverify.calculus.compose import conjuncts, free_io
from rclverify.semantics.encode import Encoder
from rclverify.semantics.query import prove
from rclverify.semantics.retry import MBQI, has_quantifier, load_canonical, strategy_solver
from rclverify.semantics.wallclock import check
from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.timing import seconds
from rclverify.lang.types import Checked, CheckedNode
from rclverify.calculus.health.finding import Finding
from rclverify.calculus.health.shared import SharedEncoder, Table

SHAPE_TIMEOUT_MS = 2_000
#: Budget (Z3 resource steps) of the counterexample looked for first (:func:`_falsified`): the case
#: study's Agent's conjuncts take 2,000-10,000 steps there, where the default strategy spends its whole
#: :data:`SHAPE_TIMEOUT_MS` on the first one and decides nothing.
FALSIFY_RLIMIT = 50_000


def _where(l: ast.Loc) -> str:
    return f"{l.file}:{l.line}:{l.col}"


def outputs_mentioned(e: ast.Expr, cn: CheckedNode) -> set[str]:
    """Outputs of ``cn`` that ``e`` mentions (``out.x``, or a bare free ``x``
    that is an output and not an input of the node)."""
    return {n for p, n in free_io(e)
            if (p == "out" and n in cn.outputs) or (p is None and n in cn.outputs and n not in cn.inputs)}


def shape_findings(checked: Checked, node: str, *, timeout_ms: int = SHAPE_TIMEOUT_MS,
                   formulas: Table | None = None) -> list[Finding]:
    """The three checks above on ``node``; returns only the findings that
    found something, in guarantee order (``formulas``: the node's formulas
    already encoded by its other checks, :mod:`.shared`).  Never raises on
    solver trouble."""
    cn = checked.nodes[node]
    n = cn.node
    out: list[Finding] = []
    enc = Encoder(checked.env) if formulas is None else SharedEncoder(checked.env, formulas)
    parts: list[tuple[int, int, ast.Expr]] = [(k, j, c) for k, g in enumerate(n.guarantees, 1)
                                             for j, c in enumerate(conjuncts(g.formula), 1)]
    for k, g in enumerate(n.guarantees, 1):
        outs = outputs_mentioned(g.formula, cn)
        if not outs and n.outputs:
            out.append(Finding(f"{node}.g{k}.constrains-no-output", node, "constrains-no-output", k, "problem",
                               f"Guarantee {k} of {node} ({_where(g.loc)}) constrains no output: it mentions none of "
                               f"{', '.join(o.name for o in n.outputs)}.",
                               "A guarantee states what the node produces; this one only speaks about inputs (or "
                               "nothing), so an implementation meets it whatever it outputs."))
    # Each conjunct: is it implied by the assumption and the other conjuncts (redundant)?  Only
    # when it is can it be valid on its own (tautology), so the tautology query runs only then --
    # or when the first query is undecided, or there are no other conjuncts.  A counterexample
    # to the first query refutes validity too, so the findings are those of asking both
    # questions of every conjunct, with half the queries on a healthy contract (docs/scale.md).
    assume = [enc.formula(a.formula, cn) for a in n.assumes] if len(parts) > 1 else []
    implied: dict[tuple[int, int], Finding] = {}
    encoded: dict[tuple[int, int], z3.BoolRef] = {}  # each conjunct encoded once, when first needed

    def formula(kk: int, jj: int, x: ast.Expr) -> z3.BoolRef:
        if (kk, jj) not in encoded:
            encoded[(kk, jj)] = enc.formula(x, cn)
        return encoded[(kk, jj)]
    for k, j, c in parts:
        if isinstance(c, ast.BoolLit):
            continue
        if len(parts) > 1:
            others = [formula(kk, jj, x) for kk, jj, x in parts
                      if (kk, jj) != (k, j) and may_imply(n.guarantees[kk - 1], n.guarantees[k - 1])]
            goal = formula(k, j, c)
            if _falsified(assume + others, goal, enc):
                continue  # neither implied by the rest nor valid: what both queries would find (_falsified)
            r = prove(goal, assume + others, enc, timeout_ms=timeout_ms, models=False,
                      comment=f"health {node}: is conjunct {j} of guarantee {k} implied by the others?")
            if r.status == "refuted":
                continue  # not valid on its own either: its counterexample falsifies the conjunct
            if r.status == "proved":
                implied[(k, j)] = Finding(f"{node}.g{k}.c{j}.redundant", node, "redundant", k, "warning",
                                          f"Conjunct {j} of guarantee {k} of {node} ({_where(c.loc)}) is redundant: "
                                          "the assumption and the other guarantee conjuncts imply it.",
                                          f"`{expr_to_rcl(c)}` adds nothing to the contract; Z3 proved it from the "
                                          "rest.", duration_s=r.duration_s, smt2=r.smt2)
        elif _falsified([], formula(k, j, c), enc):
            continue  # not valid on its own (_falsified)
        valid = _tautology(enc, node, k, j, c, formula(k, j, c), timeout_ms)
        if valid is not None:
            implied.pop((k, j), None)  # a tautology is reported as that, not also as redundant
            out.append(valid)
    out += implied.values()
    return out


def may_imply(source: ast.Clause, target: ast.Clause) -> bool:
    """May a conjunct of guarantee ``source`` serve as a hypothesis showing a
    conjunct of guarantee ``target`` redundant?  Only when deleting the
    target loses nothing the source does not promise too: the same trigger
    (``triggered by in.x`` answers one input, and a guarantee on every
    message is not one on the responses to ``x``, nor the other way round),
    and, when the target has a deadline (``within 20 ms``), a source whose
    deadline is as tight or tighter (an untimed guarantee never implies a
    timed one: deleting the timed one would lose the deadline).  A deadline
    whose length cannot be read counts as no deadline on the source and as
    the tightest one on the target (the analysis then says nothing).
    Rule: docs/rcl-language.md, "Services, actions and deadlines"."""
    st, tt = source.trigger, target.trigger
    if (st is None) != (tt is None) or (st is not None and tt is not None and st.name != tt.name):
        return False
    if target.deadline is None:
        return True
    need = seconds(target.deadline)
    have = seconds(source.deadline) if source.deadline is not None else None
    return need is not None and have is not None and have <= need


def _tautology(enc: Encoder, node: str, k: int, j: int, c: ast.Expr, goal: z3.BoolRef,
               timeout_ms: int) -> Finding | None:
    """The ``tautology`` finding of conjunct ``j`` of guarantee ``k`` (``c``,
    encoded as ``goal``) when Z3 proves it valid with no hypothesis, else ``None``."""
    r = prove(goal, [], enc, timeout_ms=timeout_ms, models=False,
              comment=f"health {node}: is conjunct {j} of guarantee {k} valid on its own?")
    if r.status != "proved":
        return None
    return Finding(f"{node}.g{k}.c{j}.tautology", node, "tautology", k, "problem",
                   f"Conjunct {j} of guarantee {k} of {node} ({_where(c.loc)}) is always true: "
                   f"`{expr_to_rcl(c)}` holds whatever the inputs and outputs.",
                   "Z3 proved it valid with no hypothesis: it promises nothing. Check it says what was "
                   "meant (a comparison of a value with itself, a premise that is always false, ...).",
                   duration_s=r.duration_s, smt2=r.smt2)


def _falsified(hyps: Sequence[z3.BoolRef], goal: z3.BoolRef, enc: Encoder) -> bool:
    """Do ``hyps``, ``enc``'s axioms and ``not goal`` (the formulas
    :func:`~rclverify.semantics.query.prove` asserts to ask whether ``hyps``
    imply ``goal``) have a model, found by model-based quantifier
    instantiation (:data:`rclverify.semantics.retry.MBQI`, in a fresh
    context from the query's canonical text, so its answer depends on the
    query alone) within :data:`FALSIFY_RLIMIT` steps?  Asked, before the
    query itself, only of a quantified query: a quantifier-free one the
    default strategy decides at once.

    ``True`` decides the check the way the queries would: a model refutes
    the implication, so the redundancy query cannot answer ``proved`` (Z3 is
    sound), and it falsifies the conjunct alone with the axioms, so the
    tautology query cannot either; neither records anything then
    (:func:`shape_findings` reports only what is proved).  ``False`` (no
    model within the budget) says nothing: the queries are asked as without
    it.  On the case study's Agent the first redundancy query spends its
    whole budget before a retry refutes it (1.3 CPU s); this answers in a
    few thousand steps."""
    axioms = enc.axioms()
    if not any(has_quantifier(f) for f in [*hyps, goal, *axioms]):
        return False
    formulas = [*hyps, *axioms, z3.Not(goal)]
    s, rewrite = strategy_solver(MBQI)
    s.set("rlimit", FALSIFY_RLIMIT)
    load_canonical(s, [rewrite(f) for f in formulas])
    return bool(check(s) == z3.sat)
