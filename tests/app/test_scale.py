"""What the pipeline needs to scale: no recursion limit on long chains, the
system model's per-node index, and the cached workspace of a doit run."""
from __future__ import annotations

import random
from pathlib import Path

import pytest

from rclverify.core.cache import Shelf
from rclverify.core.cache import workspace as wscache
from rclverify.app.pipeline import Workspace
from rclverify.model.system.model import Link, SystemModel, _loops, cycles_kept


def _sccs_by_reachability(nodes: list[str], links: list[Link]) -> tuple[tuple[str, ...], ...]:
    succ: dict[str, set[str]] = {n: set() for n in nodes}
    for l in links:
        succ[l.from_node].add(l.to_node)
    reach = {}
    for n in nodes:
        seen, todo = {n}, [n]
        while todo:
            for w in succ[todo.pop()]:
                if w not in seen:
                    seen.add(w)
                    todo.append(w)
        reach[n] = seen
    comps = {tuple(sorted(m for m in nodes if m in reach[n] and n in reach[m])) for n in nodes}
    return tuple(sorted(c for c in comps if len(c) > 1 or c[0] in succ[c[0]]))


def test_loops_of_a_long_chain_closed_into_a_ring() -> None:
    nodes = [f"N{k}" for k in range(3000)]
    links = [Link(nodes[k], "o", nodes[(k + 1) % 3000], "i", "name") for k in range(3000)]
    assert _loops(nodes, links) == (tuple(sorted(nodes)),)


def test_loops_agree_with_reachability_on_random_graphs() -> None:
    rnd = random.Random(12)
    for _ in range(200):
        nodes = [f"n{k}" for k in range(rnd.randint(1, 10))]
        links = [Link(rnd.choice(nodes), "o", rnd.choice(nodes), "i", "name") for _ in range(rnd.randint(0, 18))]
        assert _loops(nodes, links) == _sccs_by_reachability(nodes, links)


def test_model_index_answers_like_a_scan_of_the_links() -> None:
    rnd = random.Random(3)
    nodes = tuple(f"n{k}" for k in range(30))
    links = tuple(Link(rnd.choice(nodes), f"o{k}", rnd.choice(nodes), f"i{k}", "name") for k in range(60))
    m = SystemModel(nodes, links, (), ())
    for n in nodes:
        ps = {l.from_node for l in links if l.to_node == n}
        cs = {l.to_node for l in links if l.from_node == n}
        assert m.producers(n) == [x for x in nodes if x in ps]
        assert m.consumers(n) == [x for x in nodes if x in cs]
        assert m.internal_inputs(n) == {l.to_var for l in links if l.to_node == n}
        assert m.links_into(n) == tuple(l for l in links if l.to_node == n)
    for l in links:
        assert m.readers(l.from_node, l.from_var) == tuple(x.to_node for x in links
                                                            if (x.from_node, x.from_var) == (l.from_node, l.from_var))
    assert m.readers("n0", "no such output") == () and m.links_into("no such node") == ()
    assert dict(m.alias()) == {(l.to_node, "in", l.to_var): f"{l.from_node}.out.{l.from_var}" for l in links}
    loops = _loops(list(nodes), list(links))
    m2 = SystemModel(nodes, links, (), loops)
    for n in nodes:
        assert m2.loop_of(n) == next((loop for loop in loops if n in loop), None)


def test_cycles_are_kept_for_the_same_connections_and_found_again_for_others(tmp_path: Path) -> None:
    ring = SystemModel(("A", "B", "C"), (Link("A", "o", "B", "i", "name"), Link("B", "o", "C", "i", "name"),
                                         Link("C", "o", "A", "i", "name")), (), (("A", "B", "C"),))
    path = tmp_path / "cache" / "cycles.pickle"
    assert cycles_kept(ring, path) == [["A", "B", "C"]] == ring.cycles()
    shelf = Shelf(path, "system-cycles")
    (key,) = [k for k in shelf._old]  # the one entry: the ring's connections
    shelf.put(key, [["from", "the", "file"]])
    shelf.save()
    assert cycles_kept(ring, path) == [["from", "the", "file"]]  # served from the file: same connections
    chain = SystemModel(ring.nodes, ring.links[:2], (), ())
    assert cycles_kept(chain, path) == []  # other connections: found again, and the file replaced
    assert len(Shelf(path, "system-cycles")) == 1
    path.write_text("{damaged")
    assert cycles_kept(ring, path) == [["A", "B", "C"]]


