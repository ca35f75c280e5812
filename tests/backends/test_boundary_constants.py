"""Boundaries from every constant (issue 64; backends/property_tests/constants.py).

A stop node whose guarantee says ``in.separation <= ProtectiveDist`` (a
context constant) and whose code says ``if separation < PROTECTIVE_DIST``
fails its property test at exactly the constant; with the boundaries drawn
from the literals alone (as before) the same run passes, so it is the named
constant that finds it.  A threshold only the code has (a forgotten equal
case at ``SLOW_ZONE``) is found from the module's constant.  A correct
implementation passes.  Real Hypothesis, real Z3, the real harness.
"""
from __future__ import annotations

import importlib.util
import math
import sys
from fractions import Fraction
from pathlib import Path
from typing import Any

import pytest
from hypothesis import find, settings

from rclverify.backends.property_tests import boundary, harness
from rclverify.backends.property_tests.constants import boundary_constants, code_constants, named_constants
from rclverify.backends.property_tests.harness import read_config, run_guarantee
from rclverify.backends.property_tests.strategies import input_space
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check

RCL = """context {
  ProtectiveDist : REAL [m] = 1.2345 ;
  Half = ProtectiveDist / 2 ;
  MaxCount : NATURAL = 7 ;
}
node Stopper {
  inputs( separation : REAL [m] )
  outputs( stop : BOOL )
  assume( 0 <= in.separation and in.separation <= 100 )
  guarantee( in.separation <= {bound} -> out.stop )
}
node Limiter {
  inputs( separation : REAL [m], seen : NATURAL )
  outputs( speed : REAL [m/s] )
  assume( 0 <= in.separation and in.separation <= 100 and in.seen <= MaxCount )
  guarantee( out.speed <= 1.5 )
}
"""
STOPPER = """PROTECTIVE_DIST = 1.2345  # m, the protective distance of the safety case


def stopper(separation: float) -> dict[str, bool]:
    if separation {op} PROTECTIVE_DIST:
        return {{"stop": True}}
    return {{"stop": False}}
"""
LIMITER = """SLOW_ZONE = 3.7  # m: slower inside it
FAST, SLOW = 1.0, 0.4


def limiter(separation: float, seen: int) -> dict[str, float]:
    if separation > SLOW_ZONE:
        speed = FAST
    if separation < SLOW_ZONE:
        speed = SLOW
    return {"speed": speed}  # exactly at SLOW_ZONE: speed was never set
"""


def _run(tmp: Path, node: str, code: str, bound: str = "ProtectiveDist") -> Any:
    (tmp / "impl.py").write_text(code)
    checked = check([parse_text(RCL.replace("{bound}", bound), "s.rcl")])
    cn = checked.nodes[node]
    cfg = read_config({"implementation": f"impl.py:{node.lower()}", "max_examples": 100}, cn, tmp)
    return run_guarantee(checked, cn, 1, cfg, tmp)


def test_a_named_constant_boundary_slip_is_found(tmp_path: Path) -> None:
    out = _run(tmp_path, "Stopper", STOPPER.format(op="<"))
    assert out.status == "failed", out.message
    assert out.counterexample is not None and out.counterexample["in.separation"] == "1.2345"
    assert out.counterexample["out.stop"] == "FALSE"


def test_the_literal_finds_it_too_and_the_correct_code_passes(tmp_path: Path) -> None:
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    lit = _run(tmp_path / "a", "Stopper", STOPPER.format(op="<"), bound="1.2345")
    assert lit.status == "failed" and lit.counterexample["in.separation"] == "1.2345"
    ok = _run(tmp_path / "b", "Stopper", STOPPER.format(op="<="))
    assert ok.status == "discharged", ok.message


