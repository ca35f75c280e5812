"""The one-token repair of a refuted Hoare triple's program (issue 111; diagnosis/hoare_tokens.py,
docs/diagnosis.md "Refuted Hoare triple: the one-token correction"): when no change of constants repairs
the program, an operator's slip is corrected and offered only when Z3 discharges every triple of the edited
program again; ``rclverify repair --apply`` writes it and the backend proves the triple again.

One workspace, verified once: ``Door``'s program tests ``x <= 10`` where its contract opens below 10 (its
constants are the contract's: the constant change has nothing to offer), ``Swap``'s program has its
branches the wrong way round (no one-token edit repairs it: the control, nothing offered)."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.hoare import lang
from rclverify.cli.commands import main
from rclverify.diagnosis.hoare_tokens import token_edits

pytestmark = pytest.mark.slow  # a whole pipeline run (tests/conftest.py, "Tiers")

RCL = """\
node Door {
  inputs( x : NATURAL )
  outputs( ok : BOOL )
  guarantee( in.x < 10 -> out.ok == TRUE )
  guarantee( in.x >= 10 -> out.ok == FALSE )
}

node Swap {
  inputs( x : NATURAL )
  outputs( ok : BOOL )
  guarantee( in.x < 10 -> out.ok == TRUE )
}
"""
PROGRAM = """\
var x : NATURAL;
var ok : BOOL;

if x <= 10 then
  ok := TRUE
else
  ok := FALSE
end
"""
SWAPPED = PROGRAM.replace("x <= 10", "x < 10").replace("TRUE", "T").replace("FALSE", "TRUE").replace("T\n", "FALSE\n")
PLAN = """contracts: [contracts/robot.rcl]
nodes:
  Door:
    evidence:
      - {backend: hoare, program: programs/door.imp, binding: {in.x: x, out.ok: ok}}
  Swap:
    evidence:
      - {backend: hoare, program: programs/swap.imp, binding: {in.x: x, out.ok: ok}}
"""


@pytest.fixture(scope="module")
def verified(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    ws = tmp_path_factory.mktemp("hoare_tokens") / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "programs").mkdir()
    (ws / "contracts/robot.rcl").write_text(RCL, encoding="utf-8")
    (ws / "contracts/plan.yaml").write_text(PLAN, encoding="utf-8")
    (ws / "programs/door.imp").write_text(PROGRAM, encoding="utf-8")
    (ws / "programs/swap.imp").write_text(SWAPPED, encoding="utf-8")
    main(["verify", "-w", str(ws)])
    report = json.loads((ws / "reports/assurance.json").read_text(encoding="utf-8"))
    return {"ws": ws, "report": report, "diagnoses": {d["id"]: d for d in report["diagnoses"]}}


def test_the_candidates_are_the_operator_then_the_numbers() -> None:
    edits = token_edits(PROGRAM, "programs/door.imp", lang.parse_program(PROGRAM, "programs/door.imp"))
    assert [(e.line, e.col, e.end_col, e.text) for e in edits] == [(4, 6, 8, "<"), (4, 9, 11, "9"), (4, 9, 11, "11")]


def test_the_strictness_slip_is_offered_checked_by_z3(verified: dict[str, Any]) -> None:
    failed = [d for d in verified["diagnoses"].values() if d["node"] == "Door" and d["kind"] == "hoare"]
    assert failed and all(d["status"] == "failed" for d in failed)
    reps = failed[0]["repairs"]
    assert [r["kind"] for r in reps] == ["program"] * len(reps) and 1 <= len(reps) <= 2
    first = reps[0]
    assert first["edit"]["deleted"] == "<=" and first["edit"]["inserted"] == "<"
    assert "-if x <= 10 then\n+if x < 10 then" in first["diff"]
    assert first["checks"] and all(c["status"] == "discharged (Z3: proved)" for c in first["checks"])
    assert first["checked_by"].startswith("z3 ")
    assert (verified["ws"] / "programs/door.imp").read_text(encoding="utf-8") == PROGRAM  # never applied unasked


def test_control_no_one_token_edit_repairs_swapped_branches(verified: dict[str, Any]) -> None:
    failed = [d for d in verified["diagnoses"].values() if d["node"] == "Swap" and d["kind"] == "hoare"]
    assert failed and all(d["repairs"] == [] for d in failed)


def test_applied_and_proved_again(verified: dict[str, Any], capsys: pytest.CaptureFixture[str]) -> None:
    ws = verified["ws"]
    oid = next(d["id"] for d in verified["diagnoses"].values() if d["node"] == "Door" and d["kind"] == "hoare")
    assert main(["repair", "-w", str(ws), oid, "--apply"]) == 0
    out = capsys.readouterr().out
    assert f"{oid}: failed -> discharged" in out, out
    assert (ws / "programs/door.imp").read_text(encoding="utf-8") == PROGRAM.replace("x <= 10", "x < 10")
