"""One meaning of steps: a step of a recorded run is a step of the composed system.

``always (Safety.in.stop -> eventually[<= 1] Base.out.wheels == 0)`` is
proved over two contracts that each answer at once
(``progress( within 0 steps )``): the stop is Safety's input at step i, its
halt Base's input at step i + 1, where Base answers with wheels zero.  On
the correct robot's run the wheels' zero comes two messages after the stop
(stop, halt, wheels) but one step of the system after it, and the run
satisfies what the contracts prove (docs/semantics.md, "Steps";
backends/monitors/trace_states.py, ``StepClock``).  Controls: counted in
messages the same run refutes it; a robot that ignores a halt is refuted
on its run, and the diagnosis names the run's step and values; the bound 0,
which the proof refutes, is refuted on the run too.  Real parser, Z3 and
pipeline.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.step_clock import StepClock, cone_of
from rclverify.cli.commands import main
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.traces.events import Event

RCL = """node Safety {
  inputs( stop : BOOL )
  outputs( halt : BOOL )
  topics( std_msgs/Bool stop matches(in.stop), std_msgs/Bool halt matches(out.halt) )
  guarantee( out.halt == in.stop )
  progress( within 0 steps )
}
node Base {
  inputs( halt : BOOL, speed : INTEGER )
  outputs( wheels : INTEGER )
  topics( std_msgs/Bool halt matches(in.halt), std_msgs/Int64 speed matches(in.speed),
          std_msgs/Int64 wheels matches(out.wheels) )
  assume( 0 <= in.speed and in.speed <= 10 )
  guarantee( in.halt -> out.wheels == 0 )
  guarantee( not in.halt -> out.wheels == in.speed )
  progress( within 0 steps )
}
"""
STOP = "always (Safety.in.stop -> eventually[<= {n}] Base.out.wheels == 0)"


def _run(ignores_halt: bool = False) -> list[dict[str, Any]]:
    """Every 100 ms the operator sends a stop (true on the 2nd and 4th rounds) and a speed 5 at once;
    Safety answers with the halt 5 ms later, Base with the wheels 5 ms after that (``ignores_halt``:
    Base keeps driving on the first halt)."""
    rows: list[dict[str, Any]] = []
    for i in range(5):
        t = 0.1 * i
        stop = i in (1, 3)
        wheels = 0 if stop and not (ignores_halt and i == 1) else 5
        rows += [{"topic": "stop", "time": round(t, 3), "data": stop},
                 {"topic": "speed", "time": round(t + 0.001, 3), "data": 5},
                 {"topic": "halt", "time": round(t + 0.005, 3), "data": stop},
                 {"topic": "wheels", "time": round(t + 0.01, 3), "data": wheels}]
    return rows


def _checked() -> Any:
    return check([parse_text(RCL, "r.rcl")])


def _events(rows: list[dict[str, Any]]) -> list[Event]:
    return [Event(k, r["time"], r["topic"], {"data": r["data"]}, f"run.jsonl:{k + 1}") for k, r in enumerate(rows)]


def test_an_answer_is_in_its_questions_step_and_its_reader_takes_it_the_step_after() -> None:
    c = _checked()
    assert cone_of(c, ["Base"]) == ["Safety", "Base"] and cone_of(c, ["Safety"]) == ["Safety"]
    clock = StepClock(c, ["Safety", "Base"], skew=0.02)
    got = [clock.tick(ev) for ev in _events(_run())[:8]]
    # stop and speed (one instant), the halt answering the stop: step 0; Base reads the halt at step 1 and
    # answers there; the next stop, Safety's next input, is step 1 as well (every node takes one input a step)
    assert [g[0] for g in got if g is not None] == [0, 0, 0, 1, 1, 1, 1, 2]
    assert got[2] == (0, frozenset({"Base"}))  # the halt is Base's input from the next step on
    # control: two messages on one topic are two steps, even at once; another topic at once is one step
    clock = StepClock(c, ["Base"], skew=0.02)
    evs = [Event(0, 0.0, "speed", {"data": 1}, "r:1"), Event(1, 0.001, "speed", {"data": 2}, "r:2"),
           Event(2, 0.002, "halt", {"data": True}, "r:3"), Event(3, 0.2, "halt", {"data": False}, "r:4")]
    assert [g[0] for g in (clock.tick(ev) for ev in evs) if g is not None] == [0, 1, 1, 2]
    # a second output of a node in one step opens the next; a topic of no node of the clock is no step
    clock = StepClock(c, ["Safety"])
    evs = [Event(0, 0.0, "halt", {"data": True}, "r:1"), Event(1, 0.1, "halt", {"data": False}, "r:2"),
           Event(2, 0.2, "wheels", {"data": 1}, "r:3")]
    assert [clock.tick(ev) for ev in evs] == [(0, frozenset()), (1, frozenset()), None]


PLAN = """contracts: [contracts/r.rcl]
nodes:
  Safety:
    evidence:
      - backend: monitors
        mapping: mapping.yaml
        traces: [traces/run.jsonl]
  Base:
    evidence:
      - backend: monitors
        mapping: mapping.yaml
        traces: [traces/run.jsonl]
