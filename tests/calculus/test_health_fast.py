"""The health stage's fast paths against their reference paths (issue 67).

Each fast path decides a query without asking it only where the recorded
finding is provably the one the query gives; these tests check that on
small random contracts, against the reference path (the fast path switched
off) and against a brute-force enumeration of every value of the
contract's variables (the oracle: independent of Z3)."""
from __future__ import annotations

import itertools
import random
import re

import pytest

from rclverify.calculus.compose import conjuncts
from rclverify.calculus.health import shape
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.semantics import world
from rclverify.semantics.encode import Encoder
from rclverify.semantics.evaluate import evaluate
from rclverify.semantics.values import FiniteFunction


ENUM = ("a", "b")
#: Atoms over x, o : S and f, g : S --> BOOL; ``v`` is the quantified variable (``{v}`` outside a quantifier:
#: replaced by a constant).
ATOMS = ("in.x == {v}", "out.o != in.x", "out.o == {v}", "in.f({v}) == TRUE", "out.g({v}) == TRUE",
         "out.g(out.o) == FALSE", "in.f(in.x) == out.g({v})")


def _formula(rnd: random.Random, quantified: bool) -> str:
    v = "v" if quantified else rnd.choice(ENUM)
    parts = [rnd.choice(ATOMS).format(v=v) for _ in range(rnd.randint(1, 3))]
    body = parts[0]
    for p in parts[1:]:
        body = f"({body} {rnd.choice(('and', 'or', '->'))} {p})"
    return f"forall(v in S | {body})" if quantified else body


def _contract(seed: int) -> str:
    rnd = random.Random(seed)
    gs = []
    for _ in range(rnd.randint(1, 3)):
        conj = [_formula(rnd, rnd.random() < 0.6) for _ in range(rnd.randint(1, 2))]
        gs.append("  guarantee( " + " and ".join(f"({c})" for c in conj) + " )")
    return ("context { S : {a, b}; }\n"
            "node N { inputs( x : S, f : S --> BOOL ) outputs( o : S, g : S --> BOOL )\n"
            f"  assume( {_formula(rnd, False)} )\n" + "\n".join(gs) + "\n}\n")


def _assignments():
    tables = [FiniteFunction({(ENUM[0],): p, (ENUM[1],): q}, False, 1) for p, q in itertools.product((False, True), repeat=2)]
    for x, f, o, g in itertools.product(ENUM, tables, ENUM, tables):
        yield {"in.x": x, "in.f": f, "out.o": o, "out.g": g}


def _counterexample(checked, hyps, goal) -> bool:
    """Brute force: is there a value of every variable where ``hyps`` hold and ``goal`` does not?"""
    node = checked.nodes["N"]
    for values in _assignments():
        if all(evaluate(h, checked, node, values) for h in hyps) and evaluate(goal, checked, node, values) is False:
            return True
    return False


def _findings(checked) -> list[tuple]:
    world.fresh()  # the same Z3 state for both paths, as the health stage asks it (semantics/world.py)
    return [(f.id, f.status, f.message, f.explanation) for f in shape.shape_findings(checked, "N")]


SEEDS = range(24)


@pytest.fixture(scope="module")
def contracts():
    return {s: check([parse_text(_contract(s), "t.rcl")]) for s in SEEDS}


def test_the_falsified_pre_check_agrees_with_brute_force(contracts):
    """_falsified's True (a model of the hypotheses and the negated
    conjunct) is always confirmed by enumerating every value; and it does
    find the counterexample of some quantified conjunct (the test exercises
    the fast path)."""
    fired = 0
    for s, checked in contracts.items():
        n = checked.nodes["N"].node
        parts = [(k, c) for k, g in enumerate(n.guarantees, 1) for c in conjuncts(g.formula)]
        enc = Encoder(checked.env)
        cn = checked.nodes["N"]
        assume = [a.formula for a in n.assumes]
        for i, (k, c) in enumerate(parts):
            others = [x for j, (_, x) in enumerate(parts) if j != i]
            if shape._falsified([enc.formula(h, cn) for h in assume + others], enc.formula(c, cn), enc):
                fired += 1
                assert _counterexample(checked, assume + others, c), (s, k, _contract(s))
    assert fired >= 5


