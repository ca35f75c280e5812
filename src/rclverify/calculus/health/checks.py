"""Contract health: consistency and vacuity of each node's contract.

The calculus is sound only for contracts that can be met (paper lines
740-768: nodes "verified to preserve their guarantees").  Three checks per
node, each a Z3 satisfiability query over the node's assumption ``A``, its
guarantees ``G1..Gn`` and the plan's environment facts ``F``:

``assumption-satisfiable``  can ``A`` hold at all?
``contract-consistent``     can ``A and G1 and ... and Gn and F`` hold?
``non-vacuous``             for each guarantee ``forall v | P -> Q``: can the
                            premise ``P`` hold (for some witness values of
                            ``v``) together with ``A``, every guarantee and
                            ``F``?  If not, the guarantee can never fire: it
                            is vacuous in every environment the plan allows.

When the plan gives ``instances: [lo, hi]`` for the node, every universally
quantified NATURAL variable of the guarantees and facts is also instantiated
at ``lo..hi+1`` as *redundant lemmas* (implied by the formulas, so they change
no answer but help Z3's quantifier instantiation), and a premise Z3 cannot
decide is examined instance by instance.

Findings: ``ok`` (with a witness model), ``problem`` (with an unsat core in
RCL terms: which clauses contradict each other), ``inconclusive`` (Z3 could
not decide within the timeout; never counted as ok).

A contract that divides gets a ``defined`` finding per clause that does
(:mod:`.defined`): each division's divisor is non-zero wherever the
clause is read.
"""
from __future__ import annotations

import time
from msgspec.structs import replace
from typing import Any, Callable, Mapping, Sequence

import z3

from rclverify.calculus.refinement import RefinementResult
from rclverify.semantics import wallclock
from rclverify.semantics.query import QueryResult, satisfiable, smt2_script, solver_session
from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.typecheck import domain_type
from rclverify.lang.types import NATURAL, Checked, CheckedNode
from rclverify.calculus.health.defined import definedness_findings
from rclverify.calculus.health.finding import Finding as Finding  # re-exported: callers import it from here too
from rclverify.records.statuses import HealthStatus
from rclverify.calculus.health.bounded import Bound
from rclverify.calculus.health.realizable import realizability_findings
from rclverify.calculus.health.shape import shape_findings
from rclverify.calculus.health.shared import SharedEncoder, Table
from rclverify.calculus.health.witness import WITNESS_TIMEOUT_MS, Witness, extend, finite_witness, has_tables, points_for

HEALTH_TIMEOUT_MS = 5_000
#: Timeout of one per-instance premise query, and how many undecided
#: instances in a row (with no vacuous one found) end the scan.
INSTANCE_TIMEOUT_MS = 2_000
GIVE_UP_AFTER = 3
#: With an instance range, the first budgets of the general non-vacuity query
#: and of each instance ("decide first with what decides"; see
#: :func:`_non_vacuity`).  The case study's instances each take about 25,000
#: Z3 steps (0.2 of :data:`INSTANCE_FIRST_MS`); its guarantee 1's general
#: query takes its whole budget and decides nothing.
SCAN_FIRST_MS = 250
INSTANCE_FIRST_MS = 100


def _where(l: ast.Loc) -> str:
    return f"{l.file}:{l.line}:{l.col}"


def _peel(e: ast.Expr) -> tuple[list[ast.Binding], ast.Expr]:
    """Outer ``forall`` bindings and the body under them."""
    bindings: list[ast.Binding] = []
    while isinstance(e, ast.Quant) and e.kind == "forall":
        bindings.extend(e.bindings)
        e = e.body
    return bindings, e


