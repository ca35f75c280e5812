"""Property tests draw inputs under the plan's environment facts
(docs/property-tests.md, "Environment facts"): real Hypothesis runs, every
drawn example checked against the facts by Z3 here, independently of the
backend's own filter."""
from __future__ import annotations

from pathlib import Path
from typing import Any, Callable

import pytest

from rclverify.backends.property_tests import seeding
from rclverify.backends.property_tests.backend import PropertyTestsBackend
from rclverify.backends.property_tests.harness import GuaranteeRun, load_implementation, read_config
from rclverify.backends.base import NodeTarget
from rclverify.semantics.concrete import check_concrete
from rclverify.app.pipeline import Workspace

REPO = Path(__file__).resolve().parents[2]

RCL = '''
context {
  Table : NATURAL --> NATURAL ;
}
node Lookup {
  inputs( f : Table )
  outputs( seen : BOOL )
  assume( TRUE )
  guarantee( out.seen == TRUE <=> exists(n in NATURAL | in.f(n) == 6) )
}
'''
IMPL = '''
def lookup(f):
    return {"seen": 6 in f.table.values() or f.default == 6}
'''
# Seven distinct values 0..6: a plain draw (at most 4 keys plus a default,
# values 0..5) can never satisfy this fact, so filtering alone starves.
FACT = "forall(k in NATURAL | k <= 6 -> exists(n in NATURAL | in.f(n) == k))"


def workspace(tmp: Path) -> Path:
    (tmp / "contracts").mkdir(parents=True)
    (tmp / "contracts/lookup.rcl").write_text(RCL)
    (tmp / "impl.py").write_text(IMPL)
    (tmp / "contracts/plan.yaml").write_text(
        "contracts: [contracts/lookup.rcl]\n"
        f"environment:\n  Lookup:\n    facts:\n      - \"{FACT}\"\n"
        "nodes:\n  Lookup:\n    evidence:\n      - backend: property_tests\n"
        "        implementation: impl.py:lookup\n        max_examples: 60\n")
    return tmp


def recording(target: NodeTarget, guarantee: int) -> tuple[GuaranteeRun, list[dict[str, Any]]]:
    """A run of ``guarantee`` whose implementation records every input it is given."""
    cfg = read_config(target.config, target.node, target.root)
    impl = load_implementation(target.root, cfg)
    seen: list[dict[str, Any]] = []

    def wrapped(**kw: Any) -> Any:
        seen.append({f"in.{k}": v for k, v in kw.items()})
        return impl(**kw)
    run = GuaranteeRun(target.checked, target.node, guarantee, cfg, wrapped, target.facts)
    return run, seen


def assert_facts_hold(target: NodeTarget, examples: list[dict[str, Any]]) -> None:
    assert target.facts and examples
    for values in examples:
        for fact in target.facts:
            assert check_concrete(fact, target.checked, target.node, values) == (True, ""), values


def test_fact_filtering_cannot_satisfy_still_gives_valid_examples(tmp_path: Path) -> None:
    target = Workspace(workspace(tmp_path)).target("Lookup", 0)
    run, seen = recording(target, 1)
    out = run.run()
    assert out.status == "discharged", out.message
    assert out.counts.valid >= 50 and len(seen) == out.counts.valid
    assert_facts_hold(target, seen)
    # the examples vary: not every one is the Z3 model itself
    assert len({repr(sorted(v["in.f"].table.items())) for v in seen}) > 5


def test_examples_leave_the_model_results_and_default(tmp_path: Path) -> None:
    """The facts' Z3 model is where examples start, not where they stay: some
    examples give an entry another result or take another default (a bug
    that shows only off the model's values must stay findable), and every
    example still satisfies the facts."""
    target = Workspace(workspace(tmp_path)).target("Lookup", 0)
    run, seen = recording(target, 1)
    formulas = tuple(c.formula for c in target.node.node.assumes) + run.used_facts
    model = seeding.Seeder(target.checked, target.node, formulas).base()["in.f"]
    assert run.run().status == "discharged"
    assert_facts_hold(target, seen)
    assert any(v["in.f"].default != model.default for v in seen)
    assert any(sorted(v["in.f"].table.values()) != sorted(model.table.values()) for v in seen)


