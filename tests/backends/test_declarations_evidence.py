"""A declaration judged on a run is never ``discharged`` while it is pending or undecided.

The declarations' verdicts fold into the node's evidence by the rule of
docs/semantics.md, "Verdicts and evidence" (any violated -> failed; any
inconclusive or open -> inconclusive; nothing satisfied -> pending; else
discharged): a ``progress`` left pending beside 30 satisfied answers keeps
the record ``inconclusive``, named in its explanation.  A step is an input
event the contract reads, a quantifier's domain included
(``exists(r in in.ranges | ...)``), and a call part of a live run's log is
the event of its link's part.  Real parser, real Z3, the real pipeline.
"""
from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.declarations import (DeclarationResult, check_declarations, declaration_status,
                                                      with_declarations)
from rclverify.cli.commands import main
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.traces.events import Event

GUARD = """node Guard {
  inputs( ranges : seq(REAL) )
  outputs( stop : BOOL )
  topics( sensor_msgs/LaserScan scan matches(in.ranges), std_msgs/Bool stop matches(out.stop) )
  assume( exists(r in in.ranges | 0 <= r) and forall(r in in.ranges | 0 <= r and r <= 30) )
  guarantee( out.stop <=> exists(r in in.ranges | r < 0.5) )
  progress( within 0 steps )
}
"""
ESTOP = """node EStop {
  inputs( engage : BOOL )
  outputs( engaged : BOOL )
  services( std_srvs/SetBool estop serves(in.engage, out.engaged) )
  assume( TRUE )
  guarantee( out.engaged == in.engage )
  progress( within 0 steps )
}
"""


def _guard_run(answers: int, last_answered: bool = True) -> list[dict[str, Any]]:
    """``answers`` scans each followed by its stop 5 ms later; the last scan unanswered unless ``last_answered``."""
    rows: list[dict[str, Any]] = [{"topic": "stop", "time": 0.0, "data": False}]
    for i in range(answers):
        t = 0.1 * (i + 1)
        near = i % 3 == 0
        rows.append({"topic": "scan", "time": round(t, 3), "ranges": [0.3 if near else 2.0, 4.0]})
        if last_answered or i < answers - 1:
            rows.append({"topic": "stop", "time": round(t + 0.005, 3), "data": near})
    return rows


def _events(rows: list[dict[str, Any]]) -> list[Event]:
    return [Event(i, r["time"], r["topic"], {k: v for k, v in r.items() if k not in ("topic", "time")},
                  f"run.jsonl:{i + 1}") for i, r in enumerate(rows)]


def test_an_input_read_only_in_a_quantifier_domain_is_a_step() -> None:
    """The laser's ranges are read only as the domain of ``exists``/``forall``: each scan is a step (before:
    no step at all, and ``progress`` read pending beside 30 satisfied answers).  Control: a scan left
    unanswered before the next breaks ``within 0 steps``."""
    c = check([parse_text(GUARD, "g.rcl")])
    node = c.nodes["Guard"]
    [row] = check_declarations(c, node, _events(_guard_run(30)), {}).rows()
    assert (row["verdict"], row["status"]) == ("true", "discharged"), row["reason"]
    assert row["reason"].startswith("30 accepted input events")
    rows = _guard_run(3)
    del rows[2]  # the first scan's stop: the second scan comes with the first unanswered
    [row] = check_declarations(c, node, _events(rows), {}).rows()
    assert row["verdict"] == "false" and "between the input at run.jsonl:2 and the input at run.jsonl:3" in row["reason"]


def test_a_call_line_of_a_live_log_is_its_parts_event() -> None:
    """A live run's log carries a service's request and response as call lines
    (``rclverify/call``): they are the node's steps and answers (before: pending, no input event).
    Control: a second request before the first's response breaks ``within 0 steps``."""
    c = check([parse_text(ESTOP, "e.rcl")])
    node = c.nodes["EStop"]

    def line(i: int, part: str, fields: dict[str, Any], **kw: Any) -> Event:
        return Event(i, 0.1 * i, "rclverify/call", {"kind": "call", "link": "estop", "part": part, "key": ["w", "a", i],
                                                    "fields": fields, **kw}, f"estop call #{i} {part}")
    answered = [line(0, "request", {"data": True}), line(1, "response", {"success": True}),
                line(2, "request", {"data": False}), line(3, "response", {"success": False}),
                line(4, "tick", {})]
    [row] = check_declarations(c, node, answered, {}).rows()
    assert row["verdict"] == "true" and row["reason"].startswith("2 accepted input events"), row["reason"]
    late = [answered[0], answered[1], answered[2], line(3, "request", {"data": True}, also=False),
            line(5, "response", {"success": True})]
    [row] = check_declarations(c, node, late, {}).rows()
    assert row["verdict"] == "false" and "estop call #2 request" in row["reason"], row["reason"]
    [row] = check_declarations(c, node, [], {}).rows()
    assert row["verdict"] == "pending" and "no input event of in.engage was read" in row["reason"]