RCL = """\
node A {
  inputs( e : REAL )
  outputs( v : REAL )
  assume( 0 <= in.e )
  guarantee( 0 <= out.v )
}
"""


def _ws(root: Path) -> Workspace:
    (root / "contracts").mkdir(parents=True, exist_ok=True)
    (root / "contracts" / "a.rcl").write_text(RCL)
    (root / "contracts" / "plan.yaml").write_text("contracts: [contracts/a.rcl]\n")
    return Workspace(root)


def test_workspace_cache_is_used_only_while_the_inputs_are_unchanged(tmp_path: Path) -> None:
    ws = _ws(tmp_path)
    assert not wscache.restore(ws)  # nothing cached yet
    ws.model
    wscache.save(ws)
    again = Workspace(tmp_path)
    assert wscache.restore(again)
    assert again.node_names() == ["A"] and again.model == ws.model
    (tmp_path / "contracts" / "a.rcl").write_text(RCL.replace("0 <= out.v", "1 <= out.v"))
    edited = Workspace(tmp_path)
    assert not wscache.restore(edited)
    from rclverify.lang.printer import expr_to_rcl
    assert expr_to_rcl(edited.checked.nodes["A"].node.guarantees[0].formula) == "1 <= out.v"  # parsed again
    (tmp_path / "contracts" / "a.rcl").write_text(RCL)
    (tmp_path / "contracts" / "plan.yaml").write_text("contracts: [contracts/a.rcl]\nname: x\n")
    assert not wscache.restore(Workspace(tmp_path))


def test_a_background_save_is_complete_when_the_next_restore_reads_it(tmp_path: Path) -> None:
    ws = _ws(tmp_path)
    ws.model
    wscache.save_in_background(ws)  # a forked child writes the file
    again = Workspace(tmp_path)
    assert wscache.restore(again)  # restore waits for this process's saves first
    assert again.node_names() == ["A"]
    wscache.wait()  # nothing left to wait for
    assert not wscache._PENDING


def test_a_damaged_cache_is_ignored(tmp_path: Path) -> None:
    ws = _ws(tmp_path)
    (tmp_path / wscache.CACHE).parent.mkdir(parents=True)
    (tmp_path / wscache.CACHE).write_bytes(b"not a pickle")
    assert not wscache.restore(ws)
    assert ws.node_names() == ["A"]


def test_a_missing_contract_is_reported_even_with_a_cached_plan(tmp_path: Path) -> None:
    from rclverify.model.plan.errors import PlanError
    ws = _ws(tmp_path)
    ws.model
    wscache.save(ws)
    (tmp_path / "contracts" / "a.rcl").unlink()
    again = Workspace(tmp_path)
    assert not wscache.restore(again)
    with pytest.raises(PlanError):
        again.model


def _cached_and_restored(root: Path) -> tuple[Workspace, Workspace]:
    """A workspace loaded and cached, and a second one restored from that cache."""
    ws = _ws(root)
    ws.model
    wscache.save(ws)
    again = Workspace(root)
    assert wscache.restore(again)
    return ws, again


def test_a_valid_cache_defers_the_checked_contracts_until_a_task_needs_them(tmp_path: Path,
                                                                           monkeypatch: pytest.MonkeyPatch) -> None:
    ws, again = _cached_and_restored(tmp_path)
    # the task index is there at once; the plan and the parsed contracts are not unpickled yet
    assert again.index.nodes == ("A",) and again.index.contracts == ("contracts/a.rcl",)
    assert {"plan", "checked", "model"}.isdisjoint(again.__dict__) and again.deferred is not None
    import rclverify.lang.parser as parser

    def no_parse(*args: object, **kwargs: object) -> None:
        raise AssertionError("parsed although the cache holds the parsed contracts")
    monkeypatch.setattr(parser, "parse_text", no_parse)
    assert again.model == ws.model and again.deferred is None  # type-checked from the cached parse


