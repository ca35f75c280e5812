"""The monitors' compiled formulas (issue 44: semantics/straightline.py,
semantics/judges.py) against the evaluator they replace on the hot path.

Hypothesis draws well-typed formulas of the fragment the monitors evaluate
(numbers of the three numeric types with exact and inexact literals,
arithmetic including division, chained comparisons, BOOL, an enumeration, a
constructor set, function tables with and without a default, membership in
set literals, named constants, now and then a quantifier the straight-line
code leaves to the evaluator) and values for the inputs and outputs (some
missing, some of the wrong form).  On each pair:

* the compiled function gives the evaluator's (tree walk's) truth, or
  raises :class:`Missing` for exactly the value the evaluator misses first,
  or raises what the evaluator raises;
* :class:`FormulaJudge` gives :func:`judge`'s judgement (truth, semantics,
  reason) without a tolerance and with one.

And on every bundled recorded run (the case study's, the safety-stop
example's) and a classifier's run with wrong answers, the monitors give the
same verdicts, event for event, with the compiled judges as with
``judge`` alone."""
from __future__ import annotations

import json
from fractions import Fraction
from pathlib import Path
from typing import Any, Callable

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from _classifier import CLASSIFIER as _CLASSIFIER
from rclverify.backends.monitors.check import check_trace
from rclverify.backends.monitors.config import load_mapping
from rclverify.semantics.evaluator import Evaluator
from rclverify.semantics.eval_values import Undecided
from rclverify.semantics.floatsem import Tolerance, judge
from rclverify.semantics.judges import FormulaJudge
from rclverify.semantics.straightline import Missing, compile_exact
from rclverify.lang.parser import parse_formula, parse_text
from rclverify.lang.typecheck import check, load
from rclverify.traces import read_trace
from rclverify.semantics.values import FiniteFunction, Term

REPO = Path(__file__).resolve().parents[2]
SIGNATURE = """
context {
  Hue : {red, green, blue} ;
  Cmd : { move(REAL, REAL), inspect(NATURAL), stop } ;
  Seen : NATURAL --> BOOL ;
  Way : REAL x REAL --> NATURAL ;
  Gain : REAL --> REAL ;
  Low : REAL = 120.5 ;
  High = Low * 2 ;
}
node n {
  inputs( r : REAL, k : NATURAL, z : INTEGER, b : BOOL, c : Hue, cmd : Cmd, f : Seen, g : Way, h : Gain )
  outputs( o : REAL, m : NATURAL, oc : Hue, ocmd : Cmd )
  guarantee( TRUE )
}
"""
CHECKED = check([parse_text(SIGNATURE)])
NODE = CHECKED.nodes["n"]
Draw = Callable[..., Any]

REAL = ["in.r", "out.o", "in.k", "0.5", "0.1", "2", "120.5", "Low", "High", "in.h(in.r)", "in.h(0.1)", "(0 - 1.5)"]
NAT = ["in.k", "out.m", "3", "0", "in.g(in.r, out.o)", "in.g(0.5, 1)"]
INT = ["in.z", "in.k", "(0 - 2)"]


def term(draw: Draw, sort: str, depth: int) -> str:
    if sort == "REAL" and depth > 0 and draw(st.booleans()):
        op = draw(st.sampled_from(["+", "-", "*", "/"]))
        return f"({term(draw, 'REAL', depth - 1)} {op} {term(draw, 'REAL', depth - 1)})"
    if sort == "REAL" and depth > 0 and draw(st.integers(0, 5)) == 0:
        return f"(-{term(draw, 'REAL', depth - 1)})"
    if sort == "INTEGER" and depth > 0 and draw(st.booleans()):
        return f"({term(draw, 'INTEGER', depth - 1)} {draw(st.sampled_from(['+', '-', '*']))} {draw(st.sampled_from(INT))})"
    return draw(st.sampled_from({"REAL": REAL, "NATURAL": NAT, "INTEGER": INT}[sort]))


