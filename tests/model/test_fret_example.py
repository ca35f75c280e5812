"""examples/fret_rover decided in-process: ten FRET requirements proved from the rover's contract (one of
them, a trigger inside a mode, from FRET's ptExpanded; one over an Internal variable defined in Lustre;
ROVER-008 over FRET's sqrt, RCL's own), and an
edited export re-checked by reqid (docs/requirements.md, "Requirements from FRET")."""
from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest

from rclverify.app.pipeline import stage_check, stage_requirements
from rclverify.stages.workspace import Workspace
from rclverify.tools.fret.importer import import_fret

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "fret_rover"


def _verdicts(root: Path) -> dict[str, tuple[str, bool]]:
    ws = Workspace(root, "contracts/plan.yaml")
    stage_check(ws)
    return {rec["id"]: (str(rec.get("verdict")), now) for rec, now in stage_requirements(ws)}


@pytest.fixture(scope="module")
def checked(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, tuple[str, bool]]]:
    """The example copied without its outputs and its requirements decided once for the module: the
    workspace (records included) and the verdicts.  A test copies the workspace whole and starts from
    its records, as a user's next run does; the records seal the inputs' text, not their path."""
    root = tmp_path_factory.mktemp("fret") / "ws"
    shutil.copytree(EXAMPLE, root, ignore=shutil.ignore_patterns("artifacts", "reports", ".doit*"))
    return root, _verdicts(root)


def _checked_copy(checked: tuple[Path, dict[str, tuple[str, bool]]], tmp_path: Path) -> Path:
    root = tmp_path / "ws"
    shutil.copytree(checked[0], root)
    return root


def test_the_example_decides_its_fret_requirements_and_rechecks_an_edited_one(
        checked: tuple[Path, dict[str, tuple[str, bool]]], tmp_path: Path) -> None:
    root = _checked_copy(checked, tmp_path)
    first = checked[1]
    assert all(now for _, now in first.values())  # decided by the fixture's run, each of them
    assert {k: v for k, (v, _) in first.items()} == {
        "CAP": "proved", "ROVER-001": "proved", "ROVER-002": "proved", "ROVER-003": "proved",
        "ROVER-004": "proved", "ROVER-005": "proved", "ROVER-006": "proved", "ROVER-007": "proved",
        "ROVER-008": "proved", "ROVER-009": "proved",
        "ROVER-010": "proved"}
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
    reqids = {r["reqid"] for r in data["requirements"]}
    assert _matrix_ids(root) == reqids | {"CAP"}
    removed = {**data, "requirements": [r for r in data["requirements"] if r["reqid"] != "ROVER-008"]}
    edited.write_text(json.dumps(removed), encoding="utf-8")
    assert import_fret(root, "contracts/plan.yaml", edited, "rover.json").removed == ["ROVER-008"]
    _verdicts(root)
    assert _matrix_ids(root) == reqids - {"ROVER-008"} | {"CAP"}  # the control: the matrix follows the export


def _matrix_ids(root: Path) -> set[str]:
    """The requirement ids of the trace matrix (``rclverify standards --trace``) of ``root``'s report; a
    FRET requirement's is its reqid, and the assertion names any id that is neither the export's nor the
    plan's own."""
    from rclverify.report.build import build_report
    from rclverify.report.standards_sheets import trace_rows
    rows = trace_rows(build_report(Workspace(root, "contracts/plan.yaml")))
    assert rows[0][:2] == ["requirement", "requirement verdict"]
    ids = {r[0] for r in rows[1:] if r[0]}
    export = json.loads((root / "fret" / "rover_requirements.json").read_text(encoding="utf-8"))
    unknown = ids - {r["reqid"] for r in export["requirements"]} - {"CAP"}
    assert not unknown, f"the trace matrix names requirements that are not in the export: {sorted(unknown)}"
    return ids


