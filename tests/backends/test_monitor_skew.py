"""Transport skew (docs/semantics.md, "Transport skew"): an output stamped
within the skew before a question may answer it or the question before; a
verdict is given only where both readings agree.  The property at the end
checks, on random traces, that the skew never turns a verdict green nor red."""
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


def test_an_output_before_any_question_answers_none_with_or_without_skew(simple: Any) -> None:
    """Green received 0.1 ms before the first reading: it answers no question
    (nothing was asked before it), so it gets no verdict either way; the
    reading got no answer after it: unanswered (inconclusive), never
    discharged on an early output."""
    rows = [(1.0, "status", "green"), (1.0001, "r", 50.0), (5.0, "r", 60.0)]
    for skew in (0.0, DEFAULT_SKEW_S):
        got, res = run(simple, rows, skewed(skew))
        assert [(v.event, v.verdict) for v in got] == [(1, "inconclusive"), (2, "open")] and res.unasked == 1


def test_a_wrong_answer_from_the_previous_question_is_no_false_alarm(simple: Any) -> None:
    """The CI case: the sensor answers r = 300 with red, stamped 0.13 ms before
    the reading; against the previous reading (50) red is wrong, against 300 it
    is right.  The readings disagree: inconclusive, never violated."""
    rows = [(0.0, "r", 50.0), (0.01, "status", "green"), (1.0, "status", "red"), (1.00013, "r", 300.0),
            (1.5, "r", 60.0), (1.51, "status", "green")]
    got, res = run(simple, rows, skewed(0.0))
    assert [(v.event, v.verdict) for v in got if v.event == 2] == [(2, "violated")]
    got, res = run(simple, rows, rules=skewed(DEFAULT_SKEW_S))
    v = next(x for x in got if x.event == 2)
    assert v.verdict == "inconclusive" and "0.13 ms before the question at run.jsonl:4" in v.reason
    assert res.first_violation is None


def test_an_answer_right_before_but_wrong_for_the_question_just_after_is_never_left_green(simple: Any) -> None:
    """The live case study's race: the sensor answers r = 300 with orange, and the
    answer is stamped 0.3 ms before the reading; against the reading before it
    (130) orange is right.  The reading gets no answer of its own, so the two
    readings disagree: the output's satisfied is followed by an inconclusive,
    and the run is never discharged on it (before, it read discharged)."""
    from rclverify.backends.monitors.backend import verdict_status
    rows = [(0.0, "r", 130.0), (0.01, "status", "red"), (1.0, "status", "red"), (1.0003, "r", 50.0),
            (1.5, "r", 60.0), (1.51, "status", "green")]
    got, res = run(simple, rows, skewed(DEFAULT_SKEW_S))
    at2 = [v for v in got if v.event == 2]
    assert [v.verdict for v in at2] == ["satisfied", "inconclusive"]
    assert "0.30 ms before the question at run.jsonl:4" in at2[1].reason and at2[1].question == "run.jsonl:4"
    assert verdict_status(res, "run.jsonl")[0] == "inconclusive"
    got, res = run(simple, rows, skewed(0.0))  # without a skew: the reading is superseded, the run discharged
    assert verdict_status(res, "run.jsonl")[0] == "discharged"


def test_a_wrong_answer_under_every_reading_is_violated(simple: Any) -> None:
    rows = [(0.0, "r", 50.0), (0.01, "status", "green"), (1.0, "status", "red"), (1.0001, "r", 60.0)]
    got, res = run(simple, rows, rules=skewed(DEFAULT_SKEW_S))
    v = next(x for x in got if x.event == 2)
    assert v.verdict == "violated" and v.guarantee == 1 and "every question it may answer" in v.reason
    assert res.first_violation["where"] == "run.jsonl:3"


def test_an_output_older_than_the_skew_answers_the_question_before(simple: Any) -> None:
    got, _ = run(simple, [(1.0, "status", "green"), (1.5, "r", 50.0), (5.0, "r", 60.0)],
                 rules=skewed(DEFAULT_SKEW_S))
    assert [(v.event, v.verdict) for v in got] == [(1, "inconclusive"), (2, "open")]