def atom(draw: Draw) -> str:
    kind = draw(st.integers(0, 9))
    cmp = st.sampled_from(["<", "<=", "==", "!=", ">", ">="])
    if kind <= 2:
        sort = ("REAL", "NATURAL", "INTEGER")[kind]
        return f"({term(draw, sort, 2)} {draw(cmp)} {term(draw, sort, 2)})"
    if kind == 3:  # a chain
        return f"({term(draw, 'REAL', 1)} {draw(cmp)} {term(draw, 'REAL', 1)} {draw(cmp)} {term(draw, 'REAL', 1)})"
    if kind == 4:
        hue = st.sampled_from(["in.c", "out.oc", "red", "green", "blue"])
        return f"({draw(hue)} {draw(st.sampled_from(['==', '!=']))} {draw(hue)})"
    if kind == 5:
        cmd = st.sampled_from(["in.cmd", "out.ocmd", "stop", f"move({term(draw, 'REAL', 1)}, {term(draw, 'REAL', 0)})",
                               f"inspect({term(draw, 'NATURAL', 0)})"])
        return f"({draw(cmd)} {draw(st.sampled_from(['==', '!=']))} {draw(cmd)})"
    if kind == 6:
        return draw(st.sampled_from(["in.b", "TRUE", "FALSE", f"in.f({term(draw, 'NATURAL', 0)})",
                                     f"(in.f({term(draw, 'NATURAL', 0)}) == in.b)"]))
    if kind == 7:
        return draw(st.sampled_from([f"(out.oc {draw(st.sampled_from(['in', '!in']))} {{red, blue}})",
                                     f"({term(draw, 'NATURAL', 1)} in {{0, 2, in.k}})",
                                     f"({term(draw, 'REAL', 1)} !in {{0.1, Low}})"]))
    if kind == 8:  # left to the evaluator: a quantifier
        return draw(st.sampled_from(["forall(i in NATURAL | in.cmd == inspect(i) -> in.f(i))",
                                     "exists(x, y in REAL | in.g(x, y) == out.m)",
                                     f"(in.k in NATURAL and {term(draw, 'NATURAL', 0)} >= 0)"]))
    return f"((in.r {draw(cmp)} {term(draw, 'REAL', 1)}) <=> (out.o {draw(cmp)} {term(draw, 'REAL', 1)}))"


def formula_text(draw: Draw, depth: int) -> str:
    kind = draw(st.integers(0, 3)) if depth > 0 else 0
    if kind == 0:
        return atom(draw)
    if kind == 1:
        return f"(not {formula_text(draw, depth - 1)})"
    op = draw(st.sampled_from(["and", "or", "->", "<=>", "and", "->"]))
    return f"({formula_text(draw, depth - 1)} {op} {formula_text(draw, depth - 1)})"


@st.composite
def formulas(draw: Draw) -> str:
    return formula_text(draw, 3)


NUMBERS = [0, 1, 2, 3, 0.0, 0.5, 0.1, 0.30000000000000004, 120.5, 241.0, 1e308, -1.5, Fraction(1, 3)]


@st.composite
def values(draw: Draw) -> dict[str, Any]:
    """Values of the inputs and outputs; now and then one missing (absent or
    ``None``: not observed yet) or of the wrong form (a string for a number)."""
    num = st.sampled_from(NUMBERS)
    nat = st.integers(0, 3)
    cmd = st.one_of(st.builds(lambda a, b: Term("move", (a, b)), num, num),
                    st.builds(lambda k: Term("inspect", (k,)), nat), st.just(Term("stop", ())))
    hue = st.sampled_from(["red", "green", "blue", "purple"])
    out: dict[str, Any] = {
        "in.r": draw(num), "in.k": draw(nat), "in.z": draw(st.integers(-3, 3)), "in.b": draw(st.booleans()),
        "in.c": draw(hue), "in.cmd": draw(cmd),
        "in.f": FiniteFunction({(draw(nat),): draw(st.booleans()) for _ in range(draw(nat))}, False, 1),
        "in.g": FiniteFunction({(draw(num), draw(num)): draw(nat) for _ in range(draw(nat))},
                               draw(st.sampled_from([0, None])), 2),
        "in.h": FiniteFunction({(draw(num),): draw(num) for _ in range(draw(nat))}, draw(st.sampled_from([0.5, None])), 1),
        "out.o": draw(num), "out.m": draw(nat), "out.oc": draw(hue), "out.ocmd": draw(cmd)}
    for key in draw(st.lists(st.sampled_from(sorted(out)), max_size=2)):
        change = draw(st.integers(0, 2))
        if change == 0:
            out.pop(key, None)
        elif change == 1:
            out[key] = None
        else:
            out[key] = "oops"
    return out


