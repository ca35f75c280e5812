"""The elementary cycles of a directed graph (Johnson's algorithm).

Source: D. B. Johnson, "Finding all the elementary circuits of a directed
graph", SIAM J. Comput. 4(1), 1975.  The vertices are taken in a fixed
order; for each strongly connected component (Tarjan, "Depth-first search
and linear graph algorithms", SIAM J. Comput. 1(2), 1972) the circuits
through its least vertex ``s`` are enumerated by a depth-first search that
*blocks* a vertex once it is on the path, and unblocks it only when a
circuit was found through it (vertices that could not reach ``s`` stay
blocked, recorded in the lists ``B`` of the paper, so no dead end is
searched twice); then ``s`` is removed and the components of the rest of
the component are searched the same way.  Time ``O((V + E)(C + 1))`` for
``C`` circuits.  Written here so that the pipeline does not import networkx
(0.15-0.2 s of every cold ``doit`` run) for its one use of it.  Tarjan's
components also give every node's upstream cone as a bit mask in one union
per link (:func:`upstream_bits`), for the system model and the report's
confidence claims.
"""
from __future__ import annotations

from typing import Hashable, Iterable, Sequence, TypeVar

N = TypeVar("N", bound=Hashable)


def strongly_connected_components(nodes: Sequence[N], succ: dict[N, list[N]]) -> list[list[N]]:
    """The strongly connected components of the graph restricted to
    ``nodes`` (``succ``: node -> its successors; every node of ``nodes`` a
    key), by Tarjan's algorithm, iteratively; each component's nodes in the
    order of ``nodes``.  A component comes after every component it reaches
    (Tarjan completes a component only then)."""
    inside = set(nodes)
    index: dict[N, int] = {}
    low: dict[N, int] = {}
    on_stack: set[N] = set()
    stack: list[N] = []
    out: list[list[N]] = []
    for root in nodes:
        if root in index:
            continue
        work = [(root, iter([m for m in succ[root] if m in inside]))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            v, it = work[-1]
            w = next(it, None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter([m for m in succ[w] if m in inside])))
                elif w in on_stack:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp: set[N] = set()
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    comp.add(w)
                    if w == v:
                        break
                out.append([n for n in nodes if n in comp])
    return out


def _circuits_through(s: N, comp: set[N], succ: dict[N, list[N]]) -> list[list[N]]:
    """Every elementary circuit through ``s`` inside the component ``comp``
    (Johnson's CIRCUIT procedure, with an explicit stack), each starting at ``s``."""
    out: list[list[N]] = []
    blocked: set[N] = {s}
    waiting: dict[N, set[N]] = {}  # the paper's B(w): vertices to unblock when w is unblocked
    path: list[N] = [s]
    found: list[bool] = [False]  # per path position: a circuit was closed below it
    todo: list[list[N]] = [[m for m in succ[s] if m in comp]]

    def unblock(u: N) -> None:
        pending = [u]
        while pending:
            x = pending.pop()
            if x in blocked:
                blocked.discard(x)
                pending.extend(waiting.pop(x, ()))

    while todo:
        nexts = todo[-1]
        if nexts:
            w = nexts.pop()
            if w == s:
                out.append(list(path))
                found[-1] = True
            elif w not in blocked:
                path.append(w)
                found.append(False)
                blocked.add(w)
                todo.append([m for m in succ[w] if m in comp])
            continue
        v, closed = path.pop(), found.pop()
        todo.pop()
        if closed:
            unblock(v)
        else:
            for m in succ[v]:
                if m in comp:
                    waiting.setdefault(m, set()).add(v)
        if found:
            found[-1] = found[-1] or closed
    return out


def upstream_bits(nodes: Sequence[N], preds: dict[N, list[N]]) -> dict[N, int]:
    """Each node's upstream cone as a bit mask (bit ``i`` is ``nodes[i]``):
    the node and every node with a path to it over ``preds`` (node -> the
    nodes it reads from; every node of ``nodes`` a key; names outside
    ``nodes`` are left out).  The strongly connected components are taken
    producers first (:func:`strongly_connected_components` over ``preds``),
    each component's mask its nodes' bits or-ed with the masks of the
    producers outside it: one union per link, loops included (the nodes of
    a loop reach one another), and exactly the least fixpoint of
    ``cone(n) = {n} + cone(p)``.  A worklist fixpoint over a depth-first
    order, as the system model had it, re-propagated each loop's growth down
    the rest of the system (3 s at 5000 nodes with a loop every tenth node)."""
    bit = {n: 1 << i for i, n in enumerate(nodes)}
    mask: dict[N, int] = {}
    for members in strongly_connected_components(nodes, preds):
        inside = set(members)
        acc = 0
        for n in members:
            acc |= bit[n]
            for p in preds[n]:
                if p not in inside and p in bit:
                    acc |= mask[p]
        for n in members:
            mask[n] = acc
    return mask


def elementary_cycles(nodes: Sequence[N], edges: Iterable[tuple[N, N]]) -> list[list[N]]:
    """Every elementary cycle of the directed graph with vertices ``nodes``
    and ``edges`` (pairs of vertices; repeated edges count once; an edge
    from a vertex to itself is the cycle ``[v]``), each as its vertex
    sequence, in no particular order: consecutive vertices (and the last
    and the first) are joined by an edge, no vertex repeats.  Raises
    ``KeyError`` for an edge with a vertex outside ``nodes``."""
    succ: dict[N, list[N]] = {n: [] for n in nodes}
    seen: set[tuple[N, N]] = set()
    out: list[list[N]] = []
    for a, b in edges:
        if (a, b) in seen:
            continue
        seen.add((a, b))
        if b not in succ:
            raise KeyError(b)
        if a == b:
            out.append([a])
        else:
            succ[a].append(b)
    todo = [c for c in strongly_connected_components(list(nodes), succ) if len(c) > 1]
    while todo:
        comp = todo.pop()
        s, rest = comp[0], comp[1:]
        out += _circuits_through(s, set(comp), succ)
        todo += [c for c in strongly_connected_components(rest, succ) if len(c) > 1]
    return out


__all__ = ["elementary_cycles"]
