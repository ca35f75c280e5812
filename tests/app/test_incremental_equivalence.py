"""Incremental equals clean (issue: integrity): after any sequence of edits a
user makes between runs, an incremental ``doit verify`` writes the same
report files as a from-scratch run on a copy of the inputs.

The edits and the comparison live in ``tests/_incremental.py``;
``bench/incremental_equivalence.py`` runs random sequences of them (hundreds;
one in its smoke mode, which the suite runs: tests/bench/test_bench_smoke_live.py).
This file checks the harness itself, and runs the one edit a time-based
up-to-date check cannot see (a run rewritten in place with its size and
modification time kept, issue 107) through an incremental and a clean run.
"""
from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import _incremental as inc

# The random edit sequences themselves run in the suite as the smoke run of
# ``bench/incremental_equivalence.py`` (tests/bench/test_bench_smoke_live.py), which fails on any mismatch;
# this file keeps the harness honest.


def test_every_edit_changes_an_input(tmp_path: Path) -> None:
    """Each edit of the harness changes some input file (an edit that changes
    nothing would make the equivalence test pass without testing)."""
    for k, edit in enumerate(inc.EDITS):
        if edit is inc.edit_revert:  # undoes the edits before it: nothing on a fresh workspace (tested below)
            continue
        ws = inc.make_workspace(tmp_path / f"w{k}")
        before = {p: p.read_bytes() for p in ws.rglob("*") if p.is_file()}
        edit(ws, 1)
        after = {p: p.read_bytes() for p in ws.rglob("*") if p.is_file()}
        assert before != after, edit.__name__


def test_the_revert_edit_gives_back_the_inputs_as_written(tmp_path: Path) -> None:
    """``edit_revert`` undoes every other edit: after all of them and a
    revert, each input file holds what a fresh workspace holds, and the
    files the edits added are gone."""
    fresh = inc.make_workspace(tmp_path / "fresh")
    ws = inc.make_workspace(tmp_path / "ws")
    for k, edit in enumerate(inc.EDITS):
        edit(ws, k + 1)
    if not (ws / "contracts/logger.rcl").exists():
        inc.edit_contract_file(ws, 7)  # so that there is an added file to delete
    assert (ws / "contracts/logger.rcl").exists()
    inc.edit_revert(ws, 0)
    files = {p.relative_to(ws): p.read_bytes() for p in ws.rglob("*") if p.is_file()}
    assert files == {p.relative_to(fresh): p.read_bytes() for p in fresh.rglob("*") if p.is_file()}


def test_the_in_place_edit_keeps_size_and_mtime(tmp_path: Path) -> None:
    """``edit_trace_in_place`` changes the run's bytes and nothing a time-based
    up-to-date check reads: the same size, the same modification time, the same file."""
    ws = inc.make_workspace(tmp_path / "ws")
    trace = ws / "backends/monitors/traces/nominal.jsonl"
    for k in range(4):
        before, st = trace.read_bytes(), trace.stat()
        inc.edit_trace_in_place(ws, k)
        after = trace.stat()
        assert trace.read_bytes() != before
        assert (after.st_size, after.st_mtime_ns, after.st_ino) == (st.st_size, st.st_mtime_ns, st.st_ino)


RCL = """node Echo {
  inputs( r : REAL )
  outputs( y : REAL )
  topics( std_msgs/Float64 r matches(in.r), std_msgs/Float64 out matches(out.y) )
  guarantee( out.y == in.r )
}
"""
PLAN = """contracts: [contracts/echo.rcl]
nodes:
  Echo:
    evidence:
      - backend: monitors
        traces: [traces/run.jsonl]
"""


def test_a_run_edited_in_place_with_size_and_mtime_kept_is_judged_again(tmp_path: Path) -> None:
    """Issue 107: a green run rewritten in place, its size and modification time
    restored, was stale in every report and never judged again.  The
    incremental run judges it again (it is red now) and writes the clean run's
    report; control: the first run of the same workspace was green."""
    ws = tmp_path / "echo"
    (ws / "contracts").mkdir(parents=True)
    (ws / "traces").mkdir()
    shutil.copyfile(inc.REPO / "dodo.py", ws / "dodo.py")
    (ws / "contracts/echo.rcl").write_text(RCL, encoding="utf-8")
    (ws / "contracts/plan.yaml").write_text(PLAN, encoding="utf-8")
    rows = [{"topic": "r", "time": 0.0, "data": 1.5}, {"topic": "out", "time": 0.01, "data": 1.5},
            {"topic": "r", "time": 1.0, "data": 2.5}, {"topic": "out", "time": 1.01, "data": 2.5}]
    trace = ws / "traces/run.jsonl"
    trace.write_text("".join(json.dumps(r) + "\n" for r in rows), encoding="utf-8")
    report = ws / "reports/assurance.md"
    assert inc.verify(ws).returncode == 0
    assert "**Overall status:** ✅ discharged." in report.read_text(encoding="utf-8")
    st = trace.stat()
    answer = b'{"topic": "out", "time": 1.01, "data": 2.5}'
    with trace.open("r+b") as fh:  # 2.5 answered with 2.0: the same size, written where it is
        fh.write(trace.read_bytes().replace(answer, answer.replace(b"2.5", b"2.0")))
    os.utime(trace, ns=(st.st_atime_ns, st.st_mtime_ns))
    assert (trace.stat().st_size, trace.stat().st_mtime_ns) == (st.st_size, st.st_mtime_ns)
    assert inc.compare(ws, tmp_path / "scratch" / "echo") == []
    assert "**Overall status:** ❌ **failed**" in report.read_text(encoding="utf-8")
