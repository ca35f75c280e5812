"""A live log's call lines judged offline, without a bus (issue 62: live = offline; log_calls.py).

The live call book (dds_calls.py) writes its lines as ``rclverify monitor
--live --ros2`` writes them into its log; ``rclverify monitor LOG`` and the
``monitors`` backend (``doit verify``) read that log back and must give the
live book's call verdicts, call deadlines and exit code, and count a node
judged by its calls as judged (``--strict``).
"""
from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.base import NodeTarget
from rclverify.backends.monitors.backend import MonitorsBackend
from rclverify.backends.monitors.dds_calls import CallBook
from rclverify.backends.monitors.payload import monitors_payload
from rclverify.diagnosis.monitor_repair import is_call_violation
from rclverify.runtime.live import dumps
from rclverify.cli.commands import main
from rclverify.lang.typecheck import load

WS = Path(__file__).parent.parent / "data" / "dds_ws"
CHECKED = load([WS / "contracts" / "dds.rcl"])
LINKS = [(n, lk) for n in CHECKED.nodes.values() for lk in n.node.links]
NODES = ["--node", "Teleop", "--node", "Base", "--node", "Mover"]


def _live(tmp: Path, wrong: bool) -> tuple[Path, dict[str, Any]]:
    """A live run's log of calls and goals as dds_live writes it (the book's lines, its verdict and
    deadline lines), and the live book's summary.  ``wrong``: the second estop answer is wrong, the
    third is 300 ms late (deadline 200 ms), the second goal's feedback negative."""
    lines: list[dict[str, Any]] = []
    book = CallBook(CHECKED, LINKS, {}, 1.0)
    book.on_verdict = lambda v: lines.append({"topic": "rclverify/verdict", "time": v.decided_at,
                                              "verdict": {**v.to_json(), "call": True}})
    book.on_deadline = lambda v: lines.append({"topic": "rclverify/verdict", "time": book.now if book.now > 0 else
                                               v.trigger_stamp, "kind": "deadline", "verdict": v.to_json()})
    book.on_event = lines.append
    book.open("/estop", (0xA, 1), "estop call a:1", {"data": True}, 10.00)
    book.answer((0xA, 1), "response", {"success": True, "message": ""}, 10.05)
    book.tick(10.1)
    book.open("/estop", (0xA, 2), "estop call a:2", {"data": True}, 10.20)
    book.answer((0xA, 2), "response", {"success": not wrong, "message": ""}, 10.25)
    book.open("/estop", (0xA, 3), "estop call a:3", {"data": True}, 10.40)
    book.tick(10.55 if not wrong else 10.65)  # past the third call's deadline when it is late
    book.answer((0xA, 3), "response", {"success": True, "message": ""}, 10.50 if not wrong else 10.70)
    # two concurrent calls the live run could not pair (dds_order.py): inconclusive, with the reason
    book.open("/estop", (0xB, 1), "estop call b:1", {"data": True}, 11.00)
    book.unpaired((0xB, 1), 11.1, "2 requests of /estop were unanswered when this answer came")
    book.answer((0xC, 9), "response", {"success": True, "message": ""}, 11.2, name="/estop")  # an orphan
    book.open("/move", ("g1",), "move goal g1", {"target": 2.0}, 12.0, "goal")
    book.answer(("g1",), "feedback", {"progress": 0.5}, 12.1, final=False)
    book.answer(("g1",), "result", {"arrived": True}, 12.3)
    book.open("/move", ("g2",), "move goal g2", {"target": 1.0}, 12.5, "goal")
    book.answer(("g2",), "feedback", {"progress": -0.5 if wrong else 0.5}, 12.6, final=False)
    book.answer(("g2",), "result", {"arrived": True}, 12.7)
    book.open("/move", ("g3",), "move goal g3", {"target": 1.0}, 12.8, "goal")
    book.reject(("g3",), 12.81)  # refused: closed as it stood, as live
    book.tick(15.0)
    summary = book.finish()
    log = tmp / ("wrong.jsonl" if wrong else "right.jsonl")
    log.write_text("".join(dumps(x) + "\n" for x in lines))
    return log, summary


def _offline(log: Path, *extra: str) -> tuple[int, list[dict[str, Any]]]:
    import contextlib
    import io
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        code = main(["monitor", "-w", str(WS), "--horizon", "1.0", "--json", *NODES, *extra, str(log)])
    return code, json.loads(out.getvalue())