requirements:
  - id: STOP
    text: the wheels stop within one step of a stop
    formal: "{formal}"
"""


def _verify(root: Path, n: int, ignores_halt: bool = False) -> tuple[dict[str, Any], Path]:
    ws = root / f"ws{n}{'-faulty' if ignores_halt else ''}"
    (ws / "contracts").mkdir(parents=True)
    (ws / "traces").mkdir()
    (ws / "contracts/r.rcl").write_text(RCL)
    (ws / "contracts/plan.yaml").write_text(PLAN.format(formal=STOP.format(n=n)))
    (ws / "mapping.yaml").write_text("topics: {}\n")
    (ws / "traces/run.jsonl").write_text("".join(json.dumps(r) + "\n" for r in _run(ignores_halt)))
    main(["verify", "-w", str(ws)])
    report = json.loads((ws / "reports/assurance.json").read_text())
    return next(r for r in report["requirements"] if r["id"] == "STOP"), ws


@pytest.fixture(scope="module")
def verified(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[dict[str, Any], Path]]:
    root = tmp_path_factory.mktemp("steps")
    return {"correct": _verify(root, 1), "faulty": _verify(root, 1, True), "bound0": _verify(root, 0)}


def test_a_correct_run_satisfies_what_the_contracts_prove(verified: Any) -> None:
    req, _ = verified["correct"]
    assert req["check"]["temporal"]["status"] in ("proved", "met"), req["check"]["temporal"]
    [row] = req["check"]["traces"]
    assert (row["status"], row["verdict"]["verdict"]) == ("discharged", "true"), row["verdict"]["reason"]
    # 20 messages in five rounds: each round's stop and speed are one step with the halt, the wheels the next
    assert row["verdict"]["steps"] == 6
    assert req["verdict"] != "refuted", req["note"]


def test_counted_in_messages_the_same_run_would_refute_it() -> None:
    """The control: the same run read message by message (each message a step, the latest values its
    state) refutes the bound 1: the speed and the halt come between the stop and the wheels' zero."""
    from rclverify.backends.monitors.response_trace import ResponseTracker
    tracker, values = ResponseTracker(1), {}
    said = None
    for i, row in enumerate(_run()):
        values[row["topic"]] = row["data"]
        said = tracker.step(i, values.get("stop") is True, values.get("wheels") == 0)
        if said is not None:
            break
    assert said == ("false", 4)  # the stop of message 5 is not answered by the message after it


