"""The labelled query of a requirement decided over its cone (:mod:`.check`).

The premises of the cone's nodes (every guarantee, the environment
conjuncts of the assumptions, the plan's environment facts), the
requirement's own ``assuming:`` formulas and the negated statement with
its well-definedness conditions (docs/semantics.md, "Definedness"), each
listed for the record (``{label, kind, node, index, text, source}``) and
labelled for Z3's unsat core; :func:`ask` builds it and asks Z3 once,
:func:`first_undefined` finds the first definedness condition the premises do
not ensure.  :mod:`.own_nodes` asks the same query over a node's own
premises.
"""
from __future__ import annotations

from typing import Any, Sequence

import z3

from rclverify.calculus.compose import split_assumption
from rclverify.records.stage_records import RequirementBase
from rclverify.semantics.definedness import Condition, conditions, conjoin
from rclverify.semantics.encode import Encoder
from rclverify.semantics.query import QueryResult, satisfiable
from rclverify.model.plan.formal import Formal
from rclverify.model.plan.model import Plan
from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.types import Checked, CheckedNode
from rclverify.lang.walk import free_names, subexpressions
from rclverify.model.system.model import SystemModel

NEGATED = "negated requirement"


def where(l: ast.Loc) -> str:
    """``file:line:col`` of ``l``."""
    return f"{l.file}:{l.line}:{l.col}"


def io_symbols(e: ast.Expr, cn: CheckedNode, enc: Encoder) -> set[str]:
    """The Z3 symbol names of the I/O variables formula ``e`` of ``cn`` mentions (bound names excluded)."""
    free = free_names(e)
    out = set()
    for v in subexpressions(e):
        if isinstance(v, ast.Var):
            if v.prefix is not None:
                out.add(enc.symbol_name(cn.name, v.prefix, v.name))
            elif v.name in free and (v.name in cn.inputs or v.name in cn.outputs):
                out.add(enc.symbol_name(cn.name, "in" if v.name in cn.inputs else "out", v.name))
    return out



def definedness(formal: Formal, assuming: Sequence[Formal], enc: Encoder, symbols: dict[str, z3.AstRef]
                ) -> list[tuple[Condition, z3.BoolRef]]:
    """The well-definedness conditions of a requirement's ``assuming:``
    formulas (each under the ones before it) and of its statement
    (:func:`rclverify.semantics.definedness.conditions`), each with its Z3
    formula over the statements' ``symbols``; empty when nothing divides."""
    out: list[tuple[Condition, z3.BoolRef]] = []
    before: list[ast.Expr] = []
    for f in (*assuming, formal):
        for c in conditions(f.expr):
            closed = c.formula if not before else ast.Binary("->", conjoin(before, f.expr.loc), c.formula, c.loc)
            out.append((c, enc.formula(closed, f.scope, symbols)))
        before.append(f.expr)
    return out



def first_undefined(q: Query, formal: Formal, assuming: Sequence[Formal], symbols: dict[str, z3.AstRef], rid: str,
               timeout_ms: int) -> tuple[Condition, list[tuple[str, z3.BoolRef]], QueryResult] | None:
    """The first definedness condition of the statement the query's
    premises do not ensure, with the labelled query that breaks it (the
    premises and the condition negated) and its answer (``sat``, with the
    model); ``None`` when each is ensured or undecided."""
    premises = [(lbl, f) for lbl, f in q.labelled if lbl != NEGATED]
    for cond, f in definedness(formal, assuming, q.enc, symbols):
        asked = [*premises, ("undefined", z3.Not(f))]
        r = satisfiable(asked, q.enc, timeout_ms=timeout_ms,
                        comment=f"rclverify requirement {rid}: is {cond.text} ({cond.where}) ensured? sat means not")
        if r.status == "sat":
            return cond, asked, r
    return None



def ask(base: RequirementBase, nodes: Sequence[str], formal: Formal, assuming: Sequence[Formal], checked: Checked,
         model: SystemModel, plan: Plan, timeout_ms: int,
         note: str = "") -> tuple[Query, dict[str, z3.AstRef], z3.BoolRef, QueryResult]:
    """The labelled query ``premises of nodes and assuming and not formal``
    (``base``: the record's plan keys; ``note`` a line added to the script's
    comment).  Returns the query, the statements' symbols, the statement's
    term and Z3's answer.  The caller holds the term while it reads the
    answer's scripts and asks its other queries: Z3's printer names (``let``)
    a term that other references share, and a freed term's id goes to the
    next new one, so the scripts depend on which terms Python still holds."""
    q = Query(Encoder(checked.env, model.alias()))
    q.cone_premises(nodes, checked, model, plan)
    # the statements' variables are named Node.in.x in their pseudo node (model/plan/formal.py); the encoder looks
    # an input/output up as "<in|out>.<name>", here "in.Node.in.x", and takes the node's own symbol
    enc = q.enc
    symbols = {f"{p}.{n}.{p}.{v}": enc.io_symbol(checked.nodes[n], p, v)
               for f in (formal, *assuming) for n, p, v in f.mentions}
    for k, a in enumerate(assuming, 1):
        q.add(f"assuming {k}", "assuming", None, k, a.expr, enc.formula(a.expr, a.scope, symbols))
    defined = [f for _, f in definedness(formal, assuming, enc, symbols)]
    goal = enc.formula(formal.expr, formal.scope, symbols)
    if defined:  # the statement and its definedness (docs/semantics.md, "Definedness")
        goal = z3.And(*defined, goal)
    q.labelled.append((NEGATED, z3.Not(goal)))
    head = (f"rclverify requirement {base['id']}: {base['formal']}\nsource {base['source']}; "
            "unsat means the requirement follows from the premises" + note)
    return q, symbols, goal, satisfiable(q.labelled, enc, timeout_ms=timeout_ms, comment=head)



class Query:
    """The premises of one requirement's query: each listed for the record
    (``premises``, ``by_label``) and labelled for Z3's unsat core
    (``labelled``); ``g_symbols`` the inputs and outputs each guarantee reads."""

    def __init__(self, enc: Encoder) -> None:
        self.enc = enc
        self.premises: list[dict[str, Any]] = []
        self.by_label: dict[str, dict[str, Any]] = {}
        self.labelled: list[tuple[str, z3.BoolRef]] = []
        self.g_symbols: dict[str, set[str]] = {}

    def add(self, label: str, kind: str, node: str | None, index: int, e: ast.Expr, f: z3.BoolRef,
            text: str | None = None) -> None:
        row = {"label": label, "kind": kind, "node": node, "index": index,
               "text": text if text is not None else expr_to_rcl(e), "source": where(e.loc)}
        self.premises.append(row)
        self.by_label[label] = row
        self.labelled.append((label, f))

    def cone_premises(self, cone: Sequence[str], checked: Checked, model: SystemModel, plan: Plan) -> None:
        """The guarantees, environment assumptions and environment facts of the cone's nodes."""
        enc = self.enc
        for n in cone:
            cn = checked.nodes[n]
            for k, g in enumerate(cn.node.guarantees, 1):
                label = f"{n} guarantee {k}"
                self.add(label, "guarantee", n, k, g.formula, enc.formula(g.formula, cn))
                self.g_symbols[label] = io_symbols(g.formula, cn, enc)
            for k, c in enumerate(split_assumption(checked, model, n)[1], 1):
                self.add(f"{n} environment assumption {k}", "environment assumption", n, k, c, enc.formula(c, cn))
            for k, fact in enumerate(plan.facts.get(n, ()), 1):
                self.add(f"{n} environment fact {k}", "environment fact", n, k, fact.expr,
                         enc.formula(fact.expr, cn))
