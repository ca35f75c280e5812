"""The safety-stop example as shipped under ``--strict`` (issue 64): red, for the reasons its README gives.

examples/safety_stop is no seeded-defect example, but it cannot be green
honestly: Teleop's timed guarantee and Mission's guarantee have no evidence
(the button is on no topic of the recorded run, Mission's one goal comes
from the operator's command line before any input).  One ``verify
--strict`` of a copy (about 3 s): exit 1, every obligation discharged and
both deadlines proved, the two unverified guarantees the only problems, and
the strict reasons the README quotes.  Real Z3, Hypothesis, Hoare and doit.
"""
from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest

from rclverify.cli.commands import main

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "safety_stop"


@pytest.fixture(scope="module")
def strict(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    ws = tmp_path_factory.mktemp("safety_stop") / "ws"
    shutil.copytree(EXAMPLE, ws, ignore=shutil.ignore_patterns("artifacts", "reports", ".doit*", "__pycache__"))
    rc = main(["verify", "-w", str(ws), "--strict"])
    return {"rc": rc, "report": json.loads((ws / "reports/assurance.json").read_text(encoding="utf-8")),
            "summary": json.loads((ws / "artifacts/report/summary.json").read_text(encoding="utf-8"))}


def test_strict_fails_only_on_the_two_guarantees_nothing_can_evidence(strict: dict[str, Any]) -> None:
    report = strict["report"]
    assert strict["rc"] == 1
    assert report["obligations"] and all(o["status"] == "discharged" for o in report["obligations"])
    assert sorted(k for p in report["problems"] for k in p["key"]) == ["unverified:Mission", "unverified:Teleop"]
    deadlines = {d["requirement"]: (d["verdict"], d["status"]) for d in report["deadlines"]}
    assert deadlines == {"STOP": ("proved", "unverified"), "MOVE-FEEDBACK": ("proved", "discharged")}
    assert strict["summary"]["strict"] == [
        "2 guarantees are unverified (no obligation covers them): Teleop.g1, Mission.g1",
        "1 end-to-end deadline is proved from a chain whose evidence is outstanding "
        "(a hop unverified, or its deadline measured by no run: STOP)"]


def test_the_readme_says_what_strict_says(strict: dict[str, Any]) -> None:
    readme = " ".join((EXAMPLE / "README.md").read_text(encoding="utf-8").split())
    assert "--strict` exits 1" in readme
    assert strict["summary"]["strict"][0] in readme
