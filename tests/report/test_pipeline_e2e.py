"""End to end: `doit verify` on a copy of the bundled workspace (the paper's case study)."""
from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from _restore import restored
from rclverify.records.store import dumps
from rclverify.app.pipeline import Workspace
from rclverify.report.build import build_report
from rclverify.report.fragments import FragmentCache, cached_dumps
from rclverify.report.parts import FRAGMENTS, PARTS, write_part

ROOT = Path(__file__).resolve().parents[2]


def _doit(ws: Path, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "doit", *args], cwd=ws, capture_output=True, text=True, timeout=600)


@pytest.fixture(scope="module")
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    ws = tmp_path_factory.mktemp("ws")
    for item in ("contracts", "backends", "ros", "dodo.py"):
        src = ROOT / item
        (shutil.copytree if src.is_dir() else shutil.copy)(src, ws / item)
    # in parallel, as a user with two cores runs it: test_the_parallel_run_gives_the_serial_results holds
    # its statuses against the stored serial run's (one run of the case study instead of two)
    r = _doit(ws, "-n", "2", "verify")
    assert r.returncode == 0, r.stdout + r.stderr
    return ws


@pytest.fixture(scope="module")
def report(workspace: Path) -> dict:
    return json.loads((workspace / "reports" / "assurance.json").read_text())


def test_report_has_the_traceability_keys(report: dict) -> None:
    for key in ("requirements", "nodes", "side_conditions", "derived_properties", "findings", "obligations", "evidence"):
        assert isinstance(report[key], list) and report[key], key
        assert all("status" in x for x in report[key]), key
    assert [r["id"] for r in report["requirements"]] == ["REQ1", "REQ2", "REQ3", "REQ4"]
    assert report["meta"]["plan"] == "contracts/plan.yaml"


def test_report_matches_the_published_schema(report: dict) -> None:
    """The case study's reports/assurance.json against docs/assurance.schema.json and the status
    vocabulary (tests/_report_schema.py)."""
    from _report_schema import check_report
    check_report(report, "case study")


def test_calculus_reproduces_d1(report: dict) -> None:
    sc = {s["id"]: s for s in report["side_conditions"]}
    assert sc["Agent.sc1"]["status"] == "discharged"
    assert sc["Navigation.sc1"]["status"] == "discharged"
    agent = next(d for d in report["derived_properties"] if d["node"] == "Agent")
    assert "R3" in agent["rules"]
    assert agent["instances"][0]["conclusion"].endswith("and (0 <= in.r) => <> G_Agent")
    # derivation and evidence are separate: every side condition is discharged, so every
    # derived property reads "derived", with the evidence it rests on beside it
    loc = next(d for d in report["derived_properties"] if d["node"] == "Localisation")
    assert loc["property"] == "TRUE => <> G_Localisation" and loc["derivation"] == "derived"
    assert loc["evidence_status"] == "pending" and "1 pending node contract: Localisation" in loc["evidence_note"]
    assert all(d["derivation"] == "derived" for d in report["derived_properties"])
    # Navigation's worst-case experiment fails (see the experiment test below)
    assert "3 failed node contracts: Navigation, Agent, RadiationSensor" in agent["evidence_note"]
    # the loop section lists the real cycles only
    assert report["system"]["loops"] == [["Navigation", "Agent"], ["Agent", "RadiationSensor"]]
    edges = {(c["from_node"], c["to_node"]) for c in report["system"]["connections"]}
    for cycle in report["system"]["loops"]:
        assert all((cycle[k], cycle[(k + 1) % len(cycle)]) in edges for k in range(len(cycle)))
    # lint: no warning on the conventional (A and B) -> C form
    assert not any("precedence decides" in x["message"] for x in report["lint"])


