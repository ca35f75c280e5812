"""Model-checking evidence in the problems by root cause (issue 30's rule;
report/problems_mc.py): the case study's SPIN-decided instances of the
Agent's guarantees are grouped under a culprit only when their diagnosis
names one other than the guarantee checked; failed instances are one row
per guarantee, culprits at the Gwendolen lines of the trail; inconclusive
ones are outstanding rows, never members of a failed row."""
from __future__ import annotations

import gzip
import json
from pathlib import Path

import pytest
from _typed_rows import ungrouped_report
from rclverify.report import render
from rclverify.report.problems import group_problems

DATA = Path(__file__).parent.parent / "data" / "case-study-report.json.gz"


def _report() -> dict:
    """The stored case-study report, the parts added since it was written completed empty (its problems
    left out: they are what the grouping makes)."""
    return ungrouped_report(json.loads(gzip.decompress(DATA.read_bytes())))


@pytest.fixture(scope="module")
def groups() -> dict[tuple[str, ...], dict]:
    """The stored report's problems by root cause, grouped once for the tests that only read them."""
    report = _report()
    return {tuple(g.key): g.to_json() for g in group_problems(report, render.problem_items(report), render.anchor)}


def test_guarantee_3_row_keeps_only_findings_proved_to_come_from_its_flaw(groups: dict[tuple[str, ...], dict]) -> None:
    g3 = groups[("guarantee:Agent:3",)]
    ids = [m["id"] for m in g3["members"]]
    assert ids == ["Agent.g1.non-vacuous", "Agent.g2.non-vacuous", "Agent.g0.monitors.nominal_jsonl",
                   "Agent.g1.property_tests.e2", "Agent.g2.property_tests.e2", "Agent.g3.property_tests.e2", "REQ1"]
    assert not any(".ajpf." in i for i in ids)


def test_failed_instances_are_one_row_per_guarantee_at_the_trail_lines(groups: dict[tuple[str, ...], dict]) -> None:
    g2 = groups[("model-checking:Agent:2",)]
    assert g2["status"] == "failed"
    assert [m["id"] for m in g2["members"]] == [f"Agent.g2.ajpf.p{14 + i}_i{i}" for i in range(13)]
    assert g2["sentence"].startswith("13 AJPF/SPIN property instances of guarantee 2 of Agent fail: counterexample "
                                     "a lasso of 136 steps")
    sources = [c["source"] for c in g2["culprits"]]
    assert sources[:4] == [f"backends/ajpf/jackal.gwen:{n}" for n in (72, 74, 77, 78)]
    assert all(s.startswith("backends/ajpf/jackal.gwen:") for s in sources)
    g3 = groups[("model-checking:Agent:3",)]
    assert [m["id"] for m in g3["members"]] == ["Agent.g3.ajpf.p28_i12"]


def test_inconclusive_instances_are_outstanding_rows_not_members_of_a_failed_row(
        groups: dict[tuple[str, ...], dict]) -> None:
    g1 = groups[("outstanding:model-checking:Agent:1",)]
    assert g1["status"] == "inconclusive"
    assert [m["id"] for m in g1["members"]] == [f"Agent.g1.ajpf.p{1 + i}_i{i}" for i in range(13)]
    assert "are inconclusive (evidence outstanding): PARTIAL COVERAGE of guarantee 1" in g1["sentence"]
    g3 = groups[("outstanding:model-checking:Agent:3",)]
    assert len(g3["members"]) == 12 and all(m["status"] == "inconclusive" for m in g3["members"])
    for key, g in groups.items():
        if g["status"] == "failed":
            assert all(m["status"] != "inconclusive" or not m["id"].count(".ajpf.") for m in g["members"]), key
    ids = [m["id"] for g in groups.values() for m in g["members"]]
    assert len(ids) == len(set(ids))


def test_an_instance_whose_diagnosis_names_another_culprit_is_grouped_under_it() -> None:
    report = _report()
    d = next(x for x in report["diagnoses"] if x["id"] == "Agent.g2.ajpf.p14_i0")
    d["culprits"].append({"what": "assumption 1 of Agent", "source": report["nodes"][0]["source"], "text": ""})
    groups = {tuple(g.key): g.to_json() for g in group_problems(report, render.problem_items(report), render.anchor)}
    assert "Agent.g2.ajpf.p14_i0" not in [m["id"] for m in groups[("model-checking:Agent:2",)]["members"]]
    assert any("Agent.g2.ajpf.p14_i0" in [m["id"] for m in g["members"]] for g in groups.values())
