"""A requirement decided over its own nodes first, against the whole cone and brute force.

The requirements stage asks ``own_nodes.decide``: when the premises of
every node are consistent, a state statement that is no implication is
first decided over the premises of the nodes it mentions alone; only a
consistent proof is kept, anything else is decided over the whole upstream
cone in a fresh Z3 context (calculus/requirements/own_nodes.py).  Here, on random systems of
boolean nodes (random guarantees, assumptions whose conjuncts over
environment inputs are premises and the rest side conditions, joins,
branches and the odd loop), each requirement is decided three ways:

* over the whole cone (``check_requirement``, the reference path);
* own nodes first (the fast path);
* by brute force: every assignment of the cone's values, the premises as
  the requirement check defines them (guarantees, the environment
  conjuncts of assumptions), entailment and consistency enumerated.

The verdicts and the consistency of the used premises agree; where the
fast path kept its own proof, brute force confirms that its used premises
entail the statement and are consistent;
where it did not, its record is the reference path's, byte for byte but
for durations.  A seeded mistake (the fast path without its check of the
whole system's premises) is caught.
"""
from __future__ import annotations

import itertools
import random
from pathlib import Path
from typing import Any, Iterator

import pytest

from rclverify.calculus.requirements import check as req_check
from rclverify.calculus.requirements import own_nodes
from rclverify.calculus.requirements.check import check_requirement
from rclverify.model.plan.load import all_requirements
from rclverify.semantics.world import fresh
from rclverify.stages.workspace import Workspace

F = tuple  # a formula: ("var", symbol) | ("not", f) | ("and"|"or"|"iff"|"imp", f, g)
RCL_OP = {"and": "and", "or": "or", "iff": "<=>", "imp": "->"}


def _formula(rng: random.Random, names: list[str], depth: int) -> F:
    if depth == 0 or rng.random() < 0.3:
        return ("var", rng.choice(names))
    if rng.random() < 0.2:
        return ("not", _formula(rng, names, depth - 1))
    return (rng.choice(["and", "or", "or", "iff", "imp"]), _formula(rng, names, depth - 1),
            _formula(rng, names, depth - 1))


def _rcl(f: F, show: dict[str, str]) -> str:
    if f[0] == "var":
        return show[f[1]]
    if f[0] == "not":
        return f"not ({_rcl(f[1], show)})"
    return f"({_rcl(f[1], show)}) {RCL_OP[f[0]]} ({_rcl(f[2], show)})"


def _holds(f: F, v: dict[str, bool]) -> bool:
    op = f[0]
    if op == "var":
        return v[f[1]]
    if op == "not":
        return not _holds(f[1], v)
    a, b = _holds(f[1], v), _holds(f[2], v)
    return {"and": a and b, "or": a or b, "iff": a == b, "imp": (not a) or b}[op]


def _symbols(f: F) -> Iterator[str]:
    if f[0] == "var":
        yield f[1]
    else:
        for g in f[1:]:
            yield from _symbols(g)


