"""The space margin of a state formula (semantics/robustness.py, docs/semantics.md "Margins").

Its values on hand-computed cases (comparisons, connectives, quantifiers
over sequences, equality, BOOL atoms, the empty sequence, units), and the
sign oracle: on random formulas and values, a positive margin only where
the evaluator says the formula holds and a negative one only where it
fails, in exact and in double arithmetic; 0 is the boundary, where either
verdict may stand (``a <= b`` holds at 0, ``a < b`` does not).  The
controls run the oracle on a margin with ``and`` read as a maximum and on
one with a comparison's sign flipped, and show that it catches both.
"""
from __future__ import annotations

import math
from typing import Any, Callable

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rclverify.lang.parser import parse_formula, parse_text
from rclverify.lang.typecheck import check
from rclverify.semantics import robustness
from rclverify.semantics.evaluate import evaluate
from rclverify.semantics.floatsem import holds_in
from rclverify.semantics.robustness import Margin, MarginUndefined, margin

SIGNATURE = """
context {
  Hue : {red, green, blue} ;
  LIMIT : REAL [m] = 2.5 ;
}
node n {
  inputs( r : REAL [m], k : INTEGER, s : seq(REAL), b : BOOL, c : Hue, w : REAL [m/s] )
  outputs( d : REAL [m], v : REAL [m/s], m : INTEGER, oc : Hue )
  guarantee( TRUE )
}
"""
CHECKED = check([parse_text(SIGNATURE)])
NODE = CHECKED.nodes["n"]
VALUES: dict[str, object] = {"in.r": 2.5, "in.k": 3, "in.s": (3.0, 2.5, 1.5), "in.b": True, "in.c": "red",
                             "in.w": 0.75, "out.d": 2.0, "out.v": 1.25, "out.m": -1, "out.oc": "blue"}


def m(text: str, values: dict[str, object] | None = None, arithmetic: str = "exact") -> Margin:
    return margin(parse_formula(text), CHECKED, NODE, VALUES if values is None else values, arithmetic)


@pytest.mark.parametrize("text, value", [
    ("out.d <= in.r", 0.5), ("out.d < in.r", 0.5), ("out.d >= in.r", -0.5), ("out.d > in.r", -0.5),
    ("in.r >= out.d", 0.5), ("out.d == in.r", -0.5), ("out.d != in.r", 0.5), ("out.d == 2", math.inf),
    ("out.d != 2", -math.inf), ("not (out.d <= in.r)", -0.5), ("out.d <= 3 and out.v > 1", 0.25),
    ("out.d <= 3 or out.v > 2", 1.0), ("out.v > 2 -> out.d > 5", 0.75), ("out.v < 2 -> out.d > 5", -0.75),
    ("(out.d > 1) <=> (out.v > 1)", 0.25), ("(out.d > 3) <=> (out.v > 1)", -0.25),
    ("1 <= out.d <= in.r", 0.5), ("out.d <= LIMIT", 0.5), ("out.d + 1 <= 2 * in.r", 2.0),
    ("forall(x in in.s | x > 1)", 0.5), ("exists(x in in.s | x > 4)", -1.0), ("exists(x in in.s | x > 2)", 1.0),
    ("exists_unique(x in in.s | x > 2.75)", 0.25), ("exists_unique(x in in.s | x > 2)", -0.5),
    ("exists_unique(x in in.s | x > 3.5)", -0.5), ("forall(x in <> | x > 1)", math.inf),
    ("exists(x in <> | x > 1)", -math.inf), ("in.b", math.inf), ("not in.b", -math.inf),
    ("in.c == red", math.inf), ("out.oc == red", -math.inf), ("in.b -> out.d > 1", 1.0),
    ("out.d in {1, 2, 3}", math.inf), ("out.d in {1, 2.25, 3.5}", -0.25), ("out.d !in {1, 2.25, 3.5}", 0.25),
    ("forall(h in Hue | h == in.c -> out.d > 1)", 1.0), ("forall(k in NATURAL | k <= 3 -> out.d > k)", -1.0),
    ("exists(j in <1 upto 3> | out.d > j)", 1.0), ("out.m >= 0", -1.0), ("abs(out.m) <= in.k", 2.0),
])
def test_margin_values(text: str, value: float) -> None:
    got = m(text)
    assert got.value == value, (text, got)
    assert m(text, arithmetic="double").value == value, text


