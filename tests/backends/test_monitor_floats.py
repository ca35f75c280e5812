"""Numbers on the wire (issue 40; docs/monitors.md, "Numbers on the wire"):
a recorded value is judged by what the node could have computed, exactly,
in IEEE-754 double arithmetic, or within a declared tolerance, and the
evidence names the semantics that decided.  A node computing ``1000 * 1.2``
and publishing ``1200.0`` does not violate ``out.d == 1000 * in.r``; one
publishing ``1201.0`` does, in every semantics.

The oracle at the end compares :func:`rclverify.semantics.floatsem.judge` with
a direct reading of the three semantics written here (Fractions, Python
floats, the tolerance's definition) on random formulas and values."""
from __future__ import annotations

import json
from fractions import Fraction
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings, strategies as st

from rclverify.backends.monitors.check import check_trace
from rclverify.backends.monitors.config import ConfigError, load_mapping
from rclverify.backends.monitors.deadline_text import deadline_status
from rclverify.backends.monitors.deadlines import check_deadlines
from rclverify.backends.monitors.online import OnlineEngine
from rclverify.backends.monitors.backend import verdict_status
from rclverify.semantics.floatsem import Tolerance, judge, parse_tolerance, ulp_distance
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check, load
from rclverify.traces import read_trace
from rclverify.traces.events import Event
from rclverify.traces.mapping import load_rules

SCALE = """
node Scale {
  inputs( r : REAL )
  outputs( d : REAL )
  topics( std_msgs/Float64 r matches(in.r), std_msgs/Float64 d matches(out.d) )
  assume( in.r >= 0 )
  guarantee( out.d == 1000 * in.r ) triggered by in.r within 100 ms
}
node Clamp {
  inputs( a : REAL )
  outputs( x : REAL )
  topics( std_msgs/Float64 a matches(in.a), std_msgs/Float64 x matches(out.x) )
  assume( TRUE )
  guarantee( out.x <= 30 )
}
"""


@pytest.fixture(scope="module")
def checked(tmp_path_factory: pytest.TempPathFactory) -> Any:
    p = tmp_path_factory.mktemp("floats") / "scale.rcl"
    p.write_text(SCALE)
    return load([p])


def _log(tmp: Path, lines: list[dict[str, Any]]) -> Path:
    p = tmp / "run.jsonl"
    p.write_text("".join(json.dumps(x) + "\n" for x in lines))
    return p


RUN = [  # the node computes 1000 * r in double; its third answer is wrong by 1
    {"topic": "r", "time": 0.0, "data": 1.2}, {"topic": "d", "time": 0.01, "data": 1000 * 1.2},
    {"topic": "r", "time": 1.0, "data": 0.7}, {"topic": "d", "time": 1.01, "data": 1000 * 0.7},
    {"topic": "r", "time": 2.0, "data": 1.2}, {"topic": "d", "time": 2.01, "data": 1201.0},
    {"topic": "clock", "time": 9.0},  # past every horizon and deadline
]


def test_a_float_equality_that_holds_in_double_is_no_violation_and_a_real_one_is(checked: Any, tmp_path: Path) -> None:
    assert 1000 * 1.2 == 1200.0 and Fraction(1.2) * 1000 != 1200  # the premise: exact and double disagree
    seen: list[Any] = []
    _, (res,) = check_trace(checked, [checked.nodes["Scale"]], read_trace(_log(tmp_path, RUN)), {}, 5.0, seen.append)
    assert [(v.verdict, v.semantics) for v in seen] == [
        ("satisfied", "double"), ("satisfied", "double"), ("violated", "exact, double")]
    assert res.semantics == {"exact": 0, "double": 2, "tolerance": 0}
    assert res.first_inexact is not None and res.first_inexact["semantics"] == "double"
    assert res.first_inexact["formula"].startswith("guarantee 1")
    v = res.first_violation
    assert v is not None and v["where"].endswith("run.jsonl:6") and v["semantics"] == "exact, double"
    assert "false in exact and double arithmetic" in v["reason"]
    status, text = verdict_status(res, "run.jsonl")
    assert status == "failed" and "only in the node's double arithmetic" not in text.split("; the first")[0]
    # the deadlines read the same judgement: two answers in time, the wrong one never answers as guaranteed
    late = check_deadlines(checked, [checked.nodes["Scale"]], read_trace(_log(tmp_path, RUN)), {})[0]
    assert late.counts == {"true": 2, "currently_false": 0, "false": 1} and late.first_false is not None
    assert "the output at run.jsonl:6 did not satisfy guarantee 1 (false in exact, double arithmetic)" \
        in late.first_false.reason
    assert "never answered as guaranteed" in deadline_status(late, "run.jsonl")[1]