def test_an_edited_export_makes_its_requirement_stale_until_checked_again(
        checked: tuple[Path, dict[str, tuple[str, bool]]], tmp_path: Path) -> None:
    """Each imported requirement's record seals its entry of the export (``fret:<export>#<reqid>``) and
    the export's hash: an edit of ROVER-002's text alone (its statement unchanged) makes its record stale
    in the report, and only its; the next run checks it again, and then equals a clean run."""
    from rclverify.report.build import read_inputs
    from rclverify.stages.requirements import read_records

    root = _checked_copy(checked, tmp_path)
    assert not any(now for _, now in _verdicts(root).values())  # the copy's records are current: nothing re-run
    rec = json.loads((root / "artifacts" / "requirements" / "ROVER-002.json").read_text(encoding="utf-8"))
    export = "fret/rover_requirements.json"
    assert set(rec["inputs"]) >= {f"fret:{export}#ROVER-002", f"fret:{export}"}
    assert "fret:" not in json.dumps(json.loads((root / "artifacts" / "requirements" / "CAP.json").read_text(
        encoding="utf-8"))["inputs"])  # the plan's own requirement reads no export

    def stale() -> list[str]:
        ws = Workspace(root, "contracts/plan.yaml")
        return sorted(k for k, r in read_records(ws, read_inputs(ws).hashes).items() if r["verdict"] == "stale")
    assert stale() == []  # the control: nothing edited, nothing stale
    path = root / export
    data = json.loads(path.read_text(encoding="utf-8"))
    r2 = next(r for r in data["requirements"] if r["reqid"] == "ROVER-002")
    r2["fulltext"] += " (reviewed)"
    path.write_text(json.dumps(data, indent=1), encoding="utf-8")
    assert stale() == ["ROVER-002"]
    again = _verdicts(root)
    assert [k for k, (_, now) in again.items() if now] == ["ROVER-002"]
    assert stale() == []
    clean = tmp_path / "clean"
    shutil.copytree(root, clean, ignore=shutil.ignore_patterns("artifacts", "reports", ".doit*"))
    assert {k: v for k, (v, _) in _verdicts(clean).items()} == {k: v for k, (v, _) in again.items()}


def _compliance_ids(root: Path, export: dict[str, Any]) -> set[str]:
    """The requirement ids the compliance matrix (``rclverify standards --csv``) names in its clause rows'
    items of ``root``'s report; a FRET requirement's is its reqid.  An id that is neither ``export``'s nor
    the plan's own fails the assertion at its row (``compliance matrix row N (clause C)``)."""
    import re
    from rclverify.report.build import build_report
    from rclverify.report.standards_sheets import matrix_rows
    rows = matrix_rows(build_report(Workspace(root, "contracts/plan.yaml")))
    col, clause = rows[0].index("items in scope and their state"), rows[0].index("clause")
    known = {r["reqid"] for r in export["requirements"]} | {"CAP"}
    ids: set[str] = set()
    for n, row in enumerate(rows[1:], start=2):
        named = set(re.findall(r"(?:^|; )requirement (\S+):", row[col]))
        unknown = named - known
        assert not unknown, f"compliance matrix row {n} (clause {row[clause]}): {sorted(unknown)} not in the export"
        ids |= named
    return ids


def test_the_compliance_matrix_names_the_export_reqids(tmp_path: Path) -> None:
    """With a standard chosen (IEC 61508-3, SIL 2), the compliance matrix's clause rows about requirements
    name each imported requirement by its reqid, and none that is not in the export or the plan; a
    requirement removed from the export leaves every row; the control: checked against an export lacking
    one reqid, the rows naming it fail at their row."""
    root = tmp_path / "ws"
    shutil.copytree(EXAMPLE, root, ignore=shutil.ignore_patterns("artifacts", "reports", ".doit*"))
    plan = root / "contracts" / "plan.yaml"
    plan.write_text(plan.read_text(encoding="utf-8") + "\nstandards:\n  - {profile: iec61508-3, sil: 2}\n",
                    encoding="utf-8")
    _verdicts(root)
    data = json.loads((root / "fret" / "rover_requirements.json").read_text(encoding="utf-8"))
    assert _compliance_ids(root, data) == {r["reqid"] for r in data["requirements"]} | {"CAP"}
    short = {**data, "requirements": [r for r in data["requirements"] if r["reqid"] != "ROVER-009"]}
    try:  # the control: checked against an export without ROVER-009, the rows naming it are errors
        _compliance_ids(root, short)
    except AssertionError as exc:
        assert "['ROVER-009'] not in the export" in str(exc) and "compliance matrix row " in str(exc)
    else:
        raise AssertionError("a reqid not in the export was not found in the matrix")
    removed = {**data, "requirements": [r for r in data["requirements"] if r["reqid"] != "ROVER-008"]}
    edited = tmp_path / "rover.json"
    edited.write_text(json.dumps(removed), encoding="utf-8")
    assert import_fret(root, "contracts/plan.yaml", edited, "rover.json").removed == ["ROVER-008"]
    _verdicts(root)
    assert _compliance_ids(root, removed) == {r["reqid"] for r in removed["requirements"]} | {"CAP"}
