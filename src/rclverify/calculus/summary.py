"""Cone summaries: a side condition decided in context without re-reading the cone.

The in-context check (:mod:`.context`; docs/calculus.md, "Side conditions
in context") decides a conjunct of node ``n``'s assumption against the
premises ``P(n)`` of ``n``'s whole upstream cone.  Along a chain of N nodes
the cones add up to N*N/2 contracts.  Rule R1's derived
property (paper lines 564-590) is what a node's cone establishes about its
outputs; here it is made exact and finite: the **summary** of node ``m`` is

    ``S_m = exists (the cone's other values). P(cone m)``

projected onto ``I(m)``, the outputs of ``cone(m)`` that a node outside it
reads.  It is built from the summaries of ``m``'s producers, never from the
whole cone: ``S_m`` is Z3's quantifier elimination (``qe``:
Loos-Weispfenning / Fourier-Motzkin for the reals, Cooper for the integers,
exact for linear arithmetic) of the producers' summaries and ``m``'s own
premises (each guarantee under ``m``'s assumption, the environment
conjuncts of its assumption, its plan facts).  Then ``P(n) |= c`` iff
``S_p1 and ... and S_pk and local(n) |= c`` for ``n``'s producers whose
cones contain the others' (*maximal* producers), when those cones are
pairwise disjoint: the values the projections hide are then independent.

Soundness first:

* a summary is used only once Z3 proved it implied by what it was built
  from (:attr:`Summary.script`, unsat: the premises and ``not S_m``):
  never stronger than its cone, whatever ``qe`` returned;
* a node gets no summary (and nothing downstream of it one) when its cone
  has a loop (rule R4 opens loops per consumer, lines 741-743), its
  maximal producers' cones overlap (a reconverging join: the projection
  would forget that the two branches share a value), a formula leaves
  :mod:`rclverify.targets.smtlib`'s fragment, or ``qe`` fails within its budget;
* :func:`decide` answers only ``proved``, and only when the query over the
  summaries is unsat *and* its premises are satisfiable (exact summaries:
  then so is ``P(n)``, and the full cone's verdict is ``proved`` too).
  Anything else (a counterexample, unknown, contradictory premises) is
  ``None``: the caller decides over the full cone as before, so a
  counterexample is the whole cone's, traced back to its sources.

The premises a proof rests on are named as before: each summary keeps the
premises of its cone that Z3's unsat core used to establish it
(:attr:`Summary.used`), and a proof's ``used`` is its own core with each
summary replaced by those.  Everything kept is text (no Z3 object), made in
a Z3 context of its own from text alone, so it is the same whichever node
task of whichever process made it (incremental equals clean); a summary is
also kept as a file keyed by that text (:func:`use_directory`), which the
other doit worker and later runs read instead of making it again: the
proof that it is implied was made when it was, by this code and this Z3.  The query
over the summaries (:func:`decide`) is a scope of the caller's solver
session (one node's calculus, asked in a fixed order), not a context of
its own: a context cost as much as the query.  A summary is made and kept
by :mod:`.summary_store`.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Callable, Mapping, Sequence, TypedDict

import z3

from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.types import NATURAL, Checked
from rclverify.semantics.query import query_solver
from rclverify.model.system.model import SystemModel
from rclverify.calculus.cone_paths import multi_path, single_paths
from rclverify.calculus.context import NEGATED, ContextResult
from rclverify.calculus.premises import node_premises
from rclverify.targets.smtlib import SORTS, quote, to_smt
from rclverify.calculus.summary_store import (MadeFrom, Summary, forget_texts, kept_summary, summary_key,
                                              use_directory as use_directory)


class _Memo(TypedDict):
    """The summaries of the last system: ``key`` its (checked, model, facts as text),
    ``summaries`` and the ``keys`` of their stored texts by node."""

    key: tuple[Checked, SystemModel, tuple[tuple[str, tuple[str, ...]], ...]] | None
    summaries: dict[str, Summary | None]
    keys: dict[str, bytes]


_MEMO: _Memo = {"key": None, "summaries": {}, "keys": {}}


def _memo(checked: Checked, model: SystemModel, facts: Mapping[str, Sequence[ast.Expr]]) -> dict[str, Summary | None]:
    """The summaries of the last (checked, model, facts) (summaries are
    data: nothing of Z3 is kept)."""
    fp = tuple((n, tuple(expr_to_rcl(f) for f in fs)) for n, fs in sorted(facts.items()))
    key = _MEMO["key"]
    if key is None or key[0] is not checked or key[1] is not model or key[2] != fp:
        _MEMO["key"], _MEMO["summaries"], _MEMO["keys"] = (checked, model, fp), {}, {}
        forget_texts()  # the texts held in memory are the last system's (the files stay)
    return _MEMO["summaries"]


def _maximal(model: SystemModel, producers: Sequence[str]) -> list[str] | None:
    """The producers whose cone holds no other producer's, or ``None``
    when two of their cones overlap (the summaries would not be exact)."""
    masks = model.upstream_masks()
    top = [p for p in producers if not any(q != p and masks[p] & ~masks[q] == 0 for q in producers)]
    for i, p in enumerate(top):
        for q in top[i + 1:]:
            if masks[p] & masks[q]:
                return None
    return top


def _symbols(checked: Checked, model: SystemModel, m: str) -> dict[tuple[str, str], str]:
    cn = checked.nodes[m]
    alias = model.alias()
    return {(p, v): alias.get((m, p, v), f"{m}.{p}.{v}") for p, table in (("in", cn.inputs), ("out", cn.outputs))
            for v in table}


def _naturals(checked: Checked, m: str, symbol: Mapping[tuple[str, str], str]) -> list[str]:
    """``(>= x 0)`` for each NATURAL input and output of ``m`` (the encoder's axiom)."""
    cn = checked.nodes[m]
    return [f"(>= {quote(symbol[(p, v)])} 0)" for p, table in (("in", cn.inputs), ("out", cn.outputs))
            for v, t in table.items() if t == NATURAL and (p, v) in symbol]


def summary_of(checked: Checked, model: SystemModel, node: str,
               environment: Callable[[str], Sequence[ast.Expr]],
               facts: Mapping[str, Sequence[ast.Expr]] | None = None) -> Summary | None:
    """The :class:`Summary` of ``node``'s upstream cone (rule R1's derived
    property made exact, paper lines 564-590; module docstring), or
    ``None`` when it has none.  ``checked``/``model``: the system;
    ``environment(m)``: the environment conjuncts of ``m``'s assumption
    (:func:`.compose.environment_conjuncts`); ``facts``: the plan's facts
    per node (RCL formulas over its I/O).  Computed producers first, each
    once per (checked, model, facts) and process.  Never raises on solver
    trouble (``None``); a ``KeyError`` for a node not in ``model``."""
    facts = facts or {}
    memo = _memo(checked, model, facts)
    if node in memo:
        return memo[node]
    order: list[str] = []  # the cone's nodes without a summary yet, producers first (post-order)
    stack, seen = [(node, iter(model.producers(node)))], {node}
    while stack:
        v, it = stack[-1]
        for p in it:
            if p not in seen and p not in memo:
                seen.add(p)
                stack.append((p, iter(model.producers(p))))
                break
        else:
            stack.pop()
            order.append(v)
    for m in order:
        memo[m] = _build(checked, model, m, environment, facts, memo, _MEMO["keys"])
    return memo[node]


def _build(checked: Checked, model: SystemModel, m: str, environment: Callable[[str], Sequence[ast.Expr]],
           facts: Mapping[str, Sequence[ast.Expr]], memo: Mapping[str, Summary | None],
           keys: dict[str, bytes]) -> Summary | None:
    if model.loop_of(m):
        return None
    producers = model.producers(m)
    top = _maximal(model, producers)
    if top is None or any(memo.get(p) is None for p in producers):
        return None
    symbol = _symbols(checked, model, m)
    d = node_premises(checked, model, m, False, environment(m), facts.get(m, ()), symbol)
    if not d.smt:
        return None
    index = {n: i for i, n in enumerate(model.nodes)}
    # I(m): outputs of the cone read by a node outside it
    masks, bit = model.upstream_masks(), {n: 1 << i for i, n in enumerate(model.nodes)}
    outside = ~masks[m]
    keep: dict[str, str] = {}
    for p in top:
        for name, sort in memo[p].symbols:  # type: ignore[union-attr]
            keep[name] = sort
    sorts: dict[str, str] = dict(keep)
    cn = checked.nodes[m]
    for (p, v), name in symbol.items():
        t = (cn.inputs if p == "in" else cn.outputs)[v]
        if t not in SORTS:
            return None
        sorts[name] = SORTS[t]
        if p == "out":
            keep[name] = SORTS[t]
    kept = {}
    for name, sort in keep.items():  # an output symbol is named <node>.out.<var> (model.alias)
        u, prefix, var = name.split(".", 2)
        if prefix == "out" and any(bit[r] & outside for r in model.readers(u, var)):
            kept[name] = sort
    premises: list[tuple[str, str]] = [(f"{p} summary", memo[p].formula) for p in top]  # type: ignore[union-attr]
    for label, _, kind, _, term in d.items:
        body = f"(=> {d.assumption} {term})" if kind == "guarantee" and d.assumption is not None else term
        premises.append((label, body or "true"))
    axioms = _naturals(checked, m, symbol)
    decls = "".join(f"(declare-fun {quote(n)} () {s})\n" for n, s in sorted(sorts.items()))
    own = {label: (text, k) for k, (label, text, _, _, _) in enumerate(d.items)}
    made = MadeFrom(m, index[m], tuple(top), decls, tuple(premises), tuple(axioms), tuple(sorted(kept.items())),
                 tuple(sorted(sorts.items())), tuple(own.items()), tuple(keys[p] for p in top))
    keys[m] = summary_key(made)
    return kept_summary(made, keys[m], memo)


def decide(checked: Checked, model: SystemModel, node: str, conjunct: ast.Expr,
           environment: Callable[[str], Sequence[ast.Expr]],
           facts: Mapping[str, Sequence[ast.Expr]] | None, comment: str, timeout_ms: int) -> ContextResult | None:
    """The in-context verdict of ``conjunct`` (an internal conjunct of
    ``node``'s assumption, the premise of R1-R3, paper lines 564-690) from
    the summaries of ``node``'s maximal producers and ``node``'s own
    environment conjuncts and facts (arguments as :func:`summary_of`;
    ``comment`` heads the script, ``timeout_ms`` budgets each check).
    Returns a ``proved`` :class:`.ContextResult` (``used``: ``"label: RCL
    text"`` of the cone's premises it rests on, in cone order;
    ``summaries``: the producers whose summaries it read; ``smt2``: the
    query over the summaries), or ``None``: decide over the whole cone
    (module docstring).  Never raises on solver trouble."""
    facts = facts or {}
    q = _summary_query(checked, model, node, conjunct, environment, facts)
    if q is None:
        return None
    t0 = time.perf_counter()
    core = _solve(q, timeout_ms)
    if core is None:
        return None
    dt = round(time.perf_counter() - t0, 4)
    used = _core_premises(checked, model, node, environment, facts, q, core)
    node_of = {u[0]: model.nodes[u[2][0]] for u in used}
    nodes = tuple(dict.fromkeys(node_of[u[0]] for u in used if " guarantee " in u[0]))
    joins = (multi_path(model, node, model.upstream(node), set())
             if (q.joined or nodes) and not single_paths(model, node) else set())
    header = "".join(f"; {line}\n" for line in comment.splitlines())
    script = (header + f"; premises: the summaries of the cones of {', '.join(q.top)} (each proved implied by its "
              "cone by Z3 when made: calculus/summary.py) and the consumer's environment assumptions and facts\n"
              + q.decls + "".join(f"; {label}\n(assert {b})\n" for label, b in q.premises)
              + "".join(f"(assert {a})\n" for a in q.axioms) + f"; {NEGATED}\n(assert (not {q.goal}))\n(check-sat)\n")
    return ContextResult("proved", script, dt, used=tuple(f"{u[0]}: {u[1]}" for u in used), used_nodes=nodes,
                         joins=tuple(n for n in nodes if n in joins), summaries=tuple(q.top))


@dataclass(frozen=True)
class _Query:
    """The query of :func:`decide` as SMT-LIB text: ``top`` the maximal
    producers, ``joined`` whether the node has several producers,
    ``decls`` the declarations, ``premises`` ``(label, formula)`` (the
    summaries first, then the node's own premises), ``own`` label to
    ``(RCL text, index among the node's premises)``, ``axioms`` the
    naturals' bounds, ``goal`` the conjunct."""

    top: list[str]
    joined: bool
    decls: str
    premises: list[tuple[str, str]]
    own: dict[str, tuple[str, int]]
    axioms: list[str]
    goal: str


def _summary_query(checked: Checked, model: SystemModel, node: str, conjunct: ast.Expr,
                   environment: Callable[[str], Sequence[ast.Expr]],
                   facts: Mapping[str, Sequence[ast.Expr]]) -> _Query | None:
    """The query of :func:`decide` over the summaries of ``node``'s
    maximal producers (arguments as there), or ``None`` when no summary
    query applies (a loop, no producers, a missing summary, a formula or
    sort outside the fragment)."""
    if model.loop_of(node):
        return None
    producers = model.producers(node)
    top = _maximal(model, producers)
    if not producers or top is None:
        return None
    sums = [summary_of(checked, model, p, environment, facts) for p in top]
    if any(s is None for s in sums):
        return None
    symbol = _symbols(checked, model, node)
    d = node_premises(checked, model, node, True, environment(node), facts.get(node, ()), symbol)
    used_syms: dict[str, str] = {}
    goal = to_smt(conjunct, checked.nodes[node], symbol, used_syms)
    if not d.smt or goal is None:
        return None
    sorts: dict[str, str] = {n: s for sm in sums for n, s in sm.symbols}  # type: ignore[union-attr]
    cn = checked.nodes[node]
    for (p, v), name in symbol.items():
        t = (cn.inputs if p == "in" else cn.outputs)[v]
        if t not in SORTS:
            return None
        sorts[name] = SORTS[t]
    premises = [(f"{p} summary", sm.formula) for p, sm in zip(top, sums)]  # type: ignore[union-attr]
    premises += [(label, t or "true") for label, _, _, _, t in d.items]
    decls = "".join(f"(declare-fun {quote(n)} () {s})\n" for n, s in sorted(sorts.items()))
    own = {label: (text_, k) for k, (label, text_, _, _, _) in enumerate(d.items)}
    return _Query(top, len(producers) > 1, decls, premises, own, _naturals(checked, node, symbol), goal)


def _solve(q: _Query, timeout_ms: int) -> set[str] | None:
    """The unsat core (literal names ``l!k``) of ``q``'s premises and the
    negated goal, or ``None`` unless the query is unsat with the goal
    needed and the premises alone satisfiable (``timeout_ms`` per check)."""
    n = len(q.premises)
    lits = "".join(f"(declare-fun |l!{k}| () Bool)\n" for k in range(n + 1))
    text = (q.decls + lits + "".join(f"(assert (=> |l!{k}| {b}))\n" for k, (_, b) in enumerate(q.premises))
            + "".join(f"(assert {a})\n" for a in q.axioms) + f"(assert (=> |l!{n}| (not {q.goal})))\n")
    try:
        # a scope of the caller's solver session (one node's calculus, semantics/query.py): its queries follow
        # from the stage's inputs alone, in a fixed order, so a failure then decided over the whole cone
        # gets the same model in every run; a fresh Z3 context here cost as much as the query (docs/scale.md)
        with query_solver(timeout_ms, cores=True) as s:
            s.add(z3.parse_smt2_string(text))
            lit = [z3.Bool(f"l!{k}") for k in range(n + 1)]
            if s.check(*lit) != z3.unsat:
                return None  # a counterexample or unknown: the full cone decides (and traces the counterexample)
            core = {str(c) for c in s.unsat_core()}
            if f"l!{n}" not in core or s.check(*lit[:-1]) != z3.sat:
                return None  # premises that may contradict each other: the full cone says what they prove
    except z3.Z3Exception:
        return None
    return core


def _core_premises(checked: Checked, model: SystemModel, node: str,
                   environment: Callable[[str], Sequence[ast.Expr]], facts: Mapping[str, Sequence[ast.Expr]],
                   q: _Query, core: set[str]) -> list[tuple[str, str, tuple[int, int]]]:
    """The cone's premises ``core`` rests on, each ``(label, RCL text,
    (node index, premise index))`` in cone order: a summary in the core
    stands for the premises its own proof used."""
    index = {n: i for i, n in enumerate(model.nodes)}
    out: dict[str, tuple[str, str, tuple[int, int]]] = {}
    for k, (label, _) in enumerate(q.premises):
        if f"l!{k}" not in core:
            continue
        if label.endswith(" summary"):
            for u in summary_of(checked, model, label[:-len(" summary")], environment, facts).used:  # type: ignore[union-attr]
                out[u[0]] = u
        else:
            out[label] = (label, q.own[label][0], (index[node], q.own[label][1]))
    return sorted(out.values(), key=lambda u: u[2])
