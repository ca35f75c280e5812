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

from rclverify.semantics.connectives import conj
from rclverify.semantics.encode import Encoder
from rclverify.semantics.nicemodel import nicer_model
from rclverify.semantics.query import query_solver, render_model, satisfiable, smt2_script, smtlib_benchmark
from rclverify.lang import ast
from rclverify.lang.types import Checked
from rclverify.model.system.model import SystemModel
from rclverify.targets.smtlib import quote
from rclverify.calculus.premises import node_premises
from rclverify.calculus.cone_paths import link_text, multi_path, opened_links
from rclverify.calculus.cone_script import declare, merge, read_model, sort_of_symbol

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
    ``strategy`` (the retry that answered, if any);
    ``summaries`` the producers whose cone summaries the proof read instead
    of their cones (:mod:`.summary`; empty: the whole cone was read).
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
    summaries: tuple[str, ...] = ()


class ConeContext:
    """The upstream cone of one consumer as labelled Z3 premises, built once
    per node (its side conditions share it) and only when one of them fails
    locally.

    ``checked``/``model`` the system; ``node`` the consumer;
    ``environment(m)`` the environment conjuncts of node ``m``'s assumption
    (the calculus's own split, :func:`.compose.split_assumption`, passed in:
    this module sits below it); ``facts`` the plan's environment facts per
    node (RCL formulas over that node's I/O); ``fast``: read the formulas of
    :mod:`rclverify.targets.smtlib`'s fragment from their SMT-LIB text (``False``: encode
    every formula with the encoder; the verdicts are the same, tests).

    Each premise ``k`` is asserted as ``l!k -> premise`` and the query is
    checked under the literals ``l!k`` (their unsat core names the premises
    used); each node ``m`` with an assumption has a Boolean ``A!m`` defined
    as it, so a counterexample says which assumptions it violates.
    """

    def __init__(self, checked: Checked, model: SystemModel, node: str,
                 environment: Callable[[str], Sequence[ast.Expr]],
                 facts: Mapping[str, Sequence[ast.Expr]] | None = None, *, fast: bool = True) -> None:
        self.node = node
        self.cone = model.upstream(node)
        cut = opened_links(model, node)
        self.cut = tuple(link_text(l) for l in cut)
        cut_keys = {(l.to_node, "in", l.to_var) for l in cut}
        alias = {k: v for k, v in model.alias().items() if k not in cut_keys} if cut else model.alias()
        self.enc = enc = Encoder(checked.env, alias)
        self.checked = checked
        self.labels: list[str] = []
        self.tracked: list[z3.BoolRef] = []  # l!k -> premise k
        self.literals: list[z3.BoolRef] = []  # l!k
        self.definitions: list[z3.BoolRef] = []  # A!m == assumption of m
        self.flags: dict[str, str] = {}  # node -> the name of its A!m
        self.flag_nodes: list[str] = []  # the node of each definition
        self.text: dict[str, str] = {}
        self.node_of: dict[str, str] = {}
        self.joins = multi_path(model, node, self.cone, {(l.from_node, l.from_var, l.to_node, l.to_var) for l in cut})
        described = []
        for m in self.cone:
            cn = checked.nodes[m]
            symbol = {(p, v): enc.symbol_name(m, p, v) for p, table in (("in", cn.inputs), ("out", cn.outputs))
                      for v in table}
            described.append((m, node_premises(checked, model, m, m == node, environment(m),
                                                (facts or {}).get(m, ()), symbol)))
        for m, d in described:
            for label, text, _, _, _ in d.items:
                self.labels.append(label)
                self.text[label] = text
                self.node_of[label] = m
        self.all_text = fast and all(d.smt for _, d in described)
        self.script_text = ""
        lines: list[str] = []  # the fragment's premises, one parse for the whole cone
        decls: dict[str, str] = {}
        k = 0
        for m, d in described:
            n_items = len(d.items)
            if fast and d.smt:
                for name, p, v in d.symbols:
                    enc.io_symbol(checked.nodes[m], p, v)  # the encoder knows every symbol: models, NATURAL axioms
                    decls[name] = sort_of_symbol(checked.nodes[m], p, v)
                flag = None
                if d.assumption is not None:
                    flag = f"A!{m}"
                    self.flags[m] = flag
                    lines.append(f"(assert (= {quote(flag)} {d.assumption}))")
                for j, (_, _, kind, _, t) in enumerate(d.items):
                    body = f"(=> {quote(flag)} {t})" if kind == "guarantee" and flag else t
                    lines.append(f"(assert (=> {quote(f'l!{k + j}')} {body}))")
            k += n_items
        parsed = iter(z3.parse_smt2_string(declare(decls, self.flags.values(), len(self.labels)) + "\n".join(lines))
                      if lines else [])
        k = 0
        for m, d in described:
            if fast and d.smt:
                if m in self.flags:
                    self.definitions.append(next(parsed))
                    self.flag_nodes.append(m)
                for _ in d.items:
                    f = next(parsed)
                    self.tracked.append(f)
                    self.literals.append(f.arg(0))
            else:
                for j, f in enumerate(self._encode(checked.nodes[m], m, m == node, environment(m),
                                                   (facts or {}).get(m, ()))):
                    lit = z3.Bool(f"l!{k + j}")
                    self.tracked.append(z3.Implies(lit, f))
                    self.literals.append(lit)
            k += len(d.items)
        if self.all_text:
            self.script_text = declare(decls, self.flags.values(), len(self.labels)) + "\n".join(lines)

    def _encode(self, cn: Any, m: str, consumer: bool, environment: Sequence[ast.Expr],
                facts: Sequence[ast.Expr]) -> list[z3.BoolRef]:
        """The node's premises (in :class:`.NodePremises` order) through the
        encoder; its assumption becomes the definition of ``A!m``."""
        enc, out = self.enc, []
        if not consumer:
            parts = [enc.formula(x.formula, cn) for x in cn.node.assumes
                     if not (isinstance(x.formula, ast.BoolLit) and x.formula.value)]
            flag = None
            if parts:
                self.flags[m] = f"A!{m}"
                flag = z3.Bool(self.flags[m])
                self.definitions.append(flag == (conj(*parts) if len(parts) > 1 else parts[0]))
                self.flag_nodes.append(m)
            out += [z3.Implies(flag, g) if flag is not None else g
                    for g in (enc.formula(g.formula, cn) for g in cn.node.guarantees)]
        out += [enc.formula(c, cn) for c in environment]
        out += [enc.formula(f, cn) for f in facts]
        return out

    def decide(self, conjunct: ast.Expr, comment: str, timeout_ms: int) -> ContextResult:
        """Is ``conjunct`` (of the consumer's assumption) entailed by the
        cone's premises?  Never raises on solver trouble."""
        goal = self.enc.formula(conjunct, self.checked.nodes[self.node])
        negated = z3.Bool("l!goal")
        background = self.enc.axioms() + self.definitions
        tracked = self.tracked + [z3.Implies(negated, z3.Not(goal))]
        literals = self.literals + [negated]
        labels = self.labels + [NEGATED]
        script = self._script(background, tracked, literals, comment)
        t0 = time.perf_counter()
        core: list[str] | None = None
        consistency: tuple[Any, list[str], str] | None = None
        with query_solver(timeout_ms, cores=True) as s:
            s.add(*background)
            s.add(*tracked)
            r = s.check(*literals)
            dt = round(time.perf_counter() - t0, 4)
            if r == z3.unsat:
                found = {str(c) for c in s.unsat_core()}
                core = [lbl for lbl, lit in zip(labels, literals) if str(lit) in found]
                if NEGATED in core:  # can the premises used hold together?  Asked of the same solver, the goal off
                    used = [lit for lbl, lit in zip(labels, literals) if str(lit) in found and lbl != NEGATED]
                    t1 = time.perf_counter()
                    r2 = s.check(*used)
                    names = {str(lit): lbl for lbl, lit in zip(labels, literals)}
                    consistency = (r2, [names[str(c)] for c in s.unsat_core()] if r2 == z3.unsat else [],
                                   s.reason_unknown() if r2 == z3.unknown else "")
                    dt = round(dt + time.perf_counter() - t1, 4)
            elif r == z3.sat:
                m = s.model()
                read = read_model(m.sexpr()) if self.all_text else None
                if read is not None:  # the fragment: values read from the model's text, not one object each
                    values, flags = read
                    shown = {sym.display: values[name] for name, sym in sorted(self.enc.symbols.items(),
                                                                               key=lambda kv: kv[1].display)
                             if name in values}
                    violated = tuple(n for n in self.flag_nodes if flags.get(self.flags[n]) is False)
                else:
                    shown = render_model(m, self.enc)
                    violated = tuple(n for n, d in zip(self.flag_nodes, self.definitions)
                                     if z3.is_false(m.eval(d.arg(0), model_completion=True)))
                # short values where Z3 finds them, the same nodes' assumptions violated, re-checked
                same = [d.arg(0) == z3.BoolVal(n not in violated, d.ctx) for n, d in zip(self.flag_nodes, self.definitions)]
                shown = nicer_model([*background, *tracked, *literals, *same], self.enc, shown).model
                return ContextResult("refuted", script(), dt, model=shown, violated=violated)
        if core is not None:
            return self._proved(core, script, dt, consistency=consistency)
        # unknown: the retries of semantics/retry.py (fresh solvers), which answer without a Z3 model object
        plain = [(lbl, z3.substitute(f, (lit, z3.BoolVal(True)))) for lbl, f, lit in zip(labels, tracked, literals)]
        if self.definitions:
            plain.append(("definitions", conj(*self.definitions)))
        rr = satisfiable(plain, self.enc, timeout_ms=timeout_ms, comment=comment)
        dt = round(time.perf_counter() - t0, 4)
        if rr.status == "unsat":
            return self._proved([c for c in rr.core or [] if c != "definitions"], script, dt, rr.strategy)
        if rr.status == "sat":
            return ContextResult("refuted", script(), dt, model=rr.model, strategy=rr.strategy)
        return ContextResult("inconclusive", script(), dt, reason=rr.reason or "unknown")

    def _script(self, background: Sequence[z3.BoolRef], tracked: Sequence[z3.BoolRef],
                literals: Sequence[z3.BoolRef], comment: str) -> Callable[[], str]:
        """The query's SMT-LIB2 text (made when asked for): the parsed text
        itself when every premise is in the fragment, else Z3's printing;
        the premises' literals asserted, so the script's ``(check-sat)`` is
        the query."""
        header = "".join(f"; {line}\n" for line in comment.splitlines())
        if self.all_text:
            def text() -> str:
                goal_and_axioms = smtlib_benchmark(list(background[:len(background) - len(self.definitions)])
                                                   + [tracked[-1], literals[-1]])
                body = self.script_text + "\n" + "\n".join(f"(assert {quote(f'l!{k}')})"
                                                              for k in range(len(literals) - 1))
                # the goal, the axioms and the goal's literal: Z3's printing of those few formulas (with declarations)
                return header + merge(body, goal_and_axioms)
            return text
        return smt2_script(list(background) + list(tracked) + list(literals), comment)

    def _proved(self, core: Sequence[str], script: Any, dt: float, strategy: str = "",
                consistency: tuple[Any, list[str], str] | None = None) -> ContextResult:
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
        if consistency is None:  # a retry answered: ask in a scope of its own
            index = {lbl: k for k, lbl in enumerate(self.labels)}
            t0 = time.perf_counter()
            with query_solver(CONSISTENCY_TIMEOUT_MS, cores=True) as s:
                s.add(*self.enc.axioms(), *self.definitions)
                s.add(*[self.tracked[index[c]] for c in used])
                r = s.check(*[self.literals[index[c]] for c in used])
                names = {str(self.literals[index[c]]): c for c in used}
                consistency = (r, [names[str(c)] for c in s.unsat_core()] if r == z3.unsat else [],
                               s.reason_unknown() if r == z3.unknown else "")
            dt = round(dt + time.perf_counter() - t0, 4)
        r, ccore, reason = consistency
        if r != z3.sat:
            why = ("contradict each other (unsat core: " + "; ".join(ccore) + ")"
                   if r == z3.unsat else f"may contradict each other (Z3 could not decide: {reason or 'unknown'})")
            return ContextResult("inconclusive", script(), dt, used=text, strategy=strategy,
                                 reason=f"the premises the proof used {why}, so the proof establishes nothing")
        nodes = tuple(dict.fromkeys(self.node_of[c] for c in used if " guarantee " in c))
        return ContextResult("proved", script(), dt, used=text, used_nodes=nodes,
                             joins=tuple(n for n in nodes if n in self.joins), strategy=strategy)
