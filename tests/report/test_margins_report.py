"""Margins over runs (docs/semantics.md, "Margins over runs"): the report names, per guarantee, its
smallest margin over every recorded run with the run, the answer's time and message, the distribution
of its answers' margins (count, min, p5, p50) and, for two runs or more, a plot of each run's kept
margins (matplotlib, the ``plots`` extra); the figures are the bounds the kept margins prove; a timed
guarantee's row has its smallest time margin over the runs."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from _report_schema import check_report
from rclverify.backends.monitors.payload import SpaceMargin
from rclverify.backends.monitors.verdicts import KEPT_MARGINS
from rclverify.cli.commands import main
from rclverify.records.margin_rows import MarginBounds
from rclverify.report.margin_rows import figures

BRAKE = """node Brake {
  inputs( dist : REAL )
  outputs( speed : REAL )
  topics( std_msgs/Float64 dist matches(in.dist), std_msgs/Float64 speed matches(out.speed) )
  assume( TRUE )
  guarantee( out.speed <= in.dist ) triggered by in.dist within 100 ms
}
"""
PLAN = """name: brakes
contracts: [contracts/brake.rcl]
nodes:
  Brake:
    evidence:
      - {backend: monitors, traces: [runs/one.jsonl, runs/two.jsonl], mapping: contracts/mapping.yaml}
"""
# (dist, speed, latency s): margins 0.3, 0.04 on run one; 0.5, 0.1, 1.0 on run two; the smallest time
# margin 100 - 70 = 30 ms, on run two's second answer
RUNS = {"one": ((1.0, 0.7, 0.01), (2.0, 1.96, 0.01)), "two": ((3.0, 2.5, 0.01), (4.0, 3.9, 0.07), (5.0, 4.0, 0.01))}


def _workspace(root: Path) -> Path:
    for d in ("contracts", "runs"):
        (root / d).mkdir(parents=True, exist_ok=True)
    (root / "contracts" / "brake.rcl").write_text(BRAKE, encoding="utf-8")
    (root / "contracts" / "plan.yaml").write_text(PLAN, encoding="utf-8")
    (root / "contracts" / "mapping.yaml").write_text("horizon: 1.0\n", encoding="utf-8")
    for name, pairs in RUNS.items():
        rows = [r for i, (d, s, late) in enumerate(pairs, start=1) for r in
                ({"topic": "dist", "time": float(i), "data": d}, {"topic": "speed", "time": i + late, "data": s})]
        (root / "runs" / f"{name}.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows), encoding="utf-8")
    return root


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    ws = _workspace(tmp_path_factory.mktemp("margins") / "ws")
    assert main(["verify", "-w", str(ws)]) == 0
    out: dict[str, Any] = json.loads((ws / "reports" / "assurance.json").read_text(encoding="utf-8"))
    check_report(out)  # the schema declares the margins part
    out["_html"] = (ws / "reports" / "assurance.html").read_text(encoding="utf-8")
    out["_md"] = (ws / "reports" / "assurance.md").read_text(encoding="utf-8")
    return out


def test_the_smallest_margin_over_the_runs_is_named_with_its_run_and_time(report: dict[str, Any]) -> None:
    [m] = report["margins"]
    assert (m["node"], m["guarantee"], m["source"]) == ("Brake", 1, "contracts/brake.rcl:6:3")
    assert abs(m["margin"] - 0.04) < 1e-9 and m["atom"] == "out.speed <= in.dist" and m["holds"] is None
    assert m["trace"] == "runs/one.jsonl" and m["time"] == 2.01 and m["obligation"].startswith("Brake.")
    assert (m["runs"], m["answers"], m["undefined"], m["count"], m["kept"]) == (2, 5, 0, 5, 5)
    # margins 0.04, 0.1, 0.3, 0.5, 1.0: min the 1st, p5 the ceil(0.25) = 1st, p50 the ceil(2.5) = 3rd; all kept
    got = {k: (round(m[k]["low"], 9), round(m[k]["high"], 9)) for k in ("min", "p5", "p50")}
    assert got == {"min": (0.04, 0.04), "p5": (0.04, 0.04), "p50": (0.3, 0.3)}
    # and its smallest time margin over the runs, with the run's obligation and the answer
    tm = m["time_margin"]
    assert tm["margin_ns"] == 30_000_000 and (tm["answers"], tm["unanswered"]) == (5, 0)
    assert tm["answer_where"] == "two.jsonl:4" and tm["obligation"] != m["obligation"]
    # the first screen names it, in HTML and Markdown
    first = report["_html"][:report["_html"].index('<section id="dashboard">')]
    assert 'id="margins"' in first and "<strong>0.04</strong>" in first and "runs/one.jsonl, 2.010 s" in first
    assert "- Brake guarantee 1: 0.04 on `out.speed <= in.dist` at " in report["_md"]
    assert "time margin <strong>30.000 ms</strong>" in first and "time margin 30.000 ms (answer two.jsonl:4)" in report["_md"]


def test_the_distribution_over_runs_is_plotted(report: dict[str, Any]) -> None:
    pytest.importorskip("matplotlib", reason="the plots extra (matplotlib) is not installed: no plot is drawn")
    [m] = report["margins"]
    assert "plot_note" not in m and m["plot_svg"].startswith("<svg")
    assert "one.jsonl" in m["plot_svg"] and "two.jsonl" in m["plot_svg"]  # one column per run
    assert '<figure class="plot"><svg' in report["_html"]


def test_a_quantile_the_kept_margins_do_not_decide_is_given_by_its_bounds() -> None:
    # run A judged 1000 answers and kept its 256 smallest (0 .. 255): the other 744 are at least 255
    a = SpaceMargin(guarantee=1, answers=1000, lowest=[float(i) for i in range(KEPT_MARGINS)])
    b = SpaceMargin(guarantee=1, answers=10, lowest=[1000.0 + i for i in range(10)])
    count, kept, fig = figures([a, b])
    assert (count, kept) == (1010, KEPT_MARGINS + 10)
    assert fig["min"] == MarginBounds(low=0.0, high=0.0)
    assert fig["p5"] == MarginBounds(low=50.0, high=50.0)  # rank 51: decided by the kept margins
    assert fig["p50"] == MarginBounds(low=255.0, high=None)  # rank 505: past the kept, at least run A's largest
    # a run that kept fewer than it judged without being full: the rest held without a distance (+inf)
    count, kept, fig = figures([SpaceMargin(guarantee=1, answers=3, lowest=[0.5])])
    assert (count, kept, fig["p50"]) == (3, 3, MarginBounds(low=None, high=None))


def test_a_long_run_draws_its_kept_margins_spread_in_rank() -> None:
    from rclverify.report.margin_plot import POINTS_PER_RUN, _spread
    ys = [float(i) for i in range(KEPT_MARGINS)]
    drawn = _spread(ys)
    assert len(drawn) == POINTS_PER_RUN and drawn[0] == 0.0 and drawn[-1] == KEPT_MARGINS - 1
    assert drawn == sorted(set(drawn)) and _spread(ys[:5]) == ys[:5]


ONE_RUN_PLAN = """name: one run, many forms
contracts: [contracts/brake.rcl]
nodes:
  Brake:
    evidence:
      - backend: monitors
        traces: [runs/run.jsonl, runs/noted.jsonl, runs/sq, runs/mc, runs/other.jsonl]
        mapping: contracts/mapping.yaml
        target: violation probability <= 50 % at 90 % per answer
