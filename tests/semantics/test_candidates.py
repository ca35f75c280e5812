"""Candidate points (``semantics/candidates.py``): the double reading's verdict on quantifiers over
unbounded ``REAL``/``INTEGER``/``NATURAL`` domains, against two independent oracles on small
random tables: brute-force enumeration of each quantified variable over a dense explicit grid
(every breakpoint here is a multiple of 1/2 in [-3, 3], so a grid of sixths over [-4, 4] has
at least two points in every gap and beyond both ends: enough to tell ``exists_unique``), and Z3's exact verdict on the
concrete values (``logic/concrete.check_concrete``; every value here is a double, so the two
readings agree).  Clauses outside the fragment stay undecided, never contradicting."""
from __future__ import annotations

import itertools
from typing import Any
from fractions import Fraction

from hypothesis import example, given, settings, strategies as st

from rclverify.semantics import floatsem
from rclverify.semantics.concrete import check_concrete
from rclverify.lang import ast
from rclverify.lang import typeexpr
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.semantics.values import FiniteFunction, Term

CLAUSES = [
    "forall(x in REAL | in.f(x) <= in.n)",
    "exists(x in REAL | in.a < x and x < 2 and in.f(x) == 1)",
    "exists_unique(x in REAL | in.f(x) == 1)",
    "exists_unique(x, y in REAL | in.g(x, y))",
    "exists_unique(x in REAL | in.a <= x and x <= in.a)",
    "forall(x in REAL | in.a <= x -> in.f(x) == 0)",
    "exists_unique(k in NATURAL | in.h(k) == 2 and k <= in.n)",
    "forall(i in INTEGER | exists(x in REAL | in.f(x) == i) -> i <= in.n)",
    "forall(x in REAL | in.c == mv(x) -> in.f(x) >= 1)",
    "exists(k in NATURAL | in.c == ins(k + 1))",
    "exists_unique(i in INTEGER | in.a < i and i < in.a + 2)",
    "exists_unique(i in INTEGER | i < in.n)",
    "exists_unique(i in INTEGER | i > in.n)",
    "exists_unique(x in REAL | x < in.a and in.f(x) == 0)",
    "exists_unique(i in INTEGER | in.h(i) == 2)",
    "forall(b in BOOL, x in REAL | b -> in.f(x) <= in.n or in.g(x, in.a))",
    "exists_unique(m in {0, 1}, x in REAL | in.f(x) == m + 1)",
    "forall(x in REAL | x in {0.5, 1, in.a} -> in.g(x, x) or in.f(x) > 0)",
    "forall(x, y in REAL | in.g(x, y) -> exists(z in REAL | in.g(y, z) and not in.g(z, x)))",
    "exists(i in INTEGER | forall(x in REAL | in.f(x) != i + 1) and in.h(i) == 0)",
    # outside the fragment: undecided in the double reading
    "exists(x, y in REAL | x < y and in.g(x, y))",
    "exists(x in REAL | 2 * x == in.a)",
    "exists(i in INTEGER | in.h(i) == i + 1)",
]
TEXT = ("context { Cmd : { mv(REAL), ins(NATURAL) } ; }\n"
        "node Q { inputs( a : REAL, n : INTEGER, f : REAL --> NATURAL, g : REAL x REAL --> BOOL, "
        "h : INTEGER --> INTEGER, c : Cmd ) outputs( o : BOOL ) assume( TRUE ) "
        + " ".join(f"guarantee( {c} )" for c in CLAUSES) + " }")
CHECKED = check([parse_text(TEXT)])
NODE = CHECKED.nodes["Q"]
HALVES = [Fraction(k, 2) for k in range(-6, 7)]
GRID = {"REAL": [k / 6 for k in range(-24, 25)], "INTEGER": list(range(-6, 7)), "NATURAL": list(range(0, 7))}


class _Grid(floatsem._Double):
    """The double reading with every quantifier enumerated over the explicit grid."""

    def quant(self, e: ast.Quant, b):  # type: ignore[no-untyped-def]
        names, doms = [], []
        for bd in e.bindings:
            for n in bd.names:
                names.append(n)
                doms.append(GRID[bd.domain.name] if isinstance(bd.domain, typeexpr.TBase) and bd.domain.name != "BOOL"
                            else [False, True] if isinstance(bd.domain, typeexpr.TBase) else list(self.collection(bd.domain, b)))
        hits = 0
        for combo in itertools.product(*doms):
            holds = bool(self.eval(e.body, dict(b) | dict(zip(names, combo))))
            hits += holds
            if e.kind == "forall" and not holds:
                return False
            if e.kind == "exists" and holds:
                return True
        return e.kind == "forall" or (e.kind == "exists_unique" and hits == 1)


_half = st.sampled_from(HALVES).map(float)
_int = st.integers(-3, 3)


@st.composite
def _values(draw):  # type: ignore[no-untyped-def]
    f = draw(st.dictionaries(_half, st.integers(0, 2), max_size=4))
    g = draw(st.dictionaries(st.tuples(_half, _half), st.booleans(), max_size=4))
    h = draw(st.dictionaries(st.integers(-3, 3), st.integers(-1, 2), max_size=4))
    c = draw(st.one_of(_half.map(lambda x: Term("mv", (x,))), st.integers(0, 3).map(lambda k: Term("ins", (k,)))))
    return {"in.a": draw(_half), "in.n": draw(_int), "in.c": c, "out.o": True,
            "in.f": FiniteFunction(f, draw(st.integers(0, 2)), 1),
            "in.g": FiniteFunction(g, draw(st.booleans()), 2),
            "in.h": FiniteFunction(h, draw(st.integers(-1, 2)), 1)}


