"""Who checked a review, read as an assessor reads names (model/plan/standards/identity.py, reviews.py,
backends/review/backend.py; docs/standards.md "Who checked: independence").

Each attempt an assessor made to pass a self-review off as independent is a case beside a control that is
honestly independent: a name spelt without its space, with an e-mail address, in full-width letters or
through a declared alias is one person; a name that names nobody (``-``, ``unknown``, ``n/a``, empty) is
no person; a name mixing scripts or holding an invisible character is refused at its place in the record."""
from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.review.backend import read_record
from rclverify.lang.ast import Loc
from rclverify.model.plan.errors import PlanError
from rclverify.model.plan.standards.identity import confusable, is_person, person_keys, same_person
from rclverify.model.plan.standards.mapping import clause_rows
from rclverify.model.plan.standards.profiles import load_builtin
from rclverify.model.plan.standards.reviews import independence_of


def _row(reviewer: str, author: str, **more: str) -> dict[str, Any]:
    figures = [["reviewer", reviewer], ["author", author or "(not named)"]]
    figures += [[k.replace("_", " "), v] for k, v in more.items()]
    return {"obligation": "Gain.g1.review.e0", "backend": "review", "kind": "review", "status": "discharged",
            "tool": "review record", "tool_version": "reviews/gain.yaml", "figures": figures}


def _b86c(row: dict[str, Any]) -> dict[str, Any]:
    report = {"summary": {"status": "discharged"}, "nodes": [{"name": "Gain", "guarantees": [
        {"index": 1, "status": "discharged"}]}], "obligations": [{"id": row["obligation"], "node": "Gain",
                                                                  "guarantee": 1}], "evidence": [row]}
    return {c["id"]: c for c in clause_rows(load_builtin("iec61508-3"), "2", report)}["B.8 6c"]


SPELT_AROUND = [
    ("AdaLovelace", "Ada Lovelace"),                       # the space left out
    ("ada.lovelace", "Ada Lovelace"),                      # punctuation for the space
    ("Ada Lovelace <ada@example.org>", "Ada Lovelace"),    # an e-mail address added
    ("ada.lovelace@example.org", "Ada Lovelace"),          # the address alone, its local part the name
    ("ＡｄａＬｏｖｅｌａｃｅ", "Ada Lovelace"),             # full-width letters (NFKC)
    ("ADA  LOVELACE", "ada lovelace"),                     # case and repeated spaces
]


@pytest.mark.parametrize("reviewer,author", SPELT_AROUND)
def test_a_name_spelt_around_is_the_author_and_covers_nothing(reviewer: str, author: str) -> None:
    assert same_person(reviewer, author)
    clause = _b86c(_row(reviewer, author))
    assert clause["status"] == "open" and clause["evidence"][0]["counts"] is False
    assert clause["evidence"][0]["note"].startswith("self-review: ")


def test_control_a_reviewer_who_is_another_person_covers() -> None:
    clause = _b86c(_row("Charles Babbage <cb@example.org>", "Ada Lovelace"))
    assert clause["status"] == "covered" and clause["evidence"][0]["counts"] is True
    assert not same_person("Charles Babbage", "Ada Lovelace")


def test_a_declared_alias_is_the_same_person_and_its_absence_the_control() -> None:
    row = _row("AL-7", "Ada Lovelace", author_aliases="AL-7; ada@example.org")
    assert _b86c(row)["status"] == "open" and independence_of(row)[1].startswith("self-review")
    # the same record without the declaration: the tool cannot know AL-7 is Ada
    assert _b86c(_row("AL-7", "Ada Lovelace"))["status"] == "covered"
    assert same_person("ada@example.org", "Ada Lovelace", (), ("ada@example.org",))


