"""The concrete-value convention shared by property tests and trace checking."""
from fractions import Fraction

import pytest

from rclverify.lang import types as T
from rclverify.semantics.values import FiniteFunction, Term, conforms, exact, render

CMD = T.DataT("CommandSet", (("move", (T.REAL, T.REAL)), ("inspect", (T.NATURAL,))))
RAD = T.EnumT("RadStat", ("red", "orange", "green"))


def test_finite_function_call_index_and_default() -> None:
    f = FiniteFunction({(1.0, 2.0): 3}, 0, arity=2)
    assert f(1.0, 2.0) == 3 and f(0, 0) == 0 and f[(1.0, 2.0)] == 3
    g = FiniteFunction({1: True}, False)
    assert g(1) is True and g[5] is False
    assert g == FiniteFunction({(1,): True}, False) and hash(g) == hash(FiniteFunction({(1,): True}, False))
    with pytest.raises(TypeError):
        f(1.0)
    with pytest.raises(TypeError):
        FiniteFunction({(1, 2, 3): 0}, 0, arity=2)


@pytest.mark.parametrize("value, typ, fragment", [
    (-1, T.NATURAL, "below 0"),
    (1.5, T.INTEGER, "not an integer"),
    (True, T.REAL, "bool"),
    (float("nan"), T.REAL, "finite"),
    ("blue", RAD, "not a value of RadStat"),
    (Term("inspect", (-1,)), CMD, "argument 1 of inspect"),
    (Term("stop"), CMD, "not a constructor of CommandSet"),
    (FiniteFunction({(1.0,): -2}, 0), T.FuncT((T.REAL,), T.NATURAL), "result at 1.0"),
    (frozenset({1, -1}), T.SetT(T.NATURAL), "element -1"),
])
def test_conforms_names_what_is_wrong(value: object, typ: T.Type, fragment: str) -> None:
    why = conforms(value, typ)
    assert why is not None and fragment in why


def test_conforms_accepts_well_typed_values() -> None:
    assert conforms(Term("move", (1.5, 2)), CMD) is None
    assert conforms("red", RAD) is None
    assert conforms(FiniteFunction({(1.0, 2.0): 3}, 0, 2), T.FuncT((T.REAL, T.REAL), T.NATURAL)) is None
    assert conforms((1, 2), T.TupleT((T.NATURAL, T.REAL))) is None


def test_render_and_exact() -> None:
    assert render(Term("move", (1.5, 2))) == "move(1.5, 2)"
    assert render(FiniteFunction({(0,): True}, False)) == "{0 |-> TRUE, else |-> FALSE}"
    assert render(frozenset({"b", "a"})) == "{a, b}"
    assert exact(0.1) == Fraction(0.1) and exact(3) == 3
    with pytest.raises(ValueError):
        exact(float("inf"))
