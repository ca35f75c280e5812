"""examples/fret_rover decided in-process: seven FRET requirements proved from the rover's contract (the
eighth not translated, informal), and an
edited export re-checked by reqid (docs/requirements.md, "Requirements from FRET")."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

from rclverify.app.pipeline import stage_check, stage_requirements
from rclverify.stages.workspace import Workspace
from rclverify.tools.fret.importer import import_fret

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "fret_rover"


def _verdicts(root: Path) -> dict[str, tuple[str, bool]]:
    ws = Workspace(root, "contracts/plan.yaml")
    stage_check(ws)
    return {rec["id"]: (str(rec.get("verdict")), now) for rec, now in stage_requirements(ws)}


def test_the_example_decides_its_fret_requirements_and_rechecks_an_edited_one(tmp_path: Path) -> None:
    root = tmp_path / "ws"
    shutil.copytree(EXAMPLE, root, ignore=shutil.ignore_patterns("artifacts", "reports", ".doit*"))
    first = _verdicts(root)
    assert {k: v for k, (v, _) in first.items()} == {
        "CAP": "proved", "ROVER-001": "proved", "ROVER-002": "proved", "ROVER-003": "proved",
        "ROVER-004": "proved", "ROVER-005": "proved", "ROVER-006": "proved", "ROVER-007": "proved",
        "ROVER-008": "informal"}
    data = json.loads((root / "fret" / "rover_requirements.json").read_text(encoding="utf-8"))
    r1 = next(r for r in data["requirements"] if r["reqid"] == "ROVER-001")
    r1["fulltext"] = "the rover shall always satisfy speed <= 1.0"
    r1["semantics"]["post_condition"] = "(speed <= 1.0)"
    edited = tmp_path / "rover.json"
    edited.write_text(json.dumps(data), encoding="utf-8")
    res = import_fret(root, "contracts/plan.yaml", edited, "rover.json")
    assert (res.added, res.changed, res.removed) == ([], ["ROVER-001"], [])
    again = _verdicts(root)
    assert again["ROVER-001"] == ("refuted", True)  # the edited requirement, checked again: the contract allows 2
    assert [k for k, (_, now) in again.items() if now] == ["ROVER-001"]  # only it