def test_the_evidence_says_which_semantics_decided(checked: Any, tmp_path: Path) -> None:
    _, (res,) = check_trace(checked, [checked.nodes["Scale"]], read_trace(_log(tmp_path, RUN[:4] + RUN[-1:])), {}, 5.0)
    status, text = verdict_status(res, "run.jsonl")
    assert status == "discharged"
    assert "2 only in the node's double arithmetic (first at run.jsonl:2: guarantee 1 (out.d == 1000 * in.r))" in text


def test_an_output_over_a_bound_is_a_violation_unless_a_tolerance_is_declared(checked: Any, tmp_path: Path) -> None:
    run = [{"topic": "a", "time": 0.0, "data": 1.0}, {"topic": "x", "time": 0.1, "data": 30.000000000000004},
           {"topic": "clock", "time": 9.0}]
    clamp = checked.nodes["Clamp"]
    # the recorded value is never moved: above 30 in exact and in double arithmetic
    _, (res,) = check_trace(checked, [clamp], read_trace(_log(tmp_path, run)), {}, 5.0)
    assert res.counts["violated"] == 1 and res.first_violation["semantics"] == "exact"  # type: ignore[index]
    rules = load_rules({})
    rules.tolerance = parse_tolerance({"abs": 1e-9})
    seen: list[Any] = []
    _, (res,) = check_trace(checked, [clamp], read_trace(_log(tmp_path, run)), rules, 5.0, seen.append)
    assert [(v.verdict, v.semantics) for v in seen] == [("satisfied", "tolerance")]
    # an explicit tolerance overrides the rules'; a real excess is still caught within it
    far = [run[0], {"topic": "x", "time": 0.1, "data": 30.5}, run[2]]
    _, (res,) = check_trace(checked, [clamp], read_trace(_log(tmp_path, far)), rules, 5.0)
    assert res.counts["violated"] == 1 and res.first_violation["semantics"] == "exact, tolerance"  # type: ignore[index]
    _, (res,) = check_trace(checked, [clamp], read_trace(_log(tmp_path, far)), {}, 5.0,
                            tolerance=Tolerance(abs=Fraction(1)))
    assert res.counts["satisfied"] == 1


def test_the_online_engine_gives_the_same_verdicts(checked: Any, tmp_path: Path) -> None:
    offline: list[Any] = []
    check_trace(checked, list(checked.nodes.values()), read_trace(_log(tmp_path, RUN)), {}, 5.0, offline.append)
    live: list[Any] = []
    eng = OnlineEngine(checked, list(checked.nodes.values()), {}, 5.0, on_verdict=live.append)
    for x in RUN[:-1]:
        eng.push(x["topic"], {k: v for k, v in x.items() if k not in ("topic", "time")}, x["time"])
    eng.tick(RUN[-1]["time"])  # the live timer passes the horizon
    eng.finish()
    assert [v.to_json()["semantics"] for v in live] == [v.semantics for v in offline]
    assert [(v.verdict, v.event) for v in live] == [(v.verdict, v.event) for v in offline]


