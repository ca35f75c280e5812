"""What each node of an upstream cone contributes to an in-context query,
as data: its labelled premises in SMT-LIB text (docs/calculus.md, "Side
conditions in context").

For a node ``m`` of the cone of a consumer (:mod:`.context`): each
guarantee ``k`` (``m guarantee k``; taken under ``m``'s assumption, paper
lines 462-495), unless ``m`` is the consumer; the environment conjuncts of
``m``'s assumption (``m environment assumption k``); the plan's
environment facts of ``m`` (``m environment fact k``).  Kept per process:
along a chain each node is in the cone of every node after it, and the
cone summaries (:mod:`.summary`) read the same premises.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping, Sequence, TypedDict

from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.types import Checked
from rclverify.model.system.model import SystemModel
from rclverify.targets.smtlib import to_smt


@dataclass(frozen=True)
class NodePremises:
    """What one node of a cone contributes, as data (no Z3 object), kept
    per process by :func:`node_premises`.  ``items``: ``(label, RCL text,
    kind, index, SMT-LIB text or None)`` with kind ``guarantee``,
    ``environment`` or ``fact``; ``assumption``: the SMT-LIB text of the
    node's assumption (``None``: none or ``TRUE``); ``smt``: every formula
    of the node is in :mod:`rclverify.targets.smtlib`'s fragment; ``symbols``: ``{symbol
    name: (prefix, var)}`` of the I/O the texts mention."""

    items: tuple[tuple[str, str, str, int, str | None], ...]
    assumption: str | None
    smt: bool
    symbols: tuple[tuple[str, str, str], ...]


class _Cache(TypedDict):
    """The premises remembered for the last (checked, model) pair, by node, role, facts and symbols."""
    key: tuple[Checked, SystemModel] | None
    nodes: dict[Any, NodePremises]


_CACHE: _Cache = {"key": None, "nodes": {}}


def node_premises(checked: Checked, model: SystemModel, m: str, consumer: bool,
                   environment: Sequence[ast.Expr], facts: Sequence[ast.Expr],
                   symbol: Mapping[tuple[str, str], str]) -> NodePremises:
    """Node ``m``'s premises (``consumer``: ``m`` is the node whose side
    condition is decided: its own guarantees are no premise), remembered
    for the last (checked, model) pair by everything they depend on (the
    node, its role, its facts' text, the symbols of its I/O): along a chain
    each node is in the cone of every node after it."""
    if _CACHE["key"] is None or _CACHE["key"][0] is not checked or _CACHE["key"][1] is not model:
        _CACHE["key"], _CACHE["nodes"] = (checked, model), {}
    fact_texts = tuple(expr_to_rcl(f) for f in facts)
    key = (m, consumer, fact_texts, tuple(sorted(symbol.items())))
    cache: dict[Any, NodePremises] = _CACHE["nodes"]
    hit = cache.get(key)
    if hit is not None:
        return hit
    cn = checked.nodes[m]
    used: dict[str, str] = {}
    items: list[tuple[str, str, str, int, str | None]] = []
    assumption: str | None = None
    smt = True
    if not consumer:
        parts = [a.formula for a in cn.node.assumes if not (isinstance(a.formula, ast.BoolLit) and a.formula.value)]
        texts = [to_smt(a, cn, symbol, used) for a in parts]
        smt = smt and all(t is not None for t in texts)
        if parts and smt:
            assumption = texts[0] if len(texts) == 1 else "(and " + " ".join(t or "" for t in texts) + ")"
        for k, g in enumerate(cn.node.guarantees, 1):
            t = to_smt(g.formula, cn, symbol, used)
            smt = smt and t is not None
            items.append((f"{m} guarantee {k}", expr_to_rcl(g.formula) + (" (under its assumption)" if parts else ""),
                          "guarantee", k, t))
    for k, c in enumerate(environment, 1):
        t = to_smt(c, cn, symbol, used)
        smt = smt and t is not None
        items.append((f"{m} environment assumption {k}", expr_to_rcl(c), "environment", k, t))
    for k, (f, ftext) in enumerate(zip(facts, fact_texts), 1):
        t = to_smt(f, cn, symbol, used)
        smt = smt and t is not None
        items.append((f"{m} environment fact {k}", ftext, "fact", k, t))
    names = {name: pv for pv, name in symbol.items()}
    out = NodePremises(tuple(items), assumption, smt, tuple((n, *names[n]) for n in sorted(used)))
    cache[key] = out
    return out
