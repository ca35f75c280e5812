"""The worst timing path of a deadline (issue 48; calculus/worst_path.py):
another path from the same first node to the same last one, slower than the
named path, is found and named, and refutes the deadline when its sum
exceeds the bound; its verdict equals a brute-force search over the paths."""
from __future__ import annotations

import itertools
import random
from fractions import Fraction

from rclverify.calculus.deadlines import PROVED, REFUTED, decide
from rclverify.calculus.worst_path import with_worst_path
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.model.system.model import build

DIAMOND = """\
node A {
  inputs( a : REAL )
  outputs( b : REAL, c : REAL )
  guarantee( out.b == in.a and out.c == in.a ) triggered by in.a within 10 ms
}
node Fast {
  inputs( b : REAL )
  outputs( d1 : REAL )
  guarantee( out.d1 == in.b ) triggered by in.b within 20 ms
}
node Slow {
  inputs( c : REAL )
  outputs( d2 : REAL )
  guarantee( out.d2 == in.c ) triggered by in.c within 400 ms
}
node D {
  inputs( d1 : REAL, d2 : REAL )
  outputs( e : REAL )
  guarantee( out.e == in.d1 ) triggered by in.d1 within 30 ms
  guarantee( out.e == in.d2 ) triggered by in.d2 within 30 ms
}
"""


def _decided(text: str, path: list[str], within: Fraction):  # type: ignore[no-untyped-def]
    checked = check([parse_text(text, "s.rcl")])
    model = build(checked)
    return with_worst_path(decide(checked, model, "R", path, within), checked, model)


def test_a_slower_branch_refutes_the_deadline_named_along_the_fast_one() -> None:
    r = _decided(DIAMOND, ["A", "Fast", "D"], Fraction(1, 10))
    assert r.status == REFUTED and r.path == ("A", "Fast", "D") and r.worst_path == ("A", "Slow", "D")
    assert r.reason.startswith("another path from A to D is slower than the one named (A -> Fast -> D)")
    assert r.total == Fraction(44, 100) and [h.node for h in r.chain] == ["A", "Slow", "D"]
    ok = _decided(DIAMOND, ["A", "Fast", "D"], Fraction(1, 2))  # both within: proved, the slow one named
    assert ok.status == PROVED and ok.worst_path == ("A", "Slow", "D")
    assert "the slowest path from A to D is A -> Slow -> D, 440 ms, not the one named" in ok.reason
    named_slow = _decided(DIAMOND, ["A", "Slow", "D"], Fraction(1, 2))  # the named one is the slowest
    assert named_slow.status == PROVED and named_slow.worst_path == ()


def test_worst_path_equals_brute_force_on_random_diamonds() -> None:
    rnd = random.Random(48)
    for _ in range(25):
        ms = [rnd.choice([5, 10, 50, 100, 300]) for _ in range(5)]
        text = (DIAMOND.replace("within 10 ms", f"within {ms[0]} ms").replace("within 20 ms", f"within {ms[1]} ms")
                .replace("within 400 ms", f"within {ms[2]} ms")
                .replace("in.d1 within 30 ms", f"in.d1 within {ms[3]} ms")
                .replace("in.d2 within 30 ms", f"in.d2 within {ms[4]} ms"))
        bound = Fraction(rnd.choice([50, 100, 200, 400, 800]), 1000)
        sums = {("A", "Fast", "D"): ms[0] + ms[1] + ms[3], ("A", "Slow", "D"): ms[0] + ms[2] + ms[4]}
        for named in itertools.permutations(sums, 1):
            r = _decided(text, list(named[0]), bound)
            expected = REFUTED if max(sums.values()) > bound * 1000 else PROVED
            assert r.status == expected, (ms, bound, named, r.reason)


def test_the_deadline_task_reads_every_node_between_the_ends() -> None:
    """The deadlines task depends on the snapshots of these nodes: the slow branch's node is one of
    them although the named path does not pass it; a node off every path is not."""
    from rclverify.calculus.worst_path import nodes_between
    text = DIAMOND + "node E {\n  inputs( a : REAL )\n  outputs( z : REAL )\n  guarantee( out.z == in.a )\n}\n"
    model = build(check([parse_text(text, "s.rcl")]))
    assert nodes_between(model, ["A", "Fast", "D"]) == ("A", "Fast", "D", "Slow")
    assert nodes_between(model, ["A", "Slow", "D"]) == ("A", "Slow", "D", "Fast")


