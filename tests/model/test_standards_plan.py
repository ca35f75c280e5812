"""The plan's ``standards:`` key (model/plan/standards/choice.py, docs/standards.md): a profile and its
level read, and each mistake one located error naming what there is."""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.model.plan.errors import PlanError
from rclverify.model.plan.load import load_plan

PLAN = "contracts/plan.yaml"
HEAD = "name: s\ncontracts: [contracts/a.rcl]\n"
RCL = "node A {\n  inputs( x : INTEGER )\n  outputs( y : INTEGER )\n  guarantee( out.y >= 0 )\n}\n"


def _load(tmp_path: Path, tail: str) -> object:
    (tmp_path / "contracts").mkdir(exist_ok=True)
    (tmp_path / "contracts" / "a.rcl").write_text(RCL, encoding="utf-8")
    (tmp_path / PLAN).write_text(HEAD + tail, encoding="utf-8")
    return load_plan(tmp_path, PLAN)


def _error(tmp_path: Path, tail: str) -> str:
    with pytest.raises(PlanError) as info:
        _load(tmp_path, tail)
    assert len(info.value.diagnostics) == 1
    return str(info.value.diagnostics[0])


def test_profiles_and_levels_are_read(tmp_path: Path) -> None:
    plan = _load(tmp_path, "standards:\n  - {profile: iec61508-3, sil: 2}\n  - {profile: ul4600}\n"
                           "  - {profile: do-333, level: B}\n")
    got = [(c.profile.id, c.level) for c in plan.standards]  # type: ignore[attr-defined]
    assert got == [("iec61508-3", "2"), ("ul4600", None), ("do-333", "B")]


def test_no_standards_is_none(tmp_path: Path) -> None:
    assert _load(tmp_path, "").standards == ()  # type: ignore[attr-defined]


def test_unknown_profile_names_the_profiles(tmp_path: Path) -> None:
    msg = _error(tmp_path, "standards:\n  - {profile: iec61508-9, sil: 2}\n")
    assert msg.startswith(f"{PLAN}:4:15: error: unknown standard profile 'iec61508-9'; the profiles are: ")
    assert "iec61508-3" in msg and "ul4600" in msg


def test_a_level_outside_the_profile(tmp_path: Path) -> None:
    msg = _error(tmp_path, "standards:\n  - profile: iec61508-3\n    sil: 5\n")
    assert msg.startswith(f"{PLAN}:5:10: error:") and "the levels are 1, 2, 3, 4" in msg


def test_a_missing_level_and_a_foreign_key(tmp_path: Path) -> None:
    assert "needs one level, 'sil: ' one of 1, 2, 3, 4" in _error(tmp_path, "standards:\n  - {profile: iec61508-3}\n")
    msg = _error(tmp_path, "standards:\n  - profile: ul4600\n    sil: 2\n")
    assert msg.startswith(f"{PLAN}:5:5: error:") and "it has no levels" in msg


def test_a_profile_chosen_twice(tmp_path: Path) -> None:
    assert "chosen twice" in _error(tmp_path, "standards:\n  - {profile: ul4600}\n  - {profile: ul4600}\n")


def test_a_user_profile_file(tmp_path: Path) -> None:
    (tmp_path / "std").mkdir()
    (tmp_path / "std" / "mine.yaml").write_text(
        "id: mine\ntitle: Mine\nedition: In-house 1\nitems:\n"
        "  - {id: M1, title: proved, evidence: [proof], strength: proof, recommendation: HR}\n", encoding="utf-8")
    plan = _load(tmp_path, "standards:\n  - {profile: std/mine.yaml}\n")
    assert plan.standards[0].profile.id == "mine"  # type: ignore[attr-defined]
    (tmp_path / "std" / "mine.yaml").write_text("id: mine\ntitle: Mine\nedition: x\nitems: []\n", encoding="utf-8")
    assert _error(tmp_path, "standards:\n  - {profile: std/mine.yaml}\n").startswith("std/mine.yaml:4:8: error:")
    assert "inside the workspace" in _error(tmp_path, "standards:\n  - {profile: ../x.yaml}\n")


