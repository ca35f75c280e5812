"""The shape of a node's upstream cone (rule R4, paper lines 717-768): the
links at which its loops are opened (:func:`opened_links`), and the nodes
with more than one path to it over the links left (:func:`multi_path`,
:func:`single_paths`).  :mod:`rclverify.calculus.context` builds the cone's
premises on this shape; :mod:`rclverify.calculus.summary` and
:mod:`rclverify.calculus.quotient` read it too.
"""
from __future__ import annotations

from typing import Sequence

from rclverify.core.cache.memo import last_call
from rclverify.model.system.model import Link, SystemModel


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


@last_call  # one model per run: its mask made once
def _joins(model: SystemModel) -> int:
    """The bit mask (over ``model.nodes``) of the nodes with two or more links into them."""
    return sum(1 << i for i, n in enumerate(model.nodes) if len(model.links_into(n)) > 1)


def single_paths(model: SystemModel, node: str) -> bool:
    """Whether no node of ``node``'s upstream cone has two or more links
    into it.  Then every node of the cone has at most one path to ``node``
    (two paths from one node part somewhere and meet again at a node with
    two links in, and that node is in the cone), so :func:`multi_path`
    over the cone is empty whatever links are cut.  One test of the cone's
    bit mask (:meth:`SystemModel.upstream_masks`) against the mask of such
    nodes, made once per model, instead of a walk over the cone: along a
    chain the walks added up to N*N/2 steps (docs/scale.md)."""
    return model.upstream_masks().get(node, 0) & _joins(model) == 0


def multi_path(model: SystemModel, node: str, cone: Sequence[str], cut: set[tuple[str, str, str, str]]) -> set[str]:
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