def test_a_literal_is_what_the_node_wrote(tmp_path: Path) -> None:
    p = tmp_path / "lit.rcl"
    p.write_text("""node Lit {
  inputs( a : REAL ) outputs( x : REAL )
  topics( std_msgs/Float64 a matches(in.a), std_msgs/Float64 x matches(out.x) )
  assume( TRUE )
  guarantee( out.x == 0.1 + 0.2 and out.x != 0.3 )
}""")
    c = load([p])
    n = c.nodes["Lit"]
    g = n.node.guarantees[0].formula
    j = judge(g, c, n, {"in.a": 0.0, "out.x": 0.1 + 0.2})  # 0.30000000000000004
    assert (j.truth, j.semantics) == (True, "double")
    j = judge(g, c, n, {"in.a": 0.0, "out.x": 0.3})  # not what 0.1 + 0.2 gives in double, and not 3/10 exactly
    assert (j.truth, j.semantics) == (False, "exact, double")


def test_no_quantifier_over_the_reals_is_guessed_in_double(tmp_path: Path) -> None:
    """``x + 1 == out.y`` has many double solutions: the exact evaluator's
    candidate values do not cover them, so double arithmetic does not decide."""
    p = tmp_path / "q.rcl"
    p.write_text("""node Q {
  inputs( a : REAL ) outputs( y : REAL, z : REAL )
  topics( std_msgs/Float64 a matches(in.a), std_msgs/Float64 y matches(out.y), std_msgs/Float64 z matches(out.z) )
  assume( TRUE )
  guarantee( forall(x in REAL | x + 1 == out.y -> out.z == 0) )
  guarantee( forall(k in NATURAL | k <= 3 -> out.y * k >= 0.3 * k) )
}""")
    c = load([p])
    n = c.nodes["Q"]
    g1, g2 = (cl.formula for cl in n.node.guarantees)
    j = judge(g1, c, n, {"in.a": 0.0, "out.y": 1.1, "out.z": 1.0})
    assert j.truth is None and "undecided in double arithmetic" in j.reason and "REAL" in j.reason
    # a literal-bounded integer variable is enumerated in every semantics: 0.1 * 3 vs 0.3 * 3
    assert judge(g2, c, n, {"in.a": 0.0, "out.y": 0.1 * 3 / 3, "out.z": 0.0}).truth is not None
    j = judge(g2, c, n, {"in.a": 0.0, "out.y": 0.29, "out.z": 0.0})
    assert (j.truth, j.semantics) == (False, "exact, double")


def test_tolerances_are_read_and_refused_located(tmp_path: Path) -> None:
    assert parse_tolerance({"abs": "1e-9", "ulps": 4}) == Tolerance(abs=Fraction(1e-9), ulps=4)
    assert parse_tolerance(None) is None
    for bad, key in (({"abs": -1}, "abs"), ({"rel": float("nan")}, "rel"), ({"ulps": 1.5}, "ulps"),
                     ({"abz": 1}, "abz")):
        with pytest.raises(ValueError) as e:
            parse_tolerance(bad)
        assert key in str(e.value)
    (tmp_path / "mapping.yaml").write_text("topics:\n  r: {fields: [data]}\ntolerance:\n  abs: -0.5\n")
    with pytest.raises(ConfigError) as e2:
        load_mapping(tmp_path, "mapping.yaml")
    assert str(e2.value).startswith("mapping.yaml:4:8: error: tolerance: abs must be a finite number >= 0")
    (tmp_path / "mapping.yaml").write_text("topics:\n  r: {fields: [data]}\ntolerance: {rel: 1.0e-6}\n")
    cfg = load_mapping(tmp_path, "mapping.yaml")
    assert cfg.tolerance == Tolerance(rel=Fraction(1e-6)) and cfg.rules.tolerance == cfg.tolerance  # type: ignore[attr-defined]
    assert load_mapping(tmp_path, "mapping.yaml", tolerance={"abs": 0.5}).tolerance == Tolerance(abs=Fraction(1, 2))
    with pytest.raises(ConfigError) as e2:
        load_mapping(tmp_path, "mapping.yaml", tolerance={"ulps": -1})
    assert e2.value.path == ("tolerance", "ulps")


def test_ulp_distance() -> None:
    import math
    assert ulp_distance(1.0, math.nextafter(1.0, 2)) == 1
    assert ulp_distance(-0.0, 0.0) == 0
    assert ulp_distance(math.nextafter(0.0, -1), math.nextafter(0.0, 1)) == 2


