"""Deterministic queries: the answer depends on the query only, not on the
Z3 work the process did before (semantics/retry.py ``load_canonical``)."""
from __future__ import annotations

import itertools
import json
import subprocess
import sys
from pathlib import Path

import z3

from rclverify.semantics.query import prove
from rclverify.semantics.retry import TABLES, canonical_smt2, expand_finite

ROOT = Path(__file__).resolve().parents[2]
_NOISE = itertools.count()

_REPLACEMENT = """
import json, sys
from pathlib import Path
from rclverify.app.pipeline import Workspace, replacement_finding
f = replacement_finding(Workspace(Path(sys.argv[1])), "Agent")
print(json.dumps({"status": f.status, "message": f.message, "model": f.model, "explanation": f.explanation},
                 sort_keys=True))
"""


def _unrelated_z3_work() -> None:
    """Terms, sorts and quantifiers that shift Z3's ids, names and caches."""
    xs = [z3.Int(f"noise{k}") for k in range(300)]
    f = z3.Function("noise_f", z3.IntSort(), z3.IntSort())
    y = z3.Int("noise_y")
    s = z3.Solver()
    s.add(z3.ForAll([y], f(y) > y), *[x + k == f(x) for k, x in enumerate(xs)])
    s.check()
    z3.EnumSort(f"NoiseColour{next(_NOISE)}", ["c1", "c2", "c3"])
    for k in range(50):
        z3.FreshConst(z3.RealSort(), "noise")
        z3.simplify(z3.And(xs[k] > 0, xs[k + 1] < k))


def _replacement_here() -> dict[str, object]:
    from rclverify.app.pipeline import Workspace, replacement_finding
    f = replacement_finding(Workspace(ROOT), "Agent")
    return {"status": f.status, "message": f.message, "model": f.model, "explanation": f.explanation}


def test_replacement_verdict_is_the_same_in_a_fresh_process_and_after_other_z3_work() -> None:
    # the case study's replacement check: its guarantee side is answered by a
    # search near its resource limit (once MBQI after simplification, now a
    # finite-table counterexample loaded from canonical text), where Z3's search
    # used to depend on the process's history (serial and parallel `doit verify`
    # disagreed)
    fresh = subprocess.run([sys.executable, "-c", _REPLACEMENT, str(ROOT)], capture_output=True, text=True,
                           timeout=300, cwd=ROOT)
    assert fresh.returncode == 0, fresh.stderr
    _unrelated_z3_work()
    here = _replacement_here()
    assert json.loads(fresh.stdout) == here
    assert here["status"] == "problem" and "guarantee side fails" in str(here["message"])
    assert f"answered with {TABLES}" in str(here["explanation"])
    # the counterexample's functions are tables of the plan's 13 instances
    assert str(here["model"]["in.wayP"]).startswith("{(0, 0) -> ") and "(12, 0) -> " in str(here["model"]["in.wayP"])


def test_canonical_text_does_not_depend_on_term_ids() -> None:
    def query() -> list[z3.BoolRef]:
        x, y = z3.Reals("cx cy")
        g = z3.Function("cg", z3.RealSort(), z3.RealSort())
        return [z3.ForAll([x], z3.Implies(x > 0, g(x) > y)), z3.Or(y == 1, g(y) < 0, y > 2)]
    first = canonical_smt2(query())
    # build the shared subterms in another order first: ids, hence Z3's own
    # printing order, change; the canonical text must not
    x, y = z3.Reals("cx cy")
    g = z3.Function("cg", z3.RealSort(), z3.RealSort())
    _ = [y > 2, g(y) < 0, y == 1, g(x) > y, x > 0]
    _unrelated_z3_work()
    assert canonical_smt2(query()) == first


def test_same_quantified_query_same_answer_and_model_after_unrelated_work() -> None:
    def query() -> tuple[z3.BoolRef, list[z3.BoolRef]]:
        i = z3.Int("di")
        w = z3.Function("dw", z3.IntSort(), z3.IntSort())
        n = z3.Int("dn")
        return (z3.Exists([i], w(i) == n + 7),
                [z3.ForAll([i], z3.Implies(i >= 0, w(i) >= i)), n >= 3])
    goal, hyps = query()
    a = prove(goal, hyps, deterministic=True)
    _unrelated_z3_work()
    goal, hyps = query()
    b = prove(goal, hyps, deterministic=True)
    assert a.status == b.status == "refuted"
    assert (a.model, a.strategy, a.reason) == (b.model, b.strategy, b.reason)


def test_finite_expansion_names_are_not_process_history() -> None:
    # a quantifier kept by the expansion is rebuilt with names that depend on
    # the formula only (FreshConst's counter would leak history into the query)
    Colour, (red, _green) = z3.EnumSort("DetColour", ["det_red", "det_green"])
    c, r = z3.Const("dc", Colour), z3.Real("dr")
    f = z3.Function("df", Colour, z3.RealSort(), z3.BoolSort())
    q = z3.ForAll([r], z3.ForAll([c], f(c, r)))
    first = canonical_smt2([expand_finite(q)])
    _unrelated_z3_work()
    assert canonical_smt2([expand_finite(q)]) == first
    assert "?" not in first.replace("; ", "")  # no loose de Bruijn index left behind