@pytest.mark.parametrize("wrong", [True, False])
def test_the_offline_command_judges_a_live_logs_calls_as_the_live_book(wrong: bool, tmp_path: Path) -> None:
    log, live = _live(tmp_path, wrong)
    code, report = _offline(log)
    calls = {e["node"]: e["calls"]["counts"] for e in report if "calls" in e}
    assert calls == {r["node"]: r["counts"] for r in live["nodes"]}
    assert [e["call_counts"] for e in report if "calls" in e][0] == live["counts"]
    assert live["counts"]["unpaired"] == 1 and live["counts"]["orphan_answers"] == 1
    assert live["counts"]["rejected"] == 1
    deadlines = {e["node"]: e["call_deadlines"]["counts"] for e in report if "call_deadlines" in e}
    assert deadlines == {r["node"]: r["counts"] for r in live["deadlines"]}
    # the unpaired call stays inconclusive, and the answer whose request was not heard is named undecided
    base = [e for e in report if e["node"] == "Base" and "calls" in e][0]["calls"]
    assert base["counts"]["inconclusive"] == 2
    assert "1 answer(s) of /estop whose request the monitor did not hear" in base["first_inconclusive"]["reason"]
    assert "12:9" in base["first_inconclusive"]["reason"]
    if wrong:
        assert live["false"] == 3 and base["counts"]["violated"] == 1  # the wrong answer is false too
        assert code == 1  # a violated call, a missed call deadline
    else:
        assert live["false"] == 0 and base["counts"]["violated"] == 0
        # Base's unpaired call leaves its calls inconclusive (never a guess), nothing failed
        assert code == 0
    # the nodes judged by their calls are judged; /estop's undecided answer is named, whatever else was judged
    items = [i for e in report if e.get("not_judged") for i in e["not_judged"]]
    assert [(i["name"], i["reason"]) for i in items] == [("/estop", "not paired")], items
    # --strict fails on an undecided verdict too (Base's unpaired call: inconclusive, never a guess)
    assert _offline(log, "--strict")[0] == 1


def test_the_offline_text_says_the_calls_as_the_live_run_does(tmp_path: Path,
                                                              capsys: pytest.CaptureFixture[str]) -> None:
    log, _ = _live(tmp_path, True)
    assert main(["monitor", "-w", str(WS), "--horizon", "1.0", *NODES, str(log)]) == 1
    out = capsys.readouterr().out
    assert f"{log}: calls: Base: failed: " in out
    assert f"{log}: deadlines: 3 of 5 judged call(s) or goal(s) missed their deadline" in out
    assert "not judged: service /estop (Teleop): not paired: 1 answer(s) of /estop came whose request was not " \
           "heard" in out, out


def test_a_log_without_its_call_lines_is_not_judged(tmp_path: Path) -> None:
    """The converse guard: the same log without the call lines judged nothing (exit 1 under --strict)."""
    log, _ = _live(tmp_path, False)
    bare = tmp_path / "bare.jsonl"
    bare.write_text("".join(x for x in log.read_text().splitlines(True) if '"rclverify/call"' not in x))
    code, report = _offline(bare, "--strict")
    items = {(i["kind"], i["name"]) for e in report for i in e.get("not_judged", [])}
    assert ("service", "/estop") in items and ("node", "Base") in items and code == 1


def test_a_call_line_that_cannot_be_replayed_is_a_located_error(tmp_path: Path,
                                                                capsys: pytest.CaptureFixture[str]) -> None:
    log, _ = _live(tmp_path, False)
    lines = log.read_text().splitlines(True)
    k = next(i for i, x in enumerate(lines) if '"part": "request"' in x)
    lines[k] = lines[k].replace('"key": ', '"kee": ')
    log.write_text("".join(lines))
    assert main(["monitor", "-w", str(WS), "--horizon", "1.0", str(log)]) == 2
    err = capsys.readouterr().err
    assert f"{log}:{k + 1}:1: error: a call line of the live monitor that cannot be replayed" in err, err
    assert "Traceback" not in err


