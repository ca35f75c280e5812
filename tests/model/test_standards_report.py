"""The plan's standards in a verified workspace's report (report/standards_rows.py, docs/standards.md): the
JSON part against the published schema, the Markdown and HTML sections, and ``verify --strict`` failing with
the highly recommended items left uncovered named.  Runs the pipeline: slow."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from _report_schema import check_report
from rclverify.cli.commands import main
from rclverify.model.plan.standards.choice import StandardChoice
from rclverify.model.plan.standards.profiles import load_builtin
from rclverify.lang.ast import Loc
from rclverify.report.standards_rows import standards_part, strict_reason

pytestmark = pytest.mark.slow

RCL = """node Gain {
  inputs( x : INTEGER )
  outputs( y : INTEGER )
  assume( in.x >= 0 )
  guarantee( out.y >= in.x and out.y >= 0 )
}
"""
PLAN = """name: standards
contracts: [contracts/gain.rcl]
standards:
  - {profile: iec61508-3, sil: 2, strict: true}
  - {profile: ul4600}
nodes:
  Gain:
    evidence:
      - backend: property_tests
        implementation: impl/gain.py:gain
        max_examples: 20
"""
IMPL = "def gain(x: int) -> dict[str, int]:\n    return {'y': x + 1}\n"


@pytest.fixture(scope="module")
def ws(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("standards") / "ws"
    for rel, text in {"contracts/gain.rcl": RCL, "contracts/plan.yaml": PLAN, "impl/gain.py": IMPL}.items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(text, encoding="utf-8")
    assert main(["verify", "-w", str(root)]) == 0
    return root


def _report(ws: Path) -> dict[str, Any]:
    return json.loads((ws / "reports" / "assurance.json").read_text(encoding="utf-8"))  # type: ignore[no-any-return]


def test_the_json_part_maps_the_tests_and_matches_the_schema(ws: Path) -> None:
    report = _report(ws)
    check_report(report, "standards")
    iec, ul = report["standards"]
    assert (iec["profile"], iec["level"], iec["source"]) == ("iec61508-3", "2", "contracts/plan.yaml:4:5")
    clauses = {c["id"]: c for c in iec["clauses"]}
    assert clauses["B.2 1"]["status"] == "covered"
    assert clauses["B.2 1"]["evidence"][0]["backend"] == "property_tests"
    assert clauses["B.2 1"]["covered_by"] == ["Gain.g1.property_tests.e0"]
    assert clauses["B.2 1"]["scope"] == [{"item": "Gain g1", "kind": "guarantee", "covered": True, "state": "covered",
                                          "detail": "covered", "evidence": ["Gain.g1.property_tests.e0"]}]
    assert clauses["B.2 1"]["checked_by"][0].startswith("property_tests (")
    assert clauses["A.9 1"]["status"] == "open" and "A.9 1" in iec["open"]
    assert "B.8 6c" in iec["required_not_covered"] and "B.2 1" not in iec["required_not_covered"]
    assert ul["level"] is None and "16" in ul["required_not_covered"]
    assert iec["origin"]["kind"] == "built-in" and iec["origin"]["file"].endswith("iec61508-3.yaml")
    assert len(iec["origin"]["sha256"]) == 64 and iec["left_out"]
    assert any(p.startswith("Standard IEC 61508-3:2010 SIL 2 (built-in profile): ")
               for p in report["summary"]["problems"])
    assert report["meta"]["strict_ok"] is False


def test_the_markdown_and_html_sections(ws: Path) -> None:
    md = (ws / "reports" / "assurance.md").read_text(encoding="utf-8")
    assert "### Safety standards (traceability aid)" in md and "#### IEC 61508-3:2010, SIL 2" in md
    assert "not a claim of compliance" in md and "| B.2 1 |" in md
    assert "| Clause | What it asks | Recommendation | About | Evidence that covers it | Who checked it | Status | Why |" in md
    assert "(profile `iec61508-3`, built-in, IEC 61508-3:2010;" in md and "Left out of this profile: A.1 1a" in md
    assert "#### Tool classification" in md and "is a T2 off-line support tool" in md
    assert "7.4.4.4 asks a specification" in md and "UL 4600 clause 13 asks" in md  # the plan chose UL 4600
    assert "criterion 3 (TQL-5)" in md  # no DO-333 profile chosen: the general DO-330 reading
    html = (ws / "reports" / "assurance.html").read_text(encoding="utf-8")
    assert '<h3 id="standards">' in html and "<td>A.9 1</td>" in html
    assert '<h4 id="tool-classification">Tool classification</h4>' in html


def test_strict_names_the_items(ws: Path, capsys: pytest.CaptureFixture[str]) -> None:
    capsys.readouterr()
    assert main(["verify", "-w", str(ws), "--strict"]) != 0
    out = "".join(capsys.readouterr())
    assert "IEC 61508-3:2010 SIL 2: highly recommended items not covered (" in out and "B.8 6c" in out
    assert "UL 4600" not in out.split("--strict")[-1] or "UL 4600, 3rd edition (2023): highly" not in out  # not strict


def test_the_part_without_a_pipeline() -> None:
    choice = StandardChoice(load_builtin("do-333"), "D", Loc("p.yaml", 3, 5), strict=True)
    rows = [{"obligation": "A.g1.review", "backend": "review", "kind": "review", "status": "discharged"}]
    part = standards_part([choice], rows)  # evidence rows alone: nothing is in any clause's scope
    assert part["ok"] is False and part["rows"][0]["required_not_covered"] == ["FM.A-3", "FM.A-6", "FM.A-7"]
    assert part["rows"][0]["counts"]["open"] == 5 and part["rows"][0]["counts"]["covered"] == 0
    # without strict: true the item is shown and named in the summary's problems, and --strict does not fail on it
    shown = standards_part([StandardChoice(load_builtin("do-333"), "D", Loc("p.yaml", 3, 5))], rows)
    assert shown["ok"] is True and len(shown["problems"]) == 1 and strict_reason({"standards": shown["rows"]}) == []
    assert strict_reason({"standards": part["rows"]}) == [
        "RTCA DO-333 (2011) DAL D: required items not covered (FM.A-3, FM.A-6, FM.A-7)"]
    assert standards_part([], rows) == {"rows": [], "problems": [], "ok": True}


def test_the_argument_links_strategies_to_the_clauses(ws: Path) -> None:
    arg = json.loads((ws / "reports" / "argument.json").read_text(encoding="utf-8"))
    els = {e["id"]: e for e in arg["elements"]}
    ctx = {i: e for i, e in els.items() if i.startswith("C-std.")}
    assert "C-std.iec61508-3.B.2_1" in ctx and ctx["C-std.iec61508-3.B.2_1"]["type"] == "context"
    assert "C-std.iec61508-3.A.9_1" not in ctx  # open: no evidence, no link
    assert "C-std.iec61508-3.B.2_1" in els["S-contracts"]["in_context_of"]
    assert "not a compliance claim" in ctx["C-std.ul4600.12"]["text"]


def test_the_bundle_carries_the_mapping_and_the_own_profile(ws: Path, tmp_path: Path) -> None:
    from rclverify.model.plan.load import load_plan
    from rclverify.report.bundle.archive import write_bundle
    (ws / "std").mkdir(exist_ok=True)
    (ws / "std" / "mine.yaml").write_text(
        "id: mine\ntitle: Mine\nedition: In-house 1\nitems:\n"
        "  - {id: M1, title: tested, evidence: [property-tests], strength: tested, recommendation: HR}\n",
        encoding="utf-8")
    plan = ws / "contracts" / "plan.yaml"
    text = plan.read_text(encoding="utf-8")
    try:
        plan.write_text(text.replace("  - {profile: ul4600}\n", "  - {profile: ul4600}\n  - {profile: std/mine.yaml}\n"),
                        encoding="utf-8")
        manifest = write_bundle(ws, load_plan(ws), tmp_path / "b.tar.gz", tools={"z3": "x"})
    finally:
        plan.write_text(text, encoding="utf-8")
    assert "std/mine.yaml" in manifest["files"]
    iec = manifest["standards"][0]
    assert iec["profile"] == "iec61508-3" and iec["level"] == "2"
    assert iec["clauses"]["B.2 1"] == {"status": "covered", "recommendation": "HR",
                                       "why": "all 1 item in scope covered", "plan": None,
                                       "evidence": ["Gain.g1.property_tests.e0"],
                                       "covered_by": ["Gain.g1.property_tests.e0"]}
    assert iec["origin"]["kind"] == "built-in"



def test_an_edited_own_profile_is_read_again(tmp_path: Path) -> None:
    """The workspace cache and the report task both follow the workspace's own profile file."""
    root = tmp_path / "ws"
    profile = ("id: mine\ntitle: Mine\nedition: In-house 1\nitems:\n"
               "  - {id: M1, title: TITLE, evidence: [property-tests], strength: tested, recommendation: HR}\n")
    plan = PLAN.replace("  - {profile: iec61508-3, sil: 2, strict: true}\n  - {profile: ul4600}\n",
                        "  - {profile: std/mine.yaml}\n")
    for rel, text in {"contracts/gain.rcl": RCL, "contracts/plan.yaml": plan, "impl/gain.py": IMPL,
                      "std/mine.yaml": profile.replace("TITLE", "first title")}.items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(text, encoding="utf-8")
    assert main(["verify", "-w", str(root), "--strict"]) == 1  # the health warning; the profile's M1 is covered
    assert _report(root)["standards"][0]["clauses"][0]["title"] == "first title"
    assert _report(root)["standards"][0]["required_not_covered"] == []
    (root / "std" / "mine.yaml").write_text(profile.replace("TITLE", "second title"), encoding="utf-8")
    main(["verify", "-w", str(root)])
    assert _report(root)["standards"][0]["clauses"][0]["title"] == "second title"
