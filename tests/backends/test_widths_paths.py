"""Every path reads a comparison at its fields' widths (docs/semantics.md, "Widths").

The rule lives in :func:`rclverify.semantics.widths.at_widths`; each path
asks it for the width of each comparison and its constants' values there:
rclverify's monitor (recorded and live) and the property tests, which judge
the contract so read (:func:`rclverify.semantics.floatsem.judge`, Z3 on the
values where direct evaluation cannot decide), and the translations: the
evaluator ``generate ros2`` packages carry (``contract_eval.py``), the
generated C++ checks, Dafny and RML.

* **The slip and its correct twin.**  A ``std_msgs/Float32`` battery level
  and ``out.low <=> in.p <= 0.2`` in six forms: the package's carried
  judgement gives rclverify's monitor's verdict on every ``float32`` value
  three steps either side of the carried 0.2, for the correct node (``p <=
  0.2f``: satisfied everywhere) and for the ``<`` slip (violated at the
  carried 0.2 only).  The control: the clauses carried without the widths
  invert both verdicts at 0.2f (the correct node violated, the slip
  satisfied), as the carried evaluator did before it read widths.
* **The corpus.**  A node with a ``float32``, a ``float64`` and a ``float32``
  sequence input holds forty-odd guarantees ``out.ok <=> F``: each threshold
  form (literal, named constant, difference, negation, ``abs``, a sum of
  constants, the converse, a quotient, a product), implication chains,
  quantifiers over the sequence (empty and not), a division by a recorded
  value (zero among the values), mixed widths, and seeded random
  combinations of them.  On a fixed seeded set of points (every ``float32``
  three steps either side of 0.2f and 0.15f; ``float64`` values at and next
  to 0.2; sequences empty, at and next to 0.2f), each guarantee's truth is
  the same on each path: the reference judgement, Z3 on the point, rclverify's
  monitor (its streaming engine; and its batch path, numpy columns, on
  each guarantee not over the sequence as a node of the inputs it reads), the carried evaluator run as Python, and the C++ checks
  compiled once with g++ (its double reading; where the exact and double
  readings agree, the verdict).  Where a path declines a guarantee it says
  why, and the test names the reason: the carried evaluator and the C++
  checks do not enumerate a quantifier over a sequence; RCL has no modulo
  (``%``) to translate.  The plain threshold forms are also checked against
  numpy's ``float32`` comparison, the oracle independent of rclverify.
  A ``float64`` constant is all the digits of its double: the exact reading
  of ``in.q == 0.2`` at the double 0.2 is numpy's float64 verdict (a
  constant cut to 28 digits read it as false).
* **Dafny and RML** state the constant compared with a ``float32`` field as
  the exact value of its ``float32`` (a Dafny ``real``, an RML guard).
"""
from __future__ import annotations

import dataclasses
import importlib.util
import random
import shutil
import subprocess
import types
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from rclverify.backends.monitors.check import check_trace
from rclverify.backends.monitors.widths import at_carried_widths, carried_widths
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.lang.types import Checked, CheckedNode
from rclverify.semantics.concrete import check_concrete
from rclverify.semantics.definedness import defined
from rclverify.semantics.evaluate import evaluate
from rclverify.semantics.floatsem import holds_in, judge
from rclverify.semantics.operators import OPERATORS
from rclverify.targets.python.carry import carried
from rclverify.tools.generate.writer import render_tree
from rclverify.traces.events import Event

F32 = np.float32


def _f32(x: float) -> float:
    return float(F32(x))


def _steps(c: float, n: int = 3) -> list[float]:
    """The float32 values ``n`` steps either side of ``c``'s nearest float32 (numpy.nextafter), it included."""
    out, lo, hi = [F32(c)], F32(c), F32(c)
    for _ in range(n):
        lo, hi = np.nextafter(lo, F32(-np.inf)), np.nextafter(hi, F32(np.inf))
        out += [lo, hi]
    return sorted(float(v) for v in out)


def _write(files: dict[str, str], root: Path) -> None:
    for rel, text in files.items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(text)


