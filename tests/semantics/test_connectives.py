"""semantics/connectives.py: ``conj``/``disj`` give the very term ``z3.And``/``z3.Or`` give.

The reference is z3.py itself: on random lists of Boolean terms (atoms,
comparisons, negations, quantified formulas, nested connectives, in the
main context or a fresh one) the term made without coercion has the same
id as the coerced one, so every query built from it is the same query.
Arguments the direct path does not take (none, Python booleans, terms of
two contexts, a non-Boolean ``BoolRef``) give what z3.py gives or raise
what it raises.
"""
from __future__ import annotations

import pytest
import z3
from hypothesis import given, settings, strategies as st

from rclverify.semantics.connectives import conj, disj


def _atoms(ctx: z3.Context) -> list[z3.BoolRef]:
    x, y = z3.Int("x", ctx), z3.Real("y", ctx)
    p, q = z3.Bool("p", ctx), z3.Bool("q", ctx)
    f = z3.Function("f", z3.IntSort(ctx), z3.IntSort(ctx))
    return [p, q, x > 3, y <= z3.RealVal("1/3", ctx), f(x) == x, z3.Not(p), z3.BoolVal(True, ctx),
            z3.BoolVal(False, ctx), z3.ForAll([x], f(x) >= x), z3.Exists([x], f(x) < 0), z3.Implies(p, q)]


@settings(max_examples=150)
@given(st.lists(st.integers(0, 10), min_size=1, max_size=12), st.booleans(), st.booleans())
def test_the_same_term_as_z3py(picks: list[int], fresh: bool, nest: bool) -> None:
    ctx = z3.Context() if fresh else z3.main_ctx()
    atoms = _atoms(ctx)
    terms = [atoms[i] for i in picks]
    if nest:  # connectives of connectives, as the transition systems build them
        terms = terms + [z3.Or(*terms), z3.And(*terms[:1])]
    assert conj(*terms).get_id() == z3.And(*terms).get_id()
    assert disj(*terms).get_id() == z3.Or(*terms).get_id()
    assert conj(*terms).ctx is ctx and disj(*terms).ctx is ctx
    assert conj(*terms).sexpr() == z3.And(*terms).sexpr()


def test_arguments_the_direct_path_does_not_take_go_to_z3py() -> None:
    p, q = z3.Bools("p q")
    # Python booleans are coerced by z3.py, as before
    assert conj(p, True).get_id() == z3.And(p, True).get_id()
    assert disj(False, q).get_id() == z3.Or(False, q).get_id()
    # a list as the only argument
    assert conj([p, q]).get_id() == z3.And([p, q]).get_id()
    # an explicit context as the last argument
    assert disj(p, q, z3.main_ctx()).get_id() == z3.Or(p, q, z3.main_ctx()).get_id()
    # no argument: whatever z3.py does
    for mine, theirs in ((conj, z3.And), (disj, z3.Or)):
        try:
            expected: object = theirs().get_id()
        except Exception as exc:  # noqa: BLE001 - the same kind of error, whatever it is
            with pytest.raises(type(exc)):
                mine()
        else:
            assert mine().get_id() == expected


def test_terms_of_two_contexts_are_refused_as_z3py_refuses_them() -> None:
    p = z3.Bool("p")
    q = z3.Bool("q", z3.Context())
    with pytest.raises(z3.Z3Exception) as theirs:
        z3.And(p, q)
    # the same error as z3.py's (the direct path, given them, would let Z3 read a term of another
    # context and report a sort mismatch of two Booleans)
    with pytest.raises(z3.Z3Exception, match=str(theirs.value)):
        conj(p, q)
    with pytest.raises(z3.Z3Exception, match=str(theirs.value)):
        disj(q, p)


def test_a_term_that_is_not_boolean_is_a_sort_error() -> None:
    x = z3.Int("x")
    lam = z3.Lambda([x], x > 0)  # a BoolRef by class, an array by sort
    assert isinstance(lam, z3.BoolRef)
    with pytest.raises(z3.Z3Exception):
        conj(z3.Bool("p"), lam)
    with pytest.raises(z3.Z3Exception):
        disj(z3.Bool("p"), lam)
