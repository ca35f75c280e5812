"""Silence is never green, and live = offline (issue 62), below the middleware.

* the live run (:class:`LiveRun`) judges deadlines and periods as the
  offline command judges its log: the same counts, the same statuses, even
  for a trigger whose deadline only the live timer saw pass (the verdict's
  log line carries that clock to the offline check);
* :func:`judged.not_judged` names each item not judged with its reason;
* ``doit verify``'s monitors evidence of a recorded run that holds no event
  of its node is never ``discharged`` (pinned).

The real-ROS 2 side is tests/runtime/test_ros2_silence_deadlines.py.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.config import load_mapping
from rclverify.backends.monitors.judged import Heard, not_judged
from rclverify.runtime.live import LiveRun
from rclverify.cli.commands import main
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check

RCL = """\
node Echo {
  inputs( r : REAL )
  outputs( y : REAL, beat : BOOL )
  topics( std_msgs/Float64 r matches(in.r), std_msgs/Float64 out matches(out.y),
          std_msgs/Bool beat matches(out.beat) )
  assume( in.r >= 0 )
  guarantee( out.y == in.r ) triggered by in.r within 100 ms
  periodic( out.beat, 100 ms )
}

node Server {
  inputs( req : BOOL )
  outputs( ok : BOOL )
  services( std_srvs/SetBool estop serves(in.req, out.ok) )
  actions( rclverify_examples/Move move serves(in.req, out.ok, out.ok) )
  assume( TRUE )
  guarantee( in.req -> out.ok ) triggered by in.req within 1 s
}
"""


def _ws(tmp: Path) -> Path:
    ws = tmp / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/sys.rcl").write_text(RCL)
    (ws / "contracts/plan.yaml").write_text("contracts: [contracts/sys.rcl]\n")
    return ws


def _checked() -> Any:
    return check([parse_text(RCL, "sys.rcl")])


def test_live_deadlines_and_periods_are_the_offline_checks_of_its_log(tmp_path: Path,
                                                                       capsys: pytest.CaptureFixture[str]) -> None:
    ws, checked = _ws(tmp_path), _checked()
    cfg = load_mapping(ws, None, 1.0)
    log = tmp_path / "live.jsonl"
    published: list[str] = []
    live = LiveRun(checked, [checked.nodes["Echo"]], cfg.rules, cfg.horizon, log, reorder_window=0.0,
                   publish=published.append)
    # (time, topic, value): answered in 20 ms; unanswered until 250 ms late; never answered; a beat gap of 250 ms
    script = [(1.0, "r", 1.0), (1.0, "beat", True), (1.02, "out", 1.0), (1.1, "beat", True), (1.2, "beat", True),
              (1.45, "beat", True), (1.5, "r", 2.0), (1.75, "out", 2.0), (1.8, "r", 3.0)]
    for t, topic, v in script:
        live.tick(t)
        live.push(topic, {"data": v}, t)
    live.tick(1.95)  # r = 3.0 is past its deadline: only the timer says so
    assert "Echo deadlines: 1 true, 2 false" in live.status_line()
    record = live.stop()
    (dl,), (per,) = record["topic_deadlines"], record["periods"]
    assert dl["deadlines"]["counts"] == {"true": 1, "false": 2, "currently_false": 0} and dl["status"] == "failed"
    assert per["status"] == "failed" and "a gap of 250 ms" in per["explanation"]
    assert sum(1 for m in map(json.loads, published) if m.get("kind") == "deadline") == 4  # and the late answer
    capsys.readouterr()
    rc = main(["monitor", "-w", str(ws), "--horizon", "1.0", "--node", "Echo", "--json", str(log)])
    report = json.loads(capsys.readouterr().out)
    off_dl = next(e for e in report if "deadlines" in e)
    off_per = next(e for e in report if "periods" in e)
    assert rc == 1
    assert off_dl["deadlines"]["counts"] == dl["deadlines"]["counts"] and off_dl["status"] == dl["status"]
    stamps = lambda late: {k: (g["from"], g["to"], g["gap"]) for k, g in late.items()}  # noqa: E731 (where: its own)
    assert stamps(off_per["periods"]["late"]) == stamps(per["periods"]["late"]) and off_per["status"] == per["status"]
    assert next(e for e in report if "counts" in e)["counts"] == record["nodes"][0]["counts"]


def test_each_item_not_judged_has_its_reason() -> None:
    checked = _checked()
    nodes = list(checked.nodes.values())
    heard = Heard({"r": 3, "out": 0, "estop/request": 2, "move/result": 0}, {"move/result": 1},
                  {"out": 4}, ["sys.rcl:4:11: warning: beat: /imposter publishes std_msgs::msg::dds_::Float64_, "
                               "the contract's type is std_msgs::msg::dds_::Bool_; its messages are not heard"])
    statuses = {"Echo": [("pending", "nothing was checked")], "Server": [("pending", "x"), ("discharged", "y")]}
    items = not_judged(nodes, heard, statuses, {"Echo": {"true": 0, "false": 0, "currently_false": 2}}, "in run")
    got = {(i["kind"], i["name"]): (i["reason"], i["detail"]) for i in items}
    assert got[("node", "Echo")][0] == "no verdict" and ("node", "Server") not in got  # the calls judged Server
    assert got[("topic", "/out")] == ("not decoded", "4 message(s) on /out did not decode as std_msgs/Float64 in run")
    assert got[("topic", "/beat")][0] == "type refused" and "/imposter publishes" in got[("topic", "/beat")][1]
    assert got[("service", "/estop")] == ("no answer", "2 call(s) of /estop were heard, none answered in run")
    assert got[("action", "/move")][0] == "not paired" and "1 answer(s) of /move" in got[("action", "/move")][1]
    assert got[("deadline", "Echo guarantee(s) 1")] == ("no verdict", "2 trigger event(s) were still within their "
                                                                      "deadline in run")
    assert got[("deadline", "Server guarantee(s) 1")][0] == "no verdict"  # a request came, no accepted trigger
    assert ("topic", "/r") not in got
    silent = not_judged(nodes, Heard(), {}, {}, "in run")
    assert {(i["kind"], i["reason"]) for i in silent} == {("topic", "nothing heard"), ("service", "nothing heard"),
                                                         ("action", "nothing heard"), ("deadline", "nothing heard")}


def test_a_recorded_run_without_the_nodes_events_is_never_discharged(tmp_path: Path) -> None:
    """``doit verify``: the monitors evidence of a run that holds no event of
    its node is pending (nothing was checked), in the record and the report."""
    ws = _ws(tmp_path)
    (ws / "traces").mkdir()
    (ws / "traces/other.jsonl").write_text("".join(json.dumps({"topic": "unrelated", "time": 0.1 * k, "data": 1.0})
                                                   + "\n" for k in range(5)))
    (ws / "contracts/plan.yaml").write_text("contracts: [contracts/sys.rcl]\nnodes:\n  Echo:\n    evidence:\n"
                                            "      - backend: monitors\n        traces: [traces/other.jsonl]\n")
    assert main(["verify", "-w", str(ws)]) == 0
    ev = json.loads((ws / "artifacts/evidence/Echo.g0.monitors.other_jsonl.json").read_text())
    assert ev["status"] == "pending" and "nothing was checked" in ev["explanation"], ev["explanation"]
    assert "(not judged: nothing heard: no message on /r, /out, /beat in traces/other.jsonl)" in ev["explanation"]
    assert {(i["kind"], i["reason"]) for i in ev["details"]["not_judged"]} == {
        ("node", "nothing heard"), ("topic", "nothing heard"), ("deadline", "nothing heard")}
    report = json.loads((ws / "reports/assurance.json").read_text())
    statuses = {e["status"] for e in report["evidence"] if e["obligation"].startswith("Echo.g0.monitors")}
    assert statuses == {"pending"}
    assert main(["verify", "-w", str(ws), "--strict"]) == 1


def test_counting_what_a_log_holds_keeps_the_batch_path(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The offline command counts each topic's events for the not-judged
    items without turning a log's columnar reading into events one by one."""
    from rclverify.backends.monitors import batch
    from rclverify.backends.monitors.batch import check_batch
    kinds: list[str] = []
    real = batch.rows_of
    monkeypatch.setattr(batch, "rows_of", lambda head, chunk: kinds.append(type(chunk).__name__) or real(head, chunk))
    from rclverify.backends.monitors.judged import Counted
    from rclverify.traces import read_trace
    from rclverify.traces.mapping import load_rules
    rcl = ("node Lim {\n  inputs( r : REAL )\n  outputs( y : REAL )\n"
           "  topics( std_msgs/Float64 r matches(in.r), std_msgs/Float64 out matches(out.y) )\n"
           "  assume( in.r >= 0 )\n  guarantee( out.y <= in.r )\n}\n")
    node = check([parse_text(rcl, "lim.rcl")])
    log = tmp_path / "run.jsonl"
    log.write_text("".join(json.dumps({"topic": t, "time": k + d, "data": v}) + "\n"
                           for k in range(300) for t, d, v in (("r", 0.0, 1.0), ("out", 0.5, 0.5), ("noise", 0.7, 0))))
    heard: dict[str, int] = {}
    stats: dict[str, int] = {}
    rules = load_rules({"r": {"fields": ["data"]}, "out": {"fields": ["data"]}})
    got = check_batch(node, node.nodes["Lim"], Counted(read_trace(log, streams=True), heard), rules, 5.0,
                      chunk=64, stats=stats, min_run=0)  # (runs of one pair: batched only when asked)
    assert got is not None and got[1].counts["satisfied"] == 300
    assert stats["batched"] == 300 and heard == {"r": 300, "out": 300, "noise": 300}
    assert kinds and set(kinds) == {"LogBlock"}, kinds  # the log's blocks, never events made one by one
