"""Side conditions in context: a side condition that fails locally, tried
again with its upstream cone (docs/calculus.md, "Side conditions in context").

The premise of rules R1-R3 (paper lines 556-690) relates a consumer's
assumption to its *producers'* guarantees only.  A chain whose node ``i``
assumes ``0 <= x_i <= 100`` and guarantees ``x_{i+1} <= x_i + 1`` fails
that premise at every link (``x_i = 100`` allows ``x_{i+1} = 101``),
although in context (``0 <= x0 <= 50`` gives ``x_i <= 50 + i``) every
assumption holds: a correct design shown as a wall of failures.  This module
decides the conjunct against the whole upstream cone instead.

The premises (each labelled, so the unsat core names what the proof used):

* for every node ``m`` of the cone but the consumer itself, each guarantee
  ``k`` *under its own node's assumption*: ``A_m -> G_m,k`` (label
  ``m guarantee k``).  In the stream semantics (paper lines 462-495) a
  guarantee relates the output to the input only when the assumption held,
  so a guarantee taken transitively is usable only where the cone
  establishes its node's assumption in turn: the chain's inductive
  structure is left to Z3, and no premise is assumed that the cone does not
  establish;
* the environment conjuncts of the assumptions of every node of the cone,
  the consumer's own included (what the calculus leaves to the environment;
  ``m environment assumption k``);
* the plan's environment facts of every node of the cone
  (``m environment fact k``).

Loops (rule R4, paper lines 717-768): the cone of a node on a loop contains
the node's own output.  R4's derivation (lines 741-743) composes the loop's
nodes with R1-R3 along the loop *opened at one point*, and the paper assumes
no contract is used circularly (line 712).  Here the loop is opened at every
link a depth-first search from the consumer, over producer edges, meets
going back into its own search path (a back edge): that link's consumer
input becomes a fresh value of its own, not the producer's output, so no
guarantee is ever used to discharge its own premise (the graph minus its
back edges has no cycle) and the consumer's own guarantee is not a premise
at all.  The opened value is arbitrary: sound, but a counterexample may use
a value the loop never produces (the explanation says so; R4 offers no loop
invariant, lines 760-764).

Verdicts: ``proved`` (unsat; the core's premises are named), ``refuted``
(sat; the model of the whole cone, and the cone's nodes whose assumption it
violates: their guarantees promise nothing there), ``inconclusive``.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any, Callable, Mapping, Sequence

import z3

from ..logic.encode import Encoder
from ..logic.query import query_solver, render_model, satisfiable, smt2_script
from ..rcl import ast
from ..rcl.printer import expr_to_rcl
from ..rcl.types import Checked
from ..system.model import Link, SystemModel

NEGATED = "negated side condition"
#: Budget of the query that checks the premises of an in-context proof can hold together (milliseconds).
CONSISTENCY_TIMEOUT_MS = 2_000


@dataclass(frozen=True)
class ContextResult:
    """The in-context decision of one side condition.

    ``status``   ``proved`` / ``refuted`` / ``inconclusive``;
    ``used``     the premises of an unsat core as ``"label: RCL text"``
                 (proved), in cone order;
    ``used_nodes`` the nodes whose guarantees the proof used (proved);
    ``model``    the counterexample over the whole cone (refuted);
    ``violated`` the cone's nodes whose assumption the counterexample
                 violates (refuted; their guarantees promise nothing there);
    ``joins``    nodes of the cone read along more than one path that the
                 proof used (rests on R3's simplifying assumption, line 660);
    ``smt2``, ``duration_s`` (seconds), ``reason`` (Z3's, inconclusive),
    ``strategy`` (the retry that answered, if any).
    """

    status: str
    smt2: str
    duration_s: float
    used: tuple[str, ...] = ()
    used_nodes: tuple[str, ...] = ()
    model: dict[str, str] | None = None
    violated: tuple[str, ...] = ()
    joins: tuple[str, ...] = ()
    reason: str = ""
    strategy: str = ""


def opened_links(model: SystemModel, node: str) -> list[Link]:
    """The links at which the loops of ``node``'s upstream cone are opened:
    the back edges of a depth-first search from ``node`` over producer edges
    (links into a node, in link order), i.e. the links whose producer is on
    the search path to the link's consumer.  Without them the cone has no
    cycle (module docstring; rule R4, paper lines 717-768).  ``[]`` for a
    cone without a loop."""
    cut: list[Link] = []
    on_path = {node}
    done: set[str] = set()
    stack = [(node, iter(model.links_into(node)))]
    while stack:
        v, links = stack[-1]
        for l in links:
            p = l.from_node
            if p in on_path:
                cut.append(l)
                continue
            if p in done:
                continue
            on_path.add(p)
            stack.append((p, iter(model.links_into(p))))
            break
        else:
            stack.pop()
            on_path.discard(v)
            done.add(v)
    return cut


def link_text(l: Link) -> str:
    return f"{l.from_node}.out.{l.from_var} -> {l.to_node}.in.{l.to_var}"


def _multi_path(model: SystemModel, node: str, cone: Sequence[str], cut: set[tuple[str, str, str, str]]) -> set[str]:
    """Nodes of ``cone`` with more than one path to ``node`` over the links
    left after opening the loops (counts capped at 2)."""
    consumers: dict[str, list[str]] = {}
    members = set(cone)
    for n in cone:
        for l in model.links_into(n):
            if l.from_node in members and (l.from_node, l.from_var, l.to_node, l.to_var) not in cut:
                consumers.setdefault(l.from_node, []).append(n)
    paths: dict[str, int] = {node: 1}
    # the cone minus the opened links is acyclic: count paths in reverse topological order (consumers first)
    order: list[str] = []
    seen: set[str] = set()
    for root in cone:
        if root in seen:
            continue
        seen.add(root)
        stack = [(root, iter(consumers.get(root, ())))]
        while stack:
            v, it = stack[-1]
            for c in it:
                if c not in seen:
                    seen.add(c)
                    stack.append((c, iter(consumers.get(c, ()))))
                    break
            else:
                stack.pop()
                order.append(v)
    for v in order:  # post-order: every consumer of v is counted before v
        if v != node:
            paths[v] = min(2, sum(paths.get(c, 0) for c in consumers.get(v, ())))
    return {v for v, k in paths.items() if k > 1}


class ConeContext:
    """The upstream cone of one consumer as labelled Z3 premises, built once
    per node (its side conditions share it) and only when one of them fails
    locally.

    ``checked``/``model`` the system; ``node`` the consumer;
    ``environment(m)`` the environment conjuncts of node ``m``'s assumption
    (the calculus's own split, :func:`.compose.split_assumption`, passed in:
    this module sits below it); ``facts`` the plan's environment facts per
    node (RCL formulas over that node's I/O).
    """

    def __init__(self, checked: Checked, model: SystemModel, node: str,
                 environment: Callable[[str], Sequence[ast.Expr]],
                 facts: Mapping[str, Sequence[ast.Expr]] | None = None) -> None:
        self.node = node
        self.cone = model.upstream(node)
        cut = opened_links(model, node)
        self.cut = tuple(link_text(l) for l in cut)
        cut_keys = {(l.to_node, "in", l.to_var) for l in cut}
        alias = {k: v for k, v in model.alias().items() if k not in cut_keys} if cut else model.alias()
        self.enc = Encoder(checked.env, alias)
        self.checked = checked
        self.premises: list[tuple[str, z3.BoolRef]] = []
        self.text: dict[str, str] = {}
        self.assumption: dict[str, z3.BoolRef] = {}
        self.node_of: dict[str, str] = {}
        self.joins = _multi_path(model, node, self.cone, {(l.from_node, l.from_var, l.to_node, l.to_var) for l in cut})
        enc = self.enc
        for m in self.cone:
            cn = checked.nodes[m]
            if m != node:
                parts = [enc.formula(a.formula, cn) for a in cn.node.assumes
                         if not (isinstance(a.formula, ast.BoolLit) and a.formula.value)]
                a = z3.And(*parts) if len(parts) > 1 else parts[0] if parts else None
                if a is not None:
                    self.assumption[m] = a
                for k, g in enumerate(cn.node.guarantees, 1):
                    gf = enc.formula(g.formula, cn)
                    self._add(f"{m} guarantee {k}", m, z3.Implies(a, gf) if a is not None else gf,
                              expr_to_rcl(g.formula) + (" (under its assumption)" if a is not None else ""))
            for k, c in enumerate(environment(m), 1):
                self._add(f"{m} environment assumption {k}", m, enc.formula(c, cn), expr_to_rcl(c))
            for k, f in enumerate((facts or {}).get(m, ()), 1):
                self._add(f"{m} environment fact {k}", m, enc.formula(f, cn), expr_to_rcl(f))

    def _add(self, label: str, node: str, f: z3.BoolRef, text: str) -> None:
        self.premises.append((label, f))
        self.text[label] = text
        self.node_of[label] = node

    def decide(self, conjunct: ast.Expr, comment: str, timeout_ms: int) -> ContextResult:
        """Is ``conjunct`` (of the consumer's assumption) entailed by the
        cone's premises?  Never raises on solver trouble."""
        goal = self.enc.formula(conjunct, self.checked.nodes[self.node])
        labelled = self.premises + [(NEGATED, z3.Not(goal))]
        background = self.enc.axioms()
        script = smt2_script(background + [f for _, f in labelled], comment)
        t0 = time.perf_counter()
        core: list[str] | None = None
        with query_solver(timeout_ms, cores=True) as s:
            s.add(*background)
            for k, (_, f) in enumerate(labelled):
                s.assert_and_track(f, z3.Bool(f"__ctx_{k}"))
            r = s.check()
            dt = round(time.perf_counter() - t0, 4)
            if r == z3.unsat:
                found = {str(c) for c in s.unsat_core()}
                core = [lbl for k, (lbl, _) in enumerate(labelled) if f"__ctx_{k}" in found]
            elif r == z3.sat:
                m = s.model()
                violated = tuple(n for n, a in self.assumption.items()
                                 if z3.is_false(m.eval(a, model_completion=True)))
                return ContextResult("refuted", script(), dt, model=render_model(m, self.enc), violated=violated)
        if core is not None:  # after the query's scope is popped: the consistency query asks in a scope of its own
            return self._proved(core, script, dt)
        # unknown: the retries of logic/retry.py (fresh solvers), which answer without a Z3 model object
        rr = satisfiable(labelled, self.enc, timeout_ms=timeout_ms, comment=comment)
        dt = round(time.perf_counter() - t0, 4)
        if rr.status == "unsat":
            return self._proved(list(rr.core or []), script, dt, rr.strategy)
        if rr.status == "sat":
            return ContextResult("refuted", script(), dt, model=rr.model, strategy=rr.strategy)
        return ContextResult("inconclusive", script(), dt, reason=rr.reason or "unknown")

    def _proved(self, core: Sequence[str], script: Any, dt: float, strategy: str = "") -> ContextResult:
        """The unsat answer, believed only when the premises it used can hold
        together: a proof from contradictory premises (environment
        assumptions or facts that exclude each other) discharges nothing,
        so it is ``inconclusive`` with the reason (as a requirement proved
        from an inconsistency is not met, docs/requirements.md)."""
        used = [c for c in core if c != NEGATED]
        text = tuple(f"{c}: {self.text[c]}" for c in used)
        if NEGATED not in core:
            return ContextResult("inconclusive", script(), dt, used=text, strategy=strategy,
                                 reason="the premises of the cone contradict each other (unsat core: "
                                        + "; ".join(used) + "), so they entail anything")
        by_label = dict(self.premises)
        r = satisfiable([(c, by_label[c]) for c in used], self.enc, timeout_ms=CONSISTENCY_TIMEOUT_MS,
                        comment=f"side condition of {self.node} in context: can the premises its proof used hold together?")
        dt = round(dt + r.duration_s, 4)
        if r.status != "sat":
            why = ("contradict each other (unsat core: " + "; ".join(r.core or []) + ")" if r.status == "unsat"
                   else f"may contradict each other (Z3 could not decide: {r.reason or 'unknown'})")
            return ContextResult("inconclusive", script(), dt, used=text, strategy=strategy,
                                 reason=f"the premises the proof used {why}, so the proof establishes nothing")
        nodes = tuple(dict.fromkeys(self.node_of[c] for c in used if " guarantee " in c))
        return ContextResult("proved", script(), dt, used=text, used_nodes=nodes,
                             joins=tuple(n for n in nodes if n in self.joins), strategy=strategy)
