"""The candidates of the checked code repairs (diagnosis/code_repair.py, docs/diagnosis.md "Failing property
test: the one-token correction of the culprit line"): the corrections the culprit search does not make (an
integer for a non-integer number the contract names, an operand for another name, a slice dropped), the
lines around the culprit line, nearest first, and the line a repair found around it names."""
from __future__ import annotations

from fractions import Fraction

from rclverify.diagnosis.code_repair import around_lines, candidate_edits
from rclverify.diagnosis.code_repair_check import repaired_line

SRC = '''"""A node."""

LIMIT = 3.0


def step(ranges, engage):
    """Doc."""
    worst = max(ranges[:-1])
    if worst == 1:
        return {"ok": True, "c": engage - 273}
    return {"ok": worst <= LIMIT, "c": 0.0}
'''


def _texts(line: int, numbers: list[Fraction]) -> list[tuple[str, str]]:
    return [(e.deleted(SRC), e.text) for e in candidate_edits(SRC, "n.py", line, numbers)]


GOVERNOR = '''def govern(clearance, cmd_vel, limit):
    if clearance < 1.5:
        return {"safe": min(cmd_vel, 0.3)}
    return {"safe": cmd_vel}
'''


def test_a_name_is_never_put_for_one_of_another_unit() -> None:
    # the delivery slow zone's second repair was `cmd_vel < SLOW_ZONE` for `clearance < SLOW_ZONE`: a speed
    # compared with a distance, which the property tests passed (every drawn speed is under the zone)
    kinds = {"clearance": "REAL [m]", "cmd_vel": "REAL [m/s]", "limit": "REAL [m]", "safe": "REAL [m/s]"}
    got = [(e.deleted(GOVERNOR), e.text) for e in candidate_edits(GOVERNOR, "g.py", 2, [], kinds)]
    assert ("clearance", "limit") in got  # a name of the same unit
    assert ("clearance", "cmd_vel") not in got
    # control: without the contract's kinds every name of the function is a candidate
    assert ("clearance", "cmd_vel") in [(e.deleted(GOVERNOR), e.text) for e in candidate_edits(GOVERNOR, "g.py", 2, [])]


def test_operands_slices_and_named_numbers() -> None:
    eight = _texts(8, [])
    assert ("[:-1]", "") in eight  # the slice dropped
    assert ("max", "min") in eight and eight.index(("max", "min")) < eight.index(("[:-1]", ""))  # a name swap first
    ten = _texts(10, [Fraction(5463, 20)])
    assert ("True", "engage") in ten and ("True", "False") in ten  # a truth value for the input, after its negation
    assert ten.index(("True", "False")) < ten.index(("True", "engage"))
    assert ("", ".15") in ten  # 273 -> 273.15, cut to what changes
    assert ("engage", "worst") in ten and ("engage", "ranges") in ten  # an operand for another name in scope
    # control: a number the contract names that is an integer is the culprit search's own, not made twice,
    # and without a non-integer number no such edit is made
    assert ("", ".15") not in _texts(10, [])
    assert all(new != "worst" for old, new in _texts(8, []))  # never the name the statement assigns


def test_around_lines_nearest_first_earlier_first() -> None:
    assert around_lines(SRC, 10) == [9, 11, 8]
    assert around_lines(SRC, 11) == [10, 9, 8]
    assert around_lines(SRC, 3) == []  # control: no function holds the line


def test_repaired_line() -> None:
    rep = {"file": "n.py", "edit": {"line": 8}}
    assert repaired_line("n.py:11", [rep]) == "n.py:8"  # type: ignore[list-item]
    # controls: a repair at the culprit line itself, or none, names nothing more
    assert repaired_line("n.py:8", [rep]) == ""  # type: ignore[list-item]
    assert repaired_line("n.py:11", []) == ""


RATE = '''def step(count, dt, on):
    if on:
        return {"rate": 1.0, "ok": True}
    return {"rate": count / dt, "ok": False}
'''


def test_a_guard_against_a_zero_divisor() -> None:
    edits = candidate_edits(RATE, "r.py", 4, [])
    guard = edits[-1]  # class 4: after every one-token correction
    assert guard.deleted(RATE) == "" and (guard.line, guard.col) == (4, 1)
    assert guard.text == "    if dt == 0:\n        return {'rate': 0.0, 'ok': False}\n"
    assert "if dt == 0:" in guard.apply(RATE).splitlines()[3]
    # controls: no division by a name, or a return that is not a dict of the same keys: no guard
    assert not any("\n" in e.text for e in candidate_edits(RATE.replace("count / dt", "count * dt"), "r.py", 4, []))
    other = RATE.replace('return {"rate": 1.0, "ok": True}', "return None")
    assert not any("\n" in e.text for e in candidate_edits(other, "r.py", 4, []))