def _interpreted(f: Any, vals: dict[str, Any]) -> tuple[Any, ...]:
    ev = Evaluator(CHECKED, NODE, vals)
    ev.compiled = False  # the tree walk: the reference
    try:
        return ("value", bool(ev.eval(f, {})))
    except Exception as exc:  # noqa: BLE001 - the exception is part of the behaviour compared
        return ("raised", type(exc).__name__, str(exc))


def _compiled(fn: Any, vals: dict[str, Any]) -> tuple[Any, ...]:
    try:
        return ("value", fn(vals))
    except Missing as exc:
        return ("raised", Undecided.__name__, f"no value for {exc.key}")
    except Exception as exc:  # noqa: BLE001
        return ("raised", type(exc).__name__, str(exc))


TOLERANCE = Tolerance(abs=Fraction(1, 10**6))


@settings(max_examples=60, deadline=None, database=None, derandomize=True, suppress_health_check=list(HealthCheck))
@given(formulas(), st.lists(values(), min_size=3, max_size=3))
def test_compiled_formulas_decide_as_the_evaluator_and_judge(text: str, value_sets: list[dict[str, Any]]) -> None:
    f = parse_formula(text)
    straight = compile_exact(f, CHECKED, NODE)
    plain, tolerant = FormulaJudge(f, CHECKED, NODE), FormulaJudge(f, CHECKED, NODE, TOLERANCE)
    assert (straight.fn is None) == bool(straight.fallback) == (not plain.compiled)
    for vals in value_sets:
        if straight.fn is not None:
            assert _compiled(straight.fn, vals) == _interpreted(f, vals), f"{text} on {vals}\n{straight.source}"
        assert plain(vals) == judge(f, CHECKED, NODE, vals), f"{text} on {vals}"
        assert tolerant(vals) == judge(f, CHECKED, NODE, vals, TOLERANCE), f"{text} on {vals} (tolerance)"


def test_the_generator_reaches_every_outcome() -> None:
    """Not vacuous: compiled and left-to-the-evaluator formulas, true, false,
    a missing value and an exception all occur among the generated pairs."""
    seen: set[str] = set()

    @settings(max_examples=150, deadline=None, database=None, derandomize=True,
              suppress_health_check=list(HealthCheck))
    @given(formulas(), values())
    def collect(text: str, vals: dict[str, Any]) -> None:
        f = parse_formula(text)
        s = compile_exact(f, CHECKED, NODE)
        if s.fn is None:
            seen.add("fallback")
            return
        out = _compiled(s.fn, vals)
        seen.add(str(out[1]) if out[0] == "value" else ("missing" if out[2].startswith("no value for") else "raised"))
    collect()
    assert seen >= {"fallback", "True", "False", "missing", "raised"}, seen


@pytest.mark.parametrize("text, vals, expected", [
    # an absent output does not matter where the formula holds without it (short circuit)
    ("in.cmd == stop -> out.o > 1", {"in.cmd": Term("stop", ())}, ("raised", "Undecided", "no value for out.o")),
    ("in.cmd != stop -> out.o > 1", {"in.cmd": Term("stop", ())}, ("value", True)),
    # exact: the float 0.1 is not 1/10, 0.1 + 0.2 is 3/10
    ("in.r == 0.1", {"in.r": 0.1}, ("value", False)),
    ("0.1 + 0.2 == 0.3", {}, ("value", True)),
    ("in.r * 10 > in.r", {"in.r": 1e308}, ("value", True)),  # no overflow to inf
    ("High == 241", {}, ("value", True)),  # a constant through another
    ("in.h(in.r) == 0.5", {"in.r": 2.0, "in.h": FiniteFunction({}, 0.5, 1)}, ("value", True)),
])
def test_cases(text: str, vals: dict[str, Any], expected: tuple[Any, ...]) -> None:
    f = parse_formula(text)
    fn = compile_exact(f, CHECKED, NODE).fn
    assert fn is not None
    assert _compiled(fn, vals) == expected == _interpreted(f, vals)


def test_a_quantifier_is_left_to_the_evaluator_and_says_so() -> None:
    f = parse_formula("forall(i in NATURAL | in.cmd == inspect(i) -> in.f(i))")
    j = FormulaJudge(f, CHECKED, NODE)
    assert not j.compiled and "quantifier (forall)" in j.fallback
    vals = {"in.cmd": Term("inspect", (2,)), "in.f": FiniteFunction({(2,): True}, False, 1)}
    assert j(vals) == judge(f, CHECKED, NODE, vals) and j(vals).truth is True


