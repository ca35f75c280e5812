"""Tests of the review backend: checklist generation, the record's verdict
mapping, staleness when a reviewed file changes, located plan errors, and
``rclverify review``."""
from __future__ import annotations

import hashlib
from pathlib import Path

import pytest
import yaml

from rclverify.backends.review.record import checklist, parse_record
from rclverify.cli.commands import main
from rclverify.records.store import EvidenceStore
from rclverify.app.pipeline import Workspace, stage_check, stage_export, stage_run
from rclverify.app.tasks import act_check

from _evidence_ws import copy_workspace, plan_line, replace_in_plan

RECORD = "backends/review/localisation.yaml"
OID = "Localisation.g1.review.e0"


@pytest.fixture()
def ws(tmp_path: Path) -> Workspace:
    copy_workspace(tmp_path)
    return Workspace(tmp_path)


def run(ws: Workspace):  # type: ignore[no-untyped-def]
    stage_check(ws)
    ids = [o.id for o in stage_export(ws, "Localisation")]
    assert ids == [OID]
    return stage_run(ws, "Localisation", OID)


def write_record(ws: Workspace, **changes: object) -> None:
    data = yaml.safe_load((ws.root / RECORD).read_text(encoding="utf-8"))
    data.update(changes)
    (ws.root / RECORD).write_text(yaml.safe_dump(data), encoding="utf-8")


def reviewed_file(ws: Workspace) -> dict[str, str]:
    src = ws.root / "src/localisation.py"
    src.parent.mkdir(parents=True, exist_ok=True)
    src.write_text("def position(msg):\n    return msg.pose.position\n", encoding="utf-8")
    return {"path": "src/localisation.py", "sha256": hashlib.sha256(src.read_bytes()).hexdigest()}


def test_checklist_has_one_question_per_conjunct_with_its_location(ws: Workspace) -> None:
    qs = checklist(ws.checked.nodes["Localisation"])
    assert [q.id for q in qs] == ["g1.c1"]
    assert qs[0].location == "contracts/remote_inspection.rcl:37:14"
    assert "exists_unique(x, y in REAL | out.position(x, y))" in qs[0].question
    rad = checklist(ws.checked.nodes["Agent"])
    assert [q.id for q in rad][:3] == ["g1.c1", "g2.c1", "g3.c1"]


def test_bundled_record_is_the_papers_review_and_stays_pending(ws: Workspace) -> None:
    rec = parse_record((ws.root / RECORD).read_text(encoding="utf-8"), RECORD)
    assert rec.assumption == "TRUE" and rec.conjuncts == {"g1.c1": "exists_unique(x, y in REAL | out.position(x, y))"}
    assert rec.reviewer.startswith("not named in the paper") and rec.date == "not given in the paper"
    assert rec.answers == {"g1.c1": "yes"} and rec.verdict == "pass" and rec.files == ()
    ev = run(ws)
    assert ev.status == "pending" and "lists no reviewed file" in ev.explanation


def test_all_yes_and_pass_with_files_is_discharged_and_editing_a_file_makes_it_stale(ws: Workspace) -> None:
    write_record(ws, files=[reviewed_file(ws)], reviewer="A. Reviewer", date="2026-01-02")
    ev = run(ws)
    assert ev.status == "discharged", ev.explanation
    assert "src/localisation.py" in ev.input_hashes  # the reviewed file is an input of the obligation
    (ws.root / "src/localisation.py").write_text("def position(msg):\n    return None\n", encoding="utf-8")
    assert EvidenceStore(ws.root).current_status(ev) == "stale"
    again = stage_run(Workspace(ws.root), "Localisation", OID)
    assert again.status == "stale" and "reviewed file src/localisation.py changed" in again.explanation


def test_a_no_answer_fails_naming_the_question(ws: Workspace) -> None:
    write_record(ws, files=[reviewed_file(ws)],
                 checklist=[{"id": "g1.c1", "answer": "no", "note": "two estimates while converging",
                             "conjunct": "exists_unique(x, y in REAL | out.position(x, y))"}])
    ev = run(ws)
    assert ev.status == "failed"
    assert "answered no to g1.c1 (contracts/remote_inspection.rcl:37:14)" in ev.explanation
    assert "two estimates while converging" in ev.explanation


def test_verdict_fail_fails_and_unanswered_is_pending(ws: Workspace) -> None:
    write_record(ws, files=[reviewed_file(ws)], verdict="fail")
    assert run(ws).status == "failed"
    write_record(ws, verdict="pass", checklist=[{"id": "g1.c1", "answer": None}])  # no text named: still pending
    ev = run(Workspace(ws.root))
    assert ev.status == "pending" and "g1.c1 not answered" in ev.explanation


def test_record_missing_a_question_is_stale(ws: Workspace) -> None:
    write_record(ws, files=[reviewed_file(ws)], checklist=[{"id": "g2.c1", "answer": "yes"}])
    ev = run(ws)
    assert ev.status == "stale" and "regenerate it with `rclverify review Localisation`" in ev.explanation


def test_missing_record_is_a_located_error_at_check_time(ws: Workspace) -> None:
    replace_in_plan(ws.root, f"record: {RECORD}", "record: backends/review/nope.yaml")
    line, col = plan_line(ws.root, "backends/review/nope.yaml")
    out = str(act_check(str(ws.root)))
    assert f"contracts/plan.yaml:{line}:{col}: error: review record 'backends/review/nope.yaml' does not exist" in out


