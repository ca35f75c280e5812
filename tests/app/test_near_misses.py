"""Near misses (docs/monitors.md, "Near misses"): a guarantee held on every run
with a margin under the plan's ``near_miss`` threshold is named in the report,
in SARIF at the guarantee's line (level warning), in JUnit, in the summary
verify ends with, and fails --strict as a warning does; the control, the same
run under a threshold below its margins, is not named; a threshold that does
not read is a located plan error."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from _report_schema import check_report
from rclverify.cli.commands import main

BRAKE = """node Brake{x} {{
  inputs( dist : REAL )
  outputs( speed : REAL )
  topics( std_msgs/Float64 {y}_dist matches(in.dist), std_msgs/Float64 {y}_speed matches(out.speed) )
  assume( TRUE )
  guarantee( out.speed <= in.dist ) triggered by in.dist within 100 ms
}}
"""
PLAN = """name: brakes
contracts: [contracts/brake.rcl]
nodes:
  BrakeA:
    evidence:
      - {{backend: monitors, traces: [runs/run.jsonl], mapping: contracts/mapping.yaml, near_miss: {a}}}
  BrakeB:
    evidence:
      - {{backend: monitors, traces: [runs/run.jsonl], mapping: contracts/mapping.yaml, near_miss: {b}}}
"""
# each brake: dist 1.0 answered 10 ms later by speed 0.7, dist 2.0 answered 70 ms later by speed 1.96
# (smallest margins: 0.04 in value, 30 ms in time)
RUN = sorted(({"topic": f"{x}_{t}", "time": s, "data": v} for x in "ab" for t, s, v in
              (("dist", 1.0, 1.0), ("speed", 1.01, 0.7), ("dist", 2.0, 2.0), ("speed", 2.07, 1.96))),
             key=lambda r: float(r["time"]))  # type: ignore[arg-type]


def _workspace(root: Path, a: str, b: str) -> Path:
    for d in ("contracts", "runs"):
        (root / d).mkdir(parents=True, exist_ok=True)
    (root / "contracts" / "brake.rcl").write_text(BRAKE.format(x="A", y="a") + BRAKE.format(x="B", y="b"), encoding="utf-8")
    (root / "contracts" / "plan.yaml").write_text(PLAN.format(a=a, b=b), encoding="utf-8")
    (root / "contracts" / "mapping.yaml").write_text("horizon: 1.0\n", encoding="utf-8")
    (root / "runs" / "run.jsonl").write_text("".join(json.dumps(r) + "\n" for r in RUN), encoding="utf-8")
    return root


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict[str, Any], dict[str, Any], dict[str, Any]]:
    # A's threshold is above its margins (named), B's below them (the control: not named)
    ws = _workspace(tmp_path_factory.mktemp("nm") / "ws", "{value: 0.05, time: 50 ms}", "{value: 0.03, time: 20 ms}")
    assert main(["verify", "-w", str(ws)]) == 0
    read = lambda p: json.loads((ws / p).read_text(encoding="utf-8"))  # noqa: E731
    out = read("reports/assurance.json"), read("reports/assurance.sarif"), read("artifacts/report/summary.json")
    out[0]["_junit"] = (ws / "reports" / "assurance.junit.xml").read_text(encoding="utf-8")
    out[0]["_md"] = (ws / "reports" / "assurance.md").read_text(encoding="utf-8")
    out[0]["_html"] = (ws / "reports" / "assurance.html").read_text(encoding="utf-8")
    return out


def test_a_margin_under_the_threshold_is_named_and_the_control_is_not(run) -> None:
    report, _, _ = run
    rows = report["near_misses"]
    assert [(r["node"], r["kind"]) for r in rows] == [("BrakeA", "value"), ("BrakeA", "time")]
    value, time = rows
    assert abs(value["margin"] - 0.04) < 1e-9 and value["threshold"] == 0.05 and value["atom"] == "out.speed <= in.dist"
    assert abs(time["margin"] - 0.03) < 1e-9 and time["threshold"] == 0.05 and time["where"] == value["where"]
    assert value["source"] == "contracts/brake.rcl:6:3" and value["threshold_source"].startswith("contracts/plan.yaml:6:")
    # the report keeps to its schema, which declares the near misses and the runs' margins
    check_report({k: v for k, v in report.items() if not k.startswith("_")})
    assert "Smallest margins</th><td>guarantee 1: <strong>0.04" in report["_html"]
    [m] = next(e for e in report["evidence"] if e["obligation"].startswith("BrakeA."))["monitoring"]["margins"]
    assert [round(x, 9) for x in m["lowest"]] == [0.04, 0.3]
    # a near miss changes no status: both held; but it is a warning, so --strict fails and names it
    assert {o["node"]: o["status"] for o in report["obligations"]} == {"BrakeA": "discharged", "BrakeB": "discharged"}
    assert report["meta"]["strict_ok"] is False


def test_junit_and_strict_name_them_as_the_warnings_they_are(run) -> None:
    import xml.etree.ElementTree as ET
    report, _, summary = run
    [suite] = [s for s in ET.fromstring(report["_junit"]) if s.get("name") == "near_misses"]
    assert (suite.get("tests"), suite.get("failures")) == ("2", "2")
    assert {c.get("name") for c in suite} == {"BrakeA.g0.monitors.run_jsonl.g1.value", "BrakeA.g0.monitors.run_jsonl.g1.time"}
    assert summary["strict"] == ["2 near misses: a margin under the plan's near_miss threshold (BrakeA guarantee 1)"]


def test_sarif_and_the_first_screen_name_them(run, capsys) -> None:
    _, sarif, summary = run
    res = [r for r in sarif["runs"][0]["results"] if r["ruleId"] == "RCL-NEAR-MISS"]
    assert len(res) == 2 and {r["level"] for r in res} == {"warning"}
    loc = res[0]["locations"][0]["physicalLocation"]
    assert loc["artifactLocation"]["uri"].endswith("contracts/brake.rcl") and loc["region"]["startLine"] == 6
    assert "BrakeA guarantee 1 held with margin 0.04" in res[0]["message"]["text"]
    lines = summary["near_misses"]
    assert lines[0].startswith("near misses: 2 ") and all("BrakeB" not in x for x in lines)
    assert any("answered 30.000 ms before its deadline" in x for x in lines)
    # the report's first section lists them too
    md, html = run[0]["_md"], run[0]["_html"]
    block = md[md.index("**Near misses**"):md.index("**Smallest margins**")]  # every guarantee's margins follow
    assert md.index("**Near misses**") < md.index("**Smallest margins**") < md.index("## System model")
    assert "BrakeA guarantee 1: margin 0.04" in block and "BrakeB" not in block
    assert '<h3 id="near-misses">' in html[:html.index('id="system"')]


@pytest.mark.parametrize("bad, at, says", [
    ("{value: -1}", 9, "near_miss value must be a finite number > 0"),
    ("{time: 20}", 9, "near_miss time '20' must be a positive number and a unit"),
    ("{speed: 1}", 9, "near_miss has no key 'speed'"),
    ("3", 9, "near_miss must be a mapping"),
])
def test_a_threshold_that_does_not_read_is_a_located_plan_error(tmp_path, capsys, bad, at, says) -> None:
    ws = _workspace(tmp_path / "ws", "{value: 0.05}", bad)
    assert main(["verify", "-w", str(ws)]) != 0
    err = capsys.readouterr()
    text = err.out + err.err
    assert f"contracts/plan.yaml:{at}:" in text and says in text and "Traceback" not in text


RELAY = """node Copy {
  inputs( ox : REAL )
  outputs( px : REAL )
  topics( std_msgs/Float64 c_in matches(in.ox), std_msgs/Float64 c_out matches(out.px) )
  guarantee( out.px == in.ox )
}
node Below {
  inputs( ox : REAL )
  outputs( px : REAL )
  topics( std_msgs/Float64 b_in matches(in.ox), std_msgs/Float64 b_out matches(out.px) )
  guarantee( out.px <= in.ox )
}
"""
RELAY_PLAN = """name: relays
contracts: [contracts/relay.rcl]
nodes:
  Copy:
    evidence:
      - {backend: monitors, traces: [runs/run.jsonl], mapping: contracts/mapping.yaml, near_miss: {value: 0.1}}
  Below:
    evidence:
      - {backend: monitors, traces: [runs/run.jsonl], mapping: contracts/mapping.yaml, near_miss: {value: 0.1}}