def test_an_answer_after_the_question_is_judged_as_before(simple: Any) -> None:
    """The early output does not hide the real answer: red after r = 130 satisfies it."""
    got, _ = run(simple, [(1.0, "status", "green"), (1.001, "r", 130.0), (1.1, "status", "red"), (5.0, "r", 1.0)],
                 rules=skewed(DEFAULT_SKEW_S))
    assert {v.event: v.verdict for v in got} == {2: "satisfied", 3: "open"}


def test_the_mapping_sets_the_skew_and_refuses_a_bad_one(tmp_path: Path) -> None:
    (tmp_path / "m.yaml").write_text("topics: {}\n")
    assert load_mapping(tmp_path, "m.yaml").rules.skew == DEFAULT_SKEW_S
    (tmp_path / "m.yaml").write_text("topics: {}\nskew: 0\n")
    assert load_mapping(tmp_path, "m.yaml").rules.skew == 0.0
    for bad in ("-1", "true", ".nan", "fast"):
        (tmp_path / "m.yaml").write_text(f"topics: {{}}\nskew: {bad}\n")
        with pytest.raises(ConfigError, match=r"m\.yaml:2:7: error: skew must be a finite number"):
            load_mapping(tmp_path, "m.yaml")


@settings(max_examples=80, deadline=None)
@given(st.lists(st.tuples(st.sampled_from([0.0, 0.0, 0.1, 0.3, 0.6, 1.2]), ROW), min_size=1, max_size=14),
       st.sampled_from([frozenset(), frozenset({"level"})]))
def test_the_skew_never_turns_a_verdict_green_nor_red(sensor: Any, steps: list[Any], state: frozenset[str]) -> None:
    """Same trace with and without a skew of 0.3 s: a question's verdicts are the
    same; an output's verdict is the same, or became ``inconclusive``, or (an
    output that answered no question without the skew) is ``satisfied`` only
    where it is right for every question it may answer: never ``satisfied``
    where it was not, never ``violated`` where it was not."""
    t, rows = 0.0, []
    for dt, (topic, v) in steps:
        t += dt
        rows.append((t, topic, v))
    plain, _ = run(sensor, rows, rules=skewed(0.0, state))
    with_skew, _ = run(sensor, rows, rules=skewed(0.3, state))
    outputs = {k for k, (_, topic, _) in enumerate(rows) if topic in ("status", "level")}

    def per_event(vs: list[Any]) -> dict[int, list[str]]:
        out: dict[int, list[str]] = {}
        for v in vs:
            out.setdefault(v.event, []).append(v.verdict)
        return {k: sorted(x) for k, x in out.items()}
    a, b = per_event(plain), per_event(with_skew)
    for k in set(a) | set(b):
        if k not in outputs:
            assert a.get(k) == b.get(k), (k, a, b)
            continue
        before, after = a.get(k, []), b.get(k, [])
        assert "violated" not in after or "violated" in before, (k, before, after)
        assert "satisfied" not in after or "satisfied" in before or not before, (k, before, after)


TWO_OUTPUTS = """
context { Stat : {red, orange, green} ; }
node Sensor {
  inputs( r : REAL )
  outputs( status : Stat, done : BOOL )
  topics( pkg/Reading r matches(in.r), pkg/Status status matches(out.status), pkg/Done done matches(out.done) )
  assume( 0 <= in.r )
  guarantee( out.done and (in.r < 120 -> out.status == green) and (120 <= in.r -> out.status == red) )
}
"""


