"""Realizability (issue 43; docs/calculus.md, "Realizability"): an input the
assumption admits that no output answers is a health problem with that
input; the case study's Agent is one; the check against brute-force
enumeration on small random contracts."""
from __future__ import annotations

import itertools
import random
import re
from pathlib import Path

from hypothesis import given, settings
from hypothesis import strategies as st

from rclverify.calculus.health.realizable import realizability_findings
from rclverify.semantics import world
from rclverify.model.plan.load import load_plan
from rclverify.lang.parser import parse_formula, parse_text
from rclverify.lang.typecheck import check, load

ROOT = Path(__file__).resolve().parents[2]

CLAMP = """
node C {
  inputs( x : INTEGER, on : BOOL )
  outputs( y : INTEGER )
  assume( 0 <= in.x )
  guarantee( in.on -> out.y == in.x )
  guarantee( out.y <= 10 )
}
"""


def _findings(text: str, node: str, facts: list[str] = ()):  # type: ignore[no-untyped-def]
    checked = check([parse_text(text, "c.rcl")])
    world.fresh()
    return realizability_findings(checked, node, [(parse_formula(f), parse_formula(f).loc) for f in facts])


def test_an_unrealizable_contract_is_flagged_with_the_input_that_has_no_answer() -> None:
    [f] = _findings(CLAMP, "C")
    assert f.check == "realizable" and f.status == "problem" and f.id == "C.realizable"
    assert "cannot be implemented" in f.message and "guarantee 1 and guarantee 2 together" in f.message
    assert f.core == ["guarantee 1 (c.rcl:6:3)", "guarantee 2 (c.rcl:7:3)"] and f.guarantee is None
    x, on = int(f.model["C.in.x"]), f.model["C.in.on"]
    assert on == "TRUE" and x > 10  # the answer y == x breaks y <= 10
    assert "C.out.y" not in f.model  # the model is the input alone
    assert "(check-sat)" in f.smt2


def _proved(found: list) -> bool:  # type: ignore[type-arg]
    """One ``ok`` finding: Z3 proved the contract realizable, the unsat query kept for the second solver."""
    return [(f.status, f.check) for f in found] == [("ok", "realizable")] and "(check-sat)" in found[0].smt2


def test_a_fact_can_make_it_realizable_and_a_realizable_contract_has_a_verdict() -> None:
    assert _proved(_findings(CLAMP, "C", ["in.x <= 10"]))
    [f] = _findings(CLAMP.replace("out.y <= 10", "out.y <= in.x + 10"), "C")
    assert _proved([f]) and "can be implemented" in f.message and f.model is None


def test_function_typed_outputs_are_not_checked() -> None:
    text = """
context { F : INTEGER --> BOOL ; }
node S { inputs( x : INTEGER ) outputs( f : F ) assume( TRUE ) guarantee( out.f(1) and not out.f(1) ) }
"""
    assert _findings(text, "S") == []


def test_the_case_study_agent_is_unrealizable_and_its_other_nodes_are_not_checked() -> None:
    checked = load([ROOT / "contracts" / "remote_inspection.rcl"])
    plan = load_plan(ROOT, "contracts/plan.yaml")
    found = {}
    for node in checked.nodes:
        world.fresh()
        found[node] = realizability_findings(checked, node, [(f.expr, f.loc) for f in plan.facts.get(node, ())],
                                             plan.instances.get(node))
    assert {n for n, fs in found.items() if any(f.status == "problem" for f in fs)} == {"Agent"}
    [f] = found["Agent"]
    assert f.status == "problem" and len(f.core or []) == 1  # a single guarantee already has no answer
    at = f.model["Agent.in.at"]
    assert at.count("TRUE") >= 2  # the robot "at" two places: nothing says it is at one


# ---- the oracle: against enumeration ----------------------------------------------------------------

D = 3


def _random_contract(seed: int) -> tuple[str, list[str]]:
    rng = random.Random(seed)
    atoms_in = [f"in.a <= {rng.randint(0, D)}", f"in.a >= {rng.randint(0, D)}", "in.a <= in.b", "in.b == 1"]
    atoms_out = [f"out.y <= in.a + {rng.randint(-1, 1)}", f"out.y >= in.b + {rng.randint(-1, 1)}",
                 f"out.y == {rng.randint(0, D)}", f"out.y != in.a", "out.z -> out.y <= 1", "in.b >= 2 -> out.z",
                 f"out.y + in.a <= {rng.randint(0, 2 * D)}", "not out.z or out.y >= in.a"]
    a = " and ".join(rng.sample(atoms_in, rng.randint(1, 2)))
    gs = rng.sample(atoms_out, rng.randint(1, 3))
    text = ("node R { inputs( a : INTEGER, b : INTEGER ) outputs( y : INTEGER, z : BOOL ) "
            f"assume( {a} ) " + " ".join(f"guarantee( {g} )" for g in gs) + " }")
    facts = [f"0 <= in.a and in.a <= {D} and 0 <= in.b and in.b <= {D}", f"0 <= out.y and out.y <= {D}"]
    return text, facts