def test_finite_expansion_under_a_kept_quantifier_is_an_equivalence() -> None:
    # the inner quantifier (over an enumeration) is written out inside an outer
    # one over the reals that is kept: the instances must still refer to the
    # outer bound variable
    Colour, (red, green) = z3.EnumSort("EqColour", ["eq_red", "eq_green"])
    c, r = z3.Const("ec", Colour), z3.Real("er")
    f = z3.Function("ef", Colour, z3.RealSort(), z3.BoolSort())
    for q in (z3.ForAll([r], z3.ForAll([c], f(c, r))), z3.Exists([r], z3.Implies(r > 0, z3.ForAll([c], f(c, r + 1))))):
        e = expand_finite(q)
        assert not e.eq(q)
        s = z3.Solver()
        s.add(e != q)
        assert s.check() == z3.unsat
    s = z3.Solver()
    s.add(expand_finite(z3.ForAll([r], z3.ForAll([c], f(c, r)))), z3.Not(f(green, z3.RealVal(3))))
    assert s.check() == z3.unsat


def _cmd_sort() -> tuple[z3.DatatypeSortRef, z3.DatatypeSortRef]:
    global _CMD
    if _CMD is None:
        c = z3.Datatype("CaseCmd")
        c.declare("case_move", ("case_move_0", z3.RealSort()), ("case_move_1", z3.BoolSort()))
        c.declare("case_inspect", ("case_inspect_0", z3.IntSort()))
        c.declare("case_stop")
        lst = z3.Datatype("CaseList")
        lst.declare("case_nil")
        lst.declare("case_cons", ("case_head", z3.IntSort()), ("case_tail", lst))
        _CMD = (c.create(), lst.create())
    return _CMD


_CMD: tuple[z3.DatatypeSortRef, z3.DatatypeSortRef] | None = None


def test_constructor_arguments_are_split_by_constructor() -> None:
    # finite instantiation of constructor arguments (issue 10): a bound
    # constructor-set variable becomes one case per constructor, its Bool
    # argument is written out, its REAL/INTEGER arguments stay bound
    Cmd, _ = _cmd_sort()
    c, r = z3.Const("sc", Cmd), z3.Real("sr")
    p = z3.Function("sp", Cmd, z3.RealSort(), z3.BoolSort())
    for q in (z3.ForAll([c], p(c, 1)), z3.Exists([c], z3.Not(p(c, 0))),
              z3.ForAll([r], z3.Exists([c], z3.And(p(c, r), Cmd.is_case_move(c))))):
        e = expand_finite(q)
        s = z3.Solver()
        s.add(e != q)
        assert s.check() == z3.unsat, e
    e = expand_finite(z3.ForAll([c], p(c, 1)))
    text = canonical_smt2([e])
    assert "case_stop" in text and "case_move" in text and "case_inspect" in text
    assert "(case_move sc!q0_0_case_move_0!q1_0 true)" in text  # the Bool argument written out
    # a goal about every command: decided without any quantifier over commands left
    s = z3.Solver()
    s.add(z3.Not(expand_finite(z3.ForAll([c], z3.Or(Cmd.is_case_move(c), Cmd.is_case_inspect(c),
                                                        Cmd.is_case_stop(c))))))
    assert s.check() == z3.unsat and not z3.is_quantifier(s.assertions()[0].arg(0))


def test_recursive_constructor_sets_are_not_split() -> None:
    _, Lst = _cmd_sort()
    x = z3.Const("lx", Lst)
    f = z3.Function("lf", Lst, z3.BoolSort())
    q = z3.ForAll([x], f(x))
    assert expand_finite(q).eq(q)


def test_finite_expansion_of_shared_subterms_is_the_expansion_of_each() -> None:
    """expand_finite expands each distinct subterm once (semantics/retry.py): on formulas whose finite
    quantifiers occur many times over (shared), the expansion of a conjunction is the conjunction of
    the expansions, term for term, and the result is equivalent to the formula."""
    import random

    from rclverify.semantics.retry import expand_finite
    S, (a, b, _c) = z3.EnumSort("ShareS", ["sa", "sb", "sc"])
    x = z3.Int("x")
    rng = random.Random(7)

    def formula(d: int) -> z3.BoolRef:
        if d == 0:
            return rng.choice([x > rng.randint(0, 3), z3.Bool("p")])
        v = z3.Const(f"v{d}", S)
        sub = formula(d - 1)
        k = rng.randint(0, 2)
        if k == 0:
            return z3.ForAll([v], z3.Or(v == a, sub))
        if k == 1:
            return z3.Exists([v], z3.And(v != b, sub, sub))
        return z3.And(sub, z3.Or(sub, formula(d - 1)))

    for _ in range(60):
        f, g = formula(rng.randint(1, 4)), formula(rng.randint(1, 4))
        assert expand_finite(z3.And(f, g, f)).eq(z3.And(expand_finite(f), expand_finite(g), expand_finite(f)))
        s = z3.Solver()
        s.add(z3.Not(f == expand_finite(f)))
        assert s.check() == z3.unsat
