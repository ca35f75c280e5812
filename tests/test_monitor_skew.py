"""Transport skew (backends/monitors/skew.py, docs/monitors.md "Transport
skew"): an answer whose callback ran just before its question's is neither
a false alarm (``violated``, no output) nor accepted as an answer
(``satisfied``): ``inconclusive``, or ``violated`` with the guarantee it
breaks.  The property at the end checks, on random traces, that the skew
never turns a verdict green."""
from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings, strategies as st

from rclverify.backends.monitors.config import ConfigError, load_mapping
from rclverify.backends.monitors.skew import DEFAULT_SKEW_S
from rclverify.traces.mapping import load_rules

from rclverify.backends.monitors.check import check_trace
from test_monitor_answers import ROW, events, sensor, simple  # noqa: F401  (fixtures)


def run(checked: Any, rows: list[tuple[float, str, Any]], rules: Any) -> tuple[list[Any], Any]:
    got: list[Any] = []
    _, [res] = check_trace(checked, [checked.nodes["Sensor"]], events(rows), rules, 1.0, got.append)
    return sorted(got, key=lambda v: v.event), res


def skewed(skew: float, state: frozenset[str] = frozenset()) -> Any:
    rules = load_rules({s: {"state": True} for s in state})
    rules.skew = skew
    return rules


def test_a_right_answer_received_just_before_its_question_is_inconclusive_not_violated(simple: Any) -> None:
    rows = [(1.0, "status", "green"), (1.0001, "r", 50.0), (5.0, "r", 60.0)]
    got, _ = run(simple, rows, skewed(0.0))  # no skew: no answer after the question
    assert got[0].verdict == "violated" and "no output" in got[0].reason
    got, res = run(simple, rows, rules=skewed(DEFAULT_SKEW_S))
    assert got[0].verdict == "inconclusive"
    assert "0.10 ms before the input" in got[0].reason and "stale" in got[0].reason
    assert got[0].values == {"in.r": "50.0", "out.status": "green"}
    assert res.first_violation is None and res.first_inconclusive["event"] == 1


def test_a_wrong_answer_received_just_before_its_question_is_violated_with_its_guarantee(simple: Any) -> None:
    rows = [(1.0, "status", "green"), (1.0001, "r", 300.0), (5.0, "r", 60.0)]
    got, res = run(simple, rows, rules=skewed(DEFAULT_SKEW_S))
    assert got[0].verdict == "violated" and got[0].guarantee == 1
    assert got[0].values["out.status"] == "green"
    assert res.first_violation["guarantee"] == 1 and res.first_violation["where"] == "run.jsonl:1"


def test_an_output_older_than_the_skew_is_still_no_answer(simple: Any) -> None:
    got, _ = run(simple, [(1.0, "status", "green"), (1.5, "r", 50.0), (5.0, "r", 60.0)],
                 rules=skewed(DEFAULT_SKEW_S))
    assert got[0].verdict == "violated" and "no output" in got[0].reason


def test_an_answer_after_the_question_is_judged_as_before(simple: Any) -> None:
    """The early output does not hide the real answer: red after r = 130 satisfies it."""
    got, _ = run(simple, [(1.0, "status", "green"), (1.001, "r", 130.0), (1.1, "status", "red"), (5.0, "r", 1.0)],
                 rules=skewed(DEFAULT_SKEW_S))
    assert got[0].verdict == "satisfied"


def test_the_mapping_sets_the_skew_and_refuses_a_bad_one(tmp_path: Path) -> None:
    (tmp_path / "m.yaml").write_text("topics: {}\n")
    assert load_mapping(tmp_path, "m.yaml").rules.skew == DEFAULT_SKEW_S
    (tmp_path / "m.yaml").write_text("topics: {}\nskew: 0\n")
    assert load_mapping(tmp_path, "m.yaml").rules.skew == 0.0
    for bad in ("-1", "true", ".nan", "fast"):
        (tmp_path / "m.yaml").write_text(f"topics: {{}}\nskew: {bad}\n")
        with pytest.raises(ConfigError, match=r"m\.yaml:2:7: error: skew must be a finite number"):
            load_mapping(tmp_path, "m.yaml")


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.sampled_from([0.0, 0.0, 0.1, 0.3, 0.6, 1.2]), ROW), min_size=1, max_size=14),
       st.sampled_from([frozenset(), frozenset({"level"})]))
def test_the_skew_never_turns_a_verdict_green(sensor: Any, steps: list[Any], state: frozenset[str]) -> None:
    """Same trace with and without a skew of 0.3 s: each verdict is the same,
    or a ``violated`` became ``inconclusive`` or ``violated`` with another
    reason; nothing not satisfied without the skew is satisfied with it."""
    t, rows = 0.0, []
    for dt, (topic, v) in steps:
        t += dt
        rows.append((t, topic, v))
    plain, _ = run(sensor, rows, rules=skewed(0.0, state))
    with_skew, _ = run(sensor, rows, rules=skewed(0.3, state))
    assert [v.event for v in plain] == [v.event for v in with_skew]
    for a, b in zip(plain, with_skew):
        assert a.verdict == b.verdict or (a.verdict == "violated" and b.verdict == "inconclusive"), (a, b)