class System:
    """A random system of ``n`` nodes: node ``Ni`` produces ``ai`` and ``bi``
    and reads one or two earlier nodes' outputs (sometimes a later one's: a
    loop) and sometimes an environment input ``ei``.  A value's symbol is
    its producer's output name (a consumer's input is that value)."""

    def __init__(self, rng: random.Random) -> None:
        self.n = rng.randint(3, 5)
        self.inputs: list[list[str]] = []
        self.producer: dict[str, int] = {}
        for i in range(self.n):
            ins = sorted({f"{rng.choice('ab')}{j}" for j in rng.sample(range(i), min(i, rng.randint(1, 2)))})
            if i == 0 or rng.random() < 0.3:
                ins.append(f"e{i}")
            if i + 1 < self.n and rng.random() < 0.15:
                ins.append(f"b{rng.randint(i + 1, self.n - 1)}")
            self.inputs.append(ins)
            self.producer[f"a{i}"] = self.producer[f"b{i}"] = i
        # an assumption: conjuncts over the inputs (those over environment inputs alone are premises)
        self.assume = [[_formula(rng, ins, 1) for _ in range(rng.randint(0, 2))] for ins in self.inputs]
        self.guarantees = [[_formula(rng, ins + [f"a{i}", f"b{i}"], 2) for _ in range(rng.randint(1, 2))]
                           for i, ins in enumerate(self.inputs)]
        self.reqs: list[F] = []
        for _ in range(4):
            nodes = rng.sample(range(self.n), rng.randint(1, 2))
            f = _formula(rng, [f"{rng.choice('ab')}{i}" for i in nodes], 2)
            while f[0] == "imp" and rng.random() < 0.8:  # mostly no implication: the fast path's statements
                f = _formula(rng, [f"{rng.choice('ab')}{i}" for i in nodes], 2)
            self.reqs.append(f)

    def write(self, root: Path) -> None:
        (root / "contracts").mkdir(parents=True)
        for i in range(self.n):
            show = {x: f"in.{x}" for x in self.inputs[i]} | {f"a{i}": f"out.a{i}", f"b{i}": f"out.b{i}"}
            lines = [f"node N{i} {{", f"  inputs( {', '.join(f'{x} : BOOL' for x in self.inputs[i])} )",
                     f"  outputs( a{i} : BOOL, b{i} : BOOL )"]
            if self.assume[i]:
                lines.append(f"  assume( {' and '.join(f'({_rcl(c, show)})' for c in self.assume[i])} )")
            lines += [f"  guarantee( {_rcl(g, show)} )" for g in self.guarantees[i]]
            (root / "contracts" / f"n{i}.rcl").write_text("\n".join(lines + ["}", ""]))
        show = {f"{c}{i}": f"N{i}.out.{c}{i}" for i in range(self.n) for c in "ab"}
        reqs = "".join(f"  - id: R{k}\n    text: requirement {k}\n    formal: \"{_rcl(f, show)}\"\n"
                       for k, f in enumerate(self.reqs))
        contracts = ", ".join(f"contracts/n{i}.rcl" for i in range(self.n))
        (root / "contracts" / "plan.yaml").write_text(f"contracts: [{contracts}]\nrequirements:\n{reqs}")

    def cone(self, f: F) -> set[int]:
        todo = [self.producer[s] for s in _symbols(f)]
        seen: set[int] = set()
        while todo:
            i = todo.pop()
            if i not in seen:
                seen.add(i)
                todo += [self.producer[x] for x in self.inputs[i] if x in self.producer]
        return seen

    def premises(self, nodes: set[int]) -> dict[str, F]:
        """The labelled premises of ``nodes`` as the requirement check takes them."""
        out: dict[str, F] = {}
        for i in sorted(nodes):
            for k, g in enumerate(self.guarantees[i], 1):
                out[f"N{i} guarantee {k}"] = g
            env = [c for c in self.assume[i] if not any(s in self.producer for s in _symbols(c))]
            for k, c in enumerate(env, 1):
                out[f"N{i} environment assumption {k}"] = c
        return out


def _models(fs: list[F]) -> Iterator[dict[str, bool]]:
    names = sorted({s for f in fs for s in _symbols(f)})
    for bits in itertools.product((False, True), repeat=len(names)):
        v = dict(zip(names, bits))
        if all(_holds(f, v) for f in fs):
            yield v


def _entails(premises: list[F], goal: F) -> bool:
    return not any(True for _ in _models(premises + [("not", goal)]))


def _consistent(premises: list[F]) -> bool:
    return any(True for _ in _models(premises))


def _decide(req: Any, ws: Workspace, own_first: bool) -> dict[str, Any]:
    fresh()  # as the requirements stage does before each check
    if own_first:
        return own_nodes.decide(req, ws.checked, ws.model, ws.plan)
    return check_requirement(req, ws.checked, ws.model, ws.plan)


def _same_but_durations(a: dict[str, Any], b: dict[str, Any]) -> bool:
    def strip(r: dict[str, Any]) -> dict[str, Any]:
        return {k: v for k, v in r.items() if not k.endswith("duration_s")}
    return strip(a) == strip(b)