def _layer(checked: Checked, system: str, root: Path) -> types.ModuleType:
    """The contract layer (``contract.py`` with its ``contract_eval.py``) of the one node of
    ``checked``, as ``generate ros2`` writes it, loaded as a lone file."""
    gen, _, _ = render_tree(checked, system)
    _write(gen, root)
    path = next(root.glob("*/*/contract.py"))
    spec = importlib.util.spec_from_file_location(f"{system}_contract", path)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _monitor(checked: Checked, node: CheckedNode, steps: list[dict[str, Any]]) -> list[str]:
    """rclverify's monitor over a recorded run of ``steps`` (each: the inputs' messages, then the
    answer ``out.*``): the node read at its fields' widths as the monitors backend reads it
    (:func:`at_carried_widths`), one verdict per answer."""
    at = at_carried_widths(node, carried_widths(node, {}, []), checked.env.constants)
    topics = {t.match.qualified: t.field.lstrip("/") for t in node.node.topics if t.match is not None}
    events: list[Event] = []
    for vals in steps:
        for key in sorted(vals, key=lambda k: k.startswith("out.")):  # the question, then its answer
            field = "ranges" if isinstance(vals[key], tuple) else "data"
            value = list(vals[key]) if isinstance(vals[key], tuple) else vals[key]
            events.append(Event(len(events), 0.1 * (len(events) + 1), topics[key], {field: value}, f"m:{len(events)}"))
    got: dict[int, str] = {}
    check_trace(checked, [at], events, {}, 100.0, on_verdict=lambda v: got.__setitem__(v.event, v.verdict))
    answers = [e.index for e in events if e.topic == topics[next(k for k in steps[0] if k.startswith("out."))]]
    return [got.get(i, "none") for i in answers]


# ---------------------------------------------------------------------------------------------
# the slip and its correct twin: the carried judgement is the monitor's
# ---------------------------------------------------------------------------------------------

LOW_FORMS = ("in.p <= 0.2", "in.p <= Low", "in.p - 0.2 <= 0", "-in.p >= -0.2", "abs(in.p) <= 0.2",
             "in.p <= 0.1 + 0.1")
GAUGE = """
context { Low : REAL = 0.2 ; }
node Gauge {
  inputs( p : REAL )
  outputs( low : BOOL )
  topics( std_msgs/Float32 battery matches(in.p), std_msgs/Bool low matches(out.low) )
  guarantee( out.low <=> FORM )
}
"""


@pytest.mark.parametrize("form", LOW_FORMS)
def test_the_carried_judgement_finds_the_slip_as_the_monitor_does(tmp_path: Path, form: str) -> None:
    checked = check([parse_text(GAUGE.replace("FORM", form), "gauge.rcl")])
    node = checked.nodes["Gauge"]
    layer = _layer(checked, "gauge", tmp_path)
    limit = F32(0.2)
    points = [p for p in _steps(0.2) if p >= 0]
    for name, decide in (("correct", lambda p: bool(F32(p) <= limit)), ("slip", lambda p: bool(F32(p) < limit))):
        steps = [{"in.p": p, "out.low": decide(p)} for p in points]
        mine = [layer.judge(s)["verdict"] for s in steps]
        assert mine == _monitor(checked, node, steps), (name, form)
        want = ["violated" if name == "slip" and p == _f32(0.2) else "satisfied" for p in points]
        assert mine == want, (name, form, list(zip(points, mine)))
    # the control: carried without the widths, the verdicts at the carried 0.2 are inverted
    plain = carried(checked, node)["guarantees"][0]
    at = {"in.p": _f32(0.2)}
    assert layer.ev.judge(plain, {**at, "out.low": True})[0] is False  # the correct node read as violating
    assert layer.ev.judge(plain, {**at, "out.low": False})[0] is True  # the slip read as satisfying


# ---------------------------------------------------------------------------------------------
# the corpus: every path, the same truth
# ---------------------------------------------------------------------------------------------