def test_a_contract_edited_after_the_cache_was_read_is_loaded_from_the_file(tmp_path: Path) -> None:
    _, again = _cached_and_restored(tmp_path)
    (tmp_path / "contracts" / "a.rcl").write_text(RCL.replace("0 <= out.v", "2 <= out.v"))
    from rclverify.lang.printer import expr_to_rcl
    assert expr_to_rcl(again.checked.nodes["A"].node.guarantees[0].formula) == "2 <= out.v"


def test_a_node_task_runs_only_the_stages_whose_inputs_changed() -> None:
    from rclverify.app.tasks import NODE_STAGES, stages_to_run
    deps = {"compose": ["/w/a/snap/N.json", "/w/a/snap/P.json", "/w/a/model.json"],
            "health": ["/w/a/snap/N.json"], "export": ["/w/a/snap/N.json", "/w/backends/prog.imp"]}
    assert stages_to_run(deps, ["/w/a/snap/N.json"]) == ["compose", "health", "export"]
    assert stages_to_run(deps, ["/w/a/snap/P.json"]) == ["compose"]  # a producer changed: side conditions only
    assert stages_to_run(deps, ["/w/backends/prog.imp"]) == ["export"]
    assert stages_to_run(deps, ["/w/a/model.json", "/w/backends/prog.imp"]) == ["compose", "export"]
    assert stages_to_run(deps, []) == list(NODE_STAGES)  # no reason by file (forced run): everything
    # the node task holds compose and export, the health task health (app/task_table.py): each runs its own
    node_task = {k: v for k, v in deps.items() if k != "health"}
    assert stages_to_run(node_task, ["/w/a/snap/N.json"]) == ["compose", "export"]
    assert stages_to_run(node_task, []) == ["compose", "export"]
    assert stages_to_run({"health": deps["health"]}, []) == ["health"]
    assert stages_to_run({"health": deps["health"]}, ["/w/backends/prog.imp"]) == []


def test_a_plan_edited_after_the_cache_was_read_is_loaded_from_the_file(tmp_path: Path) -> None:
    _, again = _cached_and_restored(tmp_path)
    (tmp_path / "contracts" / "plan.yaml").write_text("contracts: [contracts/a.rcl]\nname: edited\n")
    assert again.plan.name == "edited"


def test_upstream_masks_are_the_upstream_cones_also_through_loops() -> None:
    rng = random.Random(11)
    for _ in range(60):
        nodes = [f"N{k}" for k in range(rng.randint(1, 25))]
        links = [Link(rng.choice(nodes), f"o{k}", rng.choice(nodes), f"i{k}", "name")
                 for k in range(rng.randint(0, 40))]
        model = SystemModel(tuple(rng.sample(nodes, len(nodes))), tuple(links), (), ())
        masks = model.upstream_masks()
        preds: dict[str, set[str]] = {n: set() for n in model.nodes}
        for l in links:
            preds[l.to_node].add(l.from_node)
        for n in model.nodes:  # reachability written out plainly: a search backwards from n
            seen, todo = {n}, [n]
            while todo:
                for p in preds[todo.pop()] - seen:
                    seen.add(p)
                    todo.append(p)
            cone = [m for m in model.nodes if m in seen]
            assert [m for i, m in enumerate(model.nodes) if masks[n] >> i & 1] == cone
            assert model.upstream(n) == cone


def test_the_task_definitions_name_the_stage_records_the_stages_write() -> None:
    """app/tasks.py names the deadlines', the second solver's and the diagnosis's records as
    text, so that defining the tasks (every doit run, the no-op included)
    imports neither stage (issue 67: the deadline stage's import loaded Z3):
    the same paths."""
    from rclverify.app import tasks
    from rclverify.stages.crosscheck.stage import INDEX as crosscheck
    from rclverify.stages.deadlines import INDEX as deadlines
    assert (tasks.DEADLINES_INDEX, tasks.CROSSCHECK_INDEX) == (deadlines, crosscheck)
    from rclverify.app.task_table import DIAGNOSIS_INDEX
    from rclverify.stages.diagnoses import INDEX as diagnoses
    assert DIAGNOSIS_INDEX == diagnoses
