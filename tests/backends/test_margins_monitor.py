"""Space margins on recorded runs (backends/monitors: check.py, judging.py, verdicts.py, summary.py).

Every output verdict a run judged with margins carries its message's margin
(the least of its guarantees'), each node's result the smallest margin of
every guarantee with the message and the time; ``rclverify monitor --json``
and the evidence details show them.  The hand-computed run below fixes the
figures; on random runs every ``satisfied`` verdict has a margin >= 0 and
every ``violated`` one <= 0.  Controls: judged without margins, the verdicts
and the result are the same and carry none; a margin computed with the
guarantee's comparison turned round is caught by the figures.
"""
from __future__ import annotations

import json
import random
import shutil
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.check import check_trace
from rclverify.backends.monitors.summary import monitoring_details
from rclverify.cli.commands import main
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.semantics import robustness
from rclverify.traces.events import Event
from rclverify.traces.mapping import load_rules

REPO = Path(__file__).resolve().parents[2]
CONTRACT = """
node Stop {
  inputs( r : REAL [m] )
  outputs( d : REAL [m], v : REAL [m/s] )
  topics( std_msgs/Float64 range matches(in.r), std_msgs/Float64 dist matches(out.d),
          std_msgs/Float64 speed matches(out.v) )
  guarantee( out.d <= in.r - 0.5 )
  guarantee( out.v <= 2 )
}
"""
CHECKED = check([parse_text(CONTRACT)])
NODE = CHECKED.nodes["Stop"]
RULES = load_rules({"range": {"fields": ["data"]}, "dist": {"fields": ["data"]}, "speed": {"fields": ["data"]}})


def _events(script: list[tuple[float, str, float]]) -> list[Event]:
    return [Event(i, t, topic, {"data": v}, f"run.jsonl:{i + 1}") for i, (t, topic, v) in enumerate(script)]


#: a range of 3 m answered 2 m (0.5 m to spare), a speed of 1.5 m/s (0.5 m/s); 2 m answered 1.75 m (0.25 m too
#: close); 5 m answered 4 m (0.5 m) with 1.9 m/s (0.1 m/s)
SCRIPT = [(1.0, "range", 3.0), (1.01, "dist", 2.0), (1.02, "speed", 1.5), (2.0, "range", 2.0), (2.01, "dist", 1.75),
          (3.0, "range", 5.0), (3.01, "dist", 4.0), (3.02, "speed", 1.9)]


def _run(margins: bool, script: list[tuple[float, str, float]] = SCRIPT) -> tuple[Any, list[Any]]:
    seen: list[Any] = []
    _, (res,) = check_trace(CHECKED, [NODE], iter(_events(script)), RULES, 0.5, seen.append, margins=margins)
    return res, seen


def test_each_answer_carries_its_margin() -> None:
    res, seen = _run(True)
    got = [(v.where, v.verdict, v.margin) for v in seen if v.verdict in ("satisfied", "violated")]
    assert got == [("run.jsonl:2", "satisfied", 0.5), ("run.jsonl:3", "satisfied", 0.5),
                   ("run.jsonl:5", "violated", -0.25), ("run.jsonl:7", "satisfied", 0.5),
                   ("run.jsonl:8", "satisfied", pytest.approx(0.1))]
    assert json.loads(json.dumps(seen[2].to_json()))["margin"] == -0.25


def test_smallest_margin_per_guarantee() -> None:
    res, _ = _run(True)
    one, two = res.margins[1], res.margins[2]
    assert (one.value, one.unit, one.atom, one.where, one.time, one.question, one.answers) == \
        (-0.25, "m", "out.d <= in.r - 0.5", "run.jsonl:5", 2.01, "run.jsonl:4", 3)
    assert (two.value, two.unit, two.where, two.time, two.answers) == (pytest.approx(0.1), "m/s", "run.jsonl:8", 3.02, 2)
    details = monitoring_details(res, "run.jsonl", 8, "", "", 0.5)
    assert [(m["guarantee"], m["margin"], m["trace"], m["holds"]) for m in details["margins"]] == \
        [(1, -0.25, "run.jsonl", None), (2, pytest.approx(0.1), "run.jsonl", None)]  # holds: an infinite one's


def test_control_without_margins_same_verdicts_none_carried() -> None:
    with_m, seen_m = _run(True)
    without, seen = _run(False)
    assert with_m == without and not without.margins
    assert [(v.where, v.verdict) for v in seen] == [(v.where, v.verdict) for v in seen_m]
    assert all(v.margin is None for v in seen) and "margin" not in seen[1].to_json()


