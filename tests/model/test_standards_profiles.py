"""Standard profiles (docs/standards.md): the built-in ones load, match their schema and their file names,
write only their own titles, and a malformed profile is one located error (model/plan/standards/)."""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.model.plan.errors import PlanError
from rclverify.model.plan.standards.profiles import CODES, builtin_names, load_builtin, load_profile_file, parse_profile

GOOD = """id: mine
title: My profile
edition: In-house 1
level_name: sil
levels: ["1", "2"]
items:
  - id: T 1
    title: Proved
    evidence: [proof]
    strength: proof
    recommendation: {"1": R, "2": HR}
"""


def _error(text: str) -> str:
    with pytest.raises(PlanError) as info:
        parse_profile(text, "std/mine.yaml")
    assert len(info.value.diagnostics) == 1
    return str(info.value.diagnostics[0])


def test_the_builtin_profiles_load_and_are_named_by_their_file() -> None:
    names = builtin_names()
    assert {"iec61508-3", "ul4600", "do-333"} <= set(names)
    assert {"iso13482", "iso10218-1"} & set(names)
    for name in names:
        p = load_builtin(name)
        assert p.id == name and p.items and p.edition
        assert len({i.id for i in p.items}) == len(p.items)
        for item in p.items:
            assert len(item.title) <= 120
            for level in p.levels or (None,):
                assert item.at(level) in CODES


def test_iec61508_3_is_by_sil_with_annex_table_ids() -> None:
    p = load_builtin("iec61508-3")
    assert p.level_name == "sil" and p.levels == ("1", "2", "3", "4")
    proof = {i.id: i for i in p.items}["A.9 1"]
    assert [proof.at(s) for s in p.levels] == ["---", "R", "R", "HR"]
    assert all(i.id.split()[0][0] in "AB" for i in p.items)


def test_unknown_builtin_is_a_key_error() -> None:
    with pytest.raises(KeyError):
        load_builtin("iec99999")


def test_a_good_user_profile_loads(tmp_path: Path) -> None:
    (tmp_path / "mine.yaml").write_text(GOOD, encoding="utf-8")
    p = load_profile_file(tmp_path / "mine.yaml", "std/mine.yaml")
    assert p.id == "mine" and p.items[0].at("2") == "HR" and p.items[0].at("1") == "R"


def test_a_schema_violation_is_located_at_the_value() -> None:
    msg = _error(GOOD.replace("[proof]", "[proofs]"))
    assert msg.startswith("std/mine.yaml:9:16: error:") and "'proofs' is not one of" in msg


def test_an_unknown_key_is_located_at_the_key() -> None:
    assert _error(GOOD + "extra: 1\n").startswith("std/mine.yaml:12:1: error:")


def test_bad_yaml_is_located_where_the_yaml_library_says() -> None:
    assert _error("id: x\n  bad: [\n").startswith("std/mine.yaml:2:6: error: invalid YAML")


def test_a_recommendation_must_name_the_profile_levels() -> None:
    msg = _error(GOOD.replace('{"1": R, "2": HR}', '{"1": R, "3": HR}'))
    assert msg.startswith("std/mine.yaml:11:21: error:") and "levels are 1, 2" in msg


def test_an_item_id_used_twice_names_the_first() -> None:
    text = GOOD + GOOD[GOOD.index("  - id"):]
    msg = _error(text)
    assert "'T 1' is used twice (first at line 7)" in msg and msg.startswith("std/mine.yaml:12:")


# --- the profiles' own text (docs/standards.md, "The built-in profiles") -------------------------

def test_functional_testing_of_the_integrated_system_is_a_7_4_not_modelling() -> None:
    ids = {i.id: i for i in load_builtin("iec61508-3").items}
    assert "A.7 4" in ids and "A.7 3" not in ids and "black-box" in ids["A.7 4"].title
    left = dict(load_builtin("iec61508-3").left_out)
    assert "modelling" in left["A.7 3"] and "A.5 3" in left  # data recording is not run data: left out, said why


def test_standards_that_do_not_grade_hr_r_are_not_shown_so() -> None:
    for name in ("ul4600", "iso13482", "do-333"):
        p = load_builtin(name)
        codes = {i.at(level) for i in p.items for level in (p.levels or (None,))}
        assert codes <= {"required", "---"}, (name, codes)


def test_do_333_codes_follow_the_profiles_own_rule() -> None:
    """``required`` where the table has objectives at the level, ``---`` where none: the low-level requirements
    and source code tables have none at level D, and independence is asked at levels A and B only."""
    items = {i.id: i for i in load_builtin("do-333").items}
    assert [items["FM.A-4"].at(d) for d in "ABCD"] == ["required", "required", "required", "---"]
    assert [items["FM.A-5"].at(d) for d in "ABCD"] == ["required", "required", "required", "---"]
    assert [items["FM.A-7"].independence_at(d) for d in "ABCD"] == ["person", "person", "none", "none"]


OUTCOME_WORDS = ("argued safe", "reach their", "are met", "meet their", "achieved", "shown to", "checked complete",
                 "analysed formally", "qualified")


def test_titles_say_what_a_clause_asks_not_an_outcome() -> None:
    for name in builtin_names():
        for item in load_builtin(name).items:
            assert not any(w in item.title.lower() for w in OUTCOME_WORDS), (name, item.id, item.title)
            assert item.about and item.evidence


def test_every_builtin_profile_says_what_it_leaves_out() -> None:
    for name in builtin_names():
        p = load_builtin(name)
        assert p.left_out and all(why for _, why in p.left_out), name
        assert not {i.id for i in p.items} & {x for x, _ in p.left_out}, name
    # IEC 61508-3 at SIL 2: the profile lists its HR items, and names the Annex A items it leaves out
    iec = load_builtin("iec61508-3")
    assert sum(1 for i in iec.items if i.at("2") == "HR") == 8 and len(iec.left_out) >= 20


def test_no_claim_of_every_clause_of_each_standard() -> None:
    root = Path(__file__).resolve().parents[2]
    for rel in ("src/rclverify/report/templates/parts/standards.md.j2",
                "src/rclverify/report/templates/parts/standards.html.j2", "docs/standards.md"):
        assert "every clause of each standard" not in (root / rel).read_text(encoding="utf-8"), rel


def test_independence_per_level_must_name_the_levels() -> None:
    msg = _error(GOOD.replace('recommendation: {"1": R, "2": HR}',
                              'recommendation: {"1": R, "2": HR}\n    independence: {"1": person}'))
    assert msg.startswith("std/mine.yaml:12:19: error:") and "independence names levels 1" in msg
    assert _error(GOOD.replace("strength: proof", "strength: proof\n    about: everything")).startswith(
        "std/mine.yaml:11:12: error:")
