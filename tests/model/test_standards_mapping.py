"""The mapping of a report's evidence rows onto a profile's clauses (model/plan/standards/mapping.py,
docs/standards.md): hand-made rows, then each clause's status against a brute-force reading of random rows,
and the profiles shipped as package data (pyproject.toml's globs cover them)."""
from __future__ import annotations

import fnmatch
import random
import tomllib
from pathlib import Path

from rclverify.model.plan.standards.mapping import SUPPORTS, clause_rows, kinds_of, not_covered
from rclverify.model.plan.standards.profiles import builtin_names, load_builtin, parse_profile
from rclverify.records.statuses import EVIDENCE_KINDS, RECORD_STATUSES

ROOT = Path(__file__).resolve().parents[2]
PROFILE = parse_profile("""id: t
title: T
edition: T 1
level_name: sil
levels: ["1", "2"]
items:
  - {id: P, title: proved, evidence: [proof], strength: proof, recommendation: {"1": R, "2": HR}}
  - {id: M, title: watched, evidence: [runtime-monitoring, run-statistics], strength: observed, recommendation: HR}
  - {id: X, title: tried, evidence: [experiment], strength: tested, recommendation: {"1": HR, "2": "---"}}
""", "t.yaml")


def _row(ob: str, backend: str, kind: str, status: str, strength: str | None = None) -> dict[str, object]:
    row: dict[str, object] = {"obligation": ob, "backend": backend, "kind": kind, "status": status}
    if strength:
        row["strength"] = {"kind": strength, "doubt": 0.1}
    return row


def _report(rows: list[dict[str, object]], guarantees: dict[str, str]) -> dict[str, object]:
    """A report of ``rows`` (obligations ``<Node>.g<k>...``) over the guarantees ``Node.gK`` -> status."""
    nodes: dict[str, list[dict[str, object]]] = {}
    for g, st in guarantees.items():
        n, k = g.split(".g")
        nodes.setdefault(n, []).append({"index": int(k), "status": st})
    obligations = [{"id": r["obligation"], "node": str(r["obligation"]).split(".")[0],
                    "guarantee": int(str(r["obligation"]).split(".")[1][1:])} for r in rows]
    return {"summary": {"status": "discharged"}, "nodes": [{"name": n, "guarantees": gs} for n, gs in nodes.items()],
            "obligations": obligations, "evidence": rows}


def test_hand_made_rows() -> None:
    rows = [_row("A.g1.hoare", "hoare", "proof", "discharged", "proof"),
            _row("A.g2.monitors", "monitors", "monitoring", "failed", "observed"),
            _row("B.g1.property_tests", "property_tests", "testing", "discharged", "tested")]
    report = _report(rows, {"A.g1": "discharged", "A.g2": "failed", "B.g1": "discharged"})
    out = {r["id"]: r for r in clause_rows(PROFILE, "2", report)}
    # P (proof) is about every guarantee: A.g1 is proved, A.g2 and B.g1 are not
    assert out["P"]["status"] == "partial" and out["P"]["recommendation"] == "HR"
    assert out["P"]["evidence"] == [{"obligation": "A.g1.hoare", "backend": "hoare", "kind": "proof",
                                     "status": "discharged", "counts": True, "note": ""}]
    assert out["P"]["covered_by"] == ["A.g1.hoare"] and out["P"]["why"] == (
        "partial: 1 of 3 in scope covered; 2 no evidence")
    assert out["M"]["status"] == "not covered" and [e["status"] for e in out["M"]["evidence"]] == ["failed"]
    assert out["X"]["status"] == "open" and out["X"]["evidence"] == [] and out["X"]["recommendation"] == "---"
    assert not_covered(list(out.values())) == ["P", "M"]
    # a failed proof beside a discharged one on the same guarantee: not covered (a pass does not hide a failure)
    both = clause_rows(PROFILE, "2", _report(rows[:1] + [_row("A.g1.dafny", "dafny", "proof", "failed", "proof")],
                                             {"A.g1": "failed"}))
    assert both[0]["status"] == "not covered" and len(both[0]["evidence"]) == 2
    assert both[0]["scope"][0]["detail"] == "1 failed of its 2 records"
    at1 = clause_rows(PROFILE, "1", report)
    assert [r["recommendation"] for r in at1] == ["R", "HR", "HR"] and not_covered(at1) == ["M", "X"]
    # a whole-contract obligation (g0) is evidence for each of its node's guarantees
    whole = _report([_row("A.g0.hoare", "hoare", "proof", "discharged")], {"A.g1": "discharged", "A.g2": "discharged"})
    whole["obligations"] = [{"id": "A.g0.hoare", "node": "A", "guarantee": 0}]
    assert clause_rows(PROFILE, "2", whole)[0]["status"] == "covered"


def test_statistical_strength_supports_run_statistics() -> None:
    row = _row("A.g1.monitors", "monitors", "monitoring", "discharged", "statistical")
    assert kinds_of(row) == {"runtime-monitoring", "run-statistics"}
    assert kinds_of(_row("x", "review", "review", "pending")) == {"review"}


def test_every_record_kind_is_in_the_one_table() -> None:
    assert {v for (f, v) in SUPPORTS if f == "kind"} == set(EVIDENCE_KINDS)


def test_the_evidence_shown_is_a_reading_of_the_kinds_table() -> None:
    """Random rows on one guarantee: the evidence a clause shows is exactly the rows one of whose
    (field, value) pairs in SUPPORTS names a kind the clause accepts (the reading of the table)."""
    rnd = random.Random(1)
    kinds = list(EVIDENCE_KINDS)
    profiles = [load_builtin(n) for n in builtin_names()] + [PROFILE]
    for _ in range(300):
        rows = [_row(f"N.g1.b{i}", "b", rnd.choice(kinds), rnd.choice(RECORD_STATUSES),
                     rnd.choice([None, "proof", "statistical", "tested"])) for i in range(rnd.randrange(0, 6))]
        p = rnd.choice(profiles)
        level = rnd.choice(p.levels) if p.levels else None
        for item, got in zip(p.items, clause_rows(p, level, _report(rows, {"N.g1": "discharged"}))):
            if item.about not in ("guarantees", "system"):
                continue
            supporting = []
            for r in rows:  # brute force: does any (field, value) of the table match and name an accepted kind?
                hits = [k for (f, v), k in SUPPORTS.items()
                        if (r.get(f) if f == "kind" else dict(r.get("strength") or {}).get("kind")) == v]  # type: ignore[call-overload]
                if set(hits) & set(item.evidence):
                    supporting.append(r["obligation"])
            assert [e["obligation"] for e in got["evidence"]] == supporting
            assert got["recommendation"] == item.at(level)
            if got["status"] == "partial":
                assert got["covered_by"]


def test_the_profiles_are_package_data() -> None:
    data = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    globs = data["tool"]["setuptools"]["package-data"]["rclverify"]
    folder = ROOT / "src" / "rclverify" / "model" / "plan" / "standards"
    files = [p for p in folder.rglob("*") if p.is_file() and p.suffix in (".yaml", ".json")]
    assert len(files) >= 5
    for p in files:
        rel = p.relative_to(ROOT / "src" / "rclverify").as_posix()
        assert any(fnmatch.fnmatch(rel, g) and rel.count("/") == g.count("/") for g in globs), rel
