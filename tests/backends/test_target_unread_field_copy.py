"""A run given again with a field no mapping reads is the same run, for a plan's target (docs/statistics.md,
"A run's identity"; backends/monitors/run_identity.py): the run-set obligation counts it once, as a
duplicate, so a target cannot be met on copies.

Clamp's target, ``violation probability <= 20 % at 90 % per run``, needs 11 clean runs.  The entry lists 10
clean runs and, as an 11th, run 0 again with an extra field on every line (``note``) that the mapping
(``fields: [data]``) does not read: 10 runs, one duplicate, ``pending``.  The controls: the 11th a run of
its own (a read value changed) meets the target; and the same copy judged with a mapping that names no
field (every field read) is a run of its own too, so the test tells the two readings apart.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from rclverify.backends.monitors.backend import MonitorsBackend
from rclverify.stages.workspace import Workspace

RCL = """
node Clamp {
  inputs( a : REAL )
  outputs( x : REAL )
  topics( std_msgs/Float64 a matches(in.a), std_msgs/Float64 x matches(out.x) )
  assume( in.a >= 0 )
  guarantee( out.x <= 30 )
}
"""
TARGET = "violation probability <= 20 % at 90 % per run"
#: the clean runs the target needs (0.8 ** 11 <= 0.1 < 0.8 ** 10)
NEED = 11
READ = "topics:\n  a: {fields: [data]}\n  x: {fields: [data]}\n"
EVERY = "topics:\n  a: {}\n  x: {}\n"


def _lines(k: int) -> list[dict[str, Any]]:
    """Run ``k`` of Clamp: two questions (their values make it unique) and their clean answers."""
    out: list[dict[str, Any]] = []
    for j, x in enumerate((5.0, 20.0)):
        out.append({"topic": "a", "time": 1000.0 + k + 0.1 * j, "data": float(j + k)})
        out.append({"topic": "x", "time": 1000.0 + k + 0.1 * j + 0.01, "data": x})
    return out


def _write(path: Path, lines: list[dict[str, Any]]) -> str:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("".join(json.dumps(x) + "\n" for x in lines))
    return path.name


def _judged(tmp: Path, last: list[dict[str, Any]], mapping: str) -> Any:
    """The run-set evidence of an entry of ``NEED - 1`` distinct clean runs and ``last``, read with
    ``mapping``."""
    (tmp / "contracts").mkdir(parents=True)
    (tmp / "contracts/sys.rcl").write_text(RCL)
    (tmp / "mapping.yaml").write_text(mapping)
    traces = [f"runs/{_write(tmp / 'runs' / f'run{k:02d}.jsonl', _lines(k))}" for k in range(NEED - 1)]
    traces.append(f"runs/{_write(tmp / 'runs' / 'last.jsonl', last)}")
    entry = {"backend": "monitors", "traces": traces, "mapping": "mapping.yaml", "target": TARGET}
    (tmp / "contracts/plan.yaml").write_text(json.dumps({"contracts": ["contracts/sys.rcl"],
                                                         "nodes": {"Clamp": {"evidence": [entry]}}}))
    ws = Workspace(tmp)
    target = ws.target("Clamp", 0)
    backend = MonitorsBackend()
    (ob,) = [o for o in backend.export(target) if o.data.get("run_set") is not None]
    return backend.run(ob, target)


def _noted(lines: list[dict[str, Any]]) -> list[dict[str, Any]]:
    return [{**x, "note": f"copy, line {i}"} for i, x in enumerate(lines)]


def test_a_copy_with_an_unread_field_on_every_line_counts_once_and_meets_no_target(tmp_path: Path) -> None:
    ev = _judged(tmp_path, _noted(_lines(0)), READ)
    c = ev.details["statistics"]["counts"]
    assert (c["runs"], c["duplicates"]) == (NEED - 1, 1), c
    assert ev.status == "pending" and "repeat a run already counted" in ev.explanation, ev.explanation


def test_control_a_run_of_its_own_meets_the_target(tmp_path: Path) -> None:
    ev = _judged(tmp_path, _noted(_lines(NEED - 1)), READ)
    c = ev.details["statistics"]["counts"]
    assert (c["runs"], c["duplicates"]) == (NEED, 0) and ev.status == "discharged", (c, ev.explanation)


def test_control_with_every_field_read_the_copy_is_a_run_of_its_own(tmp_path: Path) -> None:
    ev = _judged(tmp_path, _noted(_lines(0)), EVERY)
    c = ev.details["statistics"]["counts"]
    assert (c["runs"], c["duplicates"]) == (NEED, 0) and ev.status == "discharged", (c, ev.explanation)
