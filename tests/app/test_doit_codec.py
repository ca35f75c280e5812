"""The codec of doit's task state (src/rclverify/app/doit_codec.py): the text doit's own
codec writes, and every text read back as doit's own codec reads it."""
from __future__ import annotations

import json
import math
from typing import Any

import pytest
from doit.dependency import JSONCodec
from hypothesis import given, strategies as st

from rclverify.app.doit_codec import StateCodec
from rclverify.app.tasks import doit_config

JSON = st.recursive(
    st.none() | st.booleans() | st.integers() | st.integers(min_value=-(10 ** 30), max_value=10 ** 30)
    | st.floats(allow_nan=True, allow_infinity=True) | st.text(),
    lambda kids: st.lists(kids, max_size=4) | st.dictionaries(st.text(max_size=6), kids, max_size=4),
    max_leaves=20)


def _same(a: Any, b: Any) -> bool:
    """Equal values, of equal types, NaN equal to NaN."""
    if type(a) is not type(b):
        return False
    if isinstance(a, float):
        return a == b or (math.isnan(a) and math.isnan(b))
    if isinstance(a, list):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if isinstance(a, dict):
        return list(a) == list(b) and all(_same(a[k], b[k]) for k in a)
    return bool(a == b)


@given(JSON)
def test_the_codec_writes_and_reads_as_doits(value: Any) -> None:
    ours, doits = StateCodec(), JSONCodec()
    text = ours.encode(value)
    assert text == doits.encode(value)
    assert _same(ours.decode(text), doits.decode(text))


@pytest.mark.parametrize("text", ['{"x": NaN}', "[Infinity, -Infinity]", "1e400", '"\\ud800"', '{"a": 1, "a": 2}',
                                  "123456789012345678901234567890", '[1.5, 0.1, 1e-320, -0.0]', '{"deps": {}}'])
def test_texts_msgspec_refuses_or_reads_alike(text: str) -> None:
    assert _same(StateCodec().decode(text), JSONCodec().decode(text))


def test_a_text_that_is_not_json_is_refused_as_doits_codec_refuses_it() -> None:
    with pytest.raises(json.JSONDecodeError):
        StateCodec().decode('{"deps": ')


def test_doit_is_given_the_codec() -> None:
    assert doit_config()["codec_cls"] is StateCodec
