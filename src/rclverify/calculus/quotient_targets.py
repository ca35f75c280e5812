"""What a quotient (:mod:`.quotient`) must make hold (:class:`Target`: a
side condition or a requirement), and its computed contract put in place
and checked against them again before anything is printed: the node's block with the
computed clauses (:func:`node_block`), the whole system type-checked with
it, every target's side condition decided and every target requirement
checked (:func:`recheck_targets`, :func:`confirmed`), and, for a node that has a
contract, the computed one compared with it (:func:`compare_contract`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Sequence

import z3

from rclverify.semantics.connectives import conj
from rclverify.semantics.encode import Encoder
from rclverify.semantics.query import prove
from rclverify.lang import ast
from rclverify.lang.parser import parse_formula, parse_text
from rclverify.lang.printer import node_to_rcl
from rclverify.lang.types import Checked
from rclverify.model.system.model import SystemModel
from rclverify.calculus.compose import compose_node
from rclverify.model.plan.load import all_requirements
from rclverify.semantics import world
from rclverify.lang.typecheck import check
from rclverify.model.system.model import build

#: Re-check verdicts that rest on a proof (Z3's unsat), which a second solver confirms.
PROVED = ("discharged", "discharged in context", "proved")
#: Agreements of the second solver that make a proved re-check inconclusive (stages/crosscheck/stage.py).
NOT_CONFIRMED = ("disagree", "inconclusive")


def conj_all(fs: Sequence[z3.BoolRef]) -> z3.BoolRef:
    """The conjunction of ``fs`` (``True`` for none)."""
    return conj(*fs) if len(fs) > 1 else fs[0] if fs else z3.BoolVal(True)


@dataclass(frozen=True)
class Target:
    """What the quotient must make hold: ``kind`` ``side condition`` or
    ``requirement``, ``id`` (``N2.sc1``, ``REQ1``), ``text`` (RCL), the
    premises ``P_t`` and goal as Z3 formulas."""

    kind: str
    id: str
    text: str
    premises: tuple[z3.BoolRef, ...]
    goal: z3.BoolRef
    consumer: str = ""
    conjunct: ast.Expr | None = None


def confirmed(decided: Sequence[tuple[str, str, str]], confirm: Callable[[str], tuple[str, str]] | None
               ) -> tuple[list[tuple[str, str]], list[tuple[str, str, str]]]:
    """The re-check's ``(id, verdict)`` pairs and the second solver's
    ``(id, agreement, why)`` sayings: a proved verdict ``confirm`` does not
    confirm becomes inconclusive (``decided``: ``(id, verdict, SMT-LIB2
    script)`` from :func:`recheck_targets`)."""
    said: list[tuple[str, str, str]] = []
    recheck: list[tuple[str, str]] = []
    for i, v, script in decided:
        if confirm is not None and v in PROVED and script:
            agreement, why = confirm(script)
            said.append((i, agreement, why))
            if agreement in NOT_CONFIRMED:
                v = f"inconclusive (second solver: {why})"
        recheck.append((i, v))
    return recheck, said


def node_block(n: ast.Node, a_text: str, g_text: str) -> str:
    """RCL of ``n``'s interface with the computed clauses (parsed, so the
    canonical printer writes them)."""
    clauses = ([] if a_text == "TRUE" else [ast.Clause(parse_formula(a_text))])
    node = ast.Node(n.name, n.inputs, n.outputs, n.topics, tuple(clauses) or (ast.Clause(ast.BoolLit(True)),),
                    (ast.Clause(parse_formula(g_text)),), n.loc, n.links)
    return node_to_rcl(node)


def recheck_targets(checked: Checked, plan: Any, node: str, block: str,
             tgts: Sequence[Target]) -> list[tuple[str, str, str]]:
    """Every target's verdict with ``block`` in place of ``node`` (module
    docstring): ``(id, verdict, the SMT-LIB2 script it was decided from)``."""
    from rclverify.calculus.requirements.check import check_requirement  # deferred: start-up (loads rclverify.calculus.health, rclverify.calculus.requirements and more only when called)
    file = checked.nodes[node].node.loc.file
    [new] = parse_text(block, file).nodes
    specs = [ast.Spec(s.contexts, tuple(new if x.name == node else x for x in s.nodes), s.file) for s in checked.specs]
    checked2 = check(specs)
    model2 = build(checked2, plan.connections)
    facts = {m: [f.expr for f in fs] for m, fs in plan.facts.items()}
    out: list[tuple[str, str, str]] = []
    consumers = sorted({t.consumer for t in tgts if t.kind == "side condition"} | {node},
                       key=list(checked2.nodes).index)
    verdicts: dict[str, tuple[str, str]] = {}
    for d in consumers:
        world.fresh()
        for sc in compose_node(checked2, model2, d, facts=facts).side_conditions:
            verdicts[sc.id] = (sc.verdict or sc.status, sc.smt2 or "")
    out += [(sid, v, smt2) for sid, (v, smt2) in verdicts.items() if sid.startswith(f"{node}.")]
    for t in tgts:
        if t.kind == "side condition":
            out.append((t.id, *verdicts.get(t.id, ("absent", ""))))
    reqs = {r.id: r for r in all_requirements(plan)}
    for t in tgts:
        if t.kind == "requirement":
            world.fresh()
            rec = check_requirement(reqs[t.id], checked2, model2, plan)
            v = str(rec.get("verdict"))
            if v == "proved" and rec.get("consistency") == "inconsistent":
                v = "proved from an inconsistency"
            out.append((t.id, v, str(rec.get("smt2") or "")))
    world.fresh()
    return out


def compare_contract(cn: Any, a_text: str, g_text: str, checked: Checked, model: SystemModel, plan: Any) -> list[str]:
    """For a node that has a contract (one being replaced): does the
    context discharge its assumption, and does its guarantee give what the
    neighbours need (Z3, both where the computed assumption holds)?"""
    n = cn.node
    if not n.assumes and not n.guarantees:
        return []
    world.fresh()
    enc = Encoder(checked.env, model.alias())
    a_new, g_new = enc.formula(parse_formula(a_text), cn), enc.formula(parse_formula(g_text), cn)
    a_cur = conj_all([enc.formula(c.formula, cn) for c in n.assumes])
    g_cur = conj_all([enc.formula(c.formula, cn) for c in n.guarantees])
    r1 = prove(a_cur, [a_new], enc)
    r2 = prove(g_new, [a_new, a_cur, g_cur], enc)
    say = {"proved": "yes", "refuted": "no", "inconclusive": "undecided"}
    world.fresh()
    return [f"the current assumption of {n.name} holds wherever the computed one does: {say[r1.status]}",
            f"the current guarantee of {n.name} gives what the neighbours need: {say[r2.status]}"]
