"""The calculus's test for cones without joins (calculus/context.py, ``single_paths``; issue 67):
when it holds, the path count over the cone (``multi_path``, the reference) finds no node with two
paths, with or without links cut; checked on random graphs, loops and repeated links included, and
against a brute-force count of the paths."""
from __future__ import annotations

import itertools

import networkx as nx
from hypothesis import given, settings
from hypothesis import strategies as st

from rclverify.calculus.cone_paths import multi_path, single_paths
from rclverify.model.system.model import Link, SystemModel


@st.composite
def systems(draw):
    n = draw(st.integers(1, 6))
    nodes = tuple(f"N{i}" for i in range(n))
    pairs = draw(st.lists(st.tuples(st.sampled_from(nodes), st.sampled_from(nodes)), max_size=9))
    links = tuple(Link(a, f"o{k}", b, f"i{k}", "name") for k, (a, b) in enumerate(pairs) if a != b)
    return SystemModel(nodes, links, (), ()), draw(st.randoms())


def _paths_brute(model: SystemModel, node: str, cut: set) -> set[str]:
    """Nodes with two or more paths (a path: a sequence of links, each kept) to ``node``, by enumeration."""
    g = nx.MultiDiGraph()
    g.add_nodes_from(model.nodes)
    g.add_edges_from((l.from_node, l.to_node) for l in model.links
                     if (l.from_node, l.from_var, l.to_node, l.to_var) not in cut)
    return {v for v in model.nodes if v != node
            and sum(1 for _ in nx.all_simple_edge_paths(g, v, node)) > 1}


@settings(max_examples=120, deadline=None)
@given(systems())
def test_single_paths_means_no_node_with_two_paths(sm) -> None:
    model, rnd = sm
    keys = [(l.from_node, l.from_var, l.to_node, l.to_var) for l in model.links]
    for cut in (set(), set(rnd.sample(keys, len(keys) // 2))):
        kept = nx.DiGraph()
        kept.add_edges_from((k[0], k[2]) for k in keys if k not in cut)
        acyclic = nx.is_directed_acyclic_graph(kept)
        for node in model.nodes:
            got = multi_path(model, node, model.upstream(node), cut)
            if single_paths(model, node):
                assert got == set()
            if acyclic:  # the reference itself, against the enumeration
                assert got == _paths_brute(model, node, cut)


def test_a_join_is_seen() -> None:
    """A diamond: D has two links in, so A's two paths are found and single_paths is false for D only."""
    links = tuple(Link(a, f"o{k}", b, f"i{k}", "name") for k, (a, b) in enumerate(
        [("A", "B"), ("A", "C"), ("B", "D"), ("C", "D")]))
    model = SystemModel(("A", "B", "C", "D"), links, (), ())
    assert [single_paths(model, n) for n in model.nodes] == [True, True, True, False]
    assert multi_path(model, "D", model.upstream("D"), set()) == {"A"}
    chain = SystemModel(tuple(f"N{i}" for i in range(5)),
                        tuple(Link(f"N{i}", "o", f"N{i + 1}", "i", "name") for i in range(4)), (), ())
    assert all(single_paths(chain, n) for n in chain.nodes)
    assert not list(itertools.chain.from_iterable(multi_path(chain, n, chain.upstream(n), set()) for n in chain.nodes))