class _NodeHealth:
    def __init__(self, checked: Checked, node: CheckedNode, facts: Sequence[tuple[ast.Expr, ast.Loc]],
                 instances: tuple[int, int] | None, timeout_ms: int, table: Table | None = None) -> None:
        self.checked, self.node, self.instances, self.timeout = checked, node, instances, timeout_ms
        # the node's formulas encoded once for every check (.shared); a table of its own when none is shared
        self.enc = SharedEncoder(checked.env, {} if table is None else table)
        n = node.node
        self.assume = [(f"assumption {k} ({_where(a.loc)})", self.enc.formula(a.formula, node))
                       for k, a in enumerate(n.assumes, 1)]
        self.guars = [(f"guarantee {k} ({_where(g.loc)})", self.enc.formula(g.formula, node))
                      for k, g in enumerate(n.guarantees, 1)]
        self.facts = [(f"environment fact {k} ({_where(loc)})", self.enc.formula(f, node))
                      for k, (f, loc) in enumerate(facts, 1)]
        self.lemmas: list[tuple[str, z3.BoolRef]] = []
        #: The consistency check's finite-table witness, when it found one (see :func:`_extended`).
        self.witness: Witness | None = None
        if instances:
            for (label, _), g in zip(self.guars, n.guarantees):
                self.lemmas += self._instances(label, g.formula)
            for (label, _), (f, _) in zip(self.facts, facts):
                self.lemmas += self._instances(label, f)

    def _instances(self, label: str, e: ast.Expr) -> list[tuple[str, z3.BoolRef]]:
        assert self.instances is not None
        if not (isinstance(e, ast.Quant) and e.kind == "forall"):
            return []
        out = []
        for b in e.bindings:
            if domain_type(b, self.node, self.checked.env) != NATURAL:
                continue
            for v in b.names:
                rest = tuple(ast.Binding(tuple(n for n in bb.names if n != v), bb.domain, bb.loc)
                             for bb in e.bindings)
                rest = tuple(bb for bb in rest if bb.names)
                body = ast.Quant("forall", rest, e.body, e.loc) if rest else e.body
                lo, hi = self.instances
                for k in range(lo, hi + 2):
                    out.append((f"{label} at {v}={k}", self.enc.formula(body, self.node, bound={v: z3.IntVal(k)})))
        return out

    def labelled(self, extra: Sequence[tuple[str, z3.BoolRef]] = (), *,
                 guarantees: bool = True) -> list[tuple[str, z3.BoolRef]]:
        """The labelled formulas of a query: the assumption, then (``guarantees``)
        every guarantee, fact and instance lemma, then ``extra``."""
        return (list(self.assume) + (list(self.guars) + list(self.facts) + list(self.lemmas) if guarantees else [])
                + list(extra))

    def sat(self, extra: Sequence[tuple[str, z3.BoolRef]], *, guarantees: bool = True, comment: str = "",
            timeout_ms: int | None = None, retry: bool | None = None) -> QueryResult:
        # per-instance queries (own timeout) are not retried: the instance scan is their fallback
        return satisfiable(self.labelled(extra, guarantees=guarantees), self.enc, timeout_ms=timeout_ms or self.timeout,
                           comment=comment, retry=timeout_ms is None if retry is None else retry)

    def statement(self, extra: Sequence[tuple[str, z3.BoolRef]], *, comment: str = "") -> Callable[[], str]:
        """The SMT-LIB2 text of the query :meth:`sat` would ask (made when
        called), for a finding answered without asking it."""
        return smt2_script(self.enc.axioms() + [f for _, f in self.labelled(extra)], comment or "satisfiability query")

    def premise(self, k: int, fixed: dict[str, int] | None = None) -> tuple[list[tuple[str, z3.BoolRef]], str] | None:
        g = self.node.node.guarantees[k - 1]
        bindings, body = _peel(g.formula)
        if not (isinstance(body, ast.Binary) and body.op == "->"):
            return None
        bound: dict[str, z3.ExprRef] = {}
        guards = []
        for b in bindings:
            t = domain_type(b, self.node, self.checked.env, {})
            for v in b.names:
                if fixed and v in fixed:
                    bound[v] = z3.IntVal(fixed[v])
                    continue
                c = self.enc.fresh(f"{self.node.name}.g{k}.{v}", f"{v} (witness for guarantee {k})", t)
                bound[v] = c
                if t == NATURAL:
                    guards.append(c >= 0)
        p = self.enc.formula(body.left, self.node, bound=bound)
        label = f"premise of guarantee {k}" + (" at " + ", ".join(f"{v}={x}" for v, x in fixed.items()) if fixed else "")
        return [(label, z3.And(p, *guards) if guards else p)], expr_to_rcl(body.left)

    def natural_vars(self, k: int) -> list[str]:
        bindings, _ = _peel(self.node.node.guarantees[k - 1].formula)
        return [v for b in bindings if domain_type(b, self.node, self.checked.env) == NATURAL for v in b.names]


