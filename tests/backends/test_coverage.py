"""The property tests' coverage of the assumption's ranges (issue 50;
backends/property_tests/coverage.py), against a direct evaluation of its
definition on small random cases."""
from __future__ import annotations

from fractions import Fraction

from hypothesis import given, settings
from hypothesis import strategies as st

from rclverify.backends.property_tests.coverage import BUCKETS, Coverage
from rclverify.backends.property_tests.strategies import Bound
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check

NODE = check([parse_text("""
context { Mode : {idle, run, stop} ; }
node N {
  inputs( i : INTEGER, x : REAL, b : BOOL, m : Mode, u : REAL )
  outputs( y : REAL )
  assume( TRUE )
  guarantee( out.y == 0 )
}
""", "n.rcl")]).nodes["N"]


@settings(max_examples=40, deadline=None, derandomize=True)
@given(lo=st.integers(-20, 20), width=st.integers(0, 30), xs=st.lists(st.integers(-40, 60), max_size=12),
       reals=st.lists(st.fractions(Fraction(-5), Fraction(15)), max_size=12),
       bs=st.lists(st.booleans(), max_size=3), ms=st.lists(st.sampled_from(["idle", "run", "stop"]), max_size=3))
def test_coverage_equals_its_definition(lo: int, width: int, xs: list[int], reals: list[Fraction],
                                        bs: list[bool], ms: list[str]) -> None:
    hi = lo + width
    cov = Coverage(NODE, {"i": Bound(Fraction(lo), Fraction(hi)), "x": Bound(Fraction(0), Fraction(10)),
                          "m": Bound(enum=frozenset({"idle", "run"}))})
    rows = max(len(xs), len(reals), len(bs), len(ms))
    for k in range(rows):
        ex = {}
        if k < len(xs):
            ex["in.i"] = xs[k]
        if k < len(reals):
            ex["in.x"] = reals[k]
        if k < len(bs):
            ex["in.b"] = bs[k]
        if k < len(ms):
            ex["in.m"] = ms[k]
        cov.add(ex)
    got = cov.as_dict()
    # an integer range of at most BUCKETS values: one bucket per value; a wider one: BUCKETS equal widths
    n = min(BUCKETS, width + 1)
    inside = [x for x in xs if lo <= x <= hi]
    if width + 1 <= BUCKETS:
        want = len(set(inside))
    else:
        want = len({min(n - 1, (x - lo) * n // width) for x in inside})
    assert (got["in.i"]["buckets"], got["in.i"]["covered"]) == (n, want)
    assert got["in.i"]["fraction"] == round(want / n, 4)
    assert got["in.x"]["covered"] == len({min(9, int(r)) for r in reals if 0 <= r <= 10})
    assert got["in.b"]["covered"] == len(set(bs)) and got["in.b"]["buckets"] == 2
    assert got["in.m"]["buckets"] == 2 and got["in.m"]["covered"] == len(set(ms) & {"idle", "run"})
    assert got["in.u"]["fraction"] is None and got["in.u"]["range"] == "[-inf, inf]"
    if xs:
        assert got["in.i"]["drawn"] == f"{min(xs)}..{max(xs)}"