def test_a_robot_that_ignores_a_halt_is_refuted_on_its_run_and_the_diagnosis_names_it(verified: Any) -> None:
    req, ws = verified["faulty"]
    [row] = req["check"]["traces"]
    v = row["verdict"]
    assert (row["status"], v["verdict"], v["step"], v["where"]) == ("failed", "false", 2, "run.jsonl:11"), v
    assert req["verdict"] == "refuted" and "run.jsonl refutes it" in req["note"]
    diag = json.loads((ws / "artifacts/diagnosis/index.json").read_text())
    [d] = [d for d in diag["diagnoses"] if d["id"] == "STOP"]
    s = d["sentence"]
    assert "a run of 0 states" not in s and "The state it repeats: ." not in s, s
    assert "refuted by the recorded run traces/run.jsonl at step 2 of the run (run.jsonl:11, t = 0.205 s)" in s, s
    assert "Base.out.wheels == 0 is false at step 2 (run.jsonl:11) with Base.out.wheels = 5" in s, s
    assert "Over the composed contracts it is proved" in s, s
    assert {(r["node"], r["variable"], r["value"]) for r in d["counterexample"]} == {("Base", "out.wheels", "5")}


def test_the_bound_the_proof_refutes_is_refuted_on_the_run(verified: Any) -> None:
    req, _ = verified["bound0"]
    assert req["check"]["temporal"]["status"] == "refuted"
    [row] = req["check"]["traces"]
    assert row["verdict"]["verdict"] == "false" and row["verdict"]["step"] == 1, row["verdict"]


def test_a_live_logs_calls_are_steps_of_a_temporal_requirement() -> None:
    """The ros2_robot example's live log carries the e-stop's calls as call lines: each request and its
    response are one step, read with the link's mapping (before: no message on EStop's topics, nothing
    checked).  The control: a statement the answers break is false at the first engaged answer."""
    from rclverify.backends.monitors.config import load_mapping
    from rclverify.backends.monitors.temporal_trace import check_temporal_trace
    from rclverify.model.plan.formal import Source
    from rclverify.model.plan.temporal import parse_temporal
    from rclverify.traces import read_trace
    robot = Path(__file__).resolve().parents[2] / "examples" / "ros2_robot"
    c = check([parse_text((robot / "contracts/robot.rcl").read_text(), "robot.rcl")])
    cfg = load_mapping(robot, "contracts/mapping.yaml")

    def verdict(formal: str) -> Any:
        t = parse_temporal(Source(formal, 1, 1, "plan.yaml"), c, "T", {})
        return check_temporal_trace(t, c, (), read_trace(robot / "runs/robot.jsonl"), cfg.rules)
    ok = verdict("always EStop.out.engaged == EStop.in.engage")
    assert ok.verdict == "true" and ok.steps == 3, ok.reason  # three calls, each request and response one step
    bad = verdict("always not EStop.out.engaged")
    assert (bad.verdict, bad.step, bad.witness[0]["values"]) == ("false", 0, {"EStop.out.engaged": "TRUE"}), bad
    line = json.loads((robot / "runs/robot.jsonl").read_text().splitlines()[int(bad.where.rsplit(":", 1)[1]) - 1])
    assert (line["topic"], line["link"], line["part"], line["fields"]["success"]) == (
        "rclverify/call", "estop", "response", True)


def test_a_refuted_run_is_never_worded_as_a_run_of_no_state() -> None:
    """A temporal record that kept no state names none (the sentence the run-refuted requirement used to
    get: "a run of 0 states ... The state it repeats: ."); the control: one that kept its states names
    them, a loop as the state it repeats, a run that stops by its last state."""
    from rclverify.diagnosis.requirement import _temporal_record
    from rclverify.records.requirement_check import RequirementCheckRow

    def sentence(trace: list[Any], loop: Any) -> str:
        check = {"formal": "eventually A.out.y", "source": "plan.yaml:1:1",
                 "temporal": {"trace": trace, "loop": loop, "method": "bmc", "detail": "k = 3"}}
        return _temporal_record("R", RequirementCheckRow.of(check), lambda: []).sentence
    empty = sentence([], None)
    assert "0 states" not in empty and "The state it repeats" not in empty and "state: ." not in empty, empty
    states = [{"nodes": [{"node": "A", "values": {"out.y": "false"}}]}] * 2
    assert "a run of 2 states whose last returns to step 0" in sentence(states, 0)
    assert "The state it repeats: A.out.y = false" in sentence(states, 0)
    assert "Its last state: A.out.y = false" in sentence(states, None)