@pytest.mark.parametrize("nobody", ["-", "unknown", "Unknown", "n/a", "N/A", "", "  ", "?", "TBD", "none"])
def test_an_author_that_names_nobody_is_not_a_person(nobody: str) -> None:
    assert not is_person(nobody) and person_keys(nobody) == frozenset()
    clause = _b86c(_row("Charles Babbage", nobody))
    assert clause["status"] == "open" and "does not name a person as its author" in clause["evidence"][0]["note"]
    # nor as the reviewer
    assert independence_of(_row(nobody, "Ada Lovelace"))[0] == "none"


def test_what_a_review_states_is_shown_as_stated() -> None:
    row = _row("Charles Babbage", "Ada Lovelace", independence="department", date="2026-03-01",
               scope="the stop path against H-3")
    row["figures"] += [["file", "nodes/base.py sha256 " + "0" * 64], ["file", "nodes/stop.py sha256 " + "1" * 64]]
    clause = _b86c(row)
    assert clause["checked_by"] == ["review by Charles Babbage (author: Ada Lovelace; independence as stated: "
                                    "department; dated 2026-03-01; scope as stated: the stop path against H-3; "
                                    "files reviewed: nodes/base.py, nodes/stop.py)"]
    # control: a record that states none of it shows none
    assert _b86c(_row("Charles Babbage", "Ada Lovelace"))["checked_by"] == [
        "review by Charles Babbage (author: Ada Lovelace)"]


# --- confusable names are refused where the record writes them ----------------------------------------

RECORD = """node: Gain
reviewer: {reviewer}
author: {author}
date: 2026-01-01
scope: the gain
files: []
checklist: []
verdict: pass
"""


def _read(tmp_path: Path, reviewer: str, author: str) -> Any:
    (tmp_path / "reviews").mkdir(exist_ok=True)
    (tmp_path / "reviews/gain.yaml").write_text(RECORD.format(reviewer=reviewer, author=author), encoding="utf-8")
    return read_record(tmp_path, {"record": "reviews/gain.yaml"}, lambda *p: Loc("contracts/plan.yaml", 9, 11))


@pytest.mark.parametrize("name,why", [
    ("\u0410da Lovelace", "mixes letters of the scripts Cyrillic, Latin"),         # a Cyrillic A
    ("Ad\u0430 Lovelace", "mixes letters of the scripts Cyrillic, Latin"),         # a Cyrillic a
    ("Ada Lovel\u03b1ce", "mixes letters of the scripts Greek, Latin"),            # a Greek alpha
    ("Ada\u200bLovelace", "invisible character U+200B ZERO WIDTH SPACE"),
    ("Ada Lovelace\u200e", "invisible character U+200E LEFT-TO-RIGHT MARK"),
])
def test_a_confusable_name_is_refused_at_its_place_in_the_record(tmp_path: Path, name: str, why: str) -> None:
    assert why in (confusable(name) or "")
    with pytest.raises(PlanError) as exc:
        _read(tmp_path, "Charles Babbage", name)
    msg = str(exc.value)
    assert msg.startswith("reviews/gain.yaml:3:9: error: review record: author ") and why in msg
    assert len(msg.strip().splitlines()) == 1


@pytest.mark.parametrize("name", ["Иван Петров", "山田 太郎", "やまだ たろう 山田", "Ada Lovelace", "Zoë Ångström",
                                  "ＡｄａＬｏｖｅｌａｃｅ"])
def test_control_a_name_in_one_writing_system_is_read(tmp_path: Path, name: str) -> None:
    assert confusable(name) is None
    _, record = _read(tmp_path, "Charles Babbage", name)
    assert record.author == name


