"""The hoare backend's export -> run memo (backends/hoare/memo.py): a run in the
process of the export reuses what the export built, only for unchanged inputs,
and produces exactly what a run without it produces."""
from __future__ import annotations

import dataclasses
import shutil
from pathlib import Path
from typing import Any, Iterator

import pytest

from rclverify.backends.base import NodeTarget
from rclverify.backends.hoare import HoareBackend, backend, memo
from rclverify.evidence.records import Evidence

import test_hoare
from test_hoare import APPENDIX_B, PROGRAM, RCL, entry, workspace  # noqa: F401 - workspace: a fixture

C3 = "RadiationSensor.g1.hoare.radiation_sensor.c3"


@pytest.fixture(autouse=True)
def empty_memo() -> Iterator[None]:
    memo.clear()
    yield
    memo.clear()


@pytest.fixture()
def rebuilds(monkeypatch: pytest.MonkeyPatch) -> list[str | None]:
    """The ``only`` argument of every ``prepare`` call a run makes (a rebuild)."""
    calls: list[str | None] = []
    real = backend.prepare

    def counting(target: NodeTarget, only: str | None = None) -> Any:
        calls.append(only)
        return real(target, only)

    monkeypatch.setattr(backend, "prepare", counting)
    return calls


def target(root: Path, program: str = PROGRAM, **extra: Any) -> NodeTarget:
    """The case study's target, from a fresh load of the contracts (new objects,
    as a workspace loaded again)."""
    return test_hoare.target(root, entry(program, **extra))


def comparable(ev: Evidence) -> dict[str, Any]:
    j = ev.to_json()
    j.pop("started", None)
    j.pop("duration_s", None)
    return j


def files(root: Path) -> dict[str, bytes]:
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in sorted((root / "artifacts").rglob("*"))
            if p.is_file()}


@pytest.mark.parametrize("program", [PROGRAM, APPENDIX_B])  # all discharged/pending; two refuted
def test_run_after_export_reuses_it_and_gives_the_same_evidence_and_files(
        workspace: Path, rebuilds: list[str | None], program: str) -> None:
    t = target(workspace, program)
    b = HoareBackend()
    obligations = b.export(t)
    served = {o.id: comparable(b.run(o, t)) for o in obligations}
    assert rebuilds == [None]  # the export's own prepare; no run rebuilt its triple
    served_files = files(workspace)
    shutil.rmtree(workspace / "artifacts")
    memo.clear()
    again = b.export(t)
    memo.clear()  # as in a process that did not export
    rebuilt = {o.id: comparable(b.run(o, t)) for o in again}
    assert len(rebuilds) == 1 + 1 + len(obligations)  # export, export, one rebuild per run
    assert rebuilt == served
    assert files(workspace) == served_files


def test_a_triple_is_served_once(workspace: Path, rebuilds: list[str | None]) -> None:
    t = target(workspace)
    b = HoareBackend()
    o = next(o for o in b.export(t) if o.id == C3)
    first, second = b.run(o, t), b.run(o, t)
    assert rebuilds == [None, C3]  # the second run rebuilt
    assert comparable(first) == comparable(second)


def test_an_edited_program_is_not_served_from_the_memo(workspace: Path, rebuilds: list[str | None]) -> None:
    t = target(workspace)
    b = HoareBackend()
    obligations = {o.id: o for o in b.export(t)}
    path = workspace / PROGRAM
    path.write_text(path.read_text().replace("input < 250", "input < 200"))
    ev = b.run(obligations[C3], t)
    assert rebuilds == [None, C3]
    assert ev.status == "failed" and 200 <= ev.counterexample["radiation_at(i)"] < 250
    assert "input < 200" in (workspace / obligations[C3].artifact).read_text()  # the stale artifact replaced


def test_a_reloaded_contract_is_not_served_from_the_memo(workspace: Path, rebuilds: list[str | None]) -> None:
    b = HoareBackend()
    obligations = {o.id: o for o in b.export(target(workspace))}
    path = workspace / RCL
    path.write_text(path.read_text().replace("in.r < 250 ->", "in.r < 260 ->").replace("(250 <= in.r", "(260 <= in.r"))
    ev = b.run(obligations[C3], target(workspace))  # the workspace loaded again
    assert rebuilds == [None, C3]
    assert ev.status == "failed" and 250 <= ev.counterexample["radiation_at(i)"] < 260


def test_a_changed_plan_entry_is_not_served_from_the_memo(workspace: Path, rebuilds: list[str | None]) -> None:
    t = target(workspace)
    b = HoareBackend()
    obligations = {o.id: o for o in b.export(t)}
    changed = dataclasses.replace(t, config={**t.config, "timeout_ms": 5000})
    assert b.run(obligations[C3], changed).status == "discharged"
    assert rebuilds == [None, C3]


def test_export_prepares_each_triple_as_a_run_alone_does(workspace: Path) -> None:
    """What makes the memo exact: a triple prepared among all of them has the
    same Z3 terms (background axioms included) as prepared on its own."""
    t = target(workspace)
    for p in backend.prepare(t):
        (alone,) = backend.prepare(t, only=p.id)
        if p.triple is None:
            assert alone.triple is None
            continue
        assert alone.triple is not None
        assert [f.sexpr() for f in p.triple.background] == [f.sexpr() for f in alone.triple.background]
        assert [(v.id, v.goal.sexpr(), [h.sexpr() for h in v.hyps]) for v in p.vcs] == \
            [(v.id, v.goal.sexpr(), [h.sexpr() for h in v.hyps]) for v in alone.vcs]
        assert dict(p.triple.names) == dict(alone.triple.names)


# ---------------------------------------------------------------------------
# the low-level term walks of wp.py find what the typed API finds
# ---------------------------------------------------------------------------

def reference_terms(formulas: list[Any]) -> list[Any]:
    """Sub-terms outside quantifiers, each once, through the typed API (children())."""
    import z3
    seen: set[int] = set()
    out = []
    stack = list(reversed(formulas))
    while stack:
        t = stack.pop()
        if t.get_id() in seen:
            continue
        seen.add(t.get_id())
        if z3.is_quantifier(t) or z3.is_var(t):
            continue
        out.append(t)
        if z3.is_app(t):
            stack.extend(reversed(t.children()))
    return out


def test_term_walks_match_the_typed_api(workspace: Path) -> None:
    import z3
    from rclverify.backends.hoare.wp import iter_terms, term_ids
    t = target(workspace)
    p = next(p for p in backend.prepare(t) if p.triple is not None)
    m = p.model
    i, out = m.consts["i"], m.consts["output"]
    f = m.funcs["radiation_at"]
    k = z3.Int("k")
    extra = z3.And(f(i) >= z3.RealVal("1/3"), z3.ForAll([k], f(k) > 0), m.olds["i"] == i + 1, out == out)
    formulas = [*p.vcs[0].hyps, p.vcs[0].goal, extra, extra]
    ref = reference_terms(formulas)
    assert [x.sexpr() for x in iter_terms(formulas)] == [x.sexpr() for x in ref]
    assert term_ids(formulas) == {x.get_id() for x in ref}
    assert [x.sexpr() for x in m.extern_applications(formulas)] == ["(radiation_at i)"]  # f(k): under a quantifier
    assert [x.sexpr() for x in m.typing_facts(formulas)] == ["(>= i 0)", "(>= |old(i)| 0)"]
    assert m.olds_in(formulas) == ["i"] and m.variables_in(formulas) == ["i", "output"]
