"""Hostile round seven (issue 63), row 12: every user error located.
Two traces of one file name in different folders are two obligations
(doit aborted on a "duplicated definition" with no location); the same
trace listed twice is a located plan error; a JSON-lines line nested
200,000 deep is a located trace error, not an unlocated RecursionError."""
from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from rclverify.cli.commands import main
from rclverify.app.pipeline import Workspace
from rclverify.model.plan.errors import PlanError

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "safety_stop"


def _copy(tmp: Path, traces: str) -> Path:
    ws = tmp / "ws"
    shutil.copytree(EXAMPLE, ws)
    (ws / "traces/again").mkdir()
    shutil.copy(ws / "traces/late_stop.jsonl", ws / "traces/again/nominal.jsonl")
    plan = ws / "contracts/plan.yaml"
    text = plan.read_text()
    assert text.count("traces: [traces/nominal.jsonl]") == 2
    plan.write_text(text.replace("traces: [traces/nominal.jsonl]", f"traces: {traces}", 1))
    return ws


def test_two_traces_of_one_name_are_two_obligations(tmp_path: Path) -> None:
    ws = Workspace(_copy(tmp_path, "[traces/nominal.jsonl, traces/again/nominal.jsonl]"))
    from rclverify.backends.monitors.backend import MonitorsBackend
    index = [i for i, e in enumerate(ws.plan.evidence["Base"]) if e.config.get("backend") == "monitors"][0]
    ids = [o.id for o in MonitorsBackend().export(ws.target("Base", index))]
    assert len(set(ids)) == 2 and any("again" in i for i in ids), ids


def test_the_same_trace_twice_is_a_located_plan_error(tmp_path: Path) -> None:
    ws = Workspace(_copy(tmp_path, "[traces/nominal.jsonl, traces/./nominal.jsonl]"))
    from rclverify.backends.monitors.backend import MonitorsBackend
    index = [i for i, e in enumerate(ws.plan.evidence["Base"]) if e.config.get("backend") == "monitors"][0]
    with pytest.raises(PlanError) as exc:
        MonitorsBackend().export(ws.target("Base", index))
    assert "contracts/plan.yaml:36:" in str(exc.value) and "listed twice (also as traces[0])" in str(exc.value)


def test_a_line_nested_too_deep_is_a_located_trace_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    deep = tmp_path / "deep.jsonl"
    d = 200_000
    deep.write_text('{"topic": "estop", "time": 0.1, "data": true}\n'
                    '{"topic": "a", "time": 0.2, "x": ' + "[" * d + "]" * d + "}\n")
    assert main(["monitor", "-w", str(EXAMPLE), str(deep)]) == 2
    err = capsys.readouterr().err
    assert "deep.jsonl:2:1: error: the line nests arrays or objects too deeply" in err and "Traceback" not in err
