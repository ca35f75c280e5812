"""Terminal output of verify: the live progress line and the summary table."""
from __future__ import annotations

import io
from types import SimpleNamespace
from typing import Any

from rclverify.app.progress import ProgressReporter, backend_of
from rclverify.records.findings import HealthFinding
from rclverify.records.report_record import AssuranceReport
from rclverify.report.summary import MAX_ROWS, node_rows, print_summary

from _typed_rows import complete


def _report(n_nodes: int) -> dict[str, Any]:
    """A report of ``n_nodes`` nodes, only the parts the summary counts given, completed into a whole one
    (tests/records/_typed_rows.py: the summary reads the report decoded)."""
    nodes = [{"name": f"N{k}", "status": "failed" if k == 7 else "discharged"} for k in range(n_nodes)]
    obligations = [{"node": f"N{k}", "status": "failed" if k == 7 else "discharged"} for k in range(n_nodes)]
    obligations.append({"node": "N0", "status": "pending"})
    scs = [{"node": f"N{k}", "status": "discharged"} for k in range(1, n_nodes)]
    findings = [HealthFinding(f"{node}.consistent", node, "contract-consistent", None, status, "", "").to_json()
                for node, status in (("N7", "problem"), ("N3", "inconclusive"), ("N1", "ok"))]
    return complete(AssuranceReport, {"meta": {"workspace": "w [x]"}, "nodes": nodes, "obligations": obligations,
                                      "side_conditions": scs, "findings": findings})


def test_summary_rows_put_the_worst_node_first() -> None:
    rows = node_rows(AssuranceReport.of(_report(4)))
    assert [r["node"] for r in rows] == ["N0", "N1", "N2", "N3"]  # N0 pending ranks above discharged
    rows = node_rows(AssuranceReport.of(_report(9)))
    assert rows[0]["node"] == "N7" and rows[0]["obligations"] == {"failed": 1} and rows[0]["health_problems"] == 1


def test_plain_summary_fits_one_screen_and_has_no_escape_codes() -> None:
    out = io.StringIO()
    print_summary(AssuranceReport.of(_report(40)), "reports/assurance.html", file=out, terminal=False)
    text = out.getvalue()
    assert "\x1b[" not in text and "w [x]" in text
    lines = text.splitlines()
    assert len(lines) <= MAX_ROWS + 12
    assert any(l.startswith("| N7 ") and "failed" in l and "1 problem" in l for l in lines)
    assert any("(+25 more nodes)" in l for l in lines)
    total = next(l for l in lines if l.startswith("| total"))
    assert "1 failed, 1 pending, 39 discharged" in total and "39/39 proved" in total
    assert lines[-1] == "report: reports/assurance.html"


def test_progress_line_shows_stage_count_and_running_backend() -> None:
    rep = ProgressReporter(io.StringIO(), {})
    rep.live_mode = True  # as on a terminal, without starting the live display
    rep.tasks = {"check": 0, "evidence": 0, "evidence:A.g1.hoare.c1": 0, "evidence:A.g1.dafny.contract": 0}
    first = SimpleNamespace(name="evidence:A.g1.hoare.c1", actions=[object()])
    second = SimpleNamespace(name="evidence:A.g1.dafny.contract", actions=[object()])
    rep.execute_task(first)
    line = rep._line().plain
    assert line.startswith("evidence") and "0/2 obligations" in line and "running: hoare (A.g1.hoare.c1)" in line
    rep.add_success(first)
    rep.skip_uptodate(second)
    line = rep._line().plain
    assert "2/2 obligations" in line and "running" not in line
    assert rep.outstream.getvalue() == ""  # no per-task lines on a terminal
    assert backend_of("Agent.g0.dafny.contract") == "dafny" and backend_of("odd") == ""


def test_progress_is_doit_console_output_when_not_a_terminal() -> None:
    out = io.StringIO()
    rep = ProgressReporter(out, {})
    rep.live_mode = False
    rep.execute_task(SimpleNamespace(name="report", actions=[object()], title=lambda: "report"))
    rep.skip_uptodate(SimpleNamespace(name="check", actions=[object()], title=lambda: "check"))
    assert out.getvalue() == ".  report\n-- check\n"


def test_a_completed_run_freezes_the_heap_only_at_exit(monkeypatch: Any) -> None:
    # the final garbage collection of a large run's heap took most of a second after the work
    import atexit
    import gc

    from rclverify.core.cache import heap
    registered: list[Any] = []
    monkeypatch.setattr(atexit, "register", registered.append)
    monkeypatch.setattr(heap, "_EXIT", [])
    heap.release_after_run()  # the heap frozen by a build_tasks of an earlier test
    gc.unfreeze()  # ... or by a live monitor an earlier test ran in this process (freeze_for_live: never undone)
    assert gc.get_freeze_count() == 0
    for _ in range(2):
        rep = ProgressReporter(io.StringIO(), {})
        rep.live_mode = False
        rep.initialize({}, [])  # the run's heap is frozen while doit runs the tasks ...
        assert gc.get_freeze_count() > 0
        rep.complete_run()  # ... and given back when it completes
    assert registered == [gc.freeze]  # once per process, and nothing frozen while it still runs
    assert gc.get_freeze_count() == 0


def test_verify_prints_the_summary_written_with_the_report(tmp_path: Any, capsys: Any) -> None:
    import json

    from doit.exceptions import TaskFailed

    from rclverify.app.pipeline import Workspace
    from rclverify.report.summary import summary_data
    from rclverify.app.tasks import act_verify
    report = _report(3)
    report["meta"]["strict_ok"] = False
    report["summary"] = {**report["summary"], "status": "failed", "headline": "from the JSON report",
                         "problems": ["N7 is bad"]}
    (tmp_path / "reports").mkdir()
    (tmp_path / "reports" / "assurance.json").write_text(json.dumps(report))
    # without the summary file (a report written by an earlier version): taken from the JSON report
    assert isinstance(act_verify(str(tmp_path), True), TaskFailed)
    out = capsys.readouterr().out
    assert "overall: failed -- from the JSON report" in out and "problem: N7 is bad" in out and "N2" in out
    data = summary_data(report)
    data["summary"] = {**data["summary"], "headline": "from the summary file"}
    data["meta"]["strict_ok"] = True
    (tmp_path / Workspace.SUMMARY).parent.mkdir(parents=True)
    from rclverify.records.sealed import write_sealed
    write_sealed(tmp_path / Workspace.SUMMARY, data)  # as the report task writes it: sealed
    assert act_verify(str(tmp_path), True) is None
    assert "overall: failed -- from the summary file" in capsys.readouterr().out