def test_without_the_z3_model_filtering_starves_with_a_clear_message(tmp_path: Path,
                                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(seeding.Seeder, "base", lambda self: None)
    target = Workspace(workspace(tmp_path)).target("Lookup", 0)
    run, seen = recording(target, 1)
    out = run.run()
    assert out.status == "error" and not seen
    assert "environment facts" in out.message and "k <= 6" in out.message
    assert out.counts.rejected_by_facts == out.counts.rejected > 0


def test_evidence_names_the_facts_and_counterexample_shows_them(tmp_path: Path) -> None:
    root = workspace(tmp_path)
    (root / "impl.py").write_text(IMPL.replace("== 6}", "== 5}"))  # a wrong default check
    target = Workspace(root).target("Lookup", 0)
    backend = PropertyTestsBackend()
    ev = backend.run(backend.export(target)[0], target)
    assert ev.details["facts"] == [f"{FACT} (contracts/plan.yaml:5:10)"]
    assert ev.details["examples"]["rejected_by_facts"] < ev.details["examples"]["valid"]
    if ev.status == "failed":
        assert ev.counterexample is not None and FACT in ev.counterexample["facts"]
        assert "all hold" in ev.counterexample["facts"]
    else:  # the table default was never 6 without 6 in the table: still under the facts
        assert ev.status == "discharged"


@pytest.fixture(scope="module")
def agent() -> NodeTarget:
    ws = Workspace(REPO)
    entry = next(e for e in ws.plan.evidence["Agent"] if e.backend == "property_tests")
    return ws.target("Agent", entry.index)


@pytest.mark.parametrize("guarantee", [1, 2, 3])
def test_agent_failures_have_counterexamples_under_the_facts(agent: NodeTarget, guarantee: int) -> None:
    run, seen = recording(agent, guarantee)
    out = run.run()
    assert out.status == "failed", out.message
    assert out.counterexample is not None and "all hold" in out.counterexample["facts"]
    # every example, the shrunk counterexample (the last call) included, satisfies the facts
    assert_facts_hold(agent, seen)
    assert out.counts.rejected_by_facts < out.counts.valid  # the filter is the last resort, rarely used


def test_same_seed_same_examples_under_facts(tmp_path: Path) -> None:
    target = Workspace(workspace(tmp_path)).target("Lookup", 0)
    runs: list[list[dict[str, Any]]] = []
    for _ in range(2):
        run, seen = recording(target, 1)
        run.run()
        runs.append(seen)
    assert [repr(sorted(x.items())) for x in runs[0]] == [repr(sorted(x.items())) for x in runs[1]]


def test_z3_model_does_not_depend_on_earlier_z3_work(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import z3
    target = Workspace(workspace(tmp_path)).target("Lookup", 0)
    formulas = tuple(seeding.split_facts(target.facts, target.node)[0])
    monkeypatch.setattr(seeding, "_BASE", {})
    first = seeding.Seeder(target.checked, target.node, formulas).base()
    s = z3.Solver()
    k = z3.Int("k")
    s.add(k * k > 17, k < 100)
    assert s.check() == z3.sat
    monkeypatch.setattr(seeding, "_BASE", {})
    assert first is not None and seeding.Seeder(target.checked, target.node, formulas).base() == first


def test_table_sizes_that_cannot_hold_the_facts_are_skipped(monkeypatch: pytest.MonkeyPatch) -> None:
    """13 waypoints need 13 distinct results: tables under 12 entries (and a default) cannot, so
    Z3 is not asked about them; the first size tried that works is the one found before."""
    from rclverify.lang.parser import parse_formula
    facts = tuple(parse_formula(t, "plan.yaml", 1, 1) for t in (
        "forall(x, y in REAL | in.wayP(x, y) <= 12)",
        "forall(k in NATURAL | k <= 12 -> exists(x, y in REAL | in.wayP(x, y) == k))"))
    assert seeding.min_entries(facts) == 12
    assert seeding.min_entries(facts[:1]) == 0
    assert seeding.min_entries((parse_formula(
        "forall(k in NATURAL | k < 5 -> exists(x in REAL | in.f(x) == k))", "plan.yaml", 1, 1),)) == 4
    tried: list[int] = []
    real = seeding.Seeder._solve
    monkeypatch.setattr(seeding.Seeder, "_solve", lambda self, n: tried.append(n) or real(self, n))
    monkeypatch.setattr(seeding, "_BASE", {})
    ws = Workspace(Path(__file__).resolve().parents[2])
    node = ws.checked.nodes["Agent"]
    base = seeding.Seeder(ws.checked, node, tuple(f.expr for f in ws.plan.facts["Agent"])).base()
    assert tried == [16] and base is not None and len(base["in.wayP"].table) == 16