def test_a_guarantee_without_margins_says_so() -> None:
    """A quantifier over REAL has no margin: the guarantee is listed with none, its answers counted undefined."""
    checked = check([parse_text(CONTRACT.replace("guarantee( out.v <= 2 )",
                                                 "guarantee( forall(x in REAL | x > out.v -> x > 1) )"))])
    _, (res,) = check_trace(checked, [checked.nodes["Stop"]], iter(_events(SCRIPT)), RULES, 0.5, margins=True)
    two = next(m for m in res.margins_json() if m["guarantee"] == 2)
    assert (two["margin"], two["holds"], two["answers"], two["undefined"]) == (None, None, 0, 2)


def test_control_a_turned_comparison_gives_other_figures(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(robustness._Margins, "distance", lambda self, op, x, y: self.diff(x, y))
    res, seen = _run(True)
    assert res.margins[1].value != -0.25
    assert [v.margin for v in seen if v.verdict == "satisfied"][0] != 0.5


def test_sign_agrees_with_every_verdict_on_random_runs() -> None:
    rnd = random.Random(98)
    judged = 0
    for _ in range(30):
        script: list[tuple[float, str, float]] = []
        t = 0.0
        for _ in range(rnd.randint(3, 25)):
            t += rnd.choice([0.01, 0.1, 0.3])
            r = rnd.choice([rnd.uniform(0, 5), 2.5, 0.5])
            script.append((t, "range", r))
            d = rnd.choice([r - 0.5, r - 0.5 + rnd.uniform(-0.3, 0.3), rnd.uniform(0, 5)])
            script.append((t + rnd.choice([0.0, 0.005, 0.2]), "dist", d))
            if rnd.random() < 0.6:
                script.append((t + 0.006, "speed", rnd.choice([2.0, rnd.uniform(0, 3)])))
        script.sort(key=lambda x: x[0])
        res, seen = _run(True, script)
        for v in seen:
            if v.verdict == "satisfied":
                judged += 1
                assert v.margin is not None and v.margin >= 0, v
            elif v.verdict == "violated" and v.margin is not None:
                judged += 1
                assert v.margin <= 0, v
        carried = [v.margin for v in seen if v.margin is not None]
        if carried:  # the least over the guarantees is the least over the messages
            assert min(m.value for m in res.margins.values() if m.answers) == min(carried)
        assert all(m.undefined == 0 for m in res.margins.values())
        assert res == _run(False, script)[0]
    assert judged > 100


def test_monitor_json_names_the_smallest_margin(capsys: pytest.CaptureFixture[str]) -> None:
    ws = REPO / "examples" / "safety_stop"
    rc = main(["monitor", "-w", str(ws), "--json", str(ws / "traces" / "late_stop.jsonl")])
    report = json.loads(capsys.readouterr().out)
    mover = next(e for e in report if e["node"] == "Mover" and "margins" in e)
    first = mover["margins"][0]
    assert rc == 1
    assert (first["formula"], first["margin"], first["where"], first["time"]) == \
        ("out.progress >= 0", -1.0, "late_stop.jsonl:12", 8.5)
    assert first["trace"].endswith("late_stop.jsonl")


def test_evidence_records_carry_both_margins(tmp_path: Path) -> None:
    """`verify` on the safety-stop example with its late run: Base's evidence names the smallest space
    margin of its untimed check and the time margin of its deadline (150 ms late), Mover's both too."""
    ws = tmp_path / "ws"
    shutil.copytree(REPO / "examples" / "safety_stop", ws, ignore=shutil.ignore_patterns("artifacts", "reports",
                                                                                         "__pycache__"))
    plan = ws / "contracts" / "plan.yaml"
    plan.write_text(plan.read_text().replace("traces: [traces/nominal.jsonl]\n  Mover",
                                             "traces: [traces/late_stop.jsonl]\n  Mover"))
    main(["verify", "-w", str(ws)])
    base = json.loads((ws / "artifacts" / "evidence" / "Base.g0.monitors.late_stop_jsonl.json").read_text())
    (space,) = base["details"]["monitoring"]["margins"]
    assert (space["formula"], space["margin"], space["holds"], space["trace"]) == \
        ("in.stop_req -> out.stopped", None, True, "traces/late_stop.jsonl")  # BOOL atoms: no distance
    (time_,) = base["details"]["deadlines"]["time_margins"]
    assert (time_["margin_ns"], time_["answer_where"], time_["answers"]) == (-150_000_000, "late_stop.jsonl:5", 2)
    mover = json.loads((ws / "artifacts" / "evidence" / "Mover.g0.monitors.nominal_jsonl.json").read_text())
    assert [m["guarantee"] for m in mover["details"]["monitoring"]["margins"]] == [1, 2]
    assert mover["details"]["deadlines"]["time_margins"][0]["margin"] > 0
