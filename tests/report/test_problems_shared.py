"""One producer too loose for several consumers is one problem (issue 48).

The MissionPlanner of the delivery example guarantees ``out.dest_id <= 501``
to a Navigator and a LockerController that both assume ``<= 500``: two
failed side conditions, one per consumer, with the same first repair
(tighten the producer's bound in place).  They were two rows, each with
that repair; they are one row whose first repair is that edit.  Side
conditions whose first repairs differ stay rows of their own."""
from __future__ import annotations

import json
from pathlib import Path

from _typed_rows import complete
from rclverify.cli.commands import main
from rclverify.records.problem_rows import DiagnosisRow
from rclverify.report.problems_places import Member
from rclverify.report.problems_shared import join_by_first_repair

SYSTEM = """\
node Planner {
  inputs( order : NATURAL )
  outputs( dest : NATURAL, speed : REAL )
  guarantee( out.dest <= 501 )
  guarantee( out.speed <= 3 )
}
node Driver {
  inputs( dest : NATURAL, speed : REAL )
  outputs( ok : BOOL )
  assume( in.dest <= 500 )
  assume( in.speed <= 2 )
  guarantee( out.ok )
}
node Locker {
  inputs( dest : NATURAL, speed : REAL )
  outputs( door : NATURAL )
  assume( in.dest <= 500 )
  assume( in.speed <= 1 )
  guarantee( out.door <= 3 )
}
"""


def test_consumers_of_one_loose_bound_are_one_row_with_one_first_repair(tmp_path: Path) -> None:
    ws = tmp_path / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/sys.rcl").write_text(SYSTEM, encoding="utf-8")
    (ws / "contracts/plan.yaml").write_text("name: shared\ncontracts: [contracts/sys.rcl]\nrequirements: []\n",
                                            encoding="utf-8")
    assert main(["verify", "-w", str(ws)]) == 0
    report = json.loads((ws / "reports/assurance.json").read_text(encoding="utf-8"))
    rows = {tuple(m["id"] for m in g["members"]): g for g in report["problems"]}
    assert ("Driver.sc1", "Locker.sc1") in rows  # one row for the dest bound, both victims its findings
    assert not [k for k in rows if k in (("Driver.sc1",), ("Locker.sc1",))]
    row = rows[("Driver.sc1", "Locker.sc1")]
    assert [c["what"] for c in row["culprits"]] == ["guarantee 1 of Planner", "assumption 1 of Driver",
                                                    "assumption 1 of Locker"]  # the producer first
    ref = row["repairs"][0]
    rep = next(d for d in report["diagnoses"] if d["id"] == ref["diagnosis"])["repairs"][ref["index"]]
    assert (rep["kind"], rep["edit"]["deleted"], rep["edit"]["inserted"]) == ("strengthen-producer", "501", "500")
    # the speed bound: tightened to 2 for Driver, to 1 for Locker, two different first repairs: two rows
    assert ("Driver.sc2",) in rows and ("Locker.sc2",) in rows


def test_only_failed_side_conditions_with_the_same_first_repair_are_joined() -> None:
    def m(i: str, kind: str = "side-condition", status: str = "failed") -> Member:
        return Member(i, kind, status, "", "", True)

    def d(*diffs: str) -> DiagnosisRow:
        return DiagnosisRow.of(complete(DiagnosisRow, {"repairs": [{"diff": x} for x in diffs]}))
    by_id = {"A.sc1": d("d1"), "B.sc1": d("d1", "x"), "C.sc1": d("d2"), "D.sc1": d(), "E.sc1": d(), "R": d("d1"),
             "F.sc1": d("d1")}
    members = [(m("A.sc1"), ["assumption:A:1", "guarantee:P:1"]), (m("B.sc1"), ["assumption:B:1", "guarantee:P:1"]),
               (m("C.sc1"), ["assumption:C:1", "guarantee:P:1"]), (m("D.sc1"), ["assumption:D:1"]),
               (m("E.sc1"), ["assumption:E:1"]), (m("R", "requirement"), ["guarantee:P:1"]),
               (m("F.sc1", status="unknown"), ["assumption:F:1", "guarantee:P:1"])]
    join_by_first_repair(members, by_id)
    roots = {mm.id: r for mm, r in members}
    assert roots["A.sc1"] == roots["B.sc1"] == ["assumption:A:1", "assumption:B:1", "guarantee:P:1"]
    assert roots["C.sc1"] == ["assumption:C:1", "guarantee:P:1"]  # another first repair
    assert roots["D.sc1"] == ["assumption:D:1"] and roots["E.sc1"] == ["assumption:E:1"]  # no repair: never joined
    assert roots["R"] == ["guarantee:P:1"] and roots["F.sc1"] == ["assumption:F:1", "guarantee:P:1"]


def test_the_producer_comes_before_the_assumptions_it_fails() -> None:
    from rclverify.report.problems_shared import producer_first
    assert producer_first(["assumption:B:1", "assumption:A:2", "guarantee:P:1", "contract:Q", "p.imp:9"]) == [
        "guarantee:P:1", "contract:Q", "p.imp:9", "assumption:B:1", "assumption:A:2"]
    assert producer_first([]) == []
