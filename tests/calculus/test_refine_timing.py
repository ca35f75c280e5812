"""Refinement decides deadlines (issue 47; calculus/refine_timing.py): a
contract answering ``within 900 ms`` never replaces one answering ``within
500 ms``; the oracle compares the verdict with a direct reading of the rule
on random deadlines."""
from __future__ import annotations

from fractions import Fraction
from pathlib import Path

from hypothesis import given, settings, strategies as st

from rclverify.calculus.refinement import check_refinement, merge_envs, refines_main
from rclverify.lang.typecheck import load

NODE = """node Bridge {{
  inputs( v : REAL )
  outputs( w : REAL )
  topics( std_msgs/Float64 cmd_vel matches(in.v), std_msgs/Float64 wheel_cmd matches(out.w) )
  assume( 0 <= in.v and in.v <= 1.5 )
  guarantee( {formula} ) {timing}
}}
"""


def _node(tmp: Path, name: str, formula: str, timing: str):
    p = tmp / f"{name}.rcl"
    p.write_text(NODE.format(formula=formula, timing=timing))
    return load([p])


def _verdict(tmp: Path, a: tuple[str, str], b: tuple[str, str]) -> str:
    ca, cb = _node(tmp, "a", *a), _node(tmp, "b", *b)
    return check_refinement(ca.nodes["Bridge"], cb.nodes["Bridge"], merge_envs(ca, cb)).verdict


def test_a_slower_deadline_does_not_refine_a_faster_one(tmp_path: Path, capsys) -> None:
    a = ("out.w == in.v", "triggered by in.v within 500 ms")
    assert _verdict(tmp_path, a, ("out.w == in.v", "triggered by in.v within 900 ms")) == "does not refine"
    assert _verdict(tmp_path, a, ("out.w == in.v", "triggered by in.v within 0.2 s")) == "refines"
    # untimed: an answer eventually keeps no deadline
    assert _verdict(tmp_path, a, ("out.w == in.v", "")) == "does not refine"
    # as fast, but a weaker answer: refuted by Z3 with a model
    assert _verdict(tmp_path, a, ("out.w <= in.v", "triggered by in.v within 100 ms")) == "does not refine"
    rc = refines_main(str(tmp_path / "a.rcl") + ":Bridge", str(tmp_path / "b.rcl") + ":Bridge")
    out = capsys.readouterr().out
    assert rc == 1 and "timing" in out and "refuted" in out
    _node(tmp_path, "b", "out.w == in.v", "triggered by in.v within 900 ms")
    rc = refines_main(str(tmp_path / "a.rcl") + ":Bridge", str(tmp_path / "b.rcl") + ":Bridge")
    out = capsys.readouterr().out
    assert rc == 1 and "only within 900 ms, slower than" in out


UNITS = {"ms": Fraction(1, 1000), "s": Fraction(1)}


@settings(max_examples=25, deadline=None)
@given(st.integers(1, 2000), st.sampled_from(["ms", "s"]), st.integers(1, 2000), st.sampled_from(["ms", "s"]),
       st.booleans())
def test_the_timing_verdict_equals_a_direct_comparison(tmp_path_factory, da: int, ua: str, db: int, ub: str,
                                                       weaker: bool) -> None:
    """Oracle: same trigger, B refines A iff B's deadline <= A's (exact, in
    seconds) and B's answer implies A's (``<=`` does not imply ``==``)."""
    tmp = tmp_path_factory.mktemp("timing")
    got = _verdict(tmp, ("out.w == in.v", f"triggered by in.v within {da} {ua}"),
                   ("out.w <= in.v" if weaker else "out.w == in.v", f"triggered by in.v within {db} {ub}"))
    want = db * UNITS[ub] <= da * UNITS[ua] and not weaker
    assert got == ("refines" if want else "does not refine")
