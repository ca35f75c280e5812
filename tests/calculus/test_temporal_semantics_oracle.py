"""An independent oracle for the composed system of a temporal requirement
(issues 40 and 47): answers, progress, initial values, fairness and
published values (a value no node has published is absent: B's input
before A's first answer, a state formula over an output not yet published).

Small random two-node workspaces over a three-value enumeration: A reads an
environment input ``x`` (its assumption keeps it in a random set) and
outputs ``y`` by a random relation; B reads ``y`` (its assumption a random
set of values) and outputs ``z`` by a random relation; each node declares at
random no progress, ``progress( eventually )``, ``within 0 steps`` or
``within 1 steps``, and perhaps an initial value.  The rules of
docs/requirements.md ("The transition relation") are written out here in
plain Python, the runs enumerated, and the verdicts of ``eventually z ==
g`` and ``always z != h`` (with the rule that no run may stop) compared with
the real check (calculus/requirements/temporal_check.py): ``proved`` must be true,
``refuted`` false with a trace that is a run of the explicit system (a
lasso's loop fair); ``inconclusive`` is counted and kept rare.  Real Z3.
"""
from __future__ import annotations

import itertools
import json
import random
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from test_temporal_oracle import _closure, _fair_cycle
from rclverify.semantics.world import fresh
from rclverify.app.pipeline import Workspace
from rclverify.calculus.requirements.check import check_requirement

V = ("a", "b", "c")
KINDS = ("", "progress( eventually )", "progress( within 0 steps )", "progress( within 1 steps )")


@dataclass(frozen=True)
class Node:
    accept: frozenset[str]               # the values of its input its assumption accepts
    rel: frozenset[tuple[str, str]]      # (input, output) pairs its guarantee allows
    progress: str
    initially: str | None                # the initial value of its output

    @property
    def bound(self) -> int | None:
        return 0 if "within 0" in self.progress else 1 if "within 1" in self.progress else None

    def rcl(self, name: str, inp: str, out: str) -> str:
        def alts(vs: Any) -> str:
            return " or ".join(vs) or "FALSE"
        g = alts(f"(in.{inp} == {i} and out.{out} == {o})" for i, o in sorted(self.rel))
        a = alts(f"in.{inp} == {v}" for v in sorted(self.accept))
        init = f"\n  initially( out.{out} == {self.initially} )" if self.initially else ""
        return (f"node {name} {{\n  inputs( {inp} : V )\n  outputs( {out} : V )\n  assume( {a} )\n"
                f"  guarantee( {g} ){init}\n  {self.progress}\n}}\n")


@dataclass(frozen=True)
class Case:
    a: Node
    b: Node
    goal: str
    avoid: str


@st.composite
def cases(draw: Any) -> Case:
    rnd = random.Random(draw(st.integers(0, 2**32 - 1)))

    def node(full: bool) -> Node:
        accept = frozenset(V) if full else frozenset(v for v in V if rnd.random() < 0.7) or frozenset({rnd.choice(V)})
        rel = frozenset((i, o) for i in V for o in V if rnd.random() < 0.35)
        if rnd.random() < 0.5:  # a node that answers every input it accepts with one value: goals become reachable
            o = rnd.choice(V)
            rel = frozenset((i, o) for i in V)
        return Node(accept, rel, rnd.choice(KINDS), rnd.choice([None, None, *V]))
    a = node(False)  # A's assumption is over the environment's x: the environment keeps to it
    return Case(a, node(False), rnd.choice(V), rnd.choice(V))


# --- the explicit system ------------------------------------------------------------------------
# a state: (x, y (A's output), A answers, A waiting, y' (B's input), z, B answers, B waiting,
#          A published, B published, B heard y) -- the published-value reading of docs/semantics.md
State = tuple[str, str, bool, int, str, str, bool, int, bool, bool, bool]


def _waiting(n: Node, accepted: bool, answers: bool, before: int | None) -> list[int]:
    """The waiting values a node may have (none: the rules of progress fail)."""
    if n.bound is None:
        return [0]
    if answers or not accepted:
        return [0]
    w = 1 if before is None else before + 1
    return [w] if w <= n.bound else []


def _node_steps(n: Node, inp: str, out_before: str | None, w_before: int | None,
                ready: bool = True) -> list[tuple[str, bool, int]]:
    """(output, answers, waiting) a node may take given its input now and its output and waiting before
    (``None``: step 0, the output then free or its initial value); ``ready``: its input was published (a
    node owes an answer, and may give one, only then)."""
    accepted = ready and inp in n.accept
    res = []
    for answers in (False, True):
        if answers:
            if not accepted:
                continue
            outs = [o for i, o in n.rel if i == inp]
        elif out_before is not None:
            outs = [out_before]
        else:
            outs = [n.initially] if n.initially else list(V)
        if n.bound == 0 and accepted and not answers:
            continue
        for w in _waiting(n, accepted, answers, w_before):
            res += [(o, answers, w) for o in outs]
    return res