def test_shape_findings_equal_the_reference_path(contracts, monkeypatch):
    """With the pre-check and without it (every query asked, as before
    issue 67), the same shape findings: the pre-check decides only what the
    queries would."""
    fast = {s: _findings(c) for s, c in contracts.items()}
    monkeypatch.setattr(shape, "_falsified", lambda hyps, goal, enc: False)
    slow = {s: _findings(c) for s, c in contracts.items()}
    assert fast == slow
    assert any(fast.values())  # some contract has a redundant or tautological conjunct: the comparison bites


# -- the realizer's first synthesis round (calculus/health/realizer.py: _first_model) --------------------------

def _linear(seed: int) -> str:
    """A random quantifier-free contract over REAL and an enumeration (the realizer's templates apply)."""
    rnd = random.Random(seed)

    def atom() -> str:
        return rnd.choice(("out.o >= in.x", "out.o <= in.y + {c}", "out.o == {c}", "in.x <= {c} -> out.o >= {c}",
                           "out.s == a", "out.s != b or in.x > {c}", "out.o + in.x >= in.y", "out.o * 2 <= in.x",
                           "0 < out.o and out.o <= {d}", "out.s == b -> out.o > {d}")).format(
            c=rnd.randint(-3, 3), d=rnd.randint(1, 3))
    gs = "\n".join(f"  guarantee( {atom()} )" for _ in range(rnd.randint(1, 3)))
    return ("context { S : {a, b}; }\n"
            "node N { inputs( x : REAL, y : REAL ) outputs( o : REAL, s : S )\n"
            f"  assume( 0 <= in.x and in.x <= in.y + {rnd.randint(0, 3)} )\n{gs}\n}}\n")


def _let_normal(text: str) -> str:
    """``text`` with Z3's ``let`` names (``$x34``: a term id, history of the process) renamed in order of
    first occurrence: the same query whatever Z3 was asked before."""
    names: dict[str, str] = {}
    return re.sub(r"[$?]x[0-9]+", lambda m: names.setdefault(m.group(0), f"{m.group(0)[0]}x{len(names) + 1}"), text)


def test_the_first_synthesis_model_is_the_empty_solver_s():
    """Every sort's default in the model made without a check equals the
    one a check of an empty solver gives."""
    from rclverify.calculus.health.realizer import _first_model
    from rclverify.semantics.query import budgeted_solver
    import z3
    cmd = z3.Datatype("HealthFastCmd")
    cmd.declare("go", ("gx", z3.RealSort()), ("gy", z3.IntSort()))
    cmd.declare("halt")
    sort = cmd.create()
    enum, _ = z3.EnumSort("HealthFastEnum", ["p", "q", "r"])
    params = [z3.Real("r"), z3.Int("i"), z3.Bool("b"), z3.Const("d", sort), z3.Const("e", enum),
              z3.Const("st", z3.SetSort(z3.IntSort())), z3.Const("sq", z3.SeqSort(z3.RealSort()))]
    s = budgeted_solver(100)
    assert s.check() == z3.sat
    want = [s.model().eval(p, model_completion=True) for p in params]
    got = [_first_model(params).eval(p, model_completion=True) for p in params]
    assert [str(x) for x in got] == [str(x) for x in want]
    assert all(x.eq(y) for x, y in zip(got, want))