def _holds(formula: str, v: dict[str, object]) -> bool:
    py = re.sub(r"\b(in|out)\.(\w+)", lambda m: f"v['{m.group(2)}']", formula)
    py = re.sub(r"(.+?) -> (.+)", r"(not (\1)) or (\2)", py)
    return bool(eval(py, {"v": v}))  # noqa: S307 (our own atoms)


@settings(max_examples=40, deadline=None, derandomize=True)
@given(seed=st.integers(0, 10**6))
def test_realizability_equals_brute_force_enumeration(seed: int) -> None:
    text, facts = _random_contract(seed)
    a = re.search(r"assume\( (.*?) \)", text).group(1)  # type: ignore[union-attr]
    gs = re.findall(r"guarantee\( (.*?) \)", text)
    dom = range(D + 1)

    def answered(ins: dict[str, object]) -> bool:
        return any(all(_holds(g, {**ins, "y": y, "z": z}) for g in gs) for y in dom for z in (False, True))

    bad = [{"a": x, "b": y} for x, y in itertools.product(dom, dom)
           if all(_holds(p, {"a": x, "b": y}) for p in a.split(" and ")) and not answered({"a": x, "b": y})]
    found = [f for f in _findings(text, "R", facts) if f.status == "problem"]
    assert bool(found) == bool(bad), (text, bad, found)
    assert found or _proved(_findings(text, "R", facts))  # decided either way on these small contracts
    if found:
        f = found[0]
        ins = {"a": int(f.model["R.in.a"]), "b": int(f.model["R.in.b"])}
        assert ins in bad, (text, f.model)


PLANNER = """
node P {
  inputs( goal : REAL, pose : REAL )
  outputs( speed : REAL, remaining : REAL, reached : REAL )
  assume( 0 <= in.goal and in.goal <= 100 )
  assume( 0 <= in.pose and in.pose <= 100 )
  guarantee( 0 <= out.speed and out.speed <= 1.5 )
  guarantee( in.pose == in.goal -> out.speed == 0 )
  guarantee( out.remaining >= 0 and (out.remaining == in.goal - in.pose or out.remaining == in.pose - in.goal) )
  guarantee( out.reached == in.goal )
}
"""


def test_linear_contracts_are_decided_by_quantifier_elimination() -> None:
    """The warehouse example's Planner (examples/warehouse): four linear
    guarantees, one a disjunction.  Its realizability query went undecided
    in the general solver's budget (5.6 s, nothing reported); Z3's ``qe``
    decides it: realizable.  With the speed bound below the stop the same
    shape is decided unrealizable, with the input."""
    from rclverify.calculus.health.realizable import _Query
    checked = check([parse_text(PLANNER, "p.rcl")])
    world.fresh()
    q = _Query(checked, "P", (), None)
    status, model, _, _ = q.answer([0, 1, 2, 3], "test")
    assert (status, model) == ("unsat", None)
    assert _proved(_findings(PLANNER, "P"))
    [f] = _findings(PLANNER.replace("0 <= out.speed and", "0.5 <= out.speed and"), "P")
    assert f.status == "problem" and f.core == ["guarantee 1 (c.rcl:7:3)", "guarantee 2 (c.rcl:8:3)"]
    assert f.model["P.in.pose"] == f.model["P.in.goal"]


def test_an_output_whose_natural_parts_are_not_typed_is_never_proved_realizable() -> None:
    """Only a NATURAL output and a constructor's NATURAL field get their ``>= 0`` (semantics/encode.py): the
    NATURAL elements of a tuple or a sequence are plain integers to Z3, so its ``unsat`` ranges over
    outputs the type excludes.  Both contracts below have no answer (a NATURAL below 0); the ``ok``
    must not be claimed (an input with no answer is still reported: that query is sound)."""
    tup = ("node C { inputs( x : INTEGER ) outputs( y : (NATURAL, NATURAL) ) assume( TRUE ) "
           "guarantee( exists(a, b in INTEGER | out.y == (a, b) and a < 0) ) }")
    seq = ("node C { inputs( x : INTEGER ) outputs( y : seq(NATURAL) ) assume( TRUE ) "
           "guarantee( exists(v in INTEGER | v in out.y and v < 0) ) }")
    for text in (tup, seq):
        assert not any(f.status == "ok" for f in _findings(text, "C")), text
    assert _proved(_findings(tup.replace("a < 0", "a >= 0"), "C"))  # the tuple itself is not refused