#: tables whose one key is false and default true: the point standing for every other value must
#: count as many (``exists_unique`` false), the sharpest case of a gap's count
SHARP = [{"in.a": 0.0, "in.n": 0, "in.c": Term("ins", (0,)), "out.o": True,
          "in.f": FiniteFunction({(0.5,): 0}, 1, 1), "in.g": FiniteFunction({(0.5, 1.0): False}, True, 2),
          "in.h": FiniteFunction({(1,): 0}, 2, 1)}]


def test_candidate_points_equal_brute_force_and_z3() -> None:
    decided = [0] * len(CLAUSES)
    z3_compared = [0]

    @settings(max_examples=20, deadline=None, database=None)
    @example(SHARP[0])
    @given(_values())
    def agree(values: dict) -> None:
        for k, g in enumerate(NODE.node.guarantees):
            got = floatsem.holds_in("double", g.formula, CHECKED, NODE, values)
            if k >= len(CLAUSES) - 3:
                assert got is None, (CLAUSES[k], values)
                continue
            assert got is not None, (CLAUSES[k], values)
            decided[k] += 1
            assert got == floatsem._run(_Grid(CHECKED, NODE, values), g.formula)[0], (CLAUSES[k], values)
            exact, _ = check_concrete(g.formula, CHECKED, NODE, values)
            if exact is not None:
                assert got == exact, (CLAUSES[k], values)
                z3_compared[0] += 1

    agree()
    assert all(decided[:-3]) and z3_compared[0] >= 100, (decided, z3_compared)


def test_a_point_that_is_no_double_leaves_the_quantifier_undecided() -> None:
    """A REAL the node holds is a double: a table key 1/3 is never met in the double reading,
    so that reading does not decide (exact arithmetic does)."""
    values = {"in.a": 0.0, "in.n": 0, "in.c": Term("ins", (0,)), "out.o": True,
              "in.f": FiniteFunction({(Fraction(1, 3),): 1}, 0, 1), "in.g": FiniteFunction({}, False, 2),
              "in.h": FiniteFunction({}, 0, 1)}
    clause = NODE.node.guarantees[2].formula  # exists_unique(x in REAL | in.f(x) == 1)
    assert floatsem.holds_in("double", clause, CHECKED, NODE, values) is None
    assert check_concrete(clause, CHECKED, NODE, values)[0] is True


def test_the_double_reading_of_the_case_studys_recorded_runs_decides_more_and_never_contradicts() -> None:
    """Every judgement the monitor engine makes on the case study's bundled recorded runs (each
    guarantee and assumption on the values of a step), read again in the double reading alone
    (``holds_in("double")``, the monitor's one-arithmetic reading of a message): with candidate
    points it is undecided less often than the enumeration of finite domains alone (the reading
    before them, still floatsem's ``_enumerate``), only where a value is missing (a question
    before its answer), and wherever it and the exact reading both decide they agree."""
    from pathlib import Path

    from rclverify.backends.monitors.check import NodeMonitor
    from rclverify.backends.monitors.config import load_mapping
    from rclverify.app.pipeline import Workspace
    from rclverify.traces import read_trace

    repo = Path(__file__).resolve().parents[2]
    checked = Workspace(repo, "contracts/plan.yaml").checked
    cfg = load_mapping(repo, "backends/monitors/mapping.yaml", 2.0)
    seen: dict[tuple[str, Any, tuple[Any, ...]], tuple[Any, dict]] = {}

    class Recording(NodeMonitor):
        def _judge(self, k: Any, values: Any) -> Any:  # the engine's own judgement, recorded on the way
            formula = self._guaranteed[k] if isinstance(k, int) else self.assumption[k[1]]
            seen.setdefault((self.node.name, k, tuple(sorted((q, repr(v)) for q, v in values.items()))),
                            (formula, (self.node, dict(values))))
            return super()._judge(k, values)

    for run in ("nominal.jsonl", "env_fault.jsonl", "sensor_fault.jsonl"):
        monitors = [Recording(checked, n, cfg.rules, cfg.horizon) for n in checked.nodes.values()]
        last = 0.0
        for ev in read_trace(repo / "backends" / "monitors" / "traces" / run, [repo / "backends" / "monitors" / "msg"]):
            last = ev.time
            for m in monitors:
                m.advance(ev.time)
            for m in monitors:
                m.feed(ev)
        for m in monitors:
            m.advance(last)
            m.finish()

    class Before(floatsem._Double):  # the double reading with finite domains only
        def quant(self, e, b):  # type: ignore[no-untyped-def]
            return floatsem._enumerate(self, e, b)

    before = after = contradictions = both = 0
    for formula, (node, values) in seen.values():
        now, why = floatsem._run(floatsem._Double(checked, node, values), formula)  # holds_in("double"), with why
        assert now is not None or why.startswith("no value for"), why  # undecided only on a missing value
        before += floatsem._run(Before(checked, node, values), formula)[0] is None
        after += now is None
        exact = floatsem.holds_in("exact", formula, checked, node, values)
        if now is not None and exact is not None:
            both += 1
            contradictions += now != exact
    print(f"judgements {len(seen)}: undecided in double {before} -> {after}; both decide {both}")
    assert contradictions == 0 and after < before and both > 0, (before, after, both, contradictions)