def test_realizability_findings_equal_the_reference_path(monkeypatch):
    """The realizability findings (the answer's terms, the status, the
    conflicting guarantees) of random contracts with the first synthesis
    round's model made without a check and with it asked of a fresh solver
    (before issue 67)."""
    from rclverify.calculus.health import realizer
    from rclverify.calculus.health.realizable import realizability_findings
    # a speed limit in (0, 2]: the constants' first round (0) fails, the second round's model is the one
    # whose solver history matters (the warehouse's Base)
    limit = ("node B { inputs( v : REAL, q : BOOL ) outputs( w : REAL, m : REAL )\n  assume( 0 <= in.v and in.v <= 2.0 )\n"
             "  guarantee( 0 <= out.w and out.w <= in.v )\n  guarantee( 0 < out.m and out.m <= 2.0 )\n}\n")
    texts = [limit.replace("node B", "node N")] + [_linear(s) for s in range(30)]

    def run() -> list[list[dict]]:
        out = []
        for t in texts:
            checked = check([parse_text(t, "t.rcl")])
            world.fresh()  # each contract from the same Z3 state, as the health stage asks it (semantics/world.py)
            fs = realizability_findings(checked, "N")
            out.append([{**f.to_json(), "duration_s": 0, "smt2": _let_normal(f.smt2),
                         "witness_smt2": _let_normal(f.witness_smt2)} for f in fs])
        return out
    fast = run()

    monkeypatch.setattr(realizer, "FIRST_ROUND_UNASKED", False)
    assert run() == fast
    assert sum(1 for fs in fast for f in fs if f.get("witness")) >= 10  # the realizer answered: the comparison bites


# -- one encoding of the node's formulas shared by its checks (calculus/health/shared.py) ----------------------

def test_a_shared_encoding_registers_what_encoding_again_would():
    """An encoder served from the table another encoder filled (the
    consistency check's, which encodes the guarantees first) ends with the
    same symbols, in the same order, the same typing axioms and the same
    terms as one that encodes the formulas itself, in the shape check's
    order (the assumption, then each guarantee); on the case study, whose
    Agent has NATURAL-valued functions (axioms) and nested quantifiers."""
    from pathlib import Path
    from rclverify.calculus.health.shared import SharedEncoder
    from rclverify.lang.typecheck import load
    checked = load([Path(__file__).resolve().parents[2] / "contracts" / "remote_inspection.rcl"])
    for name, cn in checked.nodes.items():
        order = [g.formula for g in cn.node.guarantees] + [a.formula for a in cn.node.assumes]
        table: dict = {}
        first = SharedEncoder(checked.env, table)
        for e in order:
            first.formula(e, cn)
        assert len(table) == len({id(e) for e in order})
        later = [a.formula for a in cn.node.assumes] + [g.formula for g in cn.node.guarantees]
        shared, plain = SharedEncoder(checked.env, table), Encoder(checked.env)
        got = [shared.formula(e, cn) for e in later]
        want = [plain.formula(e, cn) for e in later]
        assert list(shared.symbols) == list(plain.symbols), name
        assert [s.display for s in shared.symbols.values()] == [s.display for s in plain.symbols.values()]
        assert all(x.eq(y) for x, y in zip(got, want)), name
        assert [a.sexpr() for a in shared.axioms()] == [a.sexpr() for a in plain.axioms()], name


def test_shape_findings_from_shared_formulas_equal_their_own(contracts):
    """shape_findings served from the table the node's other checks
    filled gives the findings (and the SMT-LIB2 text, up to let names) it
    gives encoding everything itself."""
    from rclverify.calculus.health.shared import SharedEncoder

    def run(shared: bool) -> list:
        out = []
        for checked in list(contracts.values())[:12] + [check([parse_text(_linear(s), "t.rcl")]) for s in range(4)]:
            world.fresh()
            cn = checked.nodes["N"]
            table: dict = {}
            if shared:
                enc = SharedEncoder(checked.env, table)
                for e in [a.formula for a in cn.node.assumes] + [g.formula for g in cn.node.guarantees]:
                    enc.formula(e, cn)
            fs = shape.shape_findings(checked, "N", formulas=table if shared else None)
            out.append([(f.to_json() | {"duration_s": 0, "smt2": ""}, _let_normal(f.smt2)) for f in fs])
        return out
    got, want = run(True), run(False)
    assert got == want
    assert sum(len(x) for x in want) >= 10
