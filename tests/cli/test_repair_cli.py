"""``rclverify repair ID [--apply]`` (issue 111; cli/repair.py, diagnosis/apply_repair.py, docs/diagnosis.md
"Applying a repair"): the checked repairs of a problem of the last report printed, nothing written; with
``--apply`` the edit written only over the text it was checked on, then the failing check run again by the
pipeline's own stage and its new verdict printed.

One workspace, verified once: ``Gate`` (a ``<`` for ``<=`` slip in its code: a property test fails),
``Router`` feeding ``Follower`` and ``Tail`` (a producer's bound over both consumers' assumption: two side
conditions fail, one problem) and
``Odd`` (code no one- or two-token edit repairs: its guarantee pins ``small`` to ``v <= 5`` both ways, where
``in.v <= 5 -> out.small`` let a two-token edit make ``small`` always true: no repair offered).  The controls: a file changed after the run is
refused and left as it is; an unknown id and a problem with no repair end in one located line."""
from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from rclverify.cli.commands import main

pytestmark = pytest.mark.slow  # a whole pipeline run (tests/conftest.py, "Tiers")

RCL = """\
node Gate {
  inputs( x : INTEGER )
  outputs( ok : BOOL )
  assume( 0 <= in.x and in.x <= 10 )
  guarantee( in.x <= 3 -> out.ok )
  guarantee( in.x >= 4 -> not out.ok )
}

node Odd {
  inputs( v : INTEGER )
  outputs( small : BOOL )
  assume( 0 <= in.v and in.v <= 10 )
  guarantee( out.small <=> in.v <= 5 )
}

node Router {
  inputs( goal : NATURAL )
  outputs( n : NATURAL )
  guarantee( out.n <= 64 )
}

node Follower {
  inputs( n : NATURAL )
  outputs( done : BOOL )
  assume( in.n <= 50 )
  guarantee( out.done == TRUE )
}

node Tail {
  inputs( n : NATURAL )
  outputs( seen : BOOL )
  assume( in.n <= 50 )
  guarantee( out.seen == TRUE )
}
"""
GATE = '"""The gate (a seeded slip: < for <=)."""\n\n\ndef gate(x):\n    return {"ok": x < 3}\n'
ODD = '"""No one- or two-token edit makes this right."""\n\n\ndef odd(v):\n    return {"small": v % 2 == 1}\n'
PLAN = """contracts: [contracts/robot.rcl]
nodes:
  Gate:
    evidence:
      - {backend: property_tests, implementation: "nodes/gate.py:gate", max_examples: 60}
  Odd:
    evidence:
      - {backend: property_tests, implementation: "nodes/odd.py:odd", max_examples: 60}
"""
GATE_ID = "Gate.g1.property_tests.e0"


@pytest.fixture(scope="module")
def ws(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("repair_cli") / "ws"
    (root / "contracts").mkdir(parents=True)
    (root / "nodes").mkdir()
    (root / "contracts/robot.rcl").write_text(RCL, encoding="utf-8")
    (root / "contracts/plan.yaml").write_text(PLAN, encoding="utf-8")
    (root / "nodes/gate.py").write_text(GATE, encoding="utf-8")
    (root / "nodes/odd.py").write_text(ODD, encoding="utf-8")
    main(["verify", "-w", str(root)])
    return root


def _run(ws: Path, capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(["repair", "-w", str(ws), *args])
    out, err = capsys.readouterr()
    return code, out, err


def test_printed_not_written(ws: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = _run(ws, capsys, GATE_ID)
    assert code == 0 and err == ""
    assert f"for {GATE_ID} (code)" in out and '+    return {"ok": x <= 3}' in out
    assert "checked: Gate.g2.property_tests.e0: discharged" in out and "nothing written" in out
    assert (ws / "nodes/gate.py").read_text(encoding="utf-8") == GATE


def test_unknown_id_and_no_repair_end_in_one_located_line(ws: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = _run(ws, capsys, "Gate.g9.nothing", "--apply")
    assert code == 1 and out == "" and len(err.splitlines()) == 1
    assert re.match(r"^.*reports/assurance\.json:1:1: error: no problem 'Gate\.g9\.nothing'", err)
    odd = "Odd.g1.property_tests.e0"
    code, out, err = _run(ws, capsys, odd)  # asked to print: says why, exit 0
    assert code == 0 and f"{odd}: no checked repair is offered" in out and "no edit the diagnosis tried" in out
    code, out, err = _run(ws, capsys, odd, "--apply")  # asked to apply: nothing to apply, exit 1
    assert code == 1 and "nothing to apply" in err and "Traceback" not in err
    assert (ws / "nodes/odd.py").read_text(encoding="utf-8") == ODD


def test_a_file_changed_since_the_check_is_refused(ws: Path, capsys: pytest.CaptureFixture[str]) -> None:
    changed = GATE + "# edited after the run\n"
    (ws / "nodes/gate.py").write_text(changed, encoding="utf-8")
    try:
        code, out, err = _run(ws, capsys, GATE_ID, "--apply")
        assert code == 1 and out == "" and len(err.splitlines()) == 1 and "Traceback" not in err
        assert f"{ws / 'nodes/gate.py'}:5:" in err and "changed since the last run checked this repair" in err
        assert (ws / "nodes/gate.py").read_text(encoding="utf-8") == changed  # nothing written
    finally:
        (ws / "nodes/gate.py").write_text(GATE, encoding="utf-8")


def test_applied_and_the_property_tests_run_again(ws: Path, capsys: pytest.CaptureFixture[str]) -> None:
    report = json.loads((ws / "reports/assurance.json").read_text(encoding="utf-8"))
    [d] = [x for x in report["diagnoses"] if x["id"] == GATE_ID]
    k = 1 + next(i for i, r in enumerate(d["repairs"]) if r["edit"]["inserted"] == "<=")
    code, out, err = _run(ws, capsys, GATE_ID, "--apply", "--index", str(k))
    assert code == 0 and err == "", err
    assert f"  {GATE_ID}: failed -> discharged" in out and "  Gate.g2.property_tests.e0: discharged -> discharged" in out
    assert (ws / "nodes/gate.py").read_text(encoding="utf-8") == GATE.replace("x < 3", "x <= 3")
    # applied twice: the file is no longer the text the repair was checked on
    code, out, err = _run(ws, capsys, GATE_ID, "--apply", "--index", str(k))
    assert code == 1 and "changed since the last run" in err
    assert (ws / "nodes/gate.py").read_text(encoding="utf-8") == GATE.replace("x < 3", "x <= 3")


def test_a_contract_repair_is_applied_and_the_side_conditions_composed_again(
        ws: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Asked by the problem's number: the producer's repair, and both consumers' side conditions checked."""
    report = json.loads((ws / "reports/assurance.json").read_text(encoding="utf-8"))
    k = 1 + next(i for i, p in enumerate(report["problems"])
                 if {"Follower.sc1", "Tail.sc1"} <= {m["id"] for m in p["members"]})
    before = (ws / "contracts/robot.rcl").read_text(encoding="utf-8")
    code, out, err = _run(ws, capsys, f"p{k}", "--apply")
    assert code == 0 and err == "", err
    assert "  Follower.sc1: failed -> discharged" in out and "  Tail.sc1: failed -> discharged" in out
    after = (ws / "contracts/robot.rcl").read_text(encoding="utf-8")
    assert after != before and "out.n <= 64" not in after