"""


def test_an_exact_copy_is_never_a_near_miss_and_a_bound_met_at_zero_is(tmp_path: Path) -> None:
    """Issue 107: ``out.px == in.ox`` right on every answer had margin 0, below every threshold, so a
    correct relay was a near miss on each answer; an equality that holds has no distance to a boundary
    (docs/semantics.md, "Margins"): the report says it held without one.  Control: ``out.px <= in.ox``
    met with equality is right by 0, and still a near miss."""
    ws = tmp_path / "ws"
    for d in ("contracts", "runs"):
        (ws / d).mkdir(parents=True)
    (ws / "contracts" / "relay.rcl").write_text(RELAY, encoding="utf-8")
    (ws / "contracts" / "plan.yaml").write_text(RELAY_PLAN, encoding="utf-8")
    (ws / "contracts" / "mapping.yaml").write_text("horizon: 1.0\n", encoding="utf-8")
    rows = [{"topic": f"{x}_{t}", "time": k + (0.01 if t == "out" else 0.0), "data": v}
            for k, v in enumerate((0.5, 1.25, 3.0)) for t in ("in", "out") for x in "cb"]  # each answer copies
    (ws / "runs" / "run.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows), encoding="utf-8")
    assert main(["verify", "-w", str(ws)]) == 0
    report = json.loads((ws / "reports" / "assurance.json").read_text(encoding="utf-8"))
    assert {o["node"]: o["status"] for o in report["obligations"]} == {"Copy": "discharged", "Below": "discharged"}
    assert [(r["node"], r["margin"]) for r in report["near_misses"]] == [("Below", 0.0)]
    margins = {r["node"]: r for r in report["margins"]}
    assert (margins["Copy"]["margin"], margins["Copy"]["holds"], margins["Copy"]["answers"]) == (None, True, 3)
    assert (margins["Below"]["margin"], margins["Below"]["answers"]) == (0.0, 3)
