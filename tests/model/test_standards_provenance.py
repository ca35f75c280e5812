"""A standard profile says where it comes from and cannot pass for a built-in one (model/plan/standards/
profiles.py, report/standards_rows.py, docs/standards.md "Where a profile comes from").

A workspace profile may not take a built-in profile's id or edition (one located error, a non-zero exit); a
profile of its own is shown as the workspace file with its sha256 in the JSON, the Markdown, the argument and
the bundle's MANIFEST, a built-in one as built-in with its edition.  Runs the pipeline: slow."""
from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

import pytest

from _report_schema import check_report
from rclverify.cli.commands import main
from rclverify.model.plan.errors import PlanError
from rclverify.model.plan.standards.profiles import load_builtin, load_profile_file

pytestmark = pytest.mark.slow

RCL = """node Gain {
  inputs( x : INTEGER )
  outputs( y : INTEGER )
  assume( in.x >= 0 )
  guarantee( out.y >= in.x and out.y >= 0 )
}
"""
PLAN = """name: provenance
contracts: [contracts/gain.rcl]
standards:
  - {profile: iec61508-3, sil: 2}
  - {profile: PROFILE}
nodes:
  Gain:
    evidence:
      - backend: property_tests
        implementation: impl/gain.py:gain
        max_examples: 20
"""
IMPL = "def gain(x: int) -> dict[str, int]:\n    return {'y': x + 1}\n"
#: the assessor's impersonation: the built-in's id, invented items, formal proof mapped to review
FAKE = """id: iec61508-3
title: Functional safety, software requirements
edition: IEC 61508-3:2010
items:
  - {id: A.9 99, title: SIL 4 achieved, evidence: [property-tests], strength: tested, recommendation: HR}
  - {id: Z.42, title: tool qualified to DO-330 TQL-1, evidence: [review], strength: reviewed, recommendation: HR}
"""


def _write(root: Path, files: dict[str, str]) -> None:
    for rel, text in files.items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(text, encoding="utf-8")


def _error(tmp_path: Path, text: str) -> str:
    (tmp_path / "p.yaml").write_text(text, encoding="utf-8")
    with pytest.raises(PlanError) as info:
        load_profile_file(tmp_path / "p.yaml", "std/p.yaml")
    assert len(info.value.diagnostics) == 1
    return str(info.value.diagnostics[0])


def test_a_workspace_profile_may_not_take_a_builtin_id(tmp_path: Path) -> None:
    msg = _error(tmp_path, FAKE)
    assert msg.startswith("std/p.yaml:1:5: error:") and "id 'iec61508-3' is the built-in profile 'iec61508-3''s" in msg


def test_nor_a_builtin_edition(tmp_path: Path) -> None:
    msg = _error(tmp_path, FAKE.replace("id: iec61508-3", "id: our-iec"))
    assert msg.startswith("std/p.yaml:3:10: error:") and "edition 'IEC 61508-3:2010'" in msg


def test_control_an_own_id_and_edition_load_as_a_workspace_profile(tmp_path: Path) -> None:
    text = FAKE.replace("id: iec61508-3", "id: our-iec").replace("edition: IEC 61508-3:2010", "edition: Ours 1")
    (tmp_path / "p.yaml").write_text(text, encoding="utf-8")
    p = load_profile_file(tmp_path / "p.yaml", "std/p.yaml")
    assert p.builtin is False and p.sha256 == hashlib.sha256(text.encode("utf-8")).hexdigest()
    assert load_builtin("iec61508-3").builtin is True