def test_nodes_between_cover_every_simple_path_on_random_graphs() -> None:
    """Oracle: every node of every simple path between the ends (brute force over node orders) is
    named, and every node named lies on a walk from the first to the last."""
    import networkx as nx

    from rclverify.calculus.worst_path import _between, _graph, nodes_between
    from rclverify.model.system.model import Link, SystemModel
    rnd = random.Random(4848)
    for _ in range(60):
        names = [f"N{i}" for i in range(rnd.randint(2, 6))]
        edges = {(a, b) for a in names for b in names if a != b and rnd.random() < 0.35}
        model = SystemModel(tuple(rnd.sample(names, len(names))),
                            tuple(Link(a, f"o{k}", b, f"i{k}", "name") for k, (a, b) in enumerate(sorted(edges))), (), ())
        a, b = names[0], names[-1]
        # issue 67: read off the model's upstream masks, the same nodes in the same order as the networkx search
        g = _graph(model)
        assert isinstance(g, nx.DiGraph)
        between = _between(g, a, b)
        assert nodes_between(model, [a, b]) == tuple(dict.fromkeys([a, b, *(n for n in model.nodes if n in between)]))
        on_paths: set[str] = set()
        for k in range(len(names) - 1):
            for mid in itertools.permutations([n for n in names if n not in (a, b)], k):
                p = (a, *mid, b)
                if all((x, y) in edges for x, y in zip(p, p[1:])):
                    on_paths |= set(p)
        got = set(nodes_between(model, [a, b]))  # type: ignore[arg-type]
        assert on_paths <= got, (edges, on_paths, got)

        def reach(x: str, y: str) -> bool:
            seen, todo = {x}, [x]
            while todo:
                n = todo.pop()
                for s, t in edges:
                    if s == n and t not in seen:
                        seen.add(t)
                        todo.append(t)
            return y in seen
        assert all(n in (a, b) or (reach(a, n) and reach(n, b)) for n in got), (edges, got)


def test_an_edit_off_the_named_path_makes_the_recorded_deadline_stale(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """The deadline record's inputs are the snapshots of every node between its ends, as the task's: a
    slower hop off the named path refutes the deadline, so a proof recorded before the edit must read
    ``stale`` in a report made without the stage (it read ``proved``)."""
    from rclverify.stages.deadlines import read_deadlines
    from rclverify.stages.contract_texts import ContractTexts
    from rclverify.app.pipeline import stage_check, stage_deadlines
    from rclverify.stages.provenance import current_snapshot_hashes
    from rclverify.stages.workspace import Workspace
    (tmp_path / "contracts").mkdir()
    rcl = tmp_path / "contracts/s.rcl"
    rcl.write_text(DIAMOND.replace("within 400 ms", "within 40 ms"))
    (tmp_path / "contracts/plan.yaml").write_text(
        "name: diamond\ncontracts:\n  - contracts/s.rcl\nrequirements:\n  - id: R\n    text: fast enough\n"
        "    deadline: {path: [A, Fast, D], within: 100 ms}\nnodes: {}\n")
    ws = Workspace(tmp_path)
    stage_check(ws)
    [rec] = stage_deadlines(ws)
    assert rec["status"] == PROVED
    rcl.write_text(DIAMOND)  # Slow: 400 ms, off the named path
    ws = Workspace(tmp_path)
    [now] = read_deadlines(ws, current_snapshot_hashes(ws, ContractTexts(ws)))[0] or []
    assert now["status"] == "stale", now


def test_a_cut_path_search_never_proves(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """Past MAX_PATHS simple paths the search is cut: a path not examined may be the slow one, so a
    proof of the named path alone is inconclusive, not proved (here the cut leaves Slow, 400 ms, out)."""
    import rclverify.calculus.worst_path as wp
    monkeypatch.setattr(wp, "MAX_PATHS", 1)
    text = DIAMOND.replace("node Slow", "node Aaa_slow")  # its path enumerated after the named one
    r = _decided(text, ["A", "Fast", "D"], Fraction(1, 10))
    assert r.status != PROVED, r.reason
