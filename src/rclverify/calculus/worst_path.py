"""The worst timing path of an end-to-end deadline.

A requirement's ``deadline: {path: [A, ..., B], within: d}`` names one path
of nodes; rule D3 (:mod:`.deadlines`) sums the timed guarantees along it.
But B's output may also be answered through another path from A (a branch
that joins again), and its answer may come later.  As AGREE's latency
analysis does, every simple path of the system model from A to B whose
timed guarantees chain (each hop triggered by an output of the one before,
D2) is decided too, and the slowest one, when it is not the named one, is
reported: it refutes the deadline when its sum exceeds ``d``, and it is
named in the record either way.

Paths are enumerated up to :data:`MAX_PATHS` (networkx's simple-path
enumeration, loops never repeated); beyond it the record says the search was
cut, and a deadline the paths examined do not refute is ``inconclusive``,
never ``proved`` (a path not examined may be the slow one).
"""
from __future__ import annotations

from dataclasses import replace
from fractions import Fraction
from typing import Any, Sequence

from rclverify.lang.types import Checked
from rclverify.model.system.model import SystemModel, names_of
from rclverify.calculus.deadlines import INCONCLUSIVE, PROVED, REFUTED, _show, chains, decide
import itertools

#: The largest number of paths from A to B examined.
MAX_PATHS = 200


def _graph(model: SystemModel) -> Any:
    """The links of ``model`` as a networkx ``DiGraph`` over its nodes."""
    import networkx as nx  # deferred: start-up (loads networkx when called)
    g = nx.DiGraph()
    g.add_nodes_from(model.nodes)
    g.add_edges_from((lk.from_node, lk.to_node) for lk in model.links)
    return g


def _between(g: Any, first: str, last: str) -> set[str]:
    """The nodes of ``g`` reachable from ``first`` that reach ``last`` (both included)."""
    import networkx as nx  # deferred: start-up (loads networkx only when called)
    both: set[str] = (nx.descendants(g, first) | {first}) & (nx.ancestors(g, last) | {last})
    return both


def other_paths(model: SystemModel, path: Sequence[str]) -> tuple[list[tuple[str, ...]], bool]:
    """``(paths, cut)``: the simple paths of ``model`` from ``path[0]`` to
    ``path[-1]`` other than ``path`` (at most :data:`MAX_PATHS`; ``cut``
    when there were more).  Every node of such a path is reachable from the
    first and reaches the last, so the search runs in the subgraph of those
    nodes: the same paths in the same order, without walking the rest of
    the system (a 1000-node system with loops downstream of the deadline
    took minutes to enumerate before)."""

    import networkx as nx  # deferred: start-up (loads networkx only when called)
    g = _graph(model)
    if path[0] not in g or path[-1] not in g or len(path) < 2:
        return [], False
    it = nx.all_simple_paths(g.subgraph(_between(g, path[0], path[-1])), path[0], path[-1])
    found = [tuple(p) for p in itertools.islice(it, MAX_PATHS + 1)]
    cut = len(found) > MAX_PATHS
    return [p for p in found[:MAX_PATHS] if p != tuple(path)], cut


def nodes_between(model: SystemModel, path: Sequence[str]) -> tuple[str, ...]:
    """The nodes whose contracts the decision of a deadline along ``path``
    reads: those of ``path``, then (in ``model.nodes`` order) every node
    reachable from ``path[0]`` that reaches ``path[-1]`` in ``model``'s
    links, a superset of the nodes on the simple paths
    :func:`with_worst_path` may take as the slowest.  The ``deadlines`` task
    depends on their snapshots: an edit of a hop off the named path changes
    the verdict too (an incremental run kept a deadline refuted
    that a clean run proved)."""
    masks = model.upstream_masks()  # bit i: model.nodes[i]; a node's mask holds the node and all that reach it
    if len(path) < 2 or path[0] not in masks or path[-1] not in masks:
        return tuple(path)
    # read off the last node's upstream cone (the model's masks, built once): the nodes whose own cone holds
    # the first; a graph built per call cost 0.06 s a deadline at 5000 nodes, 49 deadlines per process
    first = 1 << model.nodes.index(path[0])
    between = [n for n in names_of(masks[path[-1]], model.nodes) if masks[n] & first]
    return tuple(dict.fromkeys([*path, *between]))


def with_worst_path(result: Any, checked: Checked, model: SystemModel) -> Any:
    """``result`` (a :class:`.deadlines.DeadlineResult` of the named path)
    with the slowest other path considered: refuted by it when its chain's
    sum exceeds the bound (its chain, sum and stamps then shown, the named
    path kept as the record's ``path``), and ``worst_path`` naming it when
    it is slower than the named one."""
    worst: tuple[tuple[str, ...], Fraction] | None = None
    paths, cut = other_paths(model, result.path)
    for p in paths:
        found, _ = chains(checked, model, p)
        if not found:
            continue  # no chain of timed guarantees along it: not a timing path
        tight = min(sum((h.bound for h in c), Fraction(0)) for c in found)
        if worst is None or tight > worst[1]:
            worst = (p, tight)
    note = f" (more than {MAX_PATHS} paths: the search was cut)" if cut else ""
    if worst is None or (result.total is not None and worst[1] <= result.total):
        return _cut(replace(result, reason=result.reason + note) if note else result, cut)
    p, total = worst
    named = " -> ".join(result.path)
    if result.status == PROVED and total > result.within:
        other = decide(checked, model, result.requirement, p, result.within, result.loc)
        if other.status == REFUTED:
            return replace(other, path=result.path, worst_path=p,
                           reason=f"another path from {p[0]} to {p[-1]} is slower than the one named ({named}): "
                                  f"{other.reason}" + note)
    return _cut(replace(result, worst_path=p, reason=f"{result.reason}; the slowest path from {p[0]} to {p[-1]} is "
                                                     f"{' -> '.join(p)}, {_show(total)}, not the one named{note}"), cut)


def _cut(result: Any, cut: bool) -> Any:
    """``result``, not ``proved`` when the path search was cut: a path not
    examined may be slower than the bound, so the named path's proof does
    not prove the deadline (``inconclusive``, saying so)."""
    if not cut or result.status != PROVED:
        return result
    return replace(result, status=INCONCLUSIVE,
                   reason=f"{result.reason}; not every path from {result.path[0]} to {result.path[-1]} was examined "
                          f"(more than {MAX_PATHS}), and one not examined may be slower than the bound: not proved")