@solver_session()
def check_node(checked: Checked, node: str, facts: Sequence[tuple[ast.Expr, ast.Loc]] = (),
               instances: tuple[int, int] | None = None, *, timeout_ms: int = HEALTH_TIMEOUT_MS,
               bounds: Mapping[str, Bound] | None = None) -> list[Finding]:
    """Run the three health checks on ``node``, then realizability
    (:mod:`rclverify.calculus.health.realizable`: an admissible input no output
    answers) and the checks of :mod:`rclverify.calculus.health.shape` (tautologies,
    guarantees constraining no output, unconstrained outputs, redundant
    conjuncts); returns its findings (``bounds``: the output sequences the
    interface bounds, for realizability: :mod:`.bounded`)
    in order.  The queries share one solver session
    (:func:`~rclverify.semantics.query.solver_session`): they depend on the
    node's contract, facts and instances alone, and run in a fixed order.

    When the wall-clock safety net cut a query (:mod:`rclverify.semantics.wallclock`:
    a loaded machine), the findings of that check and of every later one
    are ``inconclusive`` ("took longer than N s", :func:`_cut_short`): the
    cut changed the path (the next instance of a scan, another subset of
    guarantees) and the state of the shared solver, so their models and
    cores could differ from what the budget alone decides."""
    with wallclock.watch() as w:
        cuts: list[int] = []
        out = _check_node(checked, node, facts, instances, timeout_ms, lambda k: cuts.append(k) if w.cut else None,
                          bounds)
    return out[:cuts[0]] + [_cut_short(f) for f in out[cuts[0]:]] if cuts else out


def _cut_short(f: Finding) -> Finding:
    """``f`` as an ``inconclusive`` finding of the same check: decided
    after the wall-clock safety net cut a query (:func:`check_node`)."""
    if f.status == "inconclusive" and "wall-clock" in f.explanation:
        return f
    return Finding(f.id, f.node, f.check, f.guarantee, "inconclusive",
                   f"This check of {f.node} was not decided here.",
                   f"A health query of {f.node} {wallclock.cut_reason()}.", duration_s=f.duration_s)


