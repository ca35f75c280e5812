"""A temporal proof rests only on the ``initially`` declarations it needs (issue 64).

(a) The greedy search of :func:`initially_not_needed` against brute force:
    on random families of node sets closed under subsets (the sets of
    declarations the proof can do without), its answer is one of the
    family's maximal sets.
(b) On real Z3 proofs over small self-written workspaces: a chain whose
    requirement holds whether or not its first node publishes an initial
    value lists that ``initially`` as traced, not needed; a loop that only
    an initial value starts keeps it among the premises used.
"""
from __future__ import annotations

import itertools
import json
import random
from pathlib import Path
from typing import Any

import pytest

from rclverify.app.pipeline import Workspace, stage_check, stage_requirements
from rclverify.calculus.requirements.initial_needed import initially_not_needed


def _maximal(family: set[frozenset[str]]) -> set[frozenset[str]]:
    return {s for s in family if not any(s < t for t in family)}


def test_the_greedy_search_finds_a_maximal_set_the_proof_does_without() -> None:
    rng = random.Random(64)
    for _ in range(300):
        nodes = [f"N{i}" for i in range(rng.randint(1, 4))]
        subsets = [frozenset(c) for k in range(len(nodes) + 1) for c in itertools.combinations(nodes, k)]
        # a family closed under subsets: the downward closure of a few random sets
        seeds = rng.sample(subsets, rng.randint(0, min(3, len(subsets))))
        family = {s for s in subsets if any(s <= t for t in seeds)} | {frozenset()}
        premises = [{"kind": "initial value", "node": n} for n in nodes] + [{"kind": "guarantee", "node": "X"}]
        asked: list[frozenset[str]] = []

        def proved_without(ns: Any, family: set[frozenset[str]] = family, asked: list[Any] = asked) -> bool:
            asked.append(frozenset(ns))
            return frozenset(ns) in family
        got = initially_not_needed(premises, proved_without)
        assert got in _maximal(family), (nodes, family, got)
        assert len(asked) <= 1 + len(nodes)
        assert all(a <= frozenset(nodes) for a in asked)  # only initially declarations are ever dropped


def test_no_initially_asks_nothing() -> None:
    def never(ns: Any) -> bool:
        raise AssertionError("asked")
    assert initially_not_needed([{"kind": "guarantee", "node": "A"}], never) == frozenset()


# Sensor publishes what it reads, Ctl forwards it: a chain that every input starts; Sensor's initial
# value is never needed.  Inc and Fwd: a loop that only Fwd's initial value starts.
RCL = """node Sensor { inputs( r : NATURAL ) outputs( d : NATURAL )
  guarantee( out.d == in.r )
  initially( out.d == 0 )
  progress( within 0 steps ) }
node Ctl { inputs( d : NATURAL ) outputs( c : NATURAL )
  guarantee( out.c == in.d )
  progress( within 0 steps ) }
node Inc { inputs( a : NATURAL ) outputs( b : NATURAL )
  guarantee( (in.a < 10 -> out.b == in.a + 1) and (in.a >= 10 -> out.b == in.a) )
  progress( within 0 steps ) }
node Fwd { inputs( b : NATURAL ) outputs( a : NATURAL )
  guarantee( out.a == in.b )
  initially( out.a == 0 )
  progress( within 0 steps ) }
"""
PLAN = """contracts: [contracts/n.rcl]
requirements:
  - id: CHAIN
    text: the controller eventually forwards the reading 3
    formal: "eventually Ctl.out.c == 3"
    assuming: "Sensor.in.r == 3"
  - id: LOOP
    text: the counter eventually counts
    formal: "eventually Inc.out.b >= 1"
"""


@pytest.fixture(scope="module")
def records(tmp_path_factory: pytest.TempPathFactory) -> dict[str, dict[str, Any]]:
    ws = tmp_path_factory.mktemp("initial") / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/n.rcl").write_text(RCL)
    (ws / "contracts/plan.yaml").write_text(PLAN)
    w = Workspace(ws)
    stage_check(w)
    stage_requirements(w)
    return {r: json.loads((ws / f"artifacts/requirements/{r}.json").read_text()) for r in ("CHAIN", "LOOP")}


def _labels(rows: list[dict[str, Any]]) -> set[str]:
    return {p["label"] for p in rows}


def test_an_initial_value_the_proof_does_without_is_traced_not_needed(records: dict[str, dict[str, Any]]) -> None:
    chain = records["CHAIN"]
    assert chain["verdict"] == "proved" and chain["consistency"] == "consistent"
    assert "Sensor initially 1" not in _labels(chain["used"])
    assert _labels(chain["traced_not_needed"]) == {"Sensor initially 1"}
    assert {"Sensor progress", "Ctl progress", "Sensor guarantee 1"} <= _labels(chain["used"])


def test_an_initial_value_that_starts_a_loop_stays_a_premise_used(records: dict[str, dict[str, Any]]) -> None:
    loop = records["LOOP"]
    assert loop["verdict"] == "proved", loop.get("temporal")
    assert "Fwd initially 1" in _labels(loop["used"]) and loop["traced_not_needed"] == []
