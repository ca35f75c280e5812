"""A question's guarantees are not evaluated on its inputs alone where Z3
shows that only an answer decides them (backends/monitors/needs_answer.py):
a speed fact that must never change a verdict.  Checked on random traces
(with NaN, infinite and out-of-band readings, late, missing and wrong
answers) against the same engine evaluating every question."""
from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings, strategies as st

from rclverify.backends.monitors.check import NodeMonitor, check_trace
from rclverify.backends.monitors.needs_answer import answer_decides
from rclverify.lang.typecheck import load
from rclverify.traces.events import Event
from rclverify.traces.mapping import load_rules

HEAD = """
context { Band : {green, orange, red} ; }
node Classifier {
  inputs( r : REAL %s)
  outputs( status : Band )
  topics( pkg/Reading r matches(in.r), pkg/Status status matches(out.status) %s)
  assume( %s )
  guarantee( %s )
}
"""
BANDS = ("(in.r < 120 -> out.status == green) and (120 <= in.r and in.r < 250 -> out.status == orange) "
         "and (250 <= in.r -> out.status == red)")


def _load(tmp: Path, name: str, guarantee: str, assume: str = "TRUE", extra: str = "", topics: str = "") -> Any:
    p = tmp / f"{name}.rcl"
    p.write_text(HEAD % (extra, topics, assume, guarantee))
    return load([p])


@pytest.fixture(scope="module")
def systems(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    tmp = tmp_path_factory.mktemp("needs")
    return {
        "bands": _load(tmp, "bands", BANDS, "0 <= in.r"),
        # r < 0 makes every premise false: the inputs alone decide it (true)
        "gap": _load(tmp, "gap", "(0 <= in.r and in.r < 120 -> out.status == green) and (120 <= in.r -> out.status == red)"),
        # a switch off decides it without an answer
        "switch": _load(tmp, "switch", "in.on -> " + f"({BANDS})", extra=", on : BOOL ",
                        topics=", pkg/Switch on matches(in.on) "),
        # false on the inputs alone where r > 1000
        "bounded": _load(tmp, "bounded", f"in.r <= 1000 and ({BANDS})"),
    }


def test_z3_tells_which_guarantees_only_an_answer_decides(systems: dict[str, Any]) -> None:
    node = {k: c.nodes["Classifier"] for k, c in systems.items()}
    decides = {k: answer_decides(c, node[k], [g.formula for g in node[k].node.guarantees]) for k, c in systems.items()}
    assert decides == {"bands": True, "gap": False, "switch": False, "bounded": False}
    mon = NodeMonitor(systems["bands"], node["bands"], {}, 1.0)
    assert mon._ask_at_question is False
    assert NodeMonitor(systems["gap"], node["gap"], {}, 1.0)._ask_at_question is True


def _fields(topic: str, v: Any) -> dict[str, Any]:
    return {"r": {"value": v}, "on": {"flag": v}, "status": {"level": v}}[topic]


def _verdicts(checked: Any, rows: list[tuple[float, str, Any]], ask: bool | None, skew: float) -> list[tuple[Any, ...]]:
    got: list[Any] = []
    original = NodeMonitor.__init__

    def init(self: NodeMonitor, *a: Any, **k: Any) -> None:
        original(self, *a, **k)
        if ask is not None:
            self._ask_at_question = ask
    rules = load_rules({"status": {}})
    rules.skew = skew
    NodeMonitor.__init__ = init  # type: ignore[method-assign]
    try:
        events = [Event(k, t, topic, _fields(topic, v), f"run.jsonl:{k + 1}") for k, (t, topic, v) in enumerate(rows)]
        check_trace(checked, [checked.nodes["Classifier"]], events, rules, 0.5, got.append)
    finally:
        NodeMonitor.__init__ = original  # type: ignore[method-assign]
    return [(v.event, v.verdict, v.guarantee, v.decided_at, tuple(sorted(v.values.items())), v.reason) for v in got]


READING = st.sampled_from([50.0, 119.0, 120.0, 200.0, 250.0, 300.0, -5.0, 1500.0,
                           float("nan"), float("inf"), float("-inf")])
ROW = st.one_of(st.tuples(st.just("r"), READING), st.tuples(st.just("status"), st.sampled_from(["green", "orange", "red"])),
                st.tuples(st.just("on"), st.booleans()))


@settings(max_examples=80, deadline=None)
@given(st.sampled_from(["bands", "gap", "switch", "bounded"]),
       st.lists(st.tuples(st.sampled_from([0.0, 0.0, 0.01, 0.2, 0.7]), ROW), min_size=1, max_size=14),
       st.sampled_from([0.0, 0.02]))
def test_skipping_the_question_time_evaluation_changes_no_verdict(systems: dict[str, Any], name: str,
                                                                  steps: list[Any], skew: float) -> None:
    checked = systems[name]
    t, rows = 0.0, []
    for dt, (topic, v) in steps:
        if topic == "on" and name != "switch":
            continue
        t += dt
        rows.append((t, topic, v))
    if not rows:
        return
    assert _verdicts(checked, rows, None, skew) == _verdicts(checked, rows, True, skew)