def _check_node(checked: Checked, node: str, facts: Sequence[tuple[ast.Expr, ast.Loc]],
                instances: tuple[int, int] | None, timeout_ms: int, done: Callable[[int], None],
                bounds: Mapping[str, Bound] | None = None) -> list[Finding]:
    """:func:`check_node`'s checks, whatever the wall clock did; ``done(k)``
    is called after each check with the index of its first finding."""
    table: Table = {}
    h = _NodeHealth(checked, checked.nodes[node], facts, instances, timeout_ms, table)
    out: list[Finding] = []
    n = node

    r = h.sat([], guarantees=False, comment=f"health {n}: is the assumption satisfiable?")
    mark = len(out)
    if r.status == "sat":
        out.append(Finding(f"{n}.assumption-satisfiable", n, "assumption-satisfiable", None, "ok",
                           f"The assumption of {n} can be met.", "Z3 found inputs satisfying it (witness below).", r.model,
                           duration_s=r.duration_s))
    elif r.status == "unsat":
        out.append(Finding(f"{n}.assumption-satisfiable", n, "assumption-satisfiable", None, "problem",
                           f"The assumption of {n} can never hold: the node's contract is vacuous.",
                           "Unsat core: the clauses listed contradict each other.", None, list(r.core or []), r.duration_s))
    else:
        out.append(Finding(f"{n}.assumption-satisfiable", n, "assumption-satisfiable", None, "inconclusive",
                           f"Z3 could not decide whether the assumption of {n} can hold.", r.reason, duration_s=r.duration_s))

    out[mark] = _noted(replace(out[mark], smt2=r.smt2), r)
    done(mark)
    comment = f"health {n}: can the assumption, every guarantee and the environment facts hold together?"
    tables = _table_witness(h, comment)
    r = tables or h.sat([], comment=comment)
    mark = len(out)
    check = "contract-consistent"
    if r.status == "sat":
        out.append(Finding(f"{n}.{check}", n, check, None, "ok",
                           f"The assumption and guarantees of {n} (with the environment facts) can hold together.",
                           "Z3 found a witness in which each function-typed input is a finite table (below)."
                           if tables else "Z3 found a witness (below).", r.model, duration_s=r.duration_s))
    elif r.status == "unsat":
        out.append(Finding(f"{n}.{check}", n, check, None, "problem",
                           f"The contract of {n} contradicts itself: no output can satisfy its guarantees.",
                           "Unsat core: the clauses listed contradict each other.", None, list(r.core or []), r.duration_s))
    else:
        out.append(Finding(f"{n}.{check}", n, check, None, "inconclusive",
                           f"Z3 could not decide whether the contract of {n} is consistent ({r.reason}).",
                           "The quantifier alternation in the guarantees is beyond Z3's decision procedures within the "
                           "timeout; no conclusion is drawn.", duration_s=r.duration_s))

    out[mark] = _noted(replace(out[mark], smt2=r.smt2), r)
    done(mark)
    for k in range(1, len(checked.nodes[node].node.guarantees) + 1):
        f = _non_vacuity(h, n, k)
        if f is not None:  # only implications have a premise that can be vacuous
            out.append(f)
        done(len(out) - 1 if f is not None else len(out))
    mark = len(out)
    # realizability encodes on its own: served from the table, its recorded query's shared subterms got other
    # term ids, hence other let names (bench/health_equivalence.py); shape, last, records no query of those
    out += realizability_findings(checked, node, facts, instances, bounds=bounds)
    done(mark)
    mark = len(out)
    out += shape_findings(checked, node, formulas=table)
    done(mark)
    mark = len(out)
    out += definedness_findings(checked, node, facts, timeout_ms)  # only for a contract that divides
    done(mark)
    return out


def _table_witness(h: _NodeHealth, comment: str, extra: Sequence[tuple[str, z3.BoolRef]] = (),
                   budget_ms: int = WITNESS_TIMEOUT_MS) -> QueryResult | None:
    """A witness of the consistency query (with ``extra``: of a
    non-vacuity query) in which each function-typed input is a finite
    table (:mod:`.witness`), asked before the general query when the
    contract has such inputs: Z3 finds one in a fraction of the time it
    takes to find a model with uninterpreted functions (the case study's
    Agent: 0.1-0.3 s instead of 3 s).  Its ``sat`` is a model of the
    general query, so the finding is the same (``ok``), with the general
    query's SMT-LIB2 text as its statement; anything else (None) leaves the
    question to the general query.  For non-vacuity it is asked only after
    the instance scan's first look found no instance vacuous
    (:func:`_non_vacuity`): a witness at one instance would hide a
    guarantee vacuous at others (the Agent's guarantee 1), which the scan
    reports."""
    if not has_tables(h.enc):
        return None
    t0 = time.perf_counter()
    w = finite_witness(h.enc, [f for _, f in h.labelled(extra)], points_for(h.instances), budget_ms)
    if w.status != "sat":
        return None
    if not extra:
        h.witness = w
    return QueryResult("sat", h.statement(extra, comment=comment), round(time.perf_counter() - t0, 4), model=w.model)


