"""A recorded run is user input: whatever it holds, the monitor answers with
verdicts or one located error, never a traceback (issue 23).

Covers the crash of an input arriving before the node's first REAL output,
mutated and truncated runs (missing fields, wrong types, NaN, out-of-order
times, unknown topics, an empty file, truncated lines) fed to
``rclverify monitor`` and to the online engine, a large run generated
lazily, and ``doit verify`` with a bad trace still writing its report.
"""
from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path
from typing import Any, Iterator

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rclverify.backends.monitors.check import NodeMonitor, check_trace
from rclverify.backends.monitors.config import load_mapping
from rclverify.backends.monitors.late import WITHDRAWN
from rclverify.cli.commands import main
from rclverify.lang.typecheck import load
from rclverify.traces import TraceError, read_trace
from rclverify.traces.events import Event
from rclverify.traces.mapping import TopicRule

REPO = Path(__file__).resolve().parents[2]
TRACES = REPO / "backends" / "monitors" / "traces"
MSG = [REPO / "backends" / "monitors" / "msg"]

CRUISE = """\
node Cruise {
  inputs( distance : REAL )
  outputs( speed : REAL )
  topics( std_msgs/Float64 distance matches(in.distance),
          std_msgs/Float64 speed_cmd matches(out.speed) )
  assume( 0 <= in.distance )
  guarantee( in.distance < 1 -> out.speed <= 0.1 )
}
"""

PLAN = """\
name: cruise
contracts: [contracts/cruise.rcl]
nodes:
  Cruise:
    evidence:
      - backend: monitors
        horizon: 1.0
        traces: [backends/monitors/two_lines.jsonl, backends/monitors/bad.jsonl]
"""

TWO_LINES = ('{"topic": "distance", "time": 0.0, "data": 0.5}\n'
             '{"topic": "speed_cmd", "time": 0.1, "data": 0.05}\n')


@pytest.fixture(scope="module")
def cruise_ws(tmp_path_factory: pytest.TempPathFactory) -> Path:
    ws = tmp_path_factory.mktemp("cruise")
    (ws / "contracts").mkdir()
    (ws / "contracts" / "cruise.rcl").write_text(CRUISE)
    (ws / "contracts" / "plan.yaml").write_text(PLAN)
    (ws / "backends" / "monitors").mkdir(parents=True)
    (ws / "backends" / "monitors" / "two_lines.jsonl").write_text(TWO_LINES)
    (ws / "backends" / "monitors" / "bad.jsonl").write_text(
        TWO_LINES + '{"topic": "distance", "time": 0.2, "data": \n')
    return ws


@pytest.fixture(scope="module")
def case_study() -> tuple[Any, Any]:
    checked = load([REPO / "contracts" / "remote_inspection.rcl"])
    return checked, load_mapping(REPO, "backends/monitors/mapping.yaml", 2.0)


def test_input_before_the_first_real_output_is_answered_not_a_crash(cruise_ws: Path,
                                                                    capsys: pytest.CaptureFixture[str]) -> None:
    rc = main(["monitor", "-w", str(cruise_ws), "--json", str(cruise_ws / "backends/monitors/two_lines.jsonl")])
    out = json.loads(capsys.readouterr().out)
    assert rc == 0
    assert out[0]["counts"]["satisfied"] == 1 and out[0]["status"] == "discharged"
    # no output at all: the question waits for it, then is unanswered (inconclusive: a finite run cannot show
    # the answer never comes), never discharged (docs/semantics.md)
    lone = cruise_ws / "lone.jsonl"
    lone.write_text('{"topic": "distance", "time": 0.0, "data": 0.5}\n'
                    '{"topic": "distance", "time": 6.0, "data": 0.2}\n')
    rc = main(["monitor", "-w", str(cruise_ws), "--json", str(lone)])
    out = json.loads(capsys.readouterr().out)
    # (before any output was heard, the first is not counted against the node: docs/semantics.md, "Steps")
    assert rc == 0 and out[0]["status"] == "inconclusive"
    assert out[0]["counts"]["before first answer"] == 1 and out[0]["counts"]["open"] == 1
    assert "no output of" in out[0]["explanation"] and "question(s) came before any answer" in out[0]["explanation"]
    # a wrong answer, never corrected within the horizon, violates guarantee 1, shown with the values
    wrong = cruise_ws / "wrong.jsonl"
    wrong.write_text(TWO_LINES.replace("0.05", "0.5") + '{"topic": "distance", "time": 6.0, "data": 2.0}\n')
    rc = main(["monitor", "-w", str(cruise_ws), "--json", str(wrong)])
    out = json.loads(capsys.readouterr().out)
    assert rc == 1 and out[0]["first_violation"]["guarantee"] == 1
    assert out[0]["first_violation"]["values"] == {"in.distance": "0.5", "out.speed": "0.5"}