def _compare(seed: int, root: Path, counts: dict[str, int] | None = None) -> list[str]:
    """The disagreements on the random system of ``seed`` (empty: none);
    ``counts`` counts the statements each path decided."""
    sys_ = System(random.Random(seed))
    sys_.write(root)
    ws = Workspace(root)
    wrong: list[str] = []
    everything = list(sys_.premises(set(range(sys_.n))).values())
    said = own_nodes.system_premises(ws.checked, ws.model, ws.plan)
    if said != ("consistent" if _consistent(everything) else "inconsistent"):
        wrong.append(f"seed {seed}: the premises of every node are {said} for Z3, not for brute force")
    if counts is not None and said == "inconsistent":
        counts["inconsistent systems"] += 1
    for req, goal in zip(all_requirements(ws.plan), sys_.reqs):
        full, fast = _decide(req, ws, False), _decide(req, ws, True)
        cone = sys_.cone(goal)
        every = sys_.premises(cone)
        truth = "proved" if _entails(list(every.values()), goal) else "refuted"
        where = f"seed {seed} {req.id} {req.formal.text if req.formal else ''}"
        if full["verdict"] != truth:
            wrong.append(f"{where}: the whole cone says {full['verdict']}, brute force {truth}")
        if fast["verdict"] != full["verdict"]:
            wrong.append(f"{where}: own nodes first says {fast['verdict']}, the whole cone {full['verdict']}")
        if counts is not None:
            counts["own" if "premises_of" in fast else "cone"] += 1
        if "premises_of" not in fast:
            if not _same_but_durations(fast, full):
                wrong.append(f"{where}: a statement its own nodes did not decide got another record")
            continue
        used = [every[p["label"]] for p in fast["used"]]
        if not (_entails(used, goal) and _consistent(used) and fast["consistency"] == "consistent"):
            wrong.append(f"{where}: the own nodes' proof is not a consistent proof")
        if fast.get("consistency") != full.get("consistency"):
            wrong.append(f"{where}: own nodes first says {fast.get('consistency')}, the whole cone "
                         f"{full.get('consistency')}")
    return wrong


SEEDS = range(24)


@pytest.fixture(scope="module")
def outcomes(tmp_path_factory: pytest.TempPathFactory) -> dict[str, int]:
    counts = {"own": 0, "cone": 0, "inconsistent systems": 0}
    root = tmp_path_factory.mktemp("own")
    problems: list[str] = []
    for seed in SEEDS:
        problems += _compare(seed, root / f"s{seed}", counts)
    assert problems == []
    return counts


def test_own_nodes_first_agrees_with_the_whole_cone_and_brute_force(outcomes: dict[str, int]) -> None:
    # both paths are exercised: statements proved by their own nodes, ones the cone decides, and systems
    # whose premises contradict each other (where the cone decides every statement)
    assert outcomes["own"] >= 10 and outcomes["cone"] >= 10 and outcomes["inconsistent systems"] >= 2, outcomes


def test_a_seeded_mistake_is_caught(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The fast path wrongly skips step 1 (it takes every system's premises
    for consistent): where the premises of the cone contradict each other
    its own nodes' proof reads consistent, the whole cone's does not (a
    proof from an inconsistency, never met), and the comparison says so."""
    monkeypatch.setattr(own_nodes, "system_premises", lambda *a, **k: "consistent")
    wanted = "own nodes first says consistent, the whole cone inconsistent"
    found: list[str] = []
    for seed in SEEDS:  # until the first system whose premises contradict each other shows it
        found += _compare(seed, tmp_path / f"s{seed}")
        if any(wanted in w for w in found):
            break
    assert any(wanted in w for w in found), found


def test_the_large_system_of_the_bench_takes_the_short_path(tmp_path: Path) -> None:
    """The synthetic system of bench/system_scale.py (joins, loops, services,
    deadline requirements) at 120 nodes: the system's premises are decided
    consistent and every deadline requirement is proved from its own node, as
    the whole cone proves it (the same verdict, consistency and premises used)."""
    import sys
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
    from system_scale import generate
    from rclverify.app.pipeline import stage_requirements
    generate(tmp_path / "ws", 120, deadlines=20, hoare=0, property_tests=0)
    ws = Workspace(tmp_path / "ws")
    assert own_nodes.system_premises(ws.checked, ws.model, ws.plan) == "consistent"
    recs = [rec for rec, _ in stage_requirements(ws)]
    assert len(recs) == 5 and all(r.get("premises_of") == [r["id"].replace("D", "N")] for r in recs)
    for req, rec in zip(all_requirements(ws.plan), recs):
        full = _decide(req, ws, False)
        assert (rec["verdict"], rec["consistency"]) == (full["verdict"], full["consistency"]) == ("proved", "consistent")
        assert [u["label"] for u in rec["used"]] == [u["label"] for u in full["used"]]
        assert len(rec["cone"]) == len(full["cone"]) > 10 * rec["premises"]
