"""One root cause, one problem, one first repair (issue 48): a service
answering up to 64 waypoints to a client whose buffer holds the named
constant ``RouteBuffer = 50`` gave a side-condition row whose first repair
added a redundant guarantee (which then failed ``--strict``) and a
requirement row with another first repair."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from rclverify.cli.commands import main

ROUTE = """context {
  RouteBuffer : NATURAL = 50 ;
}
node Router {
  inputs( goal : NATURAL )
  outputs( n : NATURAL )
  guarantee( out.n <= 64 )
}
node Follower {
  inputs( n : NATURAL )
  outputs( ok : BOOL )
  assume( in.n <= RouteBuffer )
  guarantee( out.ok == TRUE )
}
"""
PLAN = """name: route
contracts:
  - contracts/route.rcl
requirements:
  - id: FIT
    text: every route fits the follower's buffer
    formal: "Router.out.n <= RouteBuffer"
"""


@pytest.fixture(scope="module")
def ws(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("route") / "ws"
    (root / "contracts").mkdir(parents=True)
    (root / "contracts/route.rcl").write_text(ROUTE)
    (root / "contracts/plan.yaml").write_text(PLAN)
    assert main(["verify", "-w", str(root)]) == 0
    return root


def test_one_problem_whose_first_repair_tightens_the_bound_to_the_constant(ws: Path) -> None:
    r = json.loads((ws / "reports/assurance.json").read_text())
    rows = [g for g in r["problems"] if "Follower.sc1" in [m["id"] for m in g["members"]]]
    assert len(rows) == 1 and "FIT" in [m["id"] for m in rows[0]["members"]]
    assert not [g for g in r["problems"] if [m["id"] for m in g["members"]] == ["FIT"]]
    first = rows[0]["repairs"][0]
    d = next(x for x in r["diagnoses"] if x["id"] == first["diagnosis"])
    rep = d["repairs"][first["index"]]
    assert "tighten the bound of its guarantee 1 in place, `out.n <= 64` becoming `out.n <= RouteBuffer`" in \
        rep["summary"], rep["summary"]
    assert "-  guarantee( out.n <= 64 )\n+  guarantee( out.n <= RouteBuffer )" in rep["diff"]


def test_with_the_first_repair_applied_strict_passes_but_for_the_missing_evidence(ws: Path, tmp_path: Path) -> None:
    root = tmp_path / "ws"
    shutil.copytree(ws, root)
    rcl = root / "contracts/route.rcl"
    rcl.write_text(rcl.read_text().replace("guarantee( out.n <= 64 )", "guarantee( out.n <= RouteBuffer )"))
    main(["verify", "-w", str(root)])
    r = json.loads((root / "reports/assurance.json").read_text())
    assert all(sc["status"] == "discharged" for sc in r["side_conditions"])
    assert next(q for q in r["requirements"] if q["id"] == "FIT")["verdict"] != "refuted"
    assert not any(f["status"] in ("warning", "problem") for f in r["findings"]), r["findings"]  # nothing redundant