# -- mutated runs -------------------------------------------------------------

BASE = [json.loads(line) for line in (TRACES / "sensor_fault.jsonl").read_text().splitlines()[:80] if line.strip()]
WEIRD = st.one_of(st.none(), st.booleans(), st.integers(-10**30, 10**30), st.just(math.nan), st.just(math.inf),
                  st.floats(allow_nan=False), st.text(max_size=8), st.lists(st.integers(), max_size=3),
                  st.dictionaries(st.text(max_size=3), st.integers(), max_size=2))


@st.composite
def mutated_run(draw: st.DrawFn) -> str:
    """The first lines of the bundled fault run with random damage, as a log's text."""
    events = [dict(e) for e in BASE[:draw(st.integers(0, len(BASE)))]]
    for _ in range(draw(st.integers(0, 6))):
        if not events:
            break
        e = events[draw(st.integers(0, len(events) - 1))]
        op = draw(st.sampled_from(["drop", "retype", "time", "topic", "swap"]))
        key = draw(st.sampled_from(sorted(e)))
        if op == "drop":
            e.pop(key)
        elif op == "retype":
            e[key] = draw(WEIRD)
        elif op == "time":
            e["time"] = draw(st.one_of(st.floats(-1e3, 1e3), st.just(math.nan), st.none()))
        elif op == "topic":
            e["topic"] = draw(st.sampled_from(["unknown", "/r", "", "at", "command"]))
        else:
            j = draw(st.integers(0, len(events) - 1))
            k = events.index(e)
            events[j], events[k] = events[k], events[j]
    text = "".join(json.dumps(e) + "\n" for e in events)
    if draw(st.booleans()):
        text = text[:draw(st.integers(0, len(text)))]  # truncated mid-line
    return text


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(text=mutated_run())
def test_online_engine_gives_verdicts_or_a_located_error(case_study: tuple[Any, Any], text: str,
                                                         tmp_path_factory: pytest.TempPathFactory) -> None:
    checked, cfg = case_study
    path = tmp_path_factory.mktemp("fuzz") / "run.jsonl"
    path.write_text(text)
    seen: list[Any] = []
    try:
        _, results = check_trace(checked, list(checked.nodes.values()), read_trace(path, MSG), cfg.rules,
                                 cfg.horizon, seen.append)
    except TraceError as exc:
        assert str(exc).startswith(f"{path}:") and ": error: " in str(exc)
        return
    for res in results:  # every counted verdict was also emitted; a later one on an output replaces its earlier
        emitted = [v for v in seen if v.node == res.node]  # (a revision withdraws it: backends/monitors/late.py)
        kept: list[Any] = []
        for w in emitted:
            if w.verdict == WITHDRAWN:  # leaves its message no verdict (an incomplete input a late input completed)
                kept.pop(max(i for i, v in enumerate(kept) if v.event == w.event))
                continue
            if "replaces the" in w.reason:
                kept.pop(max(i for i, v in enumerate(kept) if v.event == w.event))
            kept.append(w)
        emitted = kept
        assert len(emitted) == sum(res.counts.values())
        for verdict, n in res.counts.items():
            assert sum(1 for v in emitted if v.verdict == verdict) == n


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(text=mutated_run())
def test_monitor_command_gives_verdicts_or_a_located_error(text: str, tmp_path_factory: pytest.TempPathFactory,
                                                           capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path_factory.mktemp("fuzzcli") / "run.jsonl"
    path.write_text(text)
    rc = main(["monitor", "-w", str(REPO), "--json", str(path)])
    out, err = capsys.readouterr()
    assert rc in (0, 1, 2)
    json.loads(out)  # the verdicts of what was checked, always printed
    if rc == 2:
        assert err.startswith(f"{path}:") and ": error: " in err and "Traceback" not in err
        assert len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("text, where", [
    ("", None),
    ("\n\n", None),
    ('{"topic": "r", "time": NaN, "value": 1.0}\n', ":1:1: error: the event's 'time' is nan"),
    ('{"topic": "r", "time": 1.0, "value": NaN}\n', None),
    ('[1, 2]\n', ":1:1: error: expected a JSON object"),
    ('{"topic": "r", "time": 1.0, "value": 1.0', ":1:"),
])
def test_edge_files(text: str, where: str | None, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "run.jsonl"
    path.write_text(text)
    rc = main(["monitor", "-w", str(REPO), "--json", str(path)])
    _, err = capsys.readouterr()
    if where is None:
        assert rc == 0 and err == ""
    else:
        assert rc == 2 and err.startswith(f"{path}{where}")


def test_nan_reading_is_an_inconclusive_event_with_the_reason(case_study: tuple[Any, Any]) -> None:
    checked, cfg = case_study
    events = [Event(0, 0.0, "command", {"command": "inspect", "posx": 0.0, "posy": 0.0, "id": 1}, "x:1"),
              Event(1, 0.1, "r", {"value": math.nan}, "x:2")]
    _, [res] = check_trace(checked, [checked.nodes["RadiationSensor"]], events, cfg.rules, cfg.horizon)
    assert res.counts["inconclusive"] == 1
    assert "not a finite number" in res.first_inconclusive["reason"]


def _lazy(n: int) -> Iterator[Event]:
    for k in range(n):
        if k % 2 == 0:
            yield Event(k, k * 0.001, "distance", {"data": float((k // 2) % 3)}, f"gen:{k}")
        else:
            yield Event(k, k * 0.001, "speed_cmd", {"data": 0.05}, f"gen:{k}")


def test_a_long_run_generated_lazily_is_checked_in_flat_memory(cruise_ws: Path) -> None:
    """10^5 events here (the bench runs 10^6): the questions watched stay
    bounded by the horizon, whatever the run's length."""
    checked = load([cruise_ws / "contracts" / "cruise.rcl"])
    node = checked.nodes["Cruise"]
    mon = NodeMonitor(checked, node, {}, 0.01)
    peak = 0
    for ev in _lazy(100_000):
        mon.feed(ev)
        peak = max(peak, len(mon._held) + (mon._open is not None))
    res = mon.finish()
    # every speed command judged (50 000), and the questions their inputs alone decide satisfied at once
    assert res.events == 100_000 and res.counts["satisfied"] >= 50_000
    assert res.counts["violated"] == res.counts["inconclusive"] == 0
    assert peak <= 1


def test_doit_verify_with_a_bad_trace_writes_the_report(cruise_ws: Path) -> None:
    (cruise_ws / "dodo.py").write_text("from pathlib import Path\nfrom rclverify.app.tasks import build_tasks, "
                                       "doit_config\nDOIT_CONFIG = doit_config()\n"
                                       "globals().update(build_tasks(Path(__file__).parent))\n")
    import os
    env = dict(os.environ, PYTHONPATH=str(REPO / "src") + os.pathsep + os.environ.get("PYTHONPATH", ""))
    r = subprocess.run([sys.executable, "-m", "doit", "verify"], cwd=cruise_ws, env=env, capture_output=True,
                       text=True, timeout=300)
    assert "Traceback" not in r.stderr and "TaskError" not in r.stdout + r.stderr
    report = json.loads((cruise_ws / "reports" / "assurance.json").read_text())
    ev = {e["obligation"]: e for e in report["evidence"]}
    assert ev["Cruise.g0.monitors.two_lines_jsonl"]["status"] == "discharged"
    bad = ev["Cruise.g0.monitors.bad_jsonl"]
    assert bad["status"] == "error" and "bad.jsonl:3:" in bad["explanation"]
    assert "malformed JSON" in bad["explanation"]