def test_malformed_record_is_a_located_error(ws: Workspace) -> None:
    (ws.root / RECORD).write_text("node: Localisation\nreviewer: x\n", encoding="utf-8")
    line, col = plan_line(ws.root, RECORD)
    out = str(act_check(str(ws.root)))
    assert f"contracts/plan.yaml:{line}:{col}: error: review record: {RECORD}: missing field(s)" in out


def test_review_command_writes_a_record_to_fill_in(ws: Workspace, capsys: pytest.CaptureFixture[str]) -> None:
    reviewed_file(ws)
    out = ws.root / "backends/review/new.yaml"
    assert main(["review", "Localisation", "-w", str(ws.root), "-o", str(out), "-f", "src/localisation.py"]) == 0
    rec = parse_record(out.read_text(encoding="utf-8"), "new.yaml")
    assert rec.node == "Localisation" and rec.answers == {"g1.c1": None} and rec.verdict is None
    assert rec.files[0][0] == "src/localisation.py"
    assert "# guarantee 1, contracts/remote_inspection.rcl:37:14" in out.read_text(encoding="utf-8")
    (ws.root / RECORD).write_text(out.read_text(encoding="utf-8"), encoding="utf-8")
    assert run(ws).status == "pending"
    assert main(["review", "Nowhere", "-w", str(ws.root)]) == 2


def test_conjuncts_split_at_top_level_and_only() -> None:
    from rclverify.backends.review.record import _conjuncts
    from rclverify.lang.parser import parse_formula
    f = parse_formula("out.a == 1 and (out.b == 2 and out.c == 3) and (out.d == 1 or out.e == 2)", "x.rcl", 1, 1)
    parts = _conjuncts(f)
    assert len(parts) == 4 and [p.loc.col for p in parts][:2] == [1, 17]


def test_an_alias_bomb_in_a_review_record_is_refused_before_expansion() -> None:
    from rclverify.backends.review.record import parse_record
    from rclverify.model.plan.errors import PlanError
    bomb = "a: &a [x, x, x, x, x, x, x, x, x, x]\n" + "".join(
        f"{chr(98 + k)}: &{chr(98 + k)} [*{chr(97 + k)}, *{chr(97 + k)}, *{chr(97 + k)}, *{chr(97 + k)}, "
        f"*{chr(97 + k)}, *{chr(97 + k)}, *{chr(97 + k)}, *{chr(97 + k)}, *{chr(97 + k)}, *{chr(97 + k)}]\n"
        for k in range(8))
    with pytest.raises(PlanError, match="alias bomb"):
        parse_record(bomb, "backends/review/bomb.yaml")


def test_review_writes_the_record_the_plan_names_when_it_is_missing(ws: Workspace, capsys) -> None:
    """Issue 48: once the plan named FILE, `rclverify review NODE -o FILE` refused to run (the plan's
    check wanted FILE), and its error said to run that same command."""
    (ws.root / RECORD).unlink()
    rc = main(["review", "Localisation", "-w", str(ws.root), "-o", str(ws.root / RECORD)])
    assert rc == 0 and (ws.root / RECORD).is_file()
    assert parse_record((ws.root / RECORD).read_text(encoding="utf-8"), RECORD).node == "Localisation"
    # any other command still refuses the plan while the record is missing
    (ws.root / RECORD).unlink()
    assert main(["review", "Localisation", "-w", str(ws.root), "-o", str(ws.root / "other.yaml")]) != 0
    assert "does not exist" in capsys.readouterr().err


def test_an_answer_binds_to_the_text_it_answered_not_the_guarantee_number(ws: Workspace) -> None:
    """Issue 63, row 1: a review answered for one guarantee text does not
    discharge the guarantee once its text changed (or the assumption did),
    and a record that names no text discharges nothing."""
    write_record(ws, files=[reviewed_file(ws)], reviewer="A. Reviewer", date="2026-01-02")
    assert run(ws).status == "discharged"
    rcl = ws.root / "contracts/remote_inspection.rcl"
    text = rcl.read_text(encoding="utf-8")
    assert text.count("exists_unique(x, y in REAL | out.position(x, y))") == 1
    rcl.write_text(text.replace("exists_unique(x, y in REAL | out.position(x, y))",
                                "exists_unique(x, y in REAL | out.position(x, y) and x >= 0.0)"), encoding="utf-8")
    ev = run(Workspace(ws.root))
    assert ev.status == "stale", ev.explanation
    assert "answered g1.c1 for 'exists_unique(x, y in REAL | out.position(x, y))'" in ev.explanation
    assert "remote_inspection.rcl:37:14 now reads" in ev.explanation
    rcl.write_text(text, encoding="utf-8")
    write_record(ws, assumption="in.x > 0.0")
    ev = run(Workspace(ws.root))
    assert ev.status == "stale" and "made under the assumption 'in.x > 0.0'" in ev.explanation
    data = yaml.safe_load((ws.root / RECORD).read_text(encoding="utf-8"))
    data.pop("assumption")
    data["checklist"][0].pop("conjunct")
    (ws.root / RECORD).write_text(yaml.safe_dump(data), encoding="utf-8")
    ev = run(Workspace(ws.root))
    assert ev.status == "stale" and "does not say which assumption" in ev.explanation