#: (form over the literal {c}, its half {h} and the constant {K}; whether it is strict) whose truth is
#: numpy's float32 comparison of in.p with the threshold: the oracle outside rclverify
THRESHOLD_FORMS = (
    ("in.p <= {c}", False), ("in.p < {K}", True), ("in.p - {c} <= 0", False), ("-in.p >= -{K}", False),
    ("abs(in.p) <= {h} + {h}", False), ("{c} >= in.p", False), ("0 > in.p - {c}", True),
    ("in.p / 2 <= {c} / 2", False), ("in.p * 4 <= {K} * 4", False), ("-{c} < -in.p", True),
)
#: further forms: implication chains, quantifiers over the sequence, a division by a recorded value,
#: mixed widths, negation and equivalence
OTHER_FORMS = (
    "in.q > 1 -> in.p <= {c}", "in.q > 1 -> (in.q > 2 -> in.p <= {K})", "in.q <= {c} or in.p > {c}",
    "in.p + in.q <= {c} + 1", "in.q - {K} >= 0", "not (in.p > {K}) <=> in.q >= 0",
    "forall(r in in.xs | r <= {c})", "exists(r in in.xs | r - {K} < 0)",
    "forall(r in in.xs | -r >= -{c} -> in.p <= {c})", "exists(r in in.xs | abs(r) <= {h} + {h})",
    "in.p / in.q <= {c}", "in.q == {c}", "in.q >= {c}", "in.q > {K}",
)
#: forms over the float64 ``in.q`` whose truth is numpy's float64 comparison of q with the threshold
Q_FORMS = (("in.q == {c}", np.equal), ("in.q >= {c}", np.greater_equal), ("in.q > {K}", np.greater),
           ("in.q - {K} >= 0", np.greater_equal))
THRESHOLDS = (("0.2", "0.1", "Low"), ("0.15", "0.075", "Mid"))


def _corpus() -> list[str]:
    forms = [f.format(c=c, h=h, K=k) for c, h, k in THRESHOLDS for f, _ in THRESHOLD_FORMS]
    forms += [f.format(c=c, h=h, K=k) for c, h, k in THRESHOLDS for f in OTHER_FORMS]
    rng = random.Random(20261127)
    atoms = [f"({f})" for f in forms]
    for _ in range(12):  # random combinations of the forms
        a, b, c = rng.sample(atoms, 3)
        forms.append(rng.choice([f"{a} and {b}", f"{a} or not {b}", f"{a} -> ({b} <=> {c})",
                                 f"not ({a} and {b}) or {c}"]))
    return forms


CORPUS = _corpus()
CORPUS_RCL = ("context { Low : REAL = 0.2 ; Mid : REAL = 0.15 ; }\n"
              "node Corpus {\n  inputs( p : REAL, q : REAL, xs : seq(REAL) )\n  outputs( ok : BOOL )\n"
              "  topics( std_msgs/Float32 p matches(in.p), std_msgs/Float64 q matches(in.q),\n"
              "          sensor_msgs/LaserScan scan matches(in.xs), std_msgs/Bool ok matches(out.ok) )\n"
              + "".join(f"  guarantee( out.ok <=> ({f}) )\n" for f in CORPUS) + "}\n")


def _points() -> list[dict[str, Any]]:
    """The fixed seeded points: every p once, q and xs drawn, each xs at least once."""
    ps = _steps(0.2) + _steps(0.15) + [_f32(0.5), -_f32(0.2), 0.0]
    qs = [0.2, float(np.nextafter(0.2, 1.0)), float(np.nextafter(0.2, 0.0)), 0.15, 1.5, 3.0, -0.2, 0.0, _f32(0.2)]
    up = float(np.nextafter(F32(0.2), F32(1)))
    down = float(np.nextafter(F32(0.2), F32(0)))
    xss = [(), (_f32(0.2),), (_f32(0.5), _f32(0.2)), (up,), (_f32(0.1), down), (_f32(0.15),)]
    rng = random.Random(7)
    out = []
    for k, p in enumerate(ps):
        out.append({"in.p": p, "in.q": rng.choice(qs), "in.xs": xss[k % len(xss)], "out.ok": True})
    for q in qs:  # each q with p at the carried thresholds
        out.append({"in.p": _f32(0.2), "in.q": q, "in.xs": rng.choice(xss), "out.ok": True})
    return out


POINTS = _points()
#: why a path declines a guarantee: the words its reason holds
#: the carried evaluator does not enumerate a sequence: its reason
CARRIED_DECLINES = "quantifier over Var"
#: nor ask Z3 where direct evaluation is undecided (``p / 0 <= c or TRUE``, which the monitor's Z3 decides)
CARRIED_NO_Z3 = "rclverify also asks Z3"
CPP_DECLINES = "a quantifier over in.xs (sets and sequences are not held here)"

CXX = ["g++", "-std=c++17", "-O1"]


