"""The report's kept pieces (report/fragments.py): a report rendered with a
warm cache is byte for byte the one rendered without any.  The checks on the
case study's verified copy (an empty, a warm and an edited cache) are in
tests/report/test_pipeline_e2e.py, which verifies it once."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from rclverify.records.store import dumps
from rclverify.report.fragments import FragmentCache, cached_dumps, fingerprint

def test_a_damaged_or_foreign_cache_file_is_an_empty_cache(tmp_path: Path) -> None:
    path = tmp_path / "c.pickle"
    path.write_bytes(b"not a pickle")
    cache = FragmentCache(path)
    assert cache.text("k", {"a": 1}, lambda: "x") == "x" and cache.misses == 1
    assert cache.save()
    again = FragmentCache(path)
    assert again.text("k", {"a": 1}, lambda: "y") == "x"  # kept
    assert again.text("k", {"a": 2}, lambda: "y") == "y"  # other data, other piece
    assert again.text("other", {"a": 1}, lambda: "z") == "z"  # other kind, other piece


def test_fingerprints_tell_apart_what_renders_differently() -> None:
    from markupsafe import Markup
    same = [{"a": [1, "x"], "b": None}, {"a": [1, "x"], "b": None}]
    assert fingerprint(same[0]) == fingerprint(same[1])
    # each of these renders differently (JSON, HTML or text), so none may share a key
    values = [1, True, 1.0, "1", [1], (1,), {"a": 1}, {"a": "1"}, None, "", Markup("<b>"), "<b>", [], {}]
    prints = [fingerprint(v) for v in values]
    assert len(set(prints)) == len(values)
    assert fingerprint(Markup("<b>")).startswith(b"j")  # marshal cannot hold a str subclass: canonical JSON
    with pytest.raises(TypeError):
        fingerprint({"a": object()})


def test_only_the_pieces_used_last_are_kept(tmp_path: Path) -> None:
    path = tmp_path / "c.pickle"
    first = FragmentCache(path)
    first.text("k", 1, lambda: "one")
    first.text("k", 2, lambda: "two")
    first.save()
    second = FragmentCache(path)
    second.text("k", 2, lambda: "changed")
    assert second.save()
    third = FragmentCache(path)
    assert third.text("k", 1, lambda: "again") == "again"
    assert not FragmentCache(None).save()


@pytest.mark.parametrize("value", [
    {}, [], {"a": []}, {"a": {}}, {"b": [1, 2.5, None, True, "x"], "a": {"z": [[]], "y": [{}]}},
    {"lists": [[{"deep": [1, {"k": "é\n\"q\\"}]}], [], [[[]]]], "n": [{"x": float("1e100")}]},
    {"top": [{"1": "a", "10": "b", "2": "c"}, ("tuple", 1)], "s": "\u2705 \ud83d"},
    [{"x": 1}, [{"y": [2, 3]}]], "scalar", 3,
])
def test_cached_json_text_is_the_standard_text(value: object, tmp_path: Path) -> None:
    cache = FragmentCache(tmp_path / "c.pickle")
    assert cached_dumps(value, cache) == dumps(value)
    cache.save()
    warm = FragmentCache(tmp_path / "c.pickle")
    assert cached_dumps(value, warm) == dumps(value) and warm.misses == 0