def test_a_confusable_alias_is_refused_at_its_item_and_a_plain_one_read(tmp_path: Path) -> None:
    (tmp_path / "reviews").mkdir()
    text = RECORD.format(reviewer="Charles Babbage", author="Ada Lovelace") + "author_aliases: [ada@example.org, AdaL\u200b]\n"
    (tmp_path / "reviews/gain.yaml").write_text(text, encoding="utf-8")
    with pytest.raises(PlanError) as exc:
        read_record(tmp_path, {"record": "reviews/gain.yaml"}, lambda *p: Loc("contracts/plan.yaml", 9, 11))
    assert str(exc.value).startswith("reviews/gain.yaml:9:35: error: review record: author_aliases.1 ")
    (tmp_path / "reviews/gain.yaml").write_text(text.replace("\u200b", ""), encoding="utf-8")
    _, record = read_record(tmp_path, {"record": "reviews/gain.yaml"}, lambda *p: Loc("contracts/plan.yaml", 9, 11))
    assert record.author_aliases == ("ada@example.org", "AdaL")


def test_the_plans_people_make_an_alias_one_person_for_every_record_and_their_absence_the_control(
        tmp_path: Path) -> None:
    from rclverify.model.plan.load import load_plan
    (tmp_path / "contracts").mkdir()
    (tmp_path / "contracts" / "a.rcl").write_text("node Gain {\n  inputs( x : INTEGER )\n  outputs( y : INTEGER )\n"
                                                  "  guarantee( out.y >= 0 )\n}\n", encoding="utf-8")
    (tmp_path / "contracts" / "plan.yaml").write_text(
        "name: s\ncontracts: [contracts/a.rcl]\nstandards:\n  - {profile: iec61508-3, sil: 2}\n"
        "people:\n  - {name: Ada Lovelace, aliases: [AL-7], emails: [countess@example.org]}\n", encoding="utf-8")
    [choice] = load_plan(tmp_path, "contracts/plan.yaml").standards
    report = {"summary": {"status": "discharged"}, "nodes": [{"name": "Gain", "guarantees": [
        {"index": 1, "status": "discharged"}]}], "obligations": [{"id": "Gain.g1.review.e0", "node": "Gain",
                                                                  "guarantee": 1}]}

    def b86c(row: dict[str, Any], people: Any) -> str:
        rows = clause_rows(load_builtin("iec61508-3"), "2", {**report, "evidence": [row]}, people=people)
        return str({c["id"]: c for c in rows}["B.8 6c"]["status"])
    for reviewer in ("AL-7", "countess@example.org", "Countess <countess@example.org>"):
        row = _row(reviewer, "Ada Lovelace")  # the record declares no alias: the plan's list does
        assert b86c(row, choice.people) == "open"
        assert independence_of(row, choice.people)[1].startswith("self-review")
        assert b86c(row, ()) == "covered"  # the control: without the list the tool cannot know
    assert b86c(_row("Charles Babbage", "Ada Lovelace"), choice.people) == "covered"  # another person still covers


@pytest.mark.parametrize("people, said", [
    ("  - {name: Ada Lovelace}\n  - {name: ada.lovelace}\n", "share a name, alias or e-mail"),
    ("  - {name: Ada Lovelace, aliases: [unknown]}\n", "'unknown' names nobody"),
    ("  - {name: Ada Lovelace, aliases: [\"Ad\u0430\"]}\n", "scripts"),
])
def test_a_people_entry_that_cannot_name_one_person_is_refused_at_its_line(tmp_path: Path, people: str,
                                                                          said: str) -> None:
    from rclverify.model.plan.load import load_plan
    (tmp_path / "contracts").mkdir()
    (tmp_path / "contracts" / "a.rcl").write_text("node Gain {\n  inputs( x : INTEGER )\n  outputs( y : INTEGER )\n"
                                                  "  guarantee( out.y >= 0 )\n}\n", encoding="utf-8")
    (tmp_path / "contracts" / "plan.yaml").write_text("name: s\ncontracts: [contracts/a.rcl]\npeople:\n" + people,
                                                      encoding="utf-8")
    with pytest.raises(PlanError) as info:
        load_plan(tmp_path, "contracts/plan.yaml")
    [d] = info.value.diagnostics
    assert said in str(d) and str(d).startswith(f"contracts/plan.yaml:{4 + people.count(chr(10)) - 1}:")