@pytest.fixture(scope="module")
def corpus(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """The corpus node checked, read at its widths, its Python layer and (with g++) its C++ checks'
    truths on every point (compiled once)."""
    tmp = tmp_path_factory.mktemp("corpus")
    checked = check([parse_text(CORPUS_RCL, "corpus.rcl")])
    node = checked.nodes["Corpus"]
    widths = carried_widths(node, {}, [])
    assert widths == {"in.p": "float32", "in.q": "float64", "in.xs": "float32"}
    out: dict[str, Any] = {"checked": checked, "node": node,
                           "at": at_carried_widths(node, widths, checked.env.constants),
                           "layer": _layer(checked, "corpus", tmp / "py"), "cpp": None}
    if shutil.which("g++") is not None:
        gen, _, _ = render_tree(checked, "corpus", lang="cpp")
        _write(gen, tmp / "cpp")
        inc = next((tmp / "cpp").glob("*/include"))
        pkg = next(inc.iterdir()).name
        header = (inc / pkg / "contract_checks.hpp").read_text()
        main_cpp = tmp / "drive.cpp"
        main_cpp.write_text(f'#include "{pkg}/contract_driver.hpp"\n#include <iostream>\n'
                            f"int main() {{ return {pkg}::drive(std::cin, std::cout); }}\n")
        subprocess.run(CXX + [f"-I{inc}", str(main_cpp), "-o", str(tmp / "drive")], check=True, capture_output=True)
        lines = "".join(" ".join(f"{k}={int(v) if isinstance(v, bool) else repr(v)}" for k, v in vals.items()
                                 if k != "in.xs") + "\n" for vals in POINTS)
        res = subprocess.run([str(tmp / "drive")], input=lines, capture_output=True, text=True, check=True)
        out["cpp"] = [row.split("|")[2] for row in res.stdout.splitlines()]
        out["header"] = header
    return out


def test_every_path_gives_each_guarantee_the_same_truth(corpus: dict[str, Any]) -> None:
    checked, node, at, layer = corpus["checked"], corpus["node"], corpus["at"], corpus["layer"]
    assert "%" not in OPERATORS  # RCL has no modulo: no path has one to translate
    clauses = list(at.node.guarantees)
    assert len(clauses) == len(CORPUS) == len(layer.CARRIED["guarantees"])
    declined: dict[str, set[int]] = {"carried": set(), "cpp": set(), "z3": set()}
    truths: set[tuple[int, bool | None]] = set()
    for k, (clause, tree) in enumerate(zip(clauses, layer.CARRIED["guarantees"])):
        f = clause.formula
        where = f"guarantee {k + 1}: {CORPUS[k]}"
        wants = []
        for i, vals in enumerate(POINTS):
            want = judge(f, checked, at, vals)
            wants.append(want.truth)
            truths.add((k, want.truth))
            exact = holds_in("exact", f, checked, at, vals)
            double = holds_in("double", f, checked, at, vals)
            # Z3 on the point, as every proof path asks it: the well-definedness conditions, then the formula
            ok, why = check_concrete(defined(f), checked, at, vals)
            if ok is False:  # a proof path declines: the divisor is 0 here (docs/semantics.md, "Definedness")
                assert "/ in.q" in CORPUS[k] and vals["in.q"] == 0, (where, vals)
                declined["z3"].add(k)
            else:
                z3, why = check_concrete(f, checked, at, vals)
                assert z3 == exact, (where, vals, z3, exact, why)
            # the carried evaluator, run as Python
            mine, _, reason = layer.ev.judge(tree, vals)
            if mine is None and want.truth is not None:
                # it does not enumerate a sequence, nor ask Z3 where direct evaluation is undecided
                assert (CARRIED_DECLINES in reason and "not judged by the carried" in reason) or (
                    CARRIED_NO_Z3 in reason and evaluate(f, checked, at, vals) is None), (where, vals, reason)
                declined["carried"].add(k)
            else:
                assert mine == want.truth, (where, vals, mine, want)
            # the C++ checks, compiled once: their double reading
            if corpus["cpp"] is not None:
                got = {"T": True, "F": False, "U": None}[corpus["cpp"][i][k]]
                if got is None and double is not None:
                    assert "in.xs" in CORPUS[k], (where, vals)
                    declined["cpp"].add(k)
                else:
                    assert got == double, (where, vals, got, double)
                    if exact == double:
                        assert got == want.truth, (where, vals)
        # rclverify's monitor: the guarantee alone, over the run of every point
        alone = dataclasses.replace(node, node=dataclasses.replace(node.node, guarantees=(node.node.guarantees[k],)))
        verdicts = _monitor(checked, alone, POINTS)
        assert verdicts == [{True: "satisfied", False: "violated", None: "inconclusive"}[w] for w in wants], where
    # the declines are named: the quantifiers over the sequence, the divisions by q = 0, nothing else
    seq = {k for k, f in enumerate(CORPUS) if "in.xs" in f}
    divides = {k for k, f in enumerate(CORPUS) if "/ in.q" in f}
    assert declined["carried"] <= seq | divides and declined["carried"] & seq, declined
    assert declined["z3"] == divides, declined
    if corpus["cpp"] is not None:
        assert declined["cpp"] == seq and CPP_DECLINES in corpus["header"]
    # the corpus meets both truths on most guarantees, and undecided (the division by q = 0)
    assert sum(1 for k in range(len(CORPUS)) if {(k, True), (k, False)} <= truths) >= len(CORPUS) * 2 // 3
    assert any(t is None for _, t in truths)


def test_the_batch_monitor_gives_each_guarantee_the_same_truth(corpus: dict[str, Any]) -> None:
    """rclverify's batch monitor (numpy columns, :mod:`rclverify.backends.monitors.batch`) takes a node
    whose inputs are one field each and all read, and declines a quotient (its columns hold none).
    Each form at 0.2 not over the sequence, as a node of the inputs it reads (its answer a ``float64``
    1.0: the columns hold numbers, so the guarantee is ``out.r == 1 <=> (F)``, of F's truth), judged
    over the run of every point, gives the reference's truth at each answer (the forms at 0.15 and
    the random combinations are left to the engine: a node each costs the engine's set-up)."""
    from rclverify.backends.monitors.batch import check_batch
    from rclverify.traces.mapping import TopicRule
    checked, at = corpus["checked"], corpus["at"]
    base = 2 * (len(THRESHOLD_FORMS) + len(OTHER_FORMS))
    kept = [(k, f) for k, f in enumerate(CORPUS[:base]) if not any(w in f for w in ("in.xs", "0.15", "Mid"))]
    types = {"p": "std_msgs/Float32", "q": "std_msgs/Float64"}
    text = "context { Low : REAL = 0.2 ; Mid : REAL = 0.15 ; }\n"
    for k, f in kept:
        ins = [v for v in ("p", "q") if f"in.{v}" in f]
        text += (f"node B{k} {{\n  inputs( {', '.join(f'{v} : REAL' for v in ins)} )\n  outputs( r : REAL )\n"
                 f"  topics( {', '.join(f'{types[v]} {v} matches(in.{v})' for v in ins)}, "
                 f"std_msgs/Float64 r matches(out.r) )\n  guarantee( out.r == 1 <=> ({f}) )\n}}\n")
    alone = check([parse_text(text, "batch.rcl")])
    rules = {t: TopicRule(("data",)) for t in ("p", "q", "r")}
    declined: set[int] = set()
    for k, f in kept:
        node = alone.nodes[f"B{k}"]
        keys = [f"in.{v}" for v in ("p", "q") if f"in.{v}" in f]
        widths = carried_widths(node, rules, [])
        assert sorted(widths) == [*keys, "out.r"], f
        node = at_carried_widths(node, widths, alone.env.constants)
        events: list[Event] = []
        for vals in POINTS:
            for key in [*keys, "out.r"]:
                value = 1.0 if key == "out.r" else vals[key]
                events.append(Event(len(events), 0.1 * (len(events) + 1), key.split(".")[1], {"data": value},
                                    f"m:{len(events)}"))
        got: dict[int, str] = {}
        done = check_batch(alone, node, events, rules, 100.0, on_verdict=lambda v: got.__setitem__(v.event, v.verdict))
        if done is None:  # the batch path declines: its columns hold no quotient (targets/columns.py)
            assert "/" in f, f
            declined.add(k)
            continue
        answers = [got.get(e.index, "none") for e in events if e.topic == "r"]
        want = [judge(at.node.guarantees[k].formula, checked, at, vals).truth for vals in POINTS]
        assert answers == [{True: "satisfied", False: "violated", None: "inconclusive"}[w] for w in want], f
    assert declined == {k for k, f in kept if "/" in f} and len(declined) < len(kept) // 3, declined


def test_the_threshold_forms_are_float32_comparisons(corpus: dict[str, Any]) -> None:
    """The independent oracle: numpy's float32 ``p <= c`` (``<`` for a strict form; ``abs(p)`` for ``abs``),
    and for the float64 ``in.q`` numpy's float64 comparison, in the exact reading alone."""
    checked, at = corpus["checked"], corpus["at"]
    n = len(THRESHOLD_FORMS)
    for t, (c, _, _) in enumerate(THRESHOLDS):
        limit = F32(float(Fraction(c)))
        for j, (form, strict) in enumerate(THRESHOLD_FORMS):
            clause = at.node.guarantees[t * n + j]
            for vals in POINTS:
                p = abs(F32(vals["in.p"])) if "abs" in form else F32(vals["in.p"])
                want = bool(p < limit) if strict else bool(p <= limit)
                assert judge(clause.formula, checked, at, vals).truth is want, (form, c, vals)
    for c, h, k in THRESHOLDS:  # float64: the constant is the double nearest it, all its digits exact
        for form, op in Q_FORMS:
            clause = at.node.guarantees[CORPUS.index(form.format(c=c, h=h, K=k))]
            for vals in POINTS:
                want = bool(op(np.float64(vals["in.q"]), np.float64(float(Fraction(c)))))
                assert holds_in("exact", clause.formula, checked, at, vals) is want, (form, c, vals)


# ---------------------------------------------------------------------------------------------
# Dafny and RML: the constant compared with a float32 field is its float32 value, exactly
# ---------------------------------------------------------------------------------------------

def test_dafny_and_rml_state_the_carried_constant(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The Dafny stub's ``ensures`` and the RML guard compare the ``float32`` field with
    0.20000000298023223876953125 (the float32 of 0.2, a Dafny ``real`` exactly; a double exactly
    in RML's guard), as the backends export them from a workspace; the ``float64`` output keeps
    the double of its constant; without a message type (no width) the decimal is kept."""
    from rclverify.backends.base import NodeTarget
    from rclverify.backends.dafny.backend import DafnyBackend
    from rclverify.backends.monitors.backend import MonitorsBackend
    from rclverify.lang.typecheck import load
    rcl = GAUGE.replace("FORM", "in.p <= Low").replace(
        "outputs( low : BOOL )", "outputs( low : BOOL, e : REAL, u : REAL )").replace(
        "std_msgs/Bool low matches(out.low) )", "std_msgs/Bool low matches(out.low),\n"
        "          std_msgs/Float64 e matches(out.e) )\n  guarantee( out.e <= 0.1 and out.u <= 0.1 )")
    (tmp_path / "contracts").mkdir()
    (tmp_path / "contracts" / "gauge.rcl").write_text(rcl)
    (tmp_path / "contracts" / "plan.yaml").write_text("contracts: [contracts/gauge.rcl]\n")
    monkeypatch.chdir(tmp_path)
    checked = load(["contracts/gauge.rcl"])

    def target(backend: str, config: dict[str, Any]) -> NodeTarget:
        return NodeTarget(root=tmp_path, checked=checked, node=checked.nodes["Gauge"],
                          config={"backend": backend, **config}, contract_files=("contracts/gauge.rcl",),
                          plan_file="contracts/plan.yaml", artifacts=tmp_path / "artifacts" / backend / "Gauge")
    stub, _ = DafnyBackend().render(target("dafny", {"implementation": "backends/dafny/gauge.dfy"}))
    ensures = [c.dafny for c in stub.clauses if c.kind == "ensures"]
    assert "low <==> (p <= 0.20000000298023223876953125)" in ensures, ensures
    assert "e <= 0.1000000000000000055511151231257827021181583404541015625" in ensures, ensures
    assert "u <= 0.1" in ensures, ensures  # no message type: no width, the decimal as written
    MonitorsBackend().export(target("monitors", {"traces": []}))
    rml = (tmp_path / "artifacts" / "monitors" / "Gauge" / "Gauge.rml").read_text()
    assert "0.20000000298023223876953125" in rml and "0.2 " not in rml, rml