def test_genuine_problems_of_the_case_study_are_shown(report: dict) -> None:
    findings = {f["id"]: f for f in report["findings"]}
    assert findings["Agent.g2.non-vacuous"]["status"] == "problem"
    ev = {e["obligation"]: e for e in report["evidence"]}
    appendix_b = [e for k, e in ev.items() if "appendix_b" in k and e["status"] == "failed"]
    assert appendix_b and all(e["counterexample"] for e in appendix_b)
    listing = [e for k, e in ev.items() if ".hoare.radiation_sensor." in k]
    assert sorted(e["status"] for e in listing) == ["discharged", "discharged", "discharged", "pending"]
    problems = "\n".join(report["summary"]["problems"])
    assert "Guarantee 2 of Agent is vacuous" in problems
    # requirements resting on failed or open evidence are not shown as verified
    assert all(r["status"] != "discharged" for r in report["requirements"])



def test_the_case_study_counterexamples_read_well(report: dict) -> None:
    """Issue 48's readability check (tests/_readable.py) on the case study: REQ4's lasso among them."""
    from _readable import assert_readable
    assert assert_readable(report) >= 1
    req4 = next(q for q in report["requirements"] if q["id"] == "REQ4")
    assert req4["verdict"] == "refuted" and req4["check"]["temporal"]["trace"]


def test_replacement_contract_is_checked_by_refinement(report: dict, workspace: Path) -> None:
    [f] = [f for f in report["findings"] if f["check"] == "replacement-refines"]
    # checked under the plan's 13-waypoint facts (the same facts the health checks use)
    assert "[environment fact]" in f["explanation"]
    # without the facts Z3 refutes it at once; with them the guarantee side needs
    # a model of nested quantifiers over wayP, which the MBQI retry finds within
    # its resource limit, the same in every run (deterministic query)
    assert f["node"] == "Agent" and f["status"] == "problem"
    assert "guarantee side fails" in f["message"]
    # the counterexample says how waypoints and radiation look
    assert {"in.wayP", "in.radiationStatus", "out.command"} <= set(f["model"])
    assert (workspace / f["smt2"]).is_file()
    assert all((workspace / x["smt2"]).is_file() for x in report["findings"] if x.get("smt2"))


def test_experiment_and_review_evidence_are_in_the_report(report: dict, workspace: Path) -> None:
    ev = {e["obligation"]: e for e in report["evidence"] if e["backend"] in ("review", "experiment")}
    assert set(ev) == {"Localisation.g1.review.e0", "Navigation.g1.experiment.e0", "Navigation.g1.experiment.e1"}
    assert ev["Localisation.g1.review.e0"]["status"] == "pending"
    worst_case = ev["Navigation.g1.experiment.e0"]
    assert worst_case["status"] == "failed" and "worst 43 cm" in worst_case["explanation"]
    assert ev["Navigation.g1.experiment.e1"]["status"] == "inconclusive"
    assert any("Navigation.g1.experiment.e0 is failed" in p for p in report["summary"]["problems"])
    html = (workspace / "reports" / "assurance.html").read_text(encoding="utf-8")
    assert '<figure class="plot"><svg' in html and "Samuelson" in html


def test_ajpf_entry_is_decided_by_spin_or_pending_not_skipped(report: dict) -> None:
    # the plan chooses model_checker: spin (MCAPL is not installable here; docs/model-checking.md)
    ajpf = [e for e in report["evidence"] if e["backend"] == "ajpf"]
    assert len(ajpf) == 39 and all(e["tool"] == "SPIN" for e in ajpf)
    if shutil.which("spin") and shutil.which("gcc"):
        assert {e["status"] for e in ajpf} <= {"discharged", "failed", "inconclusive"}
        failed = [e for e in ajpf if e["status"] == "failed"]
        assert failed and all(e["counterexample"]["trace"] for e in failed)
        assert all("checked by SPIN on rclverify's exploration" in e["explanation"] for e in ajpf)
    else:
        assert all(e["status"] == "pending" and "apt-get install spin" in e["explanation"] for e in ajpf)


def test_dafny_evidence_is_real_or_pending(report: dict) -> None:
    [ev] = [e for e in report["evidence"] if e["backend"] == "dafny"]
    if shutil.which("dafny"):
        # the Agent's guarantees are unproved, and no input of its can be fixed to show a counterexample
        assert ev["status"] == "inconclusive" and ev["tool_version"] != "-", ev["explanation"]
        assert "A verification error is no counterexample" in ev["explanation"]
    else:
        assert ev["status"] == "pending" and "dafny not installed" in ev["explanation"]