def _res(*verdicts: tuple[str, str]) -> DeclarationResult:
    res = DeclarationResult("Guard")
    for k, (verdict, premise) in enumerate(verdicts):
        res.declarations.append({"declaration": f"d{k}", "premise": premise, "index": 0, "source": f"g.rcl:{k}:3",
                                 "text": f"decl {k}", "verdict": verdict, "status": "", "reason": f"why {k}"})
    return res


@pytest.mark.parametrize("verdicts, status", [
    ((("true", "progress"), ("true", "initial value")), "discharged"),
    ((("true", "progress"), ("pending", "initial value")), "inconclusive"),
    ((("true", "progress"), ("inconclusive", "progress")), "inconclusive"),
    ((("pending", "progress"), ("pending", "initial value")), "pending"),
    ((("inconclusive", "progress"),), "inconclusive"),
    ((("true", "progress"), ("false", ""), ("pending", "progress")), "failed"),
    ((("false", "progress"), ("inconclusive", "progress")), "failed"),
], ids=["all-held", "one-pending", "one-undecided", "none-judged", "undecided-alone", "late-period", "false"])
def test_the_declarations_status_follows_the_rule_of_evidence(verdicts: Any, status: str) -> None:
    got, words = declaration_status(_res(*verdicts), "run.jsonl")
    assert got == status, words
    if status in ("inconclusive", "pending"):
        assert "not decided: " in words and "why" in words  # the reason is said


def test_an_initial_value_no_run_can_show_is_named_apart() -> None:
    """An ``initially`` whose first published value came after an input is the property tests' to show:
    it leaves the record as the other rows make it, and is named; the control: the same row when the run
    could have shown it keeps the record from discharged."""
    res = _res(("true", "progress"), ("inconclusive", "initial value"))
    res.unobservable.add("d1")
    got, words, _ = with_declarations(res, "run.jsonl", "discharged", "ok")
    assert got == "discharged" and "not shown by a run" in words and "decl 1: inconclusive (why 1)" in words
    assert declaration_status(res, "run.jsonl")[0] == "discharged"
    res.unobservable.clear()
    assert with_declarations(res, "run.jsonl", "discharged", "ok")[0] == "inconclusive"
    only = _res(("inconclusive", "initial value"))
    only.unobservable.add("d0")
    assert with_declarations(only, "run.jsonl", "discharged", "ok")[0] == "discharged"
    assert with_declarations(only, "run.jsonl", "pending", "ok")[0] == "pending"


@pytest.mark.parametrize("record, verdicts, status", [
    ("discharged", (("true", "progress"),), "discharged"),
    ("discharged", (("pending", "progress"),), "inconclusive"),
    ("discharged", (("inconclusive", "progress"),), "inconclusive"),
    ("pending", (("pending", "progress"),), "pending"),
    ("pending", (("inconclusive", "progress"),), "inconclusive"),
    ("discharged", (("false", "progress"),), "failed"),
    ("failed", (("pending", "progress"),), "failed"),
    ("error", (("true", "progress"),), "error"),
], ids=["held", "pending", "undecided", "nothing-judged", "pending-record-undecided", "false", "failed-stands",
        "error-stands"])
def test_a_declaration_not_decided_keeps_the_record_from_discharged(record: str, verdicts: Any, status: str) -> None:
    got, words, part = with_declarations(_res(*verdicts), "run.jsonl", record, "the guarantees' words")
    assert got == status, words
    assert "the guarantees' words" in words and len(part["declarations"]) == len(verdicts)
    if record == "discharged" and status == "inconclusive":
        assert "a declaration is not decided on this run" in words and "why 0" in words


PLAN = """contracts: [contracts/g.rcl]
nodes:
  Guard:
    evidence:
      - backend: monitors
        traces: [traces/run.jsonl]
"""