def test_strict_is_true_or_false(tmp_path: Path) -> None:
    """``strict:`` opts a standard into the --strict gate; anything but a boolean is one located error."""
    from rclverify.model.plan.standards.choice import read_standards
    from rclverify.model.plan.errors import PlanError
    from rclverify.lang.ast import Loc
    (choice,) = read_standards(tmp_path, {"standards": [{"profile": "ul4600", "strict": True}]},
                               {("standards", 0): Loc("plan.yaml", 3, 5)}, "plan.yaml")
    assert choice.strict is True
    (plain,) = read_standards(tmp_path, {"standards": [{"profile": "ul4600"}]}, {}, "plan.yaml")
    assert plain.strict is False
    with pytest.raises(PlanError, match="'strict' is true or false"):
        read_standards(tmp_path, {"standards": [{"profile": "ul4600", "strict": "yes"}]}, {}, "plan.yaml")


# --- what the plan says of a clause: a narrowed scope with its reason, a justification -------------

WHY = "B and C carry no safety function per hazard log H-3 revision 2"


def test_a_clause_note_is_read(tmp_path: Path) -> None:
    plan = _load(tmp_path, "standards:\n  - profile: iec61508-3\n    sil: 2\n    clauses:\n"
                           f"      B.8 6c: {{nodes: [A], reason: only A is safety related, justification: {WHY}}}\n")
    note = plan.standards[0].clauses["B.8 6c"]  # type: ignore[attr-defined]
    assert (note.nodes, note.reason, note.justification, note.at) == (
        ("A",), "only A is safety related", WHY, "contracts/plan.yaml:7:7")


def test_narrowing_a_clause_asked_at_the_level_needs_a_full_justification(tmp_path: Path) -> None:
    """A 3-word reason narrowed an HR clause and passed --strict: narrowing a clause asked at the level
    needs a justification of at least 8 words; a clause not asked there (A.9 1 is R at SIL 2) is the control."""
    msg = _error(tmp_path, "standards:\n  - profile: iec61508-3\n    sil: 2\n    clauses:\n"
                           "      B.8 6c: {nodes: [A], reason: only A matters, justification: reviewed by QA}\n")
    assert msg.startswith("contracts/plan.yaml:7:") and "is asked at this level (HR)" in msg
    assert "at least 8 words" in msg
    plan = _load(tmp_path, "standards:\n  - profile: iec61508-3\n    sil: 2\n    clauses:\n"
                           "      A.9 1: {nodes: [A], reason: only A matters}\n")
    assert plan.standards[0].clauses["A.9 1"].nodes == ("A",)  # type: ignore[attr-defined]


def test_a_clause_the_profile_lacks_is_located(tmp_path: Path) -> None:
    msg = _error(tmp_path, "standards:\n  - profile: iec61508-3\n    sil: 2\n    clauses:\n"
                           "      A.7 3: {justification: modelling is done by hand}\n")
    assert msg.startswith("contracts/plan.yaml:7:7: error:") and "'A.7 3' is not a clause of profile" in msg


def test_narrowing_needs_a_reason(tmp_path: Path) -> None:
    msg = _error(tmp_path, "standards:\n  - profile: iec61508-3\n    sil: 2\n    clauses:\n"
                           "      B.8 6c: {nodes: [A]}\n")
    assert msg.startswith("contracts/plan.yaml:7:23: error:") and "needs a 'reason' of at least three words" in msg
    msg = _error(tmp_path, "standards:\n  - profile: iec61508-3\n    sil: 2\n    clauses:\n"
                           "      B.8 6c: {nodes: [A], reason: fine, scope: all}\n")
    assert msg.startswith("contracts/plan.yaml:7:42: error:") and "'scope' is not a key here" in msg
