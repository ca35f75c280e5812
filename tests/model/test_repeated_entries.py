"""Two evidence entries that would give the same obligations (issue 39:
doit aborted ``verify`` with "duplicated definition"): the same entry twice
is a located error of ``rclverify check`` and ``doit check``; two entries
whose files share a name (their obligations are named by it) are refused,
located, when the obligations are exported."""
from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from rclverify.cli.commands import main
from rclverify.model.plan.errors import PlanError

REPO = Path(__file__).resolve().parents[2]
HOARE = """      - backend: hoare
        program: backends/hoare/radiation_sensor.imp
        binding:
          in.r: radiation_at(i)
          out.radiationStatus: output
"""


def _copy(tmp: Path, extra: str) -> Path:
    ws = tmp / "ws"
    shutil.copytree(REPO / "contracts", ws / "contracts")
    shutil.copytree(REPO / "backends", ws / "backends")
    plan = ws / "contracts" / "plan.yaml"
    text = plan.read_text()
    assert HOARE in text
    plan.write_text(text.replace(HOARE, HOARE + extra, 1))
    return ws


def test_the_same_entry_twice_is_a_located_error_of_check(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    ws = _copy(tmp_path, HOARE)
    monkeypatch.chdir(ws)
    assert main(["check", "contracts/remote_inspection.rcl", "contracts/agent_repaired.rcl"]) == 1
    err = capsys.readouterr().err
    line = next(x for x in err.splitlines() if "twice" in x)
    assert line.startswith("contracts/plan.yaml:") and ": error: node RadiationSensor has this hoare entry twice" \
        in line and "Traceback" not in err


def test_entries_whose_obligations_share_names_are_refused_at_export(tmp_path: Path) -> None:
    ws = _copy(tmp_path, HOARE.replace("backends/hoare/radiation_sensor.imp", "backends/other/radiation_sensor.imp"))
    (ws / "backends" / "other").mkdir()
    shutil.copy(ws / "backends" / "hoare" / "radiation_sensor.imp", ws / "backends" / "other")
    from rclverify.app.pipeline import Workspace, stage_export
    with pytest.raises(PlanError) as e:
        stage_export(Workspace(ws), "RadiationSensor")
    text = str(e.value)
    plan = (ws / "contracts" / "plan.yaml").read_text()
    first = plan[:plan.index(HOARE)].count("\n") + 1  # the line of the first entry's `- backend: hoare`
    assert text.startswith("contracts/plan.yaml:") and "gives obligation RadiationSensor.g1.hoare.radiation_sensor" \
        in text and f"which the entry at contracts/plan.yaml:{first}:" in text
