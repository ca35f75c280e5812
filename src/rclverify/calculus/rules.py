"""The composition rules of the paper (R1 sequence, lines 564-590; R2 branch,
612-640; R3 join, 664-690; R4 loop, 717-768): which rules a node's
connections select (:func:`instance_rule`, :func:`rules_at`), and the rule
instance that derives its contract from its producers' (:func:`rule_instances`:
premises, conclusion, graph shape in words), as
:mod:`rclverify.calculus.compose` records them.
"""
from __future__ import annotations

from typing import Sequence

from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.types import Checked
from rclverify.model.system.model import SystemModel
from rclverify.records.composition_records import RuleInstance


R4_ASSUMPTION = (
    "Rule R4 (paper lines 717-768) is applied because {loop} form a loop. It rests on an extra assumption the "
    "contracts cannot show: every node in the loop terminates and produces an output for each input that "
    "satisfies its assumption, and outputs persist once produced (R3's simplifying assumption, line 660), so "
    "the inputs that close the loop are available together. The paper assumes contracts are not circularly "
    "dependent (line 712); this system's are."
)


def contract_text(exprs: Sequence[ast.Expr]) -> str:
    """Conjunction of formulas as RCL text (``TRUE`` when empty)."""
    if not exprs:
        return "TRUE"
    if len(exprs) == 1:
        return expr_to_rcl(exprs[0])
    return " and ".join(f"({expr_to_rcl(e)})" for e in exprs)


def branch_siblings(model: SystemModel, node: str) -> list[str]:
    """Other readers of the outputs that feed ``node`` (an output read by
    several nodes is a branch, rule R2, paper lines 612-640), source order."""
    others = {r for l in model.links_into(node) for r in model.readers(l.from_node, l.from_var) if r != node}
    return [n for n in model.nodes if n in others] if others else []


def instance_rule(model: SystemModel, node: str) -> str | None:
    """The rule whose instance derives ``node``'s contract from its producers:
    ``R3`` (several producers: a join, lines 664-690), ``R2`` (one producer
    whose output another node also reads: a branch, lines 612-640), ``R1``
    (one producer feeding only ``node``: a sequence, lines 564-590), ``None``
    (no producer)."""
    producers = model.producers(node)
    if len(producers) > 1:
        return "R3"
    if not producers:
        return None
    return "R2" if branch_siblings(model, node) else "R1"


def rules_at(model: SystemModel, node: str) -> tuple[str, ...]:
    """Rules applied at ``node``: its instance's rule, ``R2`` as well when a
    join's input comes from a branching output, ``R4`` on a cycle."""
    rules: list[str] = []
    r = instance_rule(model, node)
    if r is not None:
        rules.append(r)
    if r == "R3" and branch_siblings(model, node):
        rules.append("R2")
    if model.loop_of(node):
        rules.append("R4")
    return tuple(rules)


def rule_instances(checked: Checked, model: SystemModel, node: str, rule: str, a_text: str, g_text: str,
               any_side_condition: bool) -> list[RuleInstance]:
    """The rule instance of ``node`` (none without producers): its rule,
    premises (each producer's contract, the node's, a branch's other
    readers, the side condition), conclusion and graph shape."""
    producers = model.producers(node)
    if not producers:
        return []
    premises = []
    prem_a = []
    siblings = branch_siblings(model, node) if rule == "R2" else []
    for p in producers:
        pn = checked.nodes[p]
        pa = contract_text([a.formula for a in pn.node.assumes])
        premises.append(f"{p}: ({pa}) => <> ({contract_text([g.formula for g in pn.node.guarantees])})")
        prem_a.append(pa)
    premises.append(f"{node}: ({a_text}) => <> ({g_text})")
    for sib in siblings:
        premises.append(f"{sib} (the other reader of the branch; its own side condition is checked at {sib})")
    premises.append("side condition: " + " and ".join(f"G_{p}" for p in producers) + f" => A_{node}"
                    + ("" if any_side_condition else " (no conjunct of the assumption ranges over produced inputs)"))
    return [{"rule": rule, "premises": premises,
             "conclusion": " and ".join(f"({a})" for a in prem_a) + f" => <> G_{node}",
             "shape": shape_text(rule, producers, node, siblings)}]


def shape_text(rule: str, producers: Sequence[str], node: str, siblings: Sequence[str]) -> str:
    """The graph shape that selects ``rule``, in words."""
    if rule == "R3":
        return f"join: {', '.join(producers)} feed {node}"
    if rule == "R2":
        return f"branch: the output of {producers[0]} that {node} reads is also read by {', '.join(siblings)}"
    return f"sequence: {producers[0]} feeds {node} only"