def test_html_report_shows_the_problems_first(workspace: Path) -> None:
    html = (workspace / "reports" / "assurance.html").read_text()
    assert html.index("Guarantee 2 of Agent is vacuous") < html.index('id="traceability"')
    assert "<svg" in html or "install graphviz" in html


def test_ci_formats_carry_the_case_study_findings_at_their_rcl_locations(workspace: Path) -> None:
    import jsonschema
    import junitparser
    from sarif import loader
    reports = workspace / "reports"
    log = json.loads((reports / "assurance.sarif").read_text())
    schema = json.loads((ROOT / "tests" / "data" / "sarif-schema-2.1.0.json").read_text())
    jsonschema.Draft4Validator(schema).validate(log)
    records = loader.load_sarif_file(str(reports / "assurance.sarif")).get_records()
    at = {(r["Code"], r["Location"], r["Line"]) for r in records}
    rcl = "contracts/remote_inspection.rcl"
    assert ("RCL-HEALTH-VACUOUS", rcl, 69) in at  # Agent guarantee 2
    assert ("RCL-HEALTH-REPLACEMENT", rcl, 53) in at  # the Agent node
    assert ("RCL-LINT-UNUSED-BOUND", rcl, 72) in at  # x', y' of Agent guarantee 3
    refuted = [r for r in records if r["Code"] == "RCL-OBL-FAILED" and "appendix_b" in r["Description"]]
    assert refuted and all(r["Severity"] == "error" and r["Location"] == rcl and "Counterexample: " in r["Description"]
                           for r in refuted)
    assert any("radiation_at(i) = 10" in r["Description"] for r in refuted)
    # pending work is a warning: the guarantee is not established and --strict fails on it (report/severity.py)
    assert {r["Severity"] for r in records if r["Code"] == "RCL-OBL-PENDING"} == {"warning"}
    xml = junitparser.JUnitXml.fromfile(str(reports / "assurance.junit.xml"))
    suites = {s.name: s for s in xml}
    assert set(suites) == {"Localisation", "Navigation", "Agent", "RadiationSensor", "requirements", "lint"}
    # the two lint warnings (x', y' unused in guarantee 3) are acknowledged in the plan (kept as published,
    # docs/plan.md "Acknowledged warnings"): skipped cases with the reason, not failures; in SARIF suppressed
    assert [type(c.result[0]).__name__ for c in suites["lint"]] == ["Skipped", "Skipped"]
    unused = [r for r in log["runs"][0]["results"] if r["ruleId"] == "RCL-LINT-UNUSED-BOUND"]
    assert len(unused) == 2 and all(r["suppressions"][0]["status"] == "accepted" for r in unused)
    reqs = {c.name: c for c in suites["requirements"]}
    assert set(reqs) == {"REQ1", "REQ2", "REQ3", "REQ4"}
    assert isinstance(reqs["REQ1"].result[0], junitparser.Failure)  # proved vacuously: not met
    # temporal, refuted by a lasso (the rover never arrives where it is commanded): a failure, never passed
    assert isinstance(reqs["REQ4"].result[0], junitparser.Failure)
    assert ("RCL-REQ-VACUOUS", "contracts/plan.yaml", 28) in at
    cases = {c.name: c for s in xml for c in s}
    report = json.loads((reports / "assurance.json").read_text())
    assert {o["id"] for o in report["obligations"]} | {sc["id"] for sc in report["side_conditions"]} <= set(cases)
    failed = [c for n, c in cases.items() if "appendix_b" in n and c.result and isinstance(c.result[0], junitparser.Failure)]
    assert failed and all("counterexample: " in c.result[0].text for c in failed)
    assert failed[0].classname == "RadiationSensor.obligation" and failed[0]._elem.get("file") == rcl
    review = cases["Localisation.g1.review.e0"]
    assert isinstance(review.result[0], junitparser.Skipped) and "review" in review.result[0].message
    assert not cases["Agent.sc1"].result  # the side condition of D1 is proved: the test case passes
