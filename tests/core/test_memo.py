"""One kept result per function (memo.py): the same object gives the kept
result, another object (even an equal one) or other arguments a new one."""
from __future__ import annotations

from rclverify.core.cache.memo import last_call


def test_last_call_keeps_one_result_for_the_same_object() -> None:
    calls: list[object] = []

    @last_call
    def size(report: dict[str, int], extra: int = 0, *, cache: object = None) -> int:
        calls.append(report)
        return len(report) + extra

    a, b = {"x": 1}, {"x": 1}
    assert size(a) == 1 and size(a, cache=object()) == 1 and len(calls) == 1  # keywords are not compared
    assert size(b) == 1 and len(calls) == 2  # equal but another dict: computed again
    assert size(b, 2) == 3 and len(calls) == 3  # other positional arguments: computed again
    assert size(b, 2) == 3 and len(calls) == 3
    assert size(a) == 1 and len(calls) == 4  # only the last call is kept
