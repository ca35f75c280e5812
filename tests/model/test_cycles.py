"""Johnson's elementary cycles (model/system/cycles.py) against brute force and networkx."""
from __future__ import annotations

import itertools
import random

import pytest

from rclverify.model.system.cycles import elementary_cycles


def _canonical(cycles: list[list[int]]) -> list[tuple[int, ...]]:
    out = []
    for c in cycles:
        k = c.index(min(c))
        out.append(tuple(c[k:] + c[:k]))
    return sorted(out)


def _brute_force(n: int, edges: set[tuple[int, int]]) -> list[tuple[int, ...]]:
    """Every vertex sequence without repeats, starting at its least vertex, closed by edges."""
    out = []
    for size in range(1, n + 1):
        for combo in itertools.permutations(range(n), size):
            if combo[0] != min(combo):
                continue
            if all((combo[i], combo[(i + 1) % size]) in edges for i in range(size)):
                out.append(combo)
    return sorted(out)


@pytest.mark.parametrize("seed", range(60))
def test_cycles_are_every_elementary_cycle(seed: int) -> None:
    rng = random.Random(seed)
    n = rng.randint(1, 6)
    edges = {(rng.randrange(n), rng.randrange(n)) for _ in range(rng.randint(0, n * n))}
    listed = list(edges) + list(edges)[:2]  # a repeated edge counts once
    got = elementary_cycles(list(range(n)), listed)
    assert len(got) == len(set(map(tuple, got)))
    assert _canonical(got) == _brute_force(n, edges)


def test_agrees_with_networkx_on_larger_graphs() -> None:
    nx = pytest.importorskip("networkx")
    for seed in range(10):
        rng = random.Random(seed)
        n = 40
        edges = {(k, k + 1) for k in range(n - 1)} | {(rng.randrange(n), rng.randrange(n)) for _ in range(25)}
        g = nx.DiGraph()
        g.add_nodes_from(range(n))
        g.add_edges_from(edges)
        assert _canonical(elementary_cycles(list(range(n)), edges)) == _canonical(list(nx.simple_cycles(g)))


def test_a_long_ring_needs_no_recursion() -> None:
    n = 5000
    assert elementary_cycles(list(range(n)), [(k, (k + 1) % n) for k in range(n)]) == [list(range(n))]