def test_the_argument_is_written_and_agrees_with_the_report(report: dict, workspace: Path) -> None:
    arg = json.loads((workspace / "reports" / "argument.json").read_text())
    status = {e["id"]: e["status"] for e in arg["elements"]}
    assert status[arg["top"]] == report["summary"]["status"]
    for r in report["requirements"]:
        assert status[f"G-{r['id']}"] == r["status"], r["id"]
    for n in report["nodes"]:
        assert status[f"G-{n['name']}"] == n["status"], n["name"]
        for g in n["guarantees"]:
            assert status[f"G-{n['name']}.g{g['index']}"] == g["status"]
    solutions = {e["ref"] for e in arg["elements"] if e["type"] == "solution"}
    assert {e["obligation"] for e in report["evidence"]} <= solutions
    assert (workspace / "reports" / "argument.gsn.yaml").read_text().startswith("# assurance argument of")
    html = (workspace / "reports" / "assurance.html").read_text()
    assert '<section id="argument">' in html
    if shutil.which("dot"):
        assert (workspace / "reports" / "argument.svg").read_text().startswith("<svg")


def test_bundle_of_the_case_study_verifies(workspace: Path, tmp_path: Path) -> None:
    from rclverify.report.bundle.archive import verify_bundle
    out = tmp_path / "case-study.tar.gz"
    r = subprocess.run([sys.executable, "-m", "rclverify.cli.commands", "bundle", "-w", str(workspace), "-o", str(out)],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    manifest = verify_bundle(out)
    for f in ("contracts/plan.yaml", "contracts/remote_inspection.rcl", "reports/assurance.html",
              "reports/argument.json", "backends/dafny/agent.dfy"):
        assert f in manifest["files"], f
    assert set(manifest["tools"]) >= {"rclverify", "z3", "dafny", "hypothesis", "python"}
    assert any(f.startswith("artifacts/evidence/") for f in manifest["files"])


@pytest.fixture(scope="module")
def second_run(workspace: Path) -> subprocess.CompletedProcess[str]:
    """`doit verify` again on the verified workspace, nothing changed: one run read by the two tests below."""
    return _doit(workspace, "verify")


def test_second_run_executes_no_task(second_run: subprocess.CompletedProcess[str]) -> None:
    r = second_run
    assert r.returncode == 0
    executed = [l for l in r.stdout.splitlines() if l.startswith(".  ")]
    assert executed == [], executed


def test_a_run_with_nothing_to_do_still_prints_the_status_and_the_problems_by_root_cause(
        second_run: subprocess.CompletedProcess[str]) -> None:
    r = second_run
    assert r.returncode == 0
    assert "overall: failed" in r.stdout and "11 problems by root cause (54 findings)" in r.stdout, r.stdout
    # 7: the Agent's model-checking instances are rows of their own (report/problems_mc.py), not this one
    assert "1. [failed] guarantee 3 of Agent (contracts/remote_inspection.rcl:72:3): 7 findings" in r.stdout
    assert "| Agent " in r.stdout and "report: reports/assurance.html" in r.stdout


def _stored() -> dict:
    """tests/data/case-study-report.json.gz: the report of a serial `doit verify` of the case study."""
    import gzip
    with gzip.open(ROOT / "tests" / "data" / "case-study-report.json.gz", "rt", encoding="utf-8") as f:
        return json.load(f)


def test_the_browser_tests_stored_report_is_this_codes_report(report: dict) -> None:
    """tests/data/case-study-report.json.gz, from which the browser test renders the case study's
    page, is the report this code makes: same statuses, problems by root cause and repairs. When
    this fails, regenerate it from `reports/assurance.json` of a serial `doit verify` in a copy of
    the repository root (docs/reading-the-report.md)."""
    stored = _stored()

    def gist(r: dict) -> object:
        return ({o["id"]: o["status"] for o in r["obligations"]}, {f["id"]: f["status"] for f in r["findings"]},
                [(p["key"], sorted(m["id"] for m in p["members"])) for p in r["problems"]],
                {d["id"]: [x["summary"] for x in d["repairs"]] for d in r["diagnoses"]},
                [(q["id"], q.get("verdict"), q["status"]) for q in r["requirements"]])
    assert gist(stored) == gist(report)


def test_everything_kept_between_runs_is_in_the_cache_layer(workspace: Path) -> None:
    """One cache layer (issue 25): every file a run keeps under artifacts/cache is in the cache
    layer's format, written by this code, and `rclverify cache` lists each one; only jinja2's own
    bytecode cache and the layout blobs are directories."""
    from rclverify.core.cache import kept_files
    rows = kept_files(workspace)
    files = {r["file"].removeprefix("artifacts/cache/"): r for r in rows}
    expected = {"workspace.pickle", "contract-texts.pickle", "report-fragments.html.pickle",
                "report-fragments.text.pickle", "diagnosis.pickle", "system-cycles.pickle", "ros-scan.pickle"}
    if shutil.which("dot"):  # Graphviz lays out the diagrams (else the report shows their DOT source)
        expected.add("layout/")
    assert expected <= files.keys(), sorted(files)
    for name, r in files.items():
        if name.endswith("/"):
            assert name in ("layout/", "templates/"), name
        else:
            assert r["current"] and r["kind"], r
    out = subprocess.run([sys.executable, "-m", "rclverify.cli.commands", "cache", "-w", str(workspace)],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and "report-fragments" in out.stdout and "other code" not in out.stdout, out.stdout


def test_the_model_diagram_is_drawn_by_doit_graph_not_by_verify(workspace: Path) -> None:
    system = workspace / "artifacts" / "system"
    assert not (system / "model.dot").exists() and not (system / "model.svg").exists()  # verify ran before
    r = _doit(workspace, "graph")
    assert r.returncode == 0, r.stdout + r.stderr
    dot = (system / "model.dot").read_text()
    assert dot.lstrip().startswith(("digraph", "//")) and "Agent" in dot
    if shutil.which("dot"):
        assert "<svg" in (system / "model.svg").read_text()


def test_strict_mode_fails_on_open_evidence(workspace: Path) -> None:
    r = _doit(workspace, "verify", "--strict")
    assert r.returncode != 0
    assert "--strict" in r.stdout + r.stderr


def test_bad_rcl_gives_located_error_and_keeps_evidence(workspace: Path, tmp_path: Path) -> None:
    rcl = workspace / "contracts" / "remote_inspection.rcl"
    before = {p.name: p.read_bytes() for p in (workspace / "artifacts" / "evidence").glob("*.json")}
    original = rcl.read_text()
    with restored(workspace, tmp_path / "before"):
        rcl.write_text(original.replace("assume( 0 <= in.r )", "assume( 0 <= in.rr )"))
        r = _doit(workspace, "verify")
        out = r.stdout + r.stderr
        assert r.returncode != 0
        assert "remote_inspection.rcl:" in out and "no input named 'rr'" in out
        assert "Traceback" not in out
        after = {p.name: p.read_bytes() for p in (workspace / "artifacts" / "evidence").glob("*.json")}
        assert after == before
    assert rcl.read_text() == original


def test_staleness_follows_the_inputs_of_each_obligation(workspace: Path, tmp_path: Path) -> None:
    plan = workspace / "contracts" / "plan.yaml"
    program = workspace / "backends" / "hoare" / "radiation_sensor.imp"
    plan_text, program_text = plan.read_text(), program.read_text()
    with restored(workspace, tmp_path / "before"):
        # a change that concerns no node's evidence keeps every record fresh
        plan.write_text(plan_text.replace("Each waypoint only needs", "Each waypoint needs"))
        assert _doit(workspace, "verify").returncode == 0
        report = json.loads((workspace / "reports" / "assurance.json").read_text())
        assert not [e for e in report["evidence"] if e["status"] == "stale"]
        # a changed backend input makes its evidence stale until it is re-run
        program.write_text(program_text + "\n// reviewed\n")
        r = subprocess.run([sys.executable, "-m", "rclverify.cli.commands", "report", "-w", str(workspace)],
                           capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, r.stderr
        report = json.loads((workspace / "reports" / "assurance.json").read_text())
        stale = {e["obligation"] for e in report["evidence"] if e["status"] == "stale"}
        assert stale and all(".hoare.radiation_sensor.c" in s for s in stale)
        r = _doit(workspace, "verify")
        rerun = sorted(l[3:] for l in r.stdout.splitlines() if l.startswith(".  evidence:"))
        # one task per obligation: exactly the four triples over the edited program re-run
        assert rerun == [f"evidence:RadiationSensor.g1.hoare.radiation_sensor.c{k}" for k in range(1, 5)]
        report = json.loads((workspace / "reports" / "assurance.json").read_text())
        assert not [e for e in report["evidence"] if e["status"] == "stale"]
    assert (plan.read_text(), program.read_text()) == (plan_text, program_text)


def _statuses(report: dict) -> dict:
    keys = ("requirements", "nodes", "side_conditions", "derived_properties", "findings", "obligations", "evidence")
    return {k: sorted((x.get("id") or x.get("obligation") or x.get("node"), x["status"]) for x in report[k]) for k in keys}


def test_the_parallel_run_gives_the_serial_results(report: dict) -> None:
    """The module's run is `doit -n 2 verify`; every status of its report equals the stored serial
    run's (tests/data/case-study-report.json.gz, regenerated as its test above says), the
    replacement check's too: its queries run from their canonical text in a fresh, resource-bounded
    Z3 context."""
    assert _statuses(report) == _statuses(_stored())


def test_side_conditions_are_written_for_a_second_solver(report: dict, workspace: Path) -> None:
    import z3
    for sc in report["side_conditions"]:
        s = z3.Solver(ctx=z3.Context())  # a fresh solver instance, as a second solver would be
        s.from_file(str(workspace / sc["smt2"]))  # the negated side condition: unsat means it holds
        assert s.check() == z3.unsat, sc["id"]


def test_editing_one_contract_reruns_that_node_its_consumers_and_the_report(workspace: Path, tmp_path: Path) -> None:
    rcl = workspace / "contracts" / "remote_inspection.rcl"
    original = rcl.read_text()
    with restored(workspace, tmp_path / "before"):
        rcl.write_text(original.replace("and (250 <= in.r -> out.radiationStatus == red)",
                                        "and (251 <= in.r -> out.radiationStatus == red)"))
        r = _doit(workspace, "verify")
        assert r.returncode == 0, r.stdout + r.stderr
        ran = {l[3:] for l in r.stdout.splitlines() if l.startswith(".  ")}
        evidence = {t for t in ran if t.startswith("evidence:")}
        assert evidence and all(t.startswith("evidence:RadiationSensor.") for t in evidence)
        # `ground` too: the grounding of the plan's ros: section reads every contract (its file_dep)
        # `crosscheck`: the second solver decides the changed side conditions and health checks again
        # `health:RadiationSensor`, not `health:Agent`: a consumer's health checks read only its own contract
        assert ran - evidence == {"check", "node:RadiationSensor", "node:Agent", "health:RadiationSensor",
                                  "requirements", "ground", "crosscheck", "diagnosis", "report:html", "report:text", "verify"}
        # the formal requirements whose cone holds RadiationSensor: all four (the loop; REQ4 temporal over the same cone)
        assert "requirements: 4 of 4 checked (REQ1, REQ2, REQ3, REQ4)" in r.stdout
        # in the node tasks, only the stages whose own inputs changed: the consumer's side conditions
        assert "RadiationSensor: compose, export" in r.stdout and "RadiationSensor: health" in r.stdout
        assert re.search(r"Agent: compose(?!,)", r.stdout)
        # its report tasks rendered with the previous run's pieces (report/fragments.py): the same
        # bytes as a report rendered without any, and each task kept exactly its own files' pieces
        assert _reports(workspace) == _render(workspace, tmp_path / "plain", None)
        edited = build_report(Workspace(workspace))
        for part, rel in FRAGMENTS.items():
            kept = FragmentCache(workspace / rel)
            write_part(edited, tmp_path / "warm", part, kept)
            assert kept.misses == 0, part
        assert _reports(tmp_path / "warm", "") == _reports(workspace)
    assert rcl.read_text() == original


def test_every_violation_of_a_run_is_kept_and_explained_one_by_one(workspace: Path, report: dict,
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    """Issue 47/48: a run keeps every violation (time, message, guarantee, values, the question
    answered), not only the first; `rclverify explain OBLIGATION#N` reaches each."""
    from rclverify.cli.commands import main
    ev = next(e for e in report["evidence"] if e["obligation"] == "Agent.g0.monitors.nominal_jsonl")
    vs = ev["monitoring"]["violations"]
    assert len(vs) == ev["monitoring"]["counts"]["violated"] == 12
    assert vs[0] == ev["monitoring"]["first_violation"] and all(v["guarantee"] == 3 for v in vs)
    assert main(["explain", "-w", str(workspace), "Agent.g0.monitors.nominal_jsonl#2"]) == 0
    out = capsys.readouterr().out
    assert out.startswith(f"violation Agent.g0.monitors.nominal_jsonl#2 of 12 on backends/monitors/traces/nominal.jsonl: "
                          f"{vs[1]['where']}") and "answering the question at" in out and "out.command = " in out
    assert main(["explain", "-w", str(workspace), "Agent.g0.monitors.nominal_jsonl"]) == 0
    assert "Agent.g0.monitors.nominal_jsonl#12" in capsys.readouterr().out


# --- the report's kept pieces (report/fragments.py) on this verified copy -------------------------

#: Every file the report task writes (argument.svg only with Graphviz).
FILES = ("assurance.html", "assurance.md", "assurance.json", "assurance.sarif", "assurance.junit.xml",
         "argument.json", "argument.gsn.yaml", "argument.dot", "argument.svg")


def _render(ws: Path, out: Path, fragments: FragmentCache | None) -> dict[str, bytes]:
    """Every report file of ``ws`` rendered into ``out`` (as the report task does)."""
    from rclverify.report.argument.export import write_argument
    from rclverify.report.ci import write_ci_reports
    from rclverify.report.render import render_all
    report = build_report(Workspace(ws))
    render_all(report, out, fragments=fragments)
    write_ci_reports(report, out, fragments)
    write_argument(report, out, fragments)
    return {name: (out / name).read_bytes() for name in FILES if (out / name).exists()}


def _reports(ws: Path, sub: str = "reports") -> dict[str, bytes]:
    return {name: (ws / sub / name).read_bytes() for name in FILES if (ws / sub / name).exists()}


@pytest.fixture(scope="module")
def plain(workspace: Path, tmp_path_factory: pytest.TempPathFactory) -> dict[str, bytes]:
    """Every report file of the verified workspace rendered without kept pieces: one rendering read by
    the two tests below (the workspace is as verified for both: the tests that edit it put it back)."""
    return _render(workspace, tmp_path_factory.mktemp("plain"), None)


def test_empty_and_warm_cache_give_the_uncached_report(workspace: Path, report: dict, plain: dict[str, bytes],
                                                       tmp_path: Path) -> None:
    assert set(plain) >= set(FILES) - {"argument.svg"}
    empty = FragmentCache(tmp_path / "cache.pickle")
    assert _render(workspace, tmp_path / "empty", empty) == plain
    assert empty.misses > 0 and empty.save()
    warm = FragmentCache(tmp_path / "cache.pickle")
    assert _render(workspace, tmp_path / "warm", warm) == plain
    assert warm.misses == 0 and warm.hits == empty.hits + empty.misses
    # what the doit run wrote with its own cache is the same text too
    assert _reports(workspace) == plain
    assert cached_dumps(report, FragmentCache()) == dumps(report)


def test_the_report_parts_write_disjoint_files_that_together_are_the_whole_report(
        workspace: Path, plain: dict[str, bytes], tmp_path: Path) -> None:
    built = build_report(Workspace(workspace))
    for part in reversed(PARTS):  # the order the two report tasks finish in does not matter
        written = [p.name for p in write_part(built, tmp_path / part, part)]
        assert set(written) <= set(PARTS[part]) and set(PARTS[part]) - set(written) <= {"argument.svg"}
        assert sorted(p.name for p in (tmp_path / part).iterdir()) == sorted(written)
    assert not set(PARTS["html"]) & set(PARTS["text"])
    both = {**_reports(tmp_path, "html"), **_reports(tmp_path, "text")}
    assert both == plain
