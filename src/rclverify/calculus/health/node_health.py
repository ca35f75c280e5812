"""One node's contract health queries (:mod:`.checks`): its clauses and the
plan's facts encoded once (:class:`NodeHealth`, with the redundant
instance lemmas of an instance range), the satisfiability queries over
them in one solver session, and the finite-table witnesses asked before
the general query when the contract has function-typed inputs
(:func:`table_witness`, :func:`extended_witness`).
"""
from __future__ import annotations

import time
from msgspec.structs import replace
from typing import Callable, Sequence

import z3

from rclverify.semantics.query import QueryResult, satisfiable, smt2_script
from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.typecheck import domain_type
from rclverify.lang.types import NATURAL, Checked, CheckedNode
from rclverify.calculus.health.finding import Finding
from rclverify.calculus.health.shared import SharedEncoder, Table
from rclverify.calculus.health.witness import WITNESS_TIMEOUT_MS, Witness, extend, finite_witness, has_tables, points_for


def _where(l: ast.Loc) -> str:
    return f"{l.file}:{l.line}:{l.col}"


def _peel(e: ast.Expr) -> tuple[list[ast.Binding], ast.Expr]:
    """Outer ``forall`` bindings and the body under them."""
    bindings: list[ast.Binding] = []
    while isinstance(e, ast.Quant) and e.kind == "forall":
        bindings.extend(e.bindings)
        e = e.body
    return bindings, e


class NodeHealth:
    """The health queries of one node (module docstring): ``checked`` the
    checked contracts, ``node`` the node, ``facts`` the plan's environment
    facts ``(formula, where)``, ``instances`` the instance range ``(lo, hi)``
    or ``None``, ``timeout_ms`` each query's Z3 budget, ``table`` the shared
    encoding of formulas (:mod:`.shared`)."""

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
        #: The consistency check's finite-table witness, when it found one (see :func:`extended_witness`).
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



def table_witness(h: NodeHealth, comment: str, extra: Sequence[tuple[str, z3.BoolRef]] = (),
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
    (:func:`non_vacuity`): a witness at one instance would hide a
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


def extended_witness(h: NodeHealth, comment: str, extra: Sequence[tuple[str, z3.BoolRef]]) -> QueryResult | None:
    """The consistency check's finite-table witness (:func:`table_witness`)
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


def noted(f: Finding, r: QueryResult) -> Finding:
    """``f`` with the retry strategy that answered its query (semantics/retry.py) stated."""
    if not r.strategy:
        return f
    return replace(f, explanation=f"{f.explanation} Z3's default strategy gave up; answered with {r.strategy}.")