def test_without_the_named_constant_the_same_run_misses_it(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The control: boundaries from the contract's literals only (the rule
    before issue 64, without the thresholds solved from the comparisons,
    thresholds.py, which find ProtectiveDist too) and the same seed pass the slip."""
    monkeypatch.setattr(harness, "boundary_constants", lambda *a, **k: [])
    monkeypatch.setattr(harness, "solved_thresholds", lambda *a, **k: [])  # the comparisons' thresholds too
    monkeypatch.setattr(boundary, "boundary_constants", lambda c, n, i, lit: sorted(lit))
    out = _run(tmp_path, "Stopper", STOPPER.format(op="<"))
    assert out.status == "discharged", out.message


def test_a_threshold_only_the_code_has_is_found(tmp_path: Path) -> None:
    out = _run(tmp_path, "Limiter", LIMITER)
    assert out.status == "failed" and out.counterexample is not None
    assert out.counterexample["in.separation"] == "3.7" and "UnboundLocalError" in out.counterexample["reason"]


def test_the_constants_and_their_neighbours(tmp_path: Path) -> None:
    checked = check([parse_text(RCL.replace("{bound}", "Half"), "s.rcl")])
    assert named_constants(checked, checked.nodes["Stopper"]) == [Fraction("1.2345") / 2]
    assert named_constants(checked, checked.nodes["Limiter"]) == [7]
    path = tmp_path / "b64_consts.py"
    path.write_text("LIMIT = 2.5\n_TOP = 9\nFLAG = True\nlower = 11\nunused = 12\nNAME = 'x'\n"
                    "class C:\n    STEP = 4\n    def f(self, x):\n"
                    "        return x < self.STEP or x >= -0.25 or x == lower\n")
    spec = importlib.util.spec_from_file_location("b64_consts", path)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules["b64_consts"] = mod
    try:
        spec.loader.exec_module(mod)
        got = code_constants(mod.C)
    finally:
        sys.modules.pop("b64_consts", None)
    # compared literals (-0.25), compared names (lower, self.STEP), constants in capitals; no bool, str or other name
    assert got == [Fraction(-1, 4), Fraction(5, 2), 4, 9, 11]
    lim = checked.nodes["Limiter"]
    space = input_space(lim, {}, None, [*boundary_constants(checked, lim), Fraction(37, 10)])
    assert {Fraction(37, 10), 7} <= set(space.constants)
    for x in (3.7, math.nextafter(3.7, math.inf), math.nextafter(3.7, -math.inf)):  # the value and one ulp each side
        assert find(space.real(space.bounds["separation"]), lambda v, x=x: v == x,
                    settings=settings(database=None, max_examples=2000)) == x
    for n in (6, 7, 8):  # an integer constant and one either side
        assert find(space.integer(space.bounds.get("seen"), True), lambda v, n=n: v == n,
                    settings=settings(database=None, max_examples=2000)) == n


def test_a_named_constant_bounds_an_input_as_a_literal_does(tmp_path: Path) -> None:
    """``in.separation <= MaxRange`` bounds the draws (before, the input was
    any float and two draws in three were filtered out)."""
    from rclverify.backends.property_tests.constants import constant_values
    text = RCL.replace("{bound}", "ProtectiveDist").replace("in.separation <= 100 )", "in.separation <= MaxRange )")
    text = text.replace("MaxCount : NATURAL = 7 ;", "MaxCount : NATURAL = 7 ;\n  MaxRange : REAL [m] = 30 ;")
    checked = check([parse_text(text, "s.rcl")])
    cn = checked.nodes["Stopper"]
    named = constant_values(checked, cn)
    assert named == {"MaxRange": 30, "ProtectiveDist": Fraction("1.2345")}
    bd = input_space(cn, {}, None, (), named).bounds["separation"]
    assert (bd.lo, bd.hi) == (0, 30)
    (tmp_path / "impl.py").write_text(STOPPER.format(op="<="))
    cfg = read_config({"implementation": "impl.py:stopper", "max_examples": 50}, cn, tmp_path)
    out = run_guarantee(checked, cn, 1, cfg, tmp_path)
    assert out.status == "discharged" and out.counts.rejected == 0, out.counts.as_dict()
