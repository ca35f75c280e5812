"""Side conditions in context through the whole pipeline (issue 43): the
report, SARIF, JUnit and the GSN argument keep `discharged in context` apart
from `discharged`, a failure in context shows the whole cone, and an edit
two nodes upstream re-decides a side condition exactly as a clean run does
(the compose stage's input is its cone's digest)."""
from __future__ import annotations

import json
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from _chain import write_chain


def _verify(ws: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "doit", "verify"], cwd=ws, capture_output=True, text=True,
                          timeout=600)


def _report(ws: Path) -> dict:
    return json.loads((ws / "reports/assurance.json").read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def chain(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Six nodes, node 3's guarantee weakened to +70: N1-N3 discharged in context, N4 onwards failed."""
    ws = write_chain(tmp_path_factory.mktemp("chain") / "ws", 6, weak={3: 70})
    proc = _verify(ws)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return ws


def test_the_report_keeps_the_verdict_and_the_whole_cone(chain: Path) -> None:
    r = _report(chain)
    sc = {s["id"]: s for s in r["side_conditions"]}
    assert [k for k, s in sc.items() if s["verdict"] == "discharged in context"] == ["N1.sc2", "N2.sc2", "N3.sc2"]
    assert sc["N2.sc2"]["status"] == "discharged" and sc["N2.sc2"]["context"]["used_nodes"] == ["N0", "N1"]
    assert sc["N1.sc1"]["verdict"] == "discharged" and sc["N1.sc1"]["context"] is None
    failed = sc["N4.sc2"]
    assert failed["status"] == "failed" and failed["variant"] == "in context"
    assert set(failed["model"]) == {"N0.in.x0", "N0.out.x1", "N1.out.x2", "N2.out.x3", "N3.out.x4"}  # whole cone
    assert "(3 in context)" in r["summary"]["headline"]
    assert "Side condition N4.sc2 is failed (checked in context too): in.x4 <= 100" in r["summary"]["problems"]
    md = (chain / "reports/assurance.md").read_text(encoding="utf-8")
    assert "in context" in md and "Discharged in context" in md
    # a side condition discharged in context is no problem: no diagnosis row; a failed one keeps its row
    diagnosed = {d["id"] for d in r.get("diagnoses", [])}
    assert "N4.sc2" in diagnosed and not diagnosed & {"N1.sc2", "N2.sc2", "N3.sc2"}


def test_sarif_junit_and_the_argument_keep_the_distinction(chain: Path) -> None:
    sarif = json.loads((chain / "reports/assurance.sarif").read_text(encoding="utf-8"))
    results = sarif["runs"][0]["results"]
    notes = [x for x in results if x["ruleId"] == "RCL-SC-IN-CONTEXT"]
    assert sorted(x["properties"]["sideCondition"] for x in notes) == ["N1.sc2", "N2.sc2", "N3.sc2"]
    assert all(x["level"] == "note" and x["properties"]["verdict"] == "discharged in context" for x in notes)
    assert "N0 guarantee 1" in notes[0]["properties"]["inContext"]["used"]
    refuted = [x for x in results if x["ruleId"] == "RCL-SC-REFUTED"]
    assert {x["properties"]["sideCondition"] for x in refuted} == {"N4.sc2", "N5.sc2"}
    root = ET.parse(chain / "reports/assurance.junit.xml").getroot()
    case = root.find(".//testcase[@name='N2.sc2']")
    assert case is not None and case.find("failure") is None  # a pass ...
    out = case.find("system-out")
    assert out is not None and "verdict: discharged in context" in (out.text or "")  # ... that says on what
    arg = json.loads((chain / "reports/argument.json").read_text(encoding="utf-8"))
    els = {e["id"]: e for e in arg["elements"]} if isinstance(arg.get("elements"), list) else arg["elements"]
    goal = els["G-sc.N2.sc2"]
    assert "in context" in goal["text"] and "J-context" in goal["in_context_of"]
    assert "in context" not in els["G-sc.N1.sc1"]["text"]


def test_an_edit_two_nodes_upstream_re_decides_as_a_clean_run_does(chain: Path, tmp_path: Path) -> None:
    inc = tmp_path / "inc"
    shutil.copytree(chain, inc, symlinks=True)
    plan = inc / "contracts/plan.yaml"  # x0 up to 99: x2 <= 101 in context, N2's assumption fails
    plan.write_text(plan.read_text(encoding="utf-8").replace("in.x0 <= 50", "in.x0 <= 99"), encoding="utf-8")
    proc = _verify(inc)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "N2: compose" in proc.stdout  # N0's snapshot changed, N2 is not its consumer: its cone digest did
    clean = tmp_path / "clean"
    clean.mkdir()
    for item in ("contracts", "dodo.py"):
        (shutil.copytree if (inc / item).is_dir() else shutil.copy)(inc / item, clean / item)
    assert _verify(clean).returncode == 0

    def verdicts(ws: Path) -> dict:
        return {s["id"]: (s["status"], s["verdict"], s["model"]) for s in _report(ws)["side_conditions"]}
    assert verdicts(inc) == verdicts(clean)
    assert verdicts(inc)["N2.sc2"][0] == "failed"