@pytest.mark.parametrize("wrong", [True, False])
def test_doit_verifys_monitors_evidence_judges_a_live_logs_calls(wrong: bool, tmp_path: Path) -> None:
    ws = tmp_path / "ws"
    shutil.copytree(WS, ws)
    log, live = _live(ws, wrong)
    checked = load([ws / "contracts" / "dds.rcl"])
    status = {}
    for node in ("Base", "Teleop", "Mover"):
        t = NodeTarget(root=ws, checked=checked, node=checked.nodes[node],
                       config={"backend": "monitors", "horizon": 1.0, "traces": [log.name]},
                       contract_files=("contracts/dds.rcl",), plan_file="contracts/plan.yaml",
                       artifacts=ws / "artifacts" / "monitors" / node)
        (ob,) = MonitorsBackend().export(t)
        ev = MonitorsBackend().run(ob, t)
        status[node] = ev.status
        # /estop's answer whose request was not heard is named undecided for both its ends
        assert [(i["name"], i["reason"]) for i in ev.details["not_judged"]] == \
            ([] if node == "Mover" else [("/estop", "not paired")]), (node, ev.details["not_judged"])
        assert ev.details["calls"]["counts"] == {r["node"]: r["counts"] for r in live["nodes"]}[node]
        payload = monitors_payload(ev.backend, ev.details)  # the repair search re-runs the calls it failed by
        assert payload is not None and is_call_violation(payload) == (ev.status == "failed"), (node, ev.status)
    if wrong:  # Base: a wrong answer and a late one; Mover: a negative feedback; Teleop: the undecided answer
        assert status == {"Base": "failed", "Teleop": "inconclusive", "Mover": "failed"}, status
    else:  # Base's unpaired call is inconclusive, never guessed; Mover's rejected goal was left open, as live
        assert status == {"Base": "inconclusive", "Teleop": "inconclusive", "Mover": "inconclusive"}, status


def test_the_source_a_live_log_names_is_in_the_evidence_and_the_report(tmp_path: Path) -> None:
    """A live log's origin lines (run_origin.py: the source, its middleware, the links it could not hear)
    reach the monitors evidence (``details["monitoring"]["source"]``) and the report's evidence part; a log
    without them claims no source."""
    from rclverify.backends.monitors.run_origin import origin_line, unseen_line
    from rclverify.report.evidence_rows import evidence_row
    from rclverify.report.fragments import FragmentCache
    from rclverify.report.render import part_renderer
    ws = tmp_path / "ws"
    shutil.copytree(WS, ws)
    log, _live_summary = _live(ws, False)
    body = log.read_text()
    unseen = ["/move: no introspection event of its own services was heard"]
    log.write_text(dumps(origin_line(9.0, "rclpy", "rmw_zenoh_cpp", "rclpy 9.1.2 on rmw_zenoh_cpp")) + "\n" + body
                   + dumps(unseen_line(16.0, unseen)) + "\n")
    bare = ws / "bare.jsonl"
    bare.write_text(body)
    checked = load([ws / "contracts" / "dds.rcl"])
    got = {}
    for trace in (log.name, bare.name):
        t = NodeTarget(root=ws, checked=checked, node=checked.nodes["Base"],
                       config={"backend": "monitors", "horizon": 1.0, "traces": [trace]},
                       contract_files=("contracts/dds.rcl",), plan_file="contracts/plan.yaml",
                       artifacts=ws / "artifacts" / "monitors" / "Base")
        (ob,) = MonitorsBackend().export(t)
        got[trace] = MonitorsBackend().run(ob, t)
    ev, plain = got[log.name], got[bare.name]
    assert ev.details["monitoring"]["source"] == {"source": "rclpy", "rmw": "rmw_zenoh_cpp",
                                                  "middleware": "rclpy 9.1.2 on rmw_zenoh_cpp", "unseen": unseen}
    assert "source" not in plain.details["monitoring"] and ev.status == plain.status  # the lines judge nothing
    part = part_renderer(FragmentCache(), "../")
    row = {"record": evidence_row(None, ev, ev.status, "", None), "anchor": "ev-x"}  # no plot: no workspace read
    md = part("evidence.md", rows=[row])
    assert "Heard through: rclpy on rmw\\_zenoh\\_cpp" in md or "Heard through: rclpy on rmw_zenoh_cpp" in md, md
    assert "not heard: /move: no introspection event" in md
    html = str(part("evidence.html", rows=[row]))
    assert "<th>Heard through</th><td>rclpy on rmw_zenoh_cpp" in html, html