def test_margin_units_and_atom() -> None:
    got = m("out.d <= in.r and out.v <= 2")
    assert (got.value, got.unit, got.atom) == (0.5, "m", "out.d <= in.r")
    got = m("out.d <= 3 and out.v <= in.w + 1")
    assert (got.value, got.unit, got.atom) == (0.5, "m/s", "out.v <= in.w + 1")
    assert m("out.m >= 0").unit == ""  # neither side declares a unit
    assert m("out.d <= LIMIT").unit == "m"  # the constant's unit
    assert m("1 <= out.d <= in.r").atom == "out.d <= in.r"  # the link of the chain that decides
    assert m("in.b").atom == ""


def test_exact_and_double_differ_as_the_arithmetics_do() -> None:
    """``out.d == 1000 * in.r`` on 1200.0 and 1.2: the exact reading is a hair
    negative (1.2 as a double is below 1.2), the double one holds without a
    distance (the node's product is 1200.0: an equality that holds is ``+inf``)."""
    values = dict(VALUES, **{"out.d": 1200.0, "in.r": 1.2})
    exact = m("out.d == 1000 * in.r", values)
    assert exact.value < 0 and exact.value > -1e-12
    assert m("out.d == 1000 * in.r", values, "double").value == math.inf


def test_sign_never_lost_in_the_rounding() -> None:
    tiny = 2.0 ** -1074
    got = m("out.d < in.r", dict(VALUES, **{"out.d": 0.0, "in.r": tiny}))
    assert got.value > 0
    got = m("out.d * out.d > 0", dict(VALUES, **{"out.d": tiny}))  # tiny squared: far below a double
    assert got.value > 0


def test_undefined() -> None:
    with pytest.raises(MarginUndefined, match="no value for out.d"):
        m("out.d > 1", {"in.r": 1.0})
    with pytest.raises(MarginUndefined, match="division by zero"):
        m("out.d / out.m > 1", dict(VALUES, **{"out.m": 0}))
    with pytest.raises(MarginUndefined):
        m("forall(x in REAL | x > out.d -> x > 1)")  # an infinite domain: no minimum to take
    with pytest.raises(ValueError, match="tolerance"):
        m("out.d > 1", arithmetic="tolerance")


# -- the sign oracle -------------------------------------------------------------------------------------------------

REAL_TERMS = ["in.r", "out.d", "LIMIT", "0", "1", "2.5", "0.1", "(0 - 0.5)"]
INT_TERMS = ["in.k", "out.m", "0", "1", "3", "(0 - 2)"]
Draw = Callable[..., Any]


def _pick(draw: Draw, xs: list[str]) -> str:
    return xs[draw(st.integers(0, len(xs) - 1))]


def _term(draw: Draw, scope: list[str], depth: int) -> str:
    if depth > 0 and draw(st.integers(0, 2)) == 0:
        op = _pick(draw, ["+", "-", "*"])
        return f"({_term(draw, scope, depth - 1)} {op} {_term(draw, scope, depth - 1)})"
    return _pick(draw, REAL_TERMS + INT_TERMS + scope)


def _formula(draw: Draw, scope: list[str], depth: int) -> str:
    kind = draw(st.integers(0, 7)) if depth > 0 else draw(st.integers(0, 1))
    if kind == 0:
        return f"({_term(draw, scope, 1)} {_pick(draw, ['<', '<=', '==', '!=', '>', '>='])} {_term(draw, scope, 1)})"
    if kind == 1:
        return _pick(draw, ["in.b", "(in.c == red)", "(out.oc != blue)", "TRUE", "FALSE",
                            f"({_term(draw, scope, 0)} in {{0, 1, 2.5}})", f"({_term(draw, scope, 0)} !in {{1, 3}})"])
    if kind == 2:
        return f"(not {_formula(draw, scope, depth - 1)})"
    if kind <= 4:
        op = _pick(draw, ["and", "or", "->", "<=>"])
        return f"({_formula(draw, scope, depth - 1)} {op} {_formula(draw, scope, depth - 1)})"
    q = _pick(draw, ["forall", "exists", "exists_unique"])
    x = f"x{len(scope)}"
    dom = _pick(draw, ["in.s", "<1 upto 3>", "{0, 2.5}", "<>"])
    return f"{q}({x} in {dom} | {_formula(draw, scope + [x], depth - 1)})"