def explicit(c: Case) -> tuple[set[State], dict[State, frozenset[State]]]:
    def states_from(prev: State | None) -> list[State]:
        out = []
        for x in sorted(c.a.accept):
            ya = _node_steps(c.a, x, prev[1] if prev else None, prev[3] if prev else None)
            yins = [prev[1]] if prev else list(V)  # B's input is A's output before; at step 0 it is free
            heard = bool(prev and prev[8])  # ... but absent until A has published
            for yin in yins:
                zb = _node_steps(c.b, yin, prev[5] if prev else None, prev[7] if prev else None, heard)
                for (y, ay, wa), (z, bz, wb) in itertools.product(ya, zb):
                    pa = (ay or c.a.initially is not None) if prev is None else (prev[8] or ay)
                    pb = (bz or c.b.initially is not None) if prev is None else (prev[9] or bz)
                    out.append((x, y, ay, wa, yin, z, bz, wb, pa, pb, heard))
        return out
    init = set(states_from(None))
    succ: dict[State, frozenset[State]] = {}
    todo = list(init)
    while todo:
        s = todo.pop()
        if s in succ:
            continue
        succ[s] = frozenset(states_from(s))
        todo += [t for t in succ[s] if t not in succ]
    return init, succ


def truth(c: Case, init: set[State], succ: dict[State, frozenset[State]]) -> dict[str, bool]:
    reach = _closure(init, succ)
    dead = {s for s in reach if not succ[s]}
    fair = tuple((frozenset(s for s in reach if s[4 if k else 0] in n.accept and (s[10] or not k)),
                  frozenset(s for s in reach if s[6 if k else 2]))
                 for k, n in enumerate((c.a, c.b)) if n.progress)
    missing = _closure(init, succ, lambda s: not (s[9] and s[5] == c.goal))  # reached on a published z only
    misses = bool(missing & dead) or _fair_cycle(missing, succ, fair)
    return {"eventually": not misses and not dead,
            "always": all(not s[9] or s[5] != c.avoid for s in reach) and not dead}


def _row(values: dict[str, str], key: str) -> str:
    return values[key].lower()


def as_state(step: dict[str, Any]) -> State:
    a = next(x["values"] for x in step["nodes"] if x["node"] == "A")
    b = next(x["values"] for x in step["nodes"] if x["node"] == "B")
    return (a["in.x"], a["out.y"], _row(a, "answers") == "true", int(a.get("waiting", 0)), b["in.y"], b["out.z"],
            _row(b, "answers") == "true", int(b.get("waiting", 0)), _row(a, "published") == "true",
            _row(b, "published") == "true", _row(b, "heard.y") == "true")


COUNTS: Counter[str] = Counter()


@pytest.fixture(autouse=True, scope="module")
def _fresh_z3_world() -> Any:
    fresh()
    yield
    print(dict(sorted(COUNTS.items())))
    for name in ("eventually", "always"):
        total = sum(v for k, v in COUNTS.items() if k.startswith(name + ":"))
        assert COUNTS[f"{name}: inconclusive"] <= total / 4, dict(COUNTS)


@settings(max_examples=30, deadline=None, suppress_health_check=list(HealthCheck))
@given(c=cases())
def test_composed_verdicts_agree_with_the_explicit_runs(c: Case, tmp_path_factory: pytest.TempPathFactory) -> None:
    ws = tmp_path_factory.mktemp("sem")
    (ws / "contracts").mkdir()
    (ws / "contracts/s.rcl").write_text("context { V : {a, b, c} ; }\n" + c.a.rcl("A", "x", "y") + c.b.rcl("B", "y", "z"))
    reqs = {"E": f"eventually B.out.z == {c.goal}", "S": f"always B.out.z != {c.avoid}"}
    (ws / "contracts/plan.yaml").write_text("contracts: [contracts/s.rcl]\nrequirements:\n" + "".join(
        f"  - id: {k}\n    text: {k}\n    formal: {json.dumps(f)}\n" for k, f in reqs.items()))
    w = Workspace(Path(ws))
    init, succ = explicit(c)
    want = truth(c, init, succ)
    for req in w.plan.requirements:
        name = "eventually" if req.id == "E" else "always"
        rec = check_requirement(req, w.checked, w.model, w.plan)
        t = rec["temporal"]
        COUNTS[f"{name}: {t['status']}"] += 1
        if t["status"] == "proved":
            assert want[name], (c, name, t)
        elif t["status"] == "refuted":
            assert not want[name], (c, name, t)
            path = [as_state(s) for s in t["trace"]]
            assert path[0] in init and all(b in succ[a] for a, b in zip(path, path[1:])), (c, t)
            if t["method"].endswith("deadlock"):
                assert not succ[path[-1]], (c, t)
            if t.get("loop") is not None and t["method"].endswith("lasso"):
                ring = path[t["loop"]:-1]
                assert path[-1] == path[t["loop"]]
                for k, n in enumerate((c.a, c.b)):
                    if n.progress:  # a fair loop: accepted somewhere -> answers somewhere
                        acc = any(s[4 if k else 0] in n.accept and (s[10] or not k) for s in ring)
                        assert not acc or any(s[6 if k else 2] for s in ring), (c, t)
        else:
            assert t["status"] == "inconclusive", t