def test_a_partial_answer_received_early_is_never_dropped_green(tmp_path: Path) -> None:
    """The live case study's race with an answer in two messages (the sensor's status and its
    `inspected`): green for the reading 300 is received 0.2 ms before the reading, its `done` after
    it, and the next reading follows.  Taken for the reading before (50), green is a partial answer
    right so far; the reading 300's own answer lacks the status.  Before, both questions ended with
    no verdict and the run read discharged; the early status completes the reading 300's answer
    within the skew, false there: inconclusive, with both questions named."""
    from rclverify.backends.monitors.backend import verdict_status
    from rclverify.lang.typecheck import load
    from rclverify.traces.events import Event
    p = tmp_path / "two.rcl"
    p.write_text(TWO_OUTPUTS)
    checked = load([p])
    field = {"r": "value", "status": "level", "done": "flag"}
    rows = [(0.0, "r", 50.0), (0.01, "status", "green"), (0.02, "done", True),  # answered in full
            (0.9, "r", 50.0), (1.0, "status", "green"), (1.0002, "r", 300.0), (1.001, "done", True),
            (1.5, "r", 60.0), (1.51, "status", "green"), (1.52, "done", True)]
    evs = [Event(k, t, topic, {field[topic]: v}, f"run.jsonl:{k + 1}") for k, (t, topic, v) in enumerate(rows)]

    def judged(skew: float) -> tuple[list[Any], Any]:
        got: list[Any] = []
        _, [res] = check_trace(checked, [checked.nodes["Sensor"]], iter(evs), skewed(skew), 1.0, got.append)
        return got, res
    got, res = judged(DEFAULT_SKEW_S)
    [v] = [x for x in got if x.event == 4]
    assert v.verdict == "inconclusive" and v.question == "run.jsonl:6" and "0.20 ms before" in v.reason
    assert v.values["in.r"] == "300.0" and v.values["out.status"] == "green"
    assert verdict_status(res, "run.jsonl")[0] == "inconclusive" and res.counts["satisfied"] == 2
    # without a skew the messages are in the order they were published: the early status answered the
    # reading before (50), the reading 300 got only its `done`, and the next reading superseded what it lacked
    got, res = judged(0.0)
    assert not [x for x in got if x.event in (4, 5, 6)] and verdict_status(res, "run.jsonl")[0] == "discharged"


_TWO_ROW = st.one_of(st.tuples(st.just("r"), st.sampled_from([50.0, 130.0, 300.0])),
                     st.tuples(st.just("status"), st.sampled_from(["green", "red", "orange"])),
                     st.tuples(st.just("done"), st.booleans()))


@settings(max_examples=80, deadline=None)
@given(st.lists(st.tuples(st.sampled_from([0.0, 0.0, 0.0001, 0.1, 0.3, 1.2]), _TWO_ROW), min_size=1, max_size=14))
def test_the_skew_never_turns_a_verdict_green_nor_red_with_answers_in_two_messages(tmp_path_factory: Any,
                                                                                     steps: list[Any]) -> None:
    """The property above on a guarantee that reads two outputs, so answers come in parts (partial
    answers, followed by newer questions, completed within the skew): with a skew of 0.3 s a
    question's verdicts are the same; an output's verdict is the same or became ``inconclusive``
    (never ``satisfied`` nor ``violated`` where it was not, unless it answered no question without
    the skew and is right for every question it may answer); and a run the skew leaves
    ``discharged`` was ``discharged`` without it."""
    from rclverify.backends.monitors.backend import verdict_status
    from rclverify.lang.typecheck import load
    from rclverify.traces.events import Event
    p = tmp_path_factory.mktemp("two") / "two.rcl"
    p.write_text(TWO_OUTPUTS)
    checked = load([p])
    field = {"r": "value", "status": "level", "done": "flag"}
    t, evs = 0.0, []
    for k, (dt, (topic, v)) in enumerate(steps):
        t += dt
        evs.append(Event(k, t, topic, {field[topic]: v}, f"run.jsonl:{k + 1}"))

    def judged(skew: float) -> tuple[dict[int, list[str]], str]:
        got: list[Any] = []
        _, [res] = check_trace(checked, [checked.nodes["Sensor"]], iter(evs), skewed(skew), 1.0, got.append)
        out: dict[int, list[str]] = {}
        for v in got:
            out.setdefault(v.event, []).append(v.verdict)
        return {k: sorted(x) for k, x in out.items()}, verdict_status(res, "run.jsonl")[0]
    (a, plain), (b, skewed_status) = judged(0.0), judged(0.3)
    for k in set(a) | set(b):
        if evs[k].topic == "r":
            assert a.get(k) == b.get(k), (k, a, b)
            continue
        before, after = a.get(k, []), b.get(k, [])
        assert "violated" not in after or "violated" in before, (k, before, after)
        assert "satisfied" not in after or "satisfied" in before or not before, (k, before, after)
    assert skewed_status != "discharged" or plain == "discharged", (plain, skewed_status)