"""
#: (time s, dist, speed answered 10 ms later): margins 0.3 and 0.04
ONE_RUN = ((1.0, 1.0, 0.7), (2.0, 2.0, 1.96))


def _forms(root: Path, store: Any) -> None:
    """One run as a log, the log with a field no rule reads on each line, an sqlite3 bag and an MCAP bag;
    and another run (its second answer 1.9, not 1.96): the control."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    rows = [r for t, d, s in ONE_RUN for r in ({"topic": "dist", "time": t, "data": d},
                                               {"topic": "speed", "time": t + 0.01, "data": s})]
    write = lambda name, rs: (root / "runs" / name).write_text("".join(json.dumps(r) + "\n" for r in rs))  # noqa: E731
    write("run.jsonl", rows)
    write("noted.jsonl", [{**r, "note": f"copied {k}"} for k, r in enumerate(rows)])
    write("other.jsonl", [{**r, "data": 1.9} if r["data"] == 1.96 else r for r in rows])
    float64 = store.types["std_msgs/msg/Float64"]
    for name, plugin, version in (("sq", StoragePlugin.SQLITE3, 8), ("mc", StoragePlugin.MCAP, 9)):
        with Writer(root / "runs" / name, version=version, storage_plugin=plugin) as w:
            conns = {t: w.add_connection(f"/{t}", "std_msgs/msg/Float64", typestore=store) for t in ("dist", "speed")}
            for r in rows:
                w.write(conns[r["topic"]], round(r["time"] * 1e9), store.serialize_cdr(float64(data=r["data"]),
                                                                                        "std_msgs/msg/Float64"))


def test_a_run_in_many_forms_is_one_run_in_the_margins_and_the_statistics(tmp_path: Path) -> None:
    """Issues 106 and 107: one run given as a log, an sqlite3 bag, an MCAP bag and a copy with an unread
    field was counted as four runs in the margins row (and the copy as a second run in the statistics);
    each part counts it once, by its identity over the fields the mapping reads.  Control: a run with a
    read value changed is another run."""
    pytest.importorskip("rosbags")
    from rclverify.traces.bag import typestore
    ws = tmp_path / "ws"
    for d in ("contracts", "runs"):
        (ws / d).mkdir(parents=True)
    (ws / "contracts" / "brake.rcl").write_text(BRAKE, encoding="utf-8")
    (ws / "contracts" / "plan.yaml").write_text(ONE_RUN_PLAN, encoding="utf-8")
    (ws / "contracts" / "mapping.yaml").write_text(
        "horizon: 1.0\ntopics:\n  dist: {fields: [data]}\n  speed: {fields: [data]}\n", encoding="utf-8")
    _forms(ws, typestore([]))
    assert main(["verify", "-w", str(ws)]) == 0
    report = json.loads((ws / "reports" / "assurance.json").read_text(encoding="utf-8"))
    ev = {e["obligation"]: e for e in report["evidence"]}
    assert sum(1 for o in ev if ".monitors." in o and "runs_" not in o) == 5  # every form judged
    [row] = report["margins"]
    assert (row["runs"], row["answers"], row["count"]) == (2, 4, 4)  # the run and the control, once each
    assert abs(row["margin"] - 0.04) < 1e-9
    # the statistics: the node's runs and the target's, each the same two runs with their four answers
    rows = {r["kind"]: r["counts"] for r in report["statistics"]}
    assert {k: (c["runs"], c["duplicates"], c["answers"]) for k, c in rows.items()} == {"runs": (2, 3, 4),
                                                                                         "target": (2, 3, 4)}
