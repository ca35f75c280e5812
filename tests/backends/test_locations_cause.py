"""Locations at the cause (issue 48): a property-test failure shown at the
boundary the contract names and located at the implementation line the
failing example takes, the comparison with the slip (evidence, SARIF, report); Hoare culprit lines only
the constants the program compares with, in line order."""
from __future__ import annotations

import json
from pathlib import Path

from rclverify.backends.hoare import lang
from rclverify.backends.hoare.culprit_lines import compared_constants
from rclverify.backends.property_tests.backend import PropertyTestsBackend
from rclverify.app.pipeline import Workspace

RCL = """// The speed governor: slow near obstacles.
node SpeedGovernor {
  inputs( speed_request : REAL, clearance : REAL )
  outputs( speed : REAL )
  assume( 0 <= in.speed_request and in.speed_request <= 3 and 0 <= in.clearance and in.clearance <= 10 )
  // guarantee 1: at most 0.5 within 2.0 of an obstacle
  guarantee( in.clearance <= 2.0 -> out.speed <= 0.5 )
}
"""
IMPL = '''"""The speed governor's logic (a seeded defect: the boundary is on the wrong side)."""
from __future__ import annotations

SLOW = 0.5
NEAR = 2.0


def governor(speed_request: float, clearance: float) -> dict[str, float]:
    """Slow near obstacles."""
    if clearance < NEAR:
        return {"speed": min(speed_request, SLOW)}
    speed = speed_request
    return {"speed": speed}
'''
STATEFUL = '''"""The governor as a class: it remembers the last clearance (same defect)."""


class Governor:
    def __init__(self):
        self.seen = 0

    def step(self, speed_request, clearance):
        self.seen += 1
        if clearance < 2.0:
            return {"speed": min(speed_request, 0.5)}
        return {"speed": speed_request}
'''


def _ws(tmp: Path, impl: str = IMPL, attr: str = "governor") -> Path:
    (tmp / "contracts").mkdir(parents=True)
    (tmp / "nodes").mkdir()
    (tmp / "contracts/speed_governor.rcl").write_text(RCL)
    (tmp / "nodes/speed_governor.py").write_text(impl)
    (tmp / "contracts/plan.yaml").write_text(
        "contracts: [contracts/speed_governor.rcl]\nnodes:\n  SpeedGovernor:\n    evidence:\n"
        f"      - backend: property_tests\n        implementation: nodes/speed_governor.py:{attr}\n"
        "        max_examples: 100\n")
    return tmp


def _run(root: Path):  # type: ignore[no-untyped-def]
    ws = Workspace(root)
    target = ws.target("SpeedGovernor", 0)
    backend = PropertyTestsBackend()
    return backend.run(backend.export(target)[0], target)


def test_the_failure_is_at_the_boundary_and_at_the_implementation_line(tmp_path: Path) -> None:
    ev = _run(_ws(tmp_path))
    cex = ev.counterexample
    assert ev.status == "failed" and cex is not None
    # the boundary the contract names first, and a short value where Hypothesis shrank to 0.5000000000000001
    assert list(cex)[:2] == ["in.clearance", "in.speed_request"] and cex["boundary"] == "in.clearance"
    assert cex["in.clearance"] == "2.0" and float(cex["in.speed_request"]) > 0.5
    assert len(cex["in.speed_request"].split(".")[-1]) <= 3
    assert float(cex["out.speed"]) > 0.5  # still a failure: the harness confirmed it with Z3
    assert cex["cause"] == "nodes/speed_governor.py:10"  # `if clearance < NEAR`: the slip that sent it down this branch
    assert "nodes/speed_governor.py:10" in ev.explanation


def test_a_class_is_replayed_to_its_failing_step(tmp_path: Path) -> None:
    ev = _run(_ws(tmp_path, STATEFUL, "Governor"))
    assert ev.status == "failed" and ev.counterexample is not None
    assert ev.counterexample["cause"] == "nodes/speed_governor.py:10"  # `if clearance < 2.0`


def test_sarif_and_report_put_the_failure_on_the_implementation_line(tmp_path: Path) -> None:
    from rclverify.cli.commands import main
    ws = _ws(tmp_path)
    (ws / "dodo.py").write_text("from pathlib import Path\nfrom rclverify.app.tasks import build_tasks, doit_config\n"
                                "DOIT_CONFIG = doit_config()\nglobals().update(build_tasks(Path(__file__).parent))\n")
    main(["verify", "-w", str(ws)])
    sarif = json.loads((ws / "reports/assurance.sarif").read_text())
    res = next(r for r in sarif["runs"][0]["results"] if r["partialFingerprints"]["rclverifyItem/v1"].startswith("obligation:"))
    loc = res["locations"][0]["physicalLocation"]
    assert (loc["artifactLocation"]["uri"], loc["region"]["startLine"]) == ("nodes/speed_governor.py", 10)
    rel = res["relatedLocations"][0]["physicalLocation"]
    assert (rel["artifactLocation"]["uri"], rel["region"]["startLine"]) == ("contracts/speed_governor.rcl", 7)
    html = (ws / "reports/assurance.html").read_text()
    assert "Where the implementation goes wrong" in html and "nodes/speed_governor.py:10" in html
    report = json.loads((ws / "reports/assurance.json").read_text())
    d = next(x for x in report["diagnoses"] if x["kind"] == "property-test")
    assert "nodes/speed_governor.py:10" in d["sentence"]


PROGRAM = """var x : REAL;
var y : REAL;
var out : REAL;

out := 0;
x := y + 7;
while (x < 40) invariant (TRUE) do
   x := x + 1
end;
IF (y < 120) THEN
   out := 1
ELSE
   IF (y < 25) THEN
      out := 2
   ELSE
      out := 3
"""


def test_hoare_culprits_are_the_compared_constants_in_line_order() -> None:
    prog = lang.parse_program(PROGRAM, "p.imp")
    got = [(n.loc.line, n.text) for n in compared_constants(prog)]
    assert got == [(7, "40"), (10, "120"), (13, "25")]  # not out := 0, x := y + 7, x + 1 (assignments)


def test_the_problem_row_lists_program_lines_in_natural_order() -> None:
    from rclverify.report.problems import group_problems
    report = {"nodes": [], "requirements": [], "side_conditions": [], "obligations": [], "evidence": [],
              "findings": [], "deadlines": [],
              "diagnoses": [{"id": "N.g1.hoare.p.c1", "kind": "hoare", "node": "N", "status": "failed",
                             "sentence": "s.", "repairs": [], "counterexample": [],
                             "culprits": [{"what": "p.imp line 13", "source": "p.imp:13", "text": "25"},
                                          {"what": "p.imp line 9", "source": "p.imp:9", "text": "120"}]}]}
    items = [{"status": "failed", "kind": "hoare", "ref": "N.g1.hoare.p.c1", "anchor": "x", "message": "s."}]
    from _typed_rows import ungrouped_report  # the grouping reads the report decoded: the parts left out completed empty
    groups = group_problems(ungrouped_report(report), items, lambda *a: "-".join(map(str, a)))
    g = next(g for g in groups if any(c["source"].startswith("p.imp") for c in g.culprits))
    assert [c["source"] for c in g.culprits] == ["p.imp:9", "p.imp:13"]