def _extended(h: _NodeHealth, comment: str, extra: Sequence[tuple[str, z3.BoolRef]]) -> QueryResult | None:
    """The consistency check's finite-table witness (:func:`_table_witness`)
    extended to a witness of the non-vacuity query with ``extra`` (a
    premise over new witness variables: :func:`.witness.extend`), the
    contract's functions and variables as the witness has them: when the
    premise already fires there (the case study's Agent, guarantee 3 at
    ``i = 12``, where no waypoint 13 exists), a query of a few thousand
    steps answers what a new witness takes 0.2-0.4 s for.  Its ``sat`` is
    a model of the query (the finding is the same, ``ok``); None leaves the
    question to a new witness."""
    if h.witness is None:
        return None
    t0 = time.perf_counter()
    w = extend(h.witness, h.enc, [f for _, f in extra])
    if w.status != "sat":
        return None
    return QueryResult("sat", h.statement(extra, comment=comment), round(time.perf_counter() - t0, 4), model=w.model)


def _noted(f: Finding, r: QueryResult) -> Finding:
    """``f`` with the retry strategy that answered its query (semantics/retry.py) stated."""
    if not r.strategy:
        return f
    return replace(f, explanation=f"{f.explanation} Z3's default strategy gave up; answered with {r.strategy}.")


def _non_vacuity(h: _NodeHealth, n: str, k: int) -> Finding | None:
    prem = h.premise(k)
    if prem is None:
        return None  # not forall ... (premise -> conclusion): no premise to examine
    extra, ptext = prem
    comment = f"health {n}: can the premise of guarantee {k} hold? {ptext}"
    if not (h.instances and h.natural_vars(k)):
        r = h.sat(extra, comment=comment, retry=True)
        return _noted(replace(_premise_finding(h, n, k, r, ptext), smt2=r.smt2), r)
    # With an instance range the scan decides where the general query cannot; the retries of
    # semantics/retry.py are not tried (the Agent's guarantee 1: 4 CPU s of retries that all give up).
    # Decide first with what decides: the general query with a small budget (what it decides
    # there, its whole budget decides the same way), then each instance with a small budget; the general
    # query gets its whole budget only when no instance was found vacuous.
    r = h.sat(extra, comment=comment, retry=False, timeout_ms=min(h.timeout, SCAN_FIRST_MS))
    if r.status == "inconclusive":
        quick = _scan(h, n, k, min(h.timeout, INSTANCE_FIRST_MS))
        if not any(x.status == "unsat" for x in quick.values()):
            # no instance shown vacuous: the consistency witness extended, else a finite-table witness of
            # the general query (either's sat is the general query's), else the general query with its
            # whole budget
            r = (_extended(h, comment, extra) or _table_witness(h, comment, extra)
                 or h.sat(extra, comment=comment, retry=False))
        if r.status == "inconclusive":
            return replace(_scan_finding(h, n, k, r, ptext, quick), smt2=r.smt2)
    return _noted(replace(_premise_finding(h, n, k, r, ptext), smt2=r.smt2), r)


