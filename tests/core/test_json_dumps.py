"""Deterministic JSON (core/atomic.py): the fast :func:`dumps` (compact C
encoding, indented by msgspec) writes byte for byte the text of the
reference indenting encoder, on random values and on the awkward ones
(exponent floats, integers past 64 bits, control characters, lone
surrogates, NaN, empty containers, non-string keys)."""
from __future__ import annotations

from enum import Enum, IntEnum
from typing import Any

import pytest
from hypothesis import given, settings, strategies as st

from rclverify.core.atomic import dumps, reference_dumps

#: Past this length a text is long: a list of values of many lines.
_LONG = 2048

SCALARS = (st.none() | st.booleans() | st.integers(min_value=-2**130, max_value=2**130)
           | st.floats(allow_nan=False, allow_infinity=False) | st.text(max_size=12))
VALUES = st.recursive(SCALARS, lambda inner: st.lists(inner, max_size=5)
                      | st.dictionaries(st.text(max_size=6), inner, max_size=5), max_leaves=25)


def _long(value: Any) -> list[Any]:
    """``value`` repeated until its compact text passes the fast path's threshold."""
    return [value] * (1 + _LONG // max(1, len(reference_dumps(value)) // 3))


@settings(max_examples=150, deadline=None)
@given(VALUES)
def test_the_fast_text_is_the_reference_text(value: Any) -> None:
    assert dumps(value) == reference_dumps(value)
    assert dumps(_long(value)) == reference_dumps(_long(value))


class Colour(str, Enum):
    RED = "red"


class Level(IntEnum):
    HIGH = 3


@pytest.mark.parametrize("value", [
    [1e-05, 1e16, 1.5e300, -0.0, 5e-324, 2**64, -2**70, 0.1, 123.0],
    {"\x00\x1f\x7f\u2028\u2029é𝄞\"\\/": ["\t\n\r\b\f"], "": {}, "a": [[], {}, [{}]]},
    {"ints": {10: "a", 2: "b"}, "floats": {2.5: "x", 1e-07: "y"}, "x": [None, True, False]},
    [Colour.RED, Level.HIGH, (1, 2), {"t": (3, {"u": ()})}],
    [float("nan"), float("inf"), -float("inf")],  # not strict JSON: the reference's text
    ["\ud800"],  # a lone surrogate: not UTF-8, the reference's text
])
def test_awkward_values_read_as_the_reference(value: Any) -> None:
    for v in (value, _long(value)):
        assert dumps(v) == reference_dumps(v)


def test_long_texts_and_errors_are_the_references() -> None:
    value = _long({"a": [1.5e-7, "x"]})
    assert len(reference_dumps(value)) > _LONG
    text = dumps(value)
    assert text.endswith("\n") and text == reference_dumps(value)
    with pytest.raises(TypeError):
        dumps(_long({"a": object()}))
    with pytest.raises(TypeError):  # keys of mixed types cannot be sorted, as with the reference
        dumps({1: 0, "b": 1})