@pytest.mark.parametrize("decl, last_answered, status, words", [
    ("progress( within 0 steps )", True, "discharged", "held: progress( within 0 steps )"),
    ("progress( eventually )", False, "inconclusive", "the run ends with the accepted input at run.jsonl:60"),
    ("initially( out.stop == FALSE )\n  progress( within 0 steps )", True, "discharged",
     "held: initially( out.stop == FALSE ), progress( within 0 steps )"),
    ("initially( out.stop == TRUE )\n  progress( within 0 steps )", True, "failed",
     "Guard declares initially( out.stop == TRUE )"),
    ("initially( out.stop == FALSE )\n  progress( within 0 steps )", "after input", "discharged",
     "not shown by a run (its first published value answers an input; the property tests show it): "
     "initially( out.stop == FALSE ): inconclusive"),
], ids=["held", "eventually-open", "initial-value-held", "initial-value-wrong", "initial-value-after-input"])
def test_the_record_of_a_run_follows_its_declarations(tmp_path: Path, decl: str, last_answered: Any, status: str,
                                                      words: str) -> None:
    """30 answers satisfied on the run: the record is discharged only when the declarations held too
    (before: ``discharged`` with the progress pending).  An ``initially`` no run can show (the node's
    first message comes after an input: it may be the answer) is named apart and left to the property
    tests (docs/monitors.md, "Declarations on recorded and live runs"); one the run shows decides."""
    ws = tmp_path / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "traces").mkdir()
    (ws / "contracts/g.rcl").write_text(GUARD.replace("progress( within 0 steps )", decl))
    (ws / "contracts/plan.yaml").write_text(PLAN)
    rows = _guard_run(30, last_answered is not False)
    if last_answered == "after input":
        rows = rows[1:]  # the first stop after the first scan: an answer, not the value it starts from
    (ws / "traces/run.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    # the monitors backend on the workspace's obligation, as the pipeline's evidence task runs it
    from rclverify.app.pipeline import Workspace
    from rclverify.backends.monitors.backend import MonitorsBackend
    target = Workspace(ws).target("Guard", 0)
    backend = MonitorsBackend()
    ev = backend.run(backend.export(target)[0], target).to_json()
    assert ev["status"] == status and words in ev["explanation"], ev["explanation"]
    assert ev["details"]["monitoring"]["counts"]["satisfied"] >= 29


ROBOT = Path(__file__).resolve().parents[2] / "examples" / "ros2_robot"


def test_the_recorded_robot_run_judges_progress_on_topics_and_calls(tmp_path: Path, capsys: Any) -> None:
    """The ros2_robot example's live log (rclpy nodes over Fast DDS), its contracts given a ``progress`` each
    on a copy: the scan guard's (its ranges read in a quantifier's domain), the e-stop's (a service) and the
    dock's (an action) are judged on the log (before: pending, no input event, beside 6, 3 and 11
    satisfied answers).  The control: the bag of the same run carries the calls as ROS 2 records them,
    which the declarations do not read: pending there, with the reason, never discharged."""
    ws = tmp_path / "robot"
    shutil.copytree(ROBOT / "contracts", ws / "contracts")
    shutil.copytree(ROBOT / "runs", ws / "runs")
    shutil.copytree(ROBOT / "interfaces", ws / "interfaces")
    rcl = ws / "contracts/robot.rcl"
    text = rcl.read_text()
    for end, decl in (("triggered by in.ranges within 100 ms\n}", "progress( within 0 steps )"),
                      ("triggered by in.engage within 200 ms\n}", "progress( within 0 steps )"),
                      ("out.final <= 0.05 )\n}", "progress( eventually )")):
        assert end in text
        text = text.replace(end, end[:-1] + f"  {decl}\n}}")
    rcl.write_text(text)

    def judged(trace: str) -> dict[str, dict[str, Any]]:
        main(["monitor", "-w", str(ws), "--mapping", "contracts/mapping.yaml", "--json", str(ws / trace)])
        return {e["node"]: e for e in json.loads(capsys.readouterr().out) if "declarations" in e}
    log = judged("runs/robot.jsonl")
    for node, text_ in (("ScanGuard", "progress( within 0 steps )"), ("EStop", "progress( within 0 steps )"),
                        ("Dock", "progress( eventually )")):
        [row] = log[node]["declarations"]
        assert (row["text"], row["verdict"], log[node]["status"]) == (text_, "true", "discharged"), row["reason"]
    bag = judged("runs/robot")
    assert bag["ScanGuard"]["status"] == "discharged"
    [row] = bag["EStop"]["declarations"]
    assert (row["verdict"], bag["EStop"]["status"]) == ("pending", "pending")
    assert "no input event of in.engage was read" in row["reason"]