# -- whole runs: the same verdicts, event for event -------------------------------------------

CLASSIFIER = "\n" + _CLASSIFIER  # tests/_classifier.py


def _verdicts(checked: Any, nodes: list[Any], events: Any, rules: Any, horizon: float) -> tuple[Any, Any]:
    seen: list[Any] = []
    count, results = check_trace(checked, nodes, events, rules, horizon, seen.append)
    return seen, (count, [r.to_json() for r in results])


def _runs() -> list[tuple[Path, str, Path]]:
    case = [(REPO / "contracts/remote_inspection.rcl", "backends/monitors/mapping.yaml", p)
            for p in sorted((REPO / "backends/monitors/traces").glob("*.jsonl"))]
    ex = REPO / "examples/safety_stop"
    return case + [(ex / "contracts/safety_stop.rcl", "", p) for p in sorted((ex / "traces").glob("*.jsonl"))]


def test_bundled_runs_get_the_same_verdicts_with_and_without_the_compiled_judges(monkeypatch: Any) -> None:
    runs = _runs()
    assert len(runs) >= 4
    for contracts, mapping, trace in runs:
        root = contracts.parents[1]
        checked = load([contracts])
        cfg = load_mapping(root, mapping or None, None)
        nodes = list(checked.nodes.values())
        fast = _verdicts(checked, nodes, read_trace(trace, [root / d for d in cfg.msg_dirs]), cfg.rules, cfg.horizon)
        with monkeypatch.context() as m:
            m.setattr(FormulaJudge, "quick", lambda self, values: None)  # every formula through judge()
            slow = _verdicts(checked, nodes, read_trace(trace, [root / d for d in cfg.msg_dirs]), cfg.rules,
                             cfg.horizon)
        assert fast == slow, trace
        assert fast[0], trace


def test_a_classifier_run_with_wrong_answers_gets_the_same_verdicts(tmp_path: Path, monkeypatch: Any) -> None:
    (tmp_path / "c.rcl").write_text(CLASSIFIER)
    checked = load([tmp_path / "c.rcl"])
    lines = []
    for k, r in enumerate([5.0, 119.999, 120, 120.0000001, 249.9, 250.0, 1e6, -1.0, 130.0, 260.0, 0.1]):
        band = "green" if r < 120 else "orange" if r < 250 else "red"
        if k in (3, 8):
            band = "green"  # wrong
        lines.append({"topic": "reading", "time": 3 * k, "data": r})
        if k != 9:  # no answer within the horizon
            lines.append({"topic": "status", "time": 3 * k + 0.5, "data": band})
    lines.append({"topic": "tick", "time": 40})
    (tmp_path / "run.jsonl").write_text("".join(json.dumps(x) + "\n" for x in lines))
    nodes = [checked.nodes["Classifier"]]
    fast = _verdicts(checked, nodes, read_trace(tmp_path / "run.jsonl"), {}, 2.0)
    with monkeypatch.context() as m:
        m.setattr(FormulaJudge, "quick", lambda self, values: None)
        slow = _verdicts(checked, nodes, read_trace(tmp_path / "run.jsonl"), {}, 2.0)
    assert fast == slow
    counts = fast[1][1][0]["counts"]
    # two wrong answers violated, the reading without an answer unanswered (inconclusive)
    assert counts["violated"] == 2 and counts["inconclusive"] == 1, counts
    assert counts["assumption violated"] == 1 and counts["satisfied"] == 7, counts
    # the debug field says how each formula ran (not in the evidence record)
    _, (res,) = check_trace(checked, nodes, read_trace(tmp_path / "run.jsonl"), {}, 2.0)
    assert res.evaluation == {"assumption 1": "compiled", "guarantee 1": "compiled"}
    assert "evaluation" not in res.to_json()
    case = load([REPO / "contracts/remote_inspection.rcl"])
    _, (sensor,) = check_trace(case, [case.nodes["RadiationSensor"]], iter(()), {}, 2.0)
    assert sensor.evaluation == {"assumption 1": "compiled", "guarantee 1": "evaluated by the interpreter: a quantifier "
                                                                            "(forall) is not compiled"}