_NUMBERS = st.sampled_from([0.0, 1.0, 2.5, -0.5, 0.1, 0.2, 0.30000000000000004, 3.0, 1e-300, -2.0])


@st.composite
def _case(draw: Draw) -> tuple[str, dict[str, object]]:
    text = _formula(draw, [], 3)
    values = {"in.r": draw(_NUMBERS), "out.d": draw(_NUMBERS), "in.k": draw(st.integers(-3, 3)),
              "out.m": draw(st.integers(-3, 3)), "in.s": tuple(draw(st.lists(_NUMBERS, max_size=3))),
              "in.b": draw(st.booleans()), "in.c": draw(st.sampled_from(["red", "blue"])),
              "out.oc": draw(st.sampled_from(["red", "blue"])), "in.w": 0.5, "out.v": 1.0}
    return text, values


def _agrees(text: str, values: dict[str, object], arithmetic: str) -> bool | None:
    """``None`` when the truth or the margin is undefined, else whether the margin's sign agrees with the truth."""
    e = parse_formula(text)
    truth = evaluate(e, CHECKED, NODE, values) if arithmetic == "exact" else \
        holds_in("double", e, CHECKED, NODE, values)
    try:
        r = margin(e, CHECKED, NODE, values, arithmetic).value
    except MarginUndefined:
        return None
    if truth is None:
        return None
    return not ((r > 0 and not truth) or (r < 0 and truth))


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_case())
def test_sign_agrees_with_the_verdict(case: tuple[str, dict[str, object]]) -> None:
    text, values = case
    for arithmetic in ("exact", "double"):
        assert _agrees(text, values, arithmetic) is not False, (arithmetic, text, values)


CONTROL_CASES = [("(out.d > 1) and (out.d > 3)", {"out.d": 2.0}), ("(in.r < 0) or (out.d < 0)", {"in.r": 1.0, "out.d": 1.0}),
                 ("forall(x in in.s | x > 2)", {"in.s": (3.0, 1.0)}), ("out.d <= 1", {"out.d": 2.0})]


@pytest.mark.parametrize("broken", ["and as max", "flipped comparison"])
def test_controls_the_oracle_catches_a_wrong_margin(broken: str, monkeypatch: pytest.MonkeyPatch) -> None:
    if broken == "and as max":
        monkeypatch.setattr(robustness, "_min", robustness._max)
    else:
        monkeypatch.setattr(robustness._Margins, "distance", lambda self, op, x, y: self.diff(x, y)
                            if op in ("<", "<=") else self.diff(y, x))
    found = [_agrees(t, dict(VALUES, **v), "exact") for t, v in CONTROL_CASES]
    assert False in found


def test_tuple_quantifiers_over_a_sequence_of_pairs() -> None:
    checked = check([parse_text("node p { inputs( ps : seq((REAL, REAL)) ) outputs( d : REAL ) guarantee( TRUE ) }")])
    node = checked.nodes["p"]
    values = {"in.ps": ((1.0, 3.0), (2.0, 2.5)), "out.d": 1.0}

    def got(text: str) -> float:
        return margin(parse_formula(text), checked, node, values).value
    assert got("forall((a, b) in in.ps | a < b)") == 0.5
    assert got("exists((a, b) in in.ps | a > b)") == -0.5
    assert got("exists_unique((a, b) in in.ps | b - a > 1)") == 0.5  # (1, 3) by 1 above, (2, 2.5) by 0.5 below
    assert got("exists_unique((a, b) in in.ps | b - a > 0.25)") == -0.25  # both above: not unique
