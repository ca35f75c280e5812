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
clause is read.  The queries over one node are :mod:`.node_health`'s, the
non-vacuity check :mod:`.vacuity`'s.
"""
from __future__ import annotations

from msgspec.structs import replace
from typing import Callable, Mapping, Sequence

from rclverify.calculus.refinement import RefinementResult
from rclverify.semantics import wallclock
from rclverify.semantics.query import solver_session
from rclverify.lang import ast
from rclverify.lang.types import Checked
from rclverify.calculus.health.defined import definedness_findings
from rclverify.calculus.health.finding import Finding as Finding  # re-exported: callers import it from here too
from rclverify.records.statuses import HealthStatus
from rclverify.calculus.health.bounded import Bound
from rclverify.calculus.health.realizable import realizability_findings
from rclverify.calculus.health.shape import shape_findings
from rclverify.calculus.health.shared import Table
from rclverify.calculus.health.node_health import NodeHealth, noted, table_witness
from rclverify.calculus.health.vacuity import non_vacuity

HEALTH_TIMEOUT_MS = 5_000


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
    h = NodeHealth(checked, checked.nodes[node], facts, instances, timeout_ms, table)
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

    out[mark] = noted(replace(out[mark], smt2=r.smt2), r)
    done(mark)
    comment = f"health {n}: can the assumption, every guarantee and the environment facts hold together?"
    tables = table_witness(h, comment)
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

    out[mark] = noted(replace(out[mark], smt2=r.smt2), r)
    done(mark)
    for k in range(1, len(checked.nodes[node].node.guarantees) + 1):
        f = non_vacuity(h, n, k)
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