# -- the oracle: judge against the three semantics read directly -------------------------------------------

_OPS = ("+", "-", "*")
_LITS = ("0.1", "0.2", "0.3", "3", "1000", "1.2", "0.5")


@st.composite
def _term(draw: Any, depth: int = 0) -> tuple[str, Any, Any]:
    """(RCL text, exact value function, double value function) over in.r, out.d."""
    if depth >= 2 or draw(st.booleans()):
        leaf = draw(st.sampled_from(("in.r", "out.d", *_LITS)))
        if leaf == "in.r":
            return leaf, lambda v: Fraction(v["in.r"]), lambda v: v["in.r"]
        if leaf == "out.d":
            return leaf, lambda v: Fraction(v["out.d"]), lambda v: v["out.d"]
        return leaf, (lambda q: lambda v: q)(Fraction(leaf)), (lambda f: lambda v: f)(float(leaf) if "." in leaf else int(leaf))
    op = draw(st.sampled_from(_OPS))
    (lt, le, ld), (rt, re_, rd) = draw(_term(depth + 1)), draw(_term(depth + 1))
    fn = {"+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b}[op]
    return (f"({lt} {op} {rt})", (lambda f, a, b: lambda v: f(a(v), b(v)))(fn, le, re_),
            (lambda f, a, b: lambda v: f(a(v), b(v)))(fn, ld, rd))


_CMPS = {"==": lambda a, b: a == b, "<=": lambda a, b: a <= b, "<": lambda a, b: a < b, "!=": lambda a, b: a != b}


@st.composite
def _formula(draw: Any) -> tuple[str, Any]:
    """(RCL text, truth(values, semantics)) of ``[not] (a op b) [and|or c op2 d]``."""
    atoms = []
    for _ in range(draw(st.integers(1, 2))):
        (lt, le, ld), (rt, re_, rd) = draw(_term()), draw(_term())
        op = draw(st.sampled_from(tuple(_CMPS)))
        atoms.append((f"{lt} {op} {rt}", op, le, ld, re_, rd))
    neg = draw(st.booleans())
    join = draw(st.sampled_from(("and", "or")))
    text = f" {join} ".join(f"({a[0]})" for a in atoms)
    text = f"not ({text})" if neg else text

    def reads(a: Any) -> bool:
        """Whether the atom reads a recorded value: a comparison of literals alone stays exact under tolerance."""
        return "in.r" in a[0] or "out.d" in a[0]

    def truth(v: dict[str, float], sem: str, tol: Fraction) -> bool:
        def atom(a: Any) -> bool:
            _, op, le, ld, re_, rd = a
            if sem == "double":
                return bool(_CMPS[op](ld(v), rd(v)))
            x, y = le(v), re_(v)
            if sem == "exact" or not reads(a):
                return bool(_CMPS[op](x, y))
            close = abs(x - y) <= tol
            return {"==": close, "!=": not close, "<=": x <= y or close, "<": x < y and not close}[op]
        vals = [atom(a) for a in atoms]
        out = all(vals) if join == "and" else any(vals)
        return not out if neg else out
    return text, truth


@settings(max_examples=60, deadline=None)
@given(f=_formula(), r=st.sampled_from((0.1, 0.2, 0.3, 1.2, 0.7, 3.0, 1e-9)),
       d=st.sampled_from((0.30000000000000004, 0.3, 1200.0, 120.0, 0.1, 1.0, 3.6, 0.0)),
       tol=st.sampled_from((None, Fraction(1, 10**9), Fraction(1, 100))))
def test_judge_equals_the_semantics_read_directly(f: Any, r: float, d: float, tol: Fraction | None) -> None:
    text, truth = f
    c = check([parse_text(f"node O {{ inputs( r : REAL ) outputs( d : REAL ) assume( TRUE ) guarantee( {text} ) }}",
                          "o.rcl")])
    n = c.nodes["O"]
    v = {"in.r": r, "out.d": d}
    j = judge(n.node.guarantees[0].formula, c, n, v, Tolerance(abs=tol) if tol else None)
    sems = ["exact", "double"] + (["tolerance"] if tol else [])
    expected = next((s for s in sems if truth(v, s, tol or Fraction(0))), None)
    if expected is None:
        assert j.truth is False, (text, v, j)
    else:
        assert j.truth is True, (text, v, j)
        assert j.semantics == expected, (text, v, j)  # exact first, then double, then the tolerance


def test_the_evidence_and_the_report_name_the_semantics(tmp_path: Path) -> None:
    """``rclverify verify`` on a workspace whose recorded run needs double
    arithmetic (Scale) and a declared tolerance (Clamp, plan entry)."""
    from rclverify.cli.commands import main
    ws = tmp_path / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts" / "scale.rcl").write_text(SCALE)
    runs = ws / "runs"
    runs.mkdir()
    _log(runs, RUN[:4] + RUN[-1:])
    (runs / "clamp.jsonl").write_text("".join(json.dumps(x) + "\n" for x in (
        {"topic": "a", "time": 0.0, "data": 1.0}, {"topic": "x", "time": 0.1, "data": 30.000000000000004},
        {"topic": "a", "time": 9.0, "data": 2.0}, {"topic": "x", "time": 9.1, "data": 3.0})))
    (ws / "contracts" / "plan.yaml").write_text(
        "name: floats\ncontracts: [contracts/scale.rcl]\nnodes:\n"
        "  Scale:\n    evidence:\n      - backend: monitors\n        traces: [runs/run.jsonl]\n"
        "  Clamp:\n    evidence:\n      - backend: monitors\n        tolerance: {abs: 1.0e-9}\n"
        "        traces: [runs/clamp.jsonl]\n")
    main(["verify", "-w", str(ws)])
    ev = json.loads((ws / "artifacts" / "evidence" / "Scale.g0.monitors.run_jsonl.json").read_text())
    assert ev["status"] == "discharged", ev["explanation"]
    m = ev["details"]["monitoring"]
    assert m["semantics"] == {"exact": 0, "double": 2, "tolerance": 0} and m["first_inexact"]["semantics"] == "double"
    assert m["assumption"]["verdict"] == "held" and m["tolerance"] is None
    assert "2 only in the node's double arithmetic" in ev["explanation"]
    assert ev["details"]["deadlines"]["counts"]["true"] == 2
    clamp = json.loads((ws / "artifacts" / "evidence" / "Clamp.g0.monitors.clamp_jsonl.json").read_text())
    assert clamp["status"] == "discharged" and clamp["details"]["monitoring"]["semantics"]["tolerance"] == 1
    assert clamp["details"]["monitoring"]["tolerance"] == {"abs": 1e-9, "rel": 0.0, "ulps": 0}
    md = (ws / "reports" / "assurance.md").read_text()
    assert "held only in the node's double arithmetic" in md and "held only within the tolerance" in md


def test_a_comparison_of_literals_alone_stays_exact_under_a_tolerance() -> None:
    """``0.3 * 0.3 == 0.1`` reads no recorded value: within an absolute tolerance of 0.01 (exactly the gap)
    it is still false, since a tolerance covers what a node published, not the contract's own numbers
    (found by the oracle above, whose first reading applied the tolerance to every comparison)."""
    c = check([parse_text("node O { inputs( r : REAL ) outputs( d : REAL ) assume( TRUE ) "
                          "guarantee( ((0.3 * 0.3) == 0.1) and (in.r == in.r) ) }", "o.rcl")])
    n = c.nodes["O"]
    j = judge(n.node.guarantees[0].formula, c, n, {"in.r": 0.1, "out.d": 0.3}, Tolerance(abs=Fraction(1, 100)))
    assert j.truth is False
    near = check([parse_text("node O { inputs( r : REAL ) outputs( d : REAL ) assume( TRUE ) "
                             "guarantee( (0.3 * 0.3) == out.d ) }", "o.rcl")])
    m = near.nodes["O"]
    k = judge(m.node.guarantees[0].formula, near, m, {"in.r": 0.1, "out.d": 0.1}, Tolerance(abs=Fraction(1, 50)))
    assert (k.truth, k.semantics) == (True, "tolerance")