def _scan(h: _NodeHealth, n: str, k: int, budget_ms: int,
          known: dict[int, QueryResult] | None = None, *, witness_first: bool = False) -> dict[int, QueryResult]:
    """Guarantee ``k``'s premise asked at each instance ``lo..hi`` of its
    first NATURAL variable, in order, with ``budget_ms`` each (an instance
    ``known`` decided is not asked again), until :data:`GIVE_UP_AFTER`
    instances in a row are undecided with none found vacuous before.
    ``witness_first``: an instance still undecided is first given to the
    witnesses of that instance's premise alone (the consistency witness
    extended, then a finite-table witness within ``budget_ms``: either's
    ``sat`` is a model of the instance's query, so the instance can fire);
    only what they leave open is asked with ``budget_ms``.  The case
    study's Agent, guarantee 1 at ``i = 12``: a witness in 0.3 s where the
    general query gives up after 2 s."""
    assert h.instances is not None
    v = h.natural_vars(k)[0]
    lo, hi = h.instances
    out: dict[int, QueryResult] = {}
    streak = 0
    for x in range(lo, hi + 1):
        got = (known or {}).get(x)
        if got is None or got.status == "inconclusive":
            pe = h.premise(k, {v: x})
            assert pe is not None
            comment = f"health {n}: premise of guarantee {k} at {v}={x}"
            got = ((_extended(h, comment, pe[0]) or _table_witness(h, comment, pe[0], budget_ms=budget_ms))
                   if witness_first else None) or h.sat(pe[0], comment=comment, timeout_ms=budget_ms)
        out[x] = got
        streak = streak + 1 if got.status == "inconclusive" else 0
        if streak >= GIVE_UP_AFTER and not any(y.status == "unsat" for y in out.values()):
            break
    return out


def _premise_finding(h: _NodeHealth, n: str, k: int, r: QueryResult, ptext: str) -> Finding:
    """The finding of a general non-vacuity query that decided, or of one
    that did not when there is no instance range to scan."""
    fid, check = f"{n}.g{k}.non-vacuous", "non-vacuous"
    if r.status == "sat":
        return Finding(fid, n, check, k, "ok", f"The premise of guarantee {k} of {n} can hold: the guarantee can fire.",
                       f"Premise: {ptext}. Z3 found a situation where it holds together with the assumption, every "
                       "guarantee and the environment facts (witness below).", r.model, duration_s=r.duration_s)
    if r.status == "unsat":
        return Finding(fid, n, check, k, "problem",
                       f"Guarantee {k} of {n} is vacuous: its premise can never hold together with the node's other "
                       "guarantees and the environment facts, so it promises nothing.",
                       f"Premise: {ptext}. The unsat core names the clauses that exclude it.", None, list(r.core or []),
                       r.duration_s)
    return Finding(fid, n, check, k, "inconclusive", f"Z3 could not decide whether guarantee {k} of {n} can fire ({r.reason}).",
                   f"Premise: {ptext}. Give the plan an 'instances' range for {n} to examine it instance by instance.",
                   duration_s=r.duration_s)


def _scan_finding(h: _NodeHealth, n: str, k: int, r: QueryResult, ptext: str,
                  quick: dict[int, QueryResult]) -> Finding:
    """The finding of guarantee ``k`` examined instance by instance, the
    general query ``r`` undecided: each instance the ``quick`` look did not
    decide is asked with :data:`INSTANCE_TIMEOUT_MS` (the scan of
    :func:`_scan`, in order, with its give-up rule)."""
    fid, check = f"{n}.g{k}.non-vacuous", "non-vacuous"
    assert h.instances is not None
    v = h.natural_vars(k)[0]
    lo, hi = h.instances
    full = _scan(h, n, k, min(h.timeout, INSTANCE_TIMEOUT_MS), quick, witness_first=True)
    per: dict[str, str] = {}
    cores: dict[str, list[str]] = {}
    total = r.duration_s + sum(x.duration_s for x in quick.values()) + sum(
        x.duration_s for y, x in full.items() if x is not quick.get(y))
    for x, ri in full.items():
        per[str(x)] = {"sat": "can fire", "unsat": "vacuous", "inconclusive": "inconclusive"}[ri.status]
        if ri.status == "unsat":
            cores[str(x)] = list(ri.core or [])
    if len(full) < hi - lo + 1:  # the scan gave up
        per.update({str(y): "not examined" for y in range(lo + len(full), hi + 1)})
    vac = [x for x, st in per.items() if st == "vacuous"]
    fires = [x for x, st in per.items() if st == "can fire"]
    unk = [x for x, st in per.items() if st in ("inconclusive", "not examined")]
    if vac:
        sample = cores[vac[0]]
        msg = (f"Guarantee {k} of {n} is vacuous for {v} in {_ranges(vac)}: its premise contradicts the node's other "
               f"guarantees and the environment facts there" + (f"; it can fire only for {v} in {_ranges(fires)}" if fires else "")
               + (f"; undecided for {v} in {_ranges(unk)}" if unk else "") + ".")
        return Finding(fid, n, check, k, "problem", msg,
                       f"Premise: {ptext}. Unsat core at {v}={vac[0]} below. Z3 could not decide the general case "
                       f"({r.reason}), so each instance {v}={lo}..{hi} was checked.", None, sample, round(total, 4), per)
    if fires and not unk:
        return Finding(fid, n, check, k, "ok", f"Guarantee {k} of {n} can fire for every {v} in {lo}..{hi}.",
                       f"Premise: {ptext}.", None, None, round(total, 4), per)
    return Finding(fid, n, check, k, "inconclusive", f"Z3 could not decide whether guarantee {k} of {n} can fire"
                   + (f" for {v} in {_ranges(unk)}" if unk else "") + ".",
                   f"Premise: {ptext}.", None, None, round(total, 4), per)


