"""Refinement with environment facts and extra inputs (calculus/refinement.py)."""
from __future__ import annotations

import io
from pathlib import Path

import pytest

from rclverify.calculus.refinement import check_refinement, merge_envs, refines_main
from rclverify.lang.errors import RclError
from rclverify.lang.parser import parse_formula, parse_text
from rclverify.lang.typecheck import check

ORIGINAL = """
node S {
  inputs( r : REAL )
  outputs( alarm : BOOL )
  assume( TRUE )
  guarantee( in.r > 10 -> out.alarm == TRUE )
}
"""
# reads a second input: a calibration offset; alarms when r + offset > 10
REPLACEMENT = """
node S {
  inputs( r : REAL, offset : REAL )
  outputs( alarm : BOOL )
  assume( TRUE )
  guarantee( in.r + in.offset > 10 -> out.alarm == TRUE )
}
"""


def _nodes():
    a = check([parse_text(ORIGINAL, "a.rcl")])
    b = check([parse_text(REPLACEMENT, "b.rcl")])
    return a, b


def test_extra_input_without_a_condition_is_an_interface_error():
    a, b = _nodes()
    with pytest.raises(RclError) as exc:
        check_refinement(a.nodes["S"], b.nodes["S"], merge_envs(a, b))
    assert "offset" in str(exc.value.diagnostics[0])


def test_extra_input_with_a_condition_refines_under_that_condition():
    a, b = _nodes()
    r = check_refinement(a.nodes["S"], b.nodes["S"], merge_envs(a, b), conditions=[parse_formula("in.offset >= 0")])
    assert r.verdict == "refines"
    assert r.conditions == ("in.offset >= 0  [condition]",)
    # and a condition too weak for it is refuted with a model
    r = check_refinement(a.nodes["S"], b.nodes["S"], merge_envs(a, b), conditions=[parse_formula("in.offset >= -1")])
    assert r.verdict == "does not refine" and r.guarantee.model is not None


def test_environment_facts_are_honoured():
    a = check([parse_text(ORIGINAL, "a.rcl")])
    weaker = check([parse_text(ORIGINAL.replace("in.r > 10", "in.r > 20"), "b.rcl")])
    env = merge_envs(a, weaker)
    assert check_refinement(a.nodes["S"], weaker.nodes["S"], env).verdict == "does not refine"
    # in an environment where r never lies in (10, 20], the weaker alarm is enough
    fact = parse_formula("in.r <= 10 or in.r > 20")
    r = check_refinement(a.nodes["S"], weaker.nodes["S"], env, facts=[fact])
    assert r.verdict == "refines" and "[environment fact]" in r.conditions[0]


def test_cli_states_the_condition(tmp_path: Path):
    (tmp_path / "a.rcl").write_text(ORIGINAL)
    (tmp_path / "b.rcl").write_text(REPLACEMENT)
    out, err = io.StringIO(), io.StringIO()
    code = refines_main(f"{tmp_path}/a.rcl:S", f"{tmp_path}/b.rcl:S", out=out, err=err, assumes=["in.offset >= 0"])
    assert code == 0, err.getvalue()
    assert "under the conditions:" in out.getvalue() and "wherever these conditions hold" in out.getvalue()


def test_the_refuted_finding_points_to_its_counterexample():
    from rclverify.calculus.health.checks import refinement_finding
    a = check([parse_text(ORIGINAL, "a.rcl")])
    weaker = check([parse_text(ORIGINAL.replace("in.r > 10", "in.r > 20"), "b.rcl")])
    r = check_refinement(a.nodes["S"], weaker.nodes["S"], merge_envs(a, weaker))
    f = refinement_finding("S", "b.rcl", r)
    # as the realizability finding does: the row says where its counterexample is printed
    assert f.status == "problem" and f.model
    assert f.message.endswith("its guarantee side fails (the finding's counterexample: "
                              "`rclverify explain S.replacement-refines`).")
    same = refinement_finding("S", "a.rcl", check_refinement(a.nodes["S"], a.nodes["S"], merge_envs(a, a)))
    assert same.status == "ok" and "explain" not in same.message