def test_verify_refuses_the_impersonation_at_the_profile(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    root = tmp_path / "ws"
    _write(root, {"contracts/gain.rcl": RCL, "contracts/plan.yaml": PLAN.replace("PROFILE", "std/fake.yaml"),
                  "impl/gain.py": IMPL, "std/fake.yaml": FAKE})
    capsys.readouterr()
    assert main(["verify", "-w", str(root)]) != 0
    err = "".join(capsys.readouterr())
    assert "std/fake.yaml:1:5: error: standard profile: id 'iec61508-3' is the built-in profile" in err
    assert "Traceback" not in err and not (root / "reports" / "assurance.json").exists()


@pytest.fixture(scope="module")
def ws(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("provenance") / "ws"
    own = FAKE.replace("id: iec61508-3", "id: our-rules").replace("edition: IEC 61508-3:2010", "edition: Ours 1")
    _write(root, {"contracts/gain.rcl": RCL, "contracts/plan.yaml": PLAN.replace("PROFILE", "std/ours.yaml"),
                  "impl/gain.py": IMPL, "std/ours.yaml": own})
    assert main(["verify", "-w", str(root)]) == 0
    return root


def _report(ws: Path) -> dict[str, Any]:
    return json.loads((ws / "reports" / "assurance.json").read_text(encoding="utf-8"))  # type: ignore[no-any-return]


def test_the_json_says_where_each_profile_comes_from(ws: Path) -> None:
    report = _report(ws)
    check_report(report, "provenance")
    iec, ours = report["standards"]
    digest = hashlib.sha256((ws / "std" / "ours.yaml").read_bytes()).hexdigest()
    assert ours["origin"] == {"kind": "workspace", "file": "std/ours.yaml", "sha256": digest, "edition": "Ours 1"}
    assert iec["origin"]["kind"] == "built-in" and iec["origin"]["edition"] == "IEC 61508-3:2010"
    assert any("(workspace profile std/ours.yaml, sha256 " + digest + ")" in p for p in report["summary"]["problems"])


def test_the_markdown_and_the_argument_say_so(ws: Path) -> None:
    digest = hashlib.sha256((ws / "std" / "ours.yaml").read_bytes()).hexdigest()
    md = (ws / "reports" / "assurance.md").read_text(encoding="utf-8")
    assert f"(profile `our-rules`, **from the workspace file std/ours.yaml**, sha256 `{digest}`;" in md
    assert "(profile `iec61508-3`, built-in, IEC 61508-3:2010;" in md
    arg = json.loads((ws / "reports" / "argument.json").read_text(encoding="utf-8"))
    texts = [e["text"] for e in arg["elements"] if e["id"].startswith("C-std.our-rules.")]
    assert texts and all(f"workspace profile std/ours.yaml, sha256 {digest}" in t for t in texts)


def test_the_manifest_says_so_and_packs_the_file(ws: Path, tmp_path: Path) -> None:
    from rclverify.model.plan.load import load_plan
    from rclverify.report.bundle.archive import write_bundle
    manifest = write_bundle(ws, load_plan(ws), tmp_path / "b.tar.gz", tools={"z3": "x"})
    iec, ours = manifest["standards"]
    assert ours["origin"] == {"kind": "workspace", "file": "std/ours.yaml", "edition": "Ours 1",
                              "sha256": manifest["files"]["std/ours.yaml"]["sha256"]}
    assert iec["origin"]["kind"] == "built-in" and not any(f.startswith("rclverify/") for f in manifest["files"])


def test_a_workspace_file_under_a_package_like_path_is_still_the_workspace_s(tmp_path: Path) -> None:
    """A profile whose workspace path reads like the package's is still packed, and never shown as built-in."""
    from rclverify.model.plan.load import load_plan
    from rclverify.report.bundle.manifest import collect
    rel = "rclverify/model/plan/standards/profiles/ours.yaml"
    own = FAKE.replace("id: iec61508-3", "id: our-rules").replace("edition: IEC 61508-3:2010", "edition: Ours 1")
    root = tmp_path / "ws"
    _write(root, {"contracts/gain.rcl": RCL, "contracts/plan.yaml": PLAN.replace("PROFILE", rel),
                  "impl/gain.py": IMPL, rel: own})
    plan = load_plan(root)
    assert plan.standards[1].profile.builtin is False
    assert rel in collect(root, plan)[0]


# --- a review record through the pipeline: the self-review of the first attempt -----------------

REVIEW_PLAN = """name: review
contracts: [contracts/gain.rcl]
standards:
  - {profile: iec61508-3, sil: 2}
nodes:
  Gain:
    evidence:
      - backend: property_tests
        implementation: impl/gain.py:gain
        max_examples: 20
      - backend: review
        record: reviews/gain.yaml
"""


def _review_ws(root: Path, reviewer: str, author: str) -> dict[str, Any]:
    import yaml
    _write(root, {"contracts/gain.rcl": RCL, "contracts/plan.yaml": REVIEW_PLAN, "impl/gain.py": IMPL})
    (root / "reviews").mkdir(exist_ok=True)
    assert main(["review", "Gain", "-w", str(root), "-o", str(root / "reviews" / "gain.yaml"),
                 "-f", "impl/gain.py"]) == 0
    blank = (root / "reviews" / "gain.yaml").read_text(encoding="utf-8")
    assert "\nauthor: " in blank and "\nindependence: " in blank  # the record asks for both names
    data = yaml.safe_load(blank)
    data.update(reviewer=reviewer, author=author, date="2026-11-27", scope="impl/gain.py against Gain's contract",
                verdict="pass")
    for q in data["checklist"]:
        q["answer"] = "yes"
    (root / "reviews" / "gain.yaml").write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    main(["verify", "-w", str(root)])
    report = _report(root)
    check_report(report, "review")
    assert {e["obligation"]: e["status"] for e in report["evidence"]}["Gain.g1.review.e1"] == "discharged"
    return {c["id"]: c for c in report["standards"][0]["clauses"]}


def test_a_self_review_through_the_pipeline_covers_no_independence_clause(tmp_path: Path) -> None:
    clauses = _review_ws(tmp_path / "ws", "Ada Lovelace", "Ada Lovelace")
    b86c = clauses["B.8 6c"]
    assert b86c["status"] == "open" and b86c["evidence"][0]["note"] == (
        "self-review: Ada Lovelace reviewed their own work (author: Ada Lovelace)")
    # nor static analysis (a manual review counts there only when independent), nor a modular design
    assert clauses["A.9 3"]["status"] == "open" and clauses["A.4 4"]["status"] != "covered"


def test_control_an_independent_review_through_the_pipeline_covers_it(tmp_path: Path) -> None:
    clauses = _review_ws(tmp_path / "ws", "Ada Lovelace", "Charles Babbage")
    b86c = clauses["B.8 6c"]
    assert b86c["status"] == "covered" and b86c["checked_by"] == [
        "review by Ada Lovelace (author: Charles Babbage; dated 2026-11-27; scope as stated: impl/gain.py against "
        "Gain's contract; files reviewed: impl/gain.py)"]
    assert clauses["A.9 3"]["status"] == "covered"