def refinement_finding(node: str, spec: str, r: RefinementResult) -> Finding:
    """The verdict of "may ``spec`` replace ``node``'s contract" as a finding
    (check ``replacement-refines``; paper lines 1667-1700).  Its SMT-LIB2 holds
    both refinement queries, separated by ``(reset)``."""
    sides = {"proved": "holds", "refuted": "fails", "inconclusive": "is undecided"}
    detail = (f"Assumption side (A_{node} -> A_replacement) {sides[r.assumption.status]}; guarantee side "
              f"(A_{node} and G_replacement -> G_{node}) {sides[r.guarantee.status]}.")
    if r.conditions:
        detail += " Checked under the plan's environment facts and conditions: " + "; ".join(r.conditions) + "."
    for x in (r.assumption, r.guarantee):
        if x.strategy:
            detail += f" Z3's default strategy gave up on the {x.name} side; answered with {x.strategy}."
    failed = next((s for s in (r.assumption, r.guarantee) if s.status == "refuted"), None)
    status: HealthStatus
    if r.verdict == "refines":
        status, msg = "ok", f"The replacement contract {spec} refines {node}: it may replace it."
    elif failed is not None:
        shown = (f" (the finding's counterexample: `rclverify explain {node}.replacement-refines`)"
                 if failed.model is not None else "")
        status, msg = "problem", f"The replacement contract {spec} does not refine {node}: its {failed.name} side fails{shown}."
    else:
        why = "; ".join(f"{x.name} side: {x.reason}" for x in (r.assumption, r.guarantee)
                        if x.status == "inconclusive" and x.reason)
        status, msg = "inconclusive", f"Z3 could not decide whether {spec} refines {node}" + (f" ({why})." if why else ".")
    model = dict(failed.model) if failed is not None and failed.model is not None else None
    return Finding(f"{node}.replacement-refines", node, "replacement-refines", None, status, msg,
                   detail + (f" Statement: {failed.statement}" if failed else ""), model,
                   None, round(r.assumption.duration_s + r.guarantee.duration_s, 4),
                   smt2=r.assumption.smt2 + "\n(reset)\n" + r.guarantee.smt2)


def _ranges(xs: Sequence[str]) -> str:
    nums = sorted(int(x) for x in xs)
    parts, start = [], None
    for i, x in enumerate(nums):
        if start is None:
            start = x
        if i + 1 == len(nums) or nums[i + 1] != x + 1:
            parts.append(f"{start}" if start == x else f"{start}..{x}")
            start = None
    return "{" + ", ".join(parts) + "}"
